#include "rigs/oedometer/oedometer.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "rigs/common/analysis.hpp"
#include "rigs/common/specimen.hpp"

namespace rocklab::rigs::oedometer {

using protocol::range;
using protocol::Settings;

void declare(protocol::Schema& s) {
  s.choice("loading.control", {"strain_rate", "stress_ramp"}, "strain_rate",
           "drive the axial walls at a strain rate, or servo them along a stress ramp");
  range(s.real("loading.axial_strain_rate_per_s", "1/s", 1, 5.0,
               "axial strain rate (strain_rate control); its inertial number is checked"),
        0, true, 1e6, false);
  range(s.real("loading.axial_strain_max", "-", 1, 0.03,
               "axial strain since formation at which loading stops"),
        0, true, 0.9, false);
  range(s.real("loading.axial_stress_rate_MPa_per_s", "MPa/s", 1e6, 1e5,
               "axial stress rate (stress_ramp control)"),
        0, true, 1e12, false);
  range(s.real("loading.axial_stress_max_MPa", "MPa", 1e6, 100.0,
               "axial stress at which a stress ramp stops"),
        0, true, 1e5, false);
  range(s.realList("loading.cycle_at_axial_strain", "-", 1, std::vector<double>{},
                   "axial strains at which the axial stress is cycled: unloaded, then reloaded"),
        0, true, 0.9, false);
  range(s.real("loading.cycle_unload_fraction", "-", 1, 0.5,
               "each cycle unloads this fraction of the axial stress gained since formation "
               "(below 1: a cycle never unloads past the formation state, which would core)"),
        0, true, 1, false);
  s.flag("coring.enabled", false,
         "also core the formed sample (unload to near zero stress, reload) and test it beside "
         "the virgin one");
  range(s.real("coring.unload_to_MPa", "MPa", 1e6, 0.5, "the stress coring unloads to, all axes"),
        0, true, 1e4, false);
  range(s.real("coring.stress_rate_MPa_per_s", "MPa/s", 1e6, 2e4,
               "stress rate of the coring unload and the reload"),
        0, true, 1e12, false);
}

void validate(const Settings& s) {
  const auto cycles = s.list("loading.cycle_at_axial_strain");
  if (!cycles.empty() && s.text("loading.control") != "strain_rate") {
    protocol::fail(s, "loading.cycle_at_axial_strain", "cycles need loading.control = strain_rate");
  }
  for (std::size_t k = 0; k < cycles.size(); ++k) {
    if (cycles[k] >= s.real("loading.axial_strain_max")) {
      protocol::fail(s, "loading.cycle_at_axial_strain",
                     "every cycle strain must be below loading.axial_strain_max");
    }
    if (k > 0 && cycles[k] <= cycles[k - 1]) {
      protocol::fail(s, "loading.cycle_at_axial_strain", "cycle strains must increase");
    }
  }
  if (s.flag("coring.enabled") &&
      s.real("coring.unload_to_MPa") >= s.real("formation.lateral_stress_MPa")) {
    protocol::fail(s, "coring.unload_to_MPa", "coring must unload below the formation stresses");
  }
}

namespace {

// One recorded point of the loading.
struct Sample {
  double strain, axial, lateral, broken;
  int phase;  // 0 loading, 1 unloading, 2 reloading
};

struct Cycle {
  double at_strain = 0, peak_stress = 0, peak_strain = 0, low_stress = 0, low_strain = 0;
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

// Runs the uniaxial-strain loading and records its results; returns the initial tangent
// modulus (Pa).
template <int D>
double loadOedometric(Specimen<D>& sp, const Settings& s, Recorder& rec, RunControl& control,
                      const std::string& branch) {
  using Axis = typename LoadingFrame<D>::Axis;
  using Mode = typename LoadingFrame<D>::Mode;
  constexpr int ax = Specimen<D>::kAxial;
  auto& sim = *sp.sim;
  auto& frame = *sp.frame;
  const std::string stage = branch.empty() ? "loading" : branch;
  const std::string prefix = branch.empty() ? "" : branch + ".";
  const bool strain_control = s.text("loading.control") == "strain_rate";
  const double rate = s.real("loading.axial_strain_rate_per_s");
  const double strain_max = s.real("loading.axial_strain_max");
  const double stress_max = s.si("loading.axial_stress_max_MPa");
  const std::vector<double> cycle_at = s.list("loading.cycle_at_axial_strain");
  const double unload_fraction = s.real("loading.cycle_unload_fraction");

  for (int a = 0; a < D; ++a) {
    if (a != ax) frame.set(a, Axis{Mode::Fixed});
  }
  frame.resetReference();
  const double sigma0 = frame.stress(ax);
  if (strain_control) {
    frame.set(ax, Axis{Mode::StrainRate, rate});
  } else {
    frame.set(ax, Axis{Mode::Stress, 0.0, sigma0, s.si("loading.axial_stress_rate_MPa_per_s")});
  }

  std::vector<Sample> pts;
  std::vector<Cycle> cycles;
  std::size_t next_cycle = 0;
  int phase = 0;
  double unbalanced_sum = 0.0, inertial_max = 0.0;
  std::size_t loading_records = 0;
  const std::uint64_t start = sim.steps();
  auto lateral = [&] {
    double l = 0.0;
    for (int a = 0; a < D; ++a) {
      if (a != ax) l += frame.stress(a) / (D - 1);
    }
    return l;
  };
  auto record = [&] {
    const double edot = phase == 1 ? -rate : rate;
    recordState(sp, rec, prefix, stage, strain_control ? edot : 0.0);
    rec.series(prefix + "phase", sim.steps(), sim.time(), phase);
    pts.push_back(
        {frame.strain(ax), frame.stress(ax), lateral(),
         static_cast<double>(sp.broken(BondBreakMode::Tensile) + sp.broken(BondBreakMode::Shear)),
         phase});
    if (phase == 0) {
      unbalanced_sum += sim.unbalancedForceRatio();
      ++loading_records;
      if (strain_control) inertial_max = std::max(inertial_max, inertialNumber(sp, rate));
    }
  };
  record();
  for (;;) {
    frame.step();
    const double strain = frame.strain(ax);
    const double stress = frame.stress(ax);
    if (phase == 0 && next_cycle < cycle_at.size() && strain >= cycle_at[next_cycle]) {
      record();
      cycles.push_back({cycle_at[next_cycle], stress, strain, 0, 0});
      phase = 1;
      frame.set(ax, Axis{Mode::StrainRate, -rate});
    } else if (phase == 1 && stress <= cycles.back().peak_stress -
                                           unload_fraction * (cycles.back().peak_stress - sigma0)) {
      record();
      cycles.back().low_stress = stress;
      cycles.back().low_strain = strain;
      phase = 2;
      frame.set(ax, Axis{Mode::StrainRate, rate});
    } else if (phase == 2 && strain >= cycles.back().peak_strain) {
      record();
      phase = 0;
      ++next_cycle;
    }
    const bool finished = strain_control ? strain >= strain_max : stress >= stress_max;
    if (finished) {
      record();
      snapshot(sp, s, rec, stage, "final");
      break;
    }
    if ((sim.steps() - start) % sp.record_every == 0) record();
    if (sp.snapshot_every && (sim.steps() - start) % sp.snapshot_every == 0) {
      snapshot(sp, s, rec, stage, "step " + std::to_string(sim.steps() - start));
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

  // Key results of the test.
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
  for (std::size_t k = 0; k < cycles.size(); ++k) {
    const Cycle& c = cycles[k];
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
  const double mean_unbalanced = loading_records ? unbalanced_sum / loading_records : 0.0;
  put("loading_steps", static_cast<double>(sim.steps() - start), "");
  put("mean_unbalanced_force_ratio", mean_unbalanced, "");
  if (strain_control) put("max_inertial_number", inertial_max, "");

  warnIfNotQuasiStatic(sim, s, rec, stage, mean_unbalanced, strain_control ? inertial_max : 0.0);
  return e0;
}

template <int D>
void runDimension(const Settings& s, Recorder& rec, RunControl& control) {
  Specimen<D> sp = buildSpecimen<D>(s, control);
  rec.result("particles", static_cast<double>(sp.sim->particles().size()), "");
  formAndCement(sp, s, rec, control);
  if (!s.flag("coring.enabled")) {
    loadOedometric(sp, s, rec, control, "");
    recordTimings<D>(rec, {sp.sim.get()});
    return;
  }
  Specimen<D> virgin = sp.branch();
  const double virgin_modulus = loadOedometric(virgin, s, rec, control, "virgin");

  constexpr int ax = Specimen<D>::kAxial;
  const double rate = s.si("coring.stress_rate_MPa_per_s");
  const double low = s.si("coring.unload_to_MPa");
  servoTo(sp, s, low, low, rate, "coring", rec, control);
  rec.result(
      "broken_bonds_by_coring",
      static_cast<double>(sp.broken(BondBreakMode::Tensile) + sp.broken(BondBreakMode::Shear)), "");
  servoTo(sp, s, s.si("formation.axial_stress_MPa"), s.si("formation.lateral_stress_MPa"), rate,
          "reloading", rec, control);
  rec.result("axial_strain_after_coring_and_reloading", sp.frame->strain(ax), "");
  sp.frame->resetReference();
  sp.resetBrokenCount();
  const double cored_modulus = loadOedometric(sp, s, rec, control, "cored");
  rec.result("cored_to_virgin_initial_modulus_ratio", cored_modulus / virgin_modulus, "");
  recordTimings<D>(rec, {sp.sim.get(), virgin.sim.get()});
}

}  // namespace

void run(const Settings& s, Recorder& rec, RunControl& control) {
  byDimension(s, [&](auto dim) { runDimension<dim.value>(s, rec, control); });
}

}  // namespace rocklab::rigs::oedometer
