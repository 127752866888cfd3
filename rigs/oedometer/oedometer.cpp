#include "rigs/oedometer/oedometer.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "rigs/common/analysis.hpp"
#include "rigs/common/formation.hpp"
#include "rigs/common/measurements.hpp"

namespace rocklab::rigs::oedometer {

void Settings::validate() const {
  const std::string cycles = "loading.cycle_at_axial_strain";
  const auto& at = cycle_at_axial_strain;
  if (!at.empty() && control != Control::StrainRate) {
    throw InvalidParameter("", cycles, "cycles need loading.control = strain_rate");
  }
  for (std::size_t k = 0; k < at.size(); ++k) {
    if (at[k] >= axial_strain_max) {
      throw InvalidParameter("", cycles,
                             "every cycle strain must be below loading.axial_strain_max");
    }
    if (k > 0 && at[k] <= at[k - 1])
      throw InvalidParameter("", cycles, "cycle strains must increase");
  }
  if (boost.max > 1.0 && control != Control::StrainRate) {
    throw InvalidParameter("", "loading.rate_boost_max",
                           "the rate boost needs loading.control = strain_rate");
  }
  if (coring && coring_unload_to >= specimen.formation.lateral_stress) {
    throw InvalidParameter("", "coring.unload_to_MPa",
                           "coring must unload below the formation stresses");
  }
}

namespace {

// One recorded point of the loading.
struct Sample {
  double strain, axial, lateral, broken;
  int phase;  // 0 loading, 1 unloading, 2 reloading
  template <class Archive>
  void visit(Archive& ar) {
    ar("strain", strain), ar("axial", axial), ar("lateral", lateral), ar("broken", broken);
    ar("phase", phase);
  }
};

struct Cycle {
  double at_strain = 0, peak_stress = 0, peak_strain = 0, low_stress = 0, low_strain = 0;
  template <class Archive>
  void visit(Archive& ar) {
    ar("at_strain", at_strain), ar("peak_stress", peak_stress), ar("peak_strain", peak_strain);
    ar("low_stress", low_stress), ar("low_strain", low_strain);
  }
};

// Fits over the loading points with strain in [lo, hi].
double fitWindow(const std::vector<Sample>& pts, double lo, double hi, bool stress_path) {
  std::vector<double> x, y;
  for (const Sample& p : pts) {
    if (p.phase != 0 || p.strain < lo || p.strain > hi) continue;
    x.push_back(stress_path ? p.axial : p.strain);
    y.push_back(stress_path ? p.lateral : p.axial);
  }
  return slope(x, y);
}

// What the loading loop keeps: every recorded point, the cycles, where it is in them, and
// how well the loading was controlled.
struct OedometricHistory {
  std::vector<Sample> pts;
  std::vector<Cycle> cycles;
  std::size_t next_cycle = 0;
  int phase = 0;
  std::uint64_t steps = 0;
  double unbalanced_sum = 0.0, inertial_max = 0.0;
  std::size_t loading_records = 0;
  AdaptiveRate rate;
  double meanUnbalanced() const { return loading_records ? unbalanced_sum / loading_records : 0.0; }
  // The loop's state in a checkpoint (rigs/common/journal.hpp).
  template <class Archive>
  void visit(Archive& ar) {
    ar("pts", pts), ar("cycles", cycles), ar("next_cycle", next_cycle), ar("phase", phase);
    ar("steps", steps), ar("unbalanced_sum", unbalanced_sum), ar("inertial_max", inertial_max);
    ar("loading_records", loading_records), ar("rate", rate);
  }
};

// Drives the axial walls (strain rate or stress ramp; the lateral walls fixed) to the end of
// loading, cycling where asked, and records the state.
template <int D>
OedometricHistory loadUniaxially(Specimen<D>& sp, const Settings& s, Recorder& rec,
                                 RunControl& control, const std::string& stage,
                                 const std::string& prefix) {
  using Axis = typename LoadingFrame<D>::Axis;
  using Mode = typename LoadingFrame<D>::Mode;
  constexpr int ax = Specimen<D>::kAxial;
  auto& sim = *sp.sim;
  auto& frame = *sp.frame;
  const bool strain_control = s.control == Control::StrainRate;
  const double rate = s.axial_strain_rate;
  const double strain_max = s.axial_strain_max;
  const double stress_max = s.axial_stress_max;
  const std::vector<double>& cycle_at = s.cycle_at_axial_strain;
  const auto record_every = static_cast<std::uint64_t>(sp.settings.output.record_every_steps);
  const auto snapshot_every = static_cast<std::uint64_t>(sp.settings.output.snapshot_every_steps);

  OedometricHistory h;
  h.rate = AdaptiveRate(s.boost);
  Journal::Unit unit = control.unit(stage);
  if (unit.done(h, sp)) return h;
  for (int a = 0; a < D; ++a) {
    if (a != ax) frame.set(a, Axis{Mode::Fixed});
  }
  frame.resetReference();
  const double sigma0 = frame.stress(ax);
  if (strain_control) {
    frame.set(ax, Axis{Mode::StrainRate, rate});
  } else {
    frame.set(ax, Axis{Mode::Stress, 0.0, sigma0, s.axial_stress_rate});
  }

  std::size_t& next_cycle = h.next_cycle;
  int& phase = h.phase;
  const std::uint64_t start = sim.steps();
  auto lateral = [&] {
    double l = 0.0;
    for (int a = 0; a < D; ++a) {
      if (a != ax) l += frame.stress(a) / (D - 1);
    }
    return l;
  };
  // The axial strain rate now: the set one times the boost (1 unless the sample is calm)
  // while loading; a cycle is a measurement of the moduli and runs at the set rate,
  // negative while it unloads.
  auto rateNow = [&] { return phase == 0 ? rate * h.rate.factor() : phase == 1 ? -rate : rate; };
  auto record = [&] {
    const double edot = rateNow();
    recordState(sp, rec, prefix, stage, strain_control ? edot : 0.0);
    rec.series(prefix + "phase", sim.steps(), sim.time(), phase);
    if (strain_control)
      rec.series(prefix + "axial_strain_rate_per_s", sim.steps(), sim.time(), edot);
    h.pts.push_back(
        {frame.strain(ax), frame.stress(ax), lateral(),
         static_cast<double>(sp.broken(BondBreakMode::Tensile) + sp.broken(BondBreakMode::Shear)),
         phase});
    if (phase == 0) {
      h.unbalanced_sum += sim.unbalancedForceRatio();
      ++h.loading_records;
      if (strain_control) {
        h.inertial_max = std::max(h.inertial_max, inertialNumber(sp, std::abs(edot)));
      }
    }
  };
  record();
  unit.resume(h, sp);
  for (;;) {
    unit.tick(h, sp);  // before the step: the loop goes on from a checkpoint's state
    frame.step();
    const double strain = frame.strain(ax);
    const double stress = frame.stress(ax);
    auto& cycles = h.cycles;
    if (phase == 0 && next_cycle < cycle_at.size() && strain >= cycle_at[next_cycle]) {
      record();
      cycles.push_back({cycle_at[next_cycle], stress, strain, 0, 0});
      phase = 1;
      frame.set(ax, Axis{Mode::StrainRate, rateNow()});
    } else if (phase == 1 &&
               stress <= cycles.back().peak_stress -
                             s.cycle_unload_fraction * (cycles.back().peak_stress - sigma0)) {
      record();
      cycles.back().low_stress = stress;
      cycles.back().low_strain = strain;
      phase = 2;
      frame.set(ax, Axis{Mode::StrainRate, rateNow()});
    } else if (phase == 2 && strain >= cycles.back().peak_strain) {
      record();
      phase = 0;
      ++next_cycle;
      h.rate = AdaptiveRate(s.boost);  // from the set rate again, rising as the sample stays calm
    }
    const bool finished = strain_control ? strain >= strain_max : stress >= stress_max;
    if (finished) {
      record();
      snapshot(sp, rec, stage, "final");
      break;
    }
    if ((sim.steps() - start) % record_every == 0) record();
    if (h.rate.window(sim.steps() - start, sim)) frame.set(ax, Axis{Mode::StrainRate, rateNow()});
    if (snapshot_every && (sim.steps() - start) % snapshot_every == 0) {
      snapshot(sp, rec, stage, "step " + std::to_string(sim.steps() - start));
    }
    if (sim.steps() % 100 == 0) {
      const double fraction =
          strain_control ? strain / strain_max : (stress - sigma0) / (stress_max - sigma0);
      control.tick(stage, sim.steps(), fraction,
                   "axial " + fmt(stress / 1e6) + " MPa, strain " + fmt(strain));
    }
    if (!strain_control && strain >= 0.9) {
      throw std::runtime_error(stage + ": the axial stress ramp reached 90% strain before " +
                               fmt(stress_max / 1e6) + " MPa");
    }
  }
  h.steps = sim.steps() - start;
  unit.finish(h, sp);
  return h;
}

// The test's results: tangent moduli and stress-path slopes over the first and last tenth,
// the final state, the breaks, each cycle's moduli, the loading's control. Returns the
// initial tangent modulus (Pa).
template <int D>
double recordOedometricResults(const Specimen<D>& sp, const OedometricHistory& h,
                               bool strain_control, const std::string& prefix, Recorder& rec) {
  const auto& pts = h.pts;
  const double eps_end = pts.back().strain;
  auto put = [&](const std::string& name, double v, const std::string& unit) {
    rec.result(prefix + name, v, unit);
  };
  const double window = 0.1 * eps_end;
  const double e0 = fitWindow(pts, 0.0, window, false);
  const double e1 = fitWindow(pts, eps_end - 1.5 * window, eps_end, false);
  put("tangent_modulus_initial_MPa", e0 / 1e6, "MPa");
  put("tangent_modulus_final_MPa", e1 / 1e6, "MPa");
  put("tangent_modulus_ratio", e1 / e0, "");
  put("stress_path_slope_initial", fitWindow(pts, 0.0, window, true), "");
  put("stress_path_slope_final", fitWindow(pts, eps_end - 1.5 * window, eps_end, true), "");
  put("axial_strain_final", eps_end, "");
  put("axial_stress_final_MPa", pts.back().axial / 1e6, "MPa");
  put("lateral_stress_final_MPa", pts.back().lateral / 1e6, "MPa");
  const double tensile = static_cast<double>(sp.broken(BondBreakMode::Tensile));
  const double shear = static_cast<double>(sp.broken(BondBreakMode::Shear));
  put("broken_bonds_tensile", tensile, "");
  put("broken_bonds_shear", shear, "");
  put("broken_bonds_total", tensile + shear, "");
  double first_break = NAN, at_tenth = 0.0;
  for (const Sample& p : pts) {
    if (std::isnan(first_break) && p.broken > 0) first_break = p.strain;
    if (p.strain <= 0.1 * eps_end) at_tenth = p.broken;
  }
  put("axial_strain_at_first_break", first_break, "");
  put("broken_bonds_by_tenth_of_loading", at_tenth, "");
  for (std::size_t k = 0; k < h.cycles.size(); ++k) {
    const Cycle& c = h.cycles[k];
    const std::string n = "cycle" + std::to_string(k + 1) + "_";
    // The loading tangent just before the cycle, against the secant of the unloading: 1 for
    // an elastic cycle, below 1 as the loading carried plastic strain.
    const double e_load = fitWindow(pts, 0.8 * c.peak_strain, c.peak_strain, false);
    const double e_unload = (c.peak_stress - c.low_stress) / (c.peak_strain - c.low_strain);
    put(n + "at_axial_strain", c.at_strain, "");
    put(n + "loading_modulus_MPa", e_load / 1e6, "MPa");
    put(n + "unloading_modulus_MPa", e_unload / 1e6, "MPa");
    put(n + "modulus_ratio", e_load / e_unload, "");
  }
  put("loading_steps", static_cast<double>(h.steps), "");
  put("mean_unbalanced_force_ratio", h.meanUnbalanced(), "");
  if (strain_control) put("max_inertial_number", h.inertial_max, "");
  return e0;
}

// The uniaxial-strain test of one branch (none, "virgin", "cored"); returns its initial
// tangent modulus (Pa).
template <int D>
double loadOedometric(Specimen<D>& sp, const Settings& s, Recorder& rec, RunControl& control,
                      const std::string& branch) {
  const std::string stage = branch.empty() ? "loading" : branch;
  const std::string prefix = branch.empty() ? "" : branch + ".";
  const bool strain_control = s.control == Control::StrainRate;
  const OedometricHistory h = loadUniaxially(sp, s, rec, control, stage, prefix);
  const double e0 = recordOedometricResults(sp, h, strain_control, prefix, rec);
  warnIfNotQuasiStatic(sp, rec, stage, h.meanUnbalanced(), strain_control ? h.inertial_max : 0.0);
  return e0;
}

template <int D>
void runDimension(const Settings& s, Recorder& rec, RunControl& control) {
  Specimen<D> sp = buildSpecimen<D>(s.specimen, control);
  rec.result("particles", static_cast<double>(sp.sim->particles().size()), "");
  formAndCement(sp, rec, control);
  if (!s.coring) {
    loadOedometric(sp, s, rec, control, "");
    recordTimings<D>(rec, {sp.sim.get()});
    return;
  }
  Specimen<D> virgin = sp.branch();
  const double virgin_modulus = loadOedometric(virgin, s, rec, control, "virgin");

  constexpr int ax = Specimen<D>::kAxial;
  const double rate = s.coring_stress_rate;
  const double low = s.coring_unload_to;
  servoTo(sp, low, low, rate, "coring", rec, control);
  rec.result(
      "broken_bonds_by_coring",
      static_cast<double>(sp.broken(BondBreakMode::Tensile) + sp.broken(BondBreakMode::Shear)), "");
  const FormationSettings& formed = s.specimen.formation;
  servoTo(sp, formed.axial_stress, formed.lateral_stress, rate, "reloading", rec, control);
  rec.result("axial_strain_after_coring_and_reloading", sp.frame->strain(ax), "");
  sp.frame->resetReference();
  sp.resetBrokenCount();
  const double cored_modulus = loadOedometric(sp, s, rec, control, "cored");
  rec.result("cored_to_virgin_initial_modulus_ratio", cored_modulus / virgin_modulus, "");
  recordTimings<D>(rec, {sp.sim.get(), virgin.sim.get()});
}

}  // namespace

void run(const Settings& s, Recorder& rec, RunControl& control) {
  byDimension(s.specimen.protocol.dimension,
              [&](auto dim) { runDimension<dim.value>(s, rec, control); });
}

}  // namespace rocklab::rigs::oedometer
