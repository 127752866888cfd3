#include "rigs/biaxial/biaxial.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <sstream>

#include "rigs/biaxial/loading.hpp"
#include "rigs/common/localisation.hpp"

namespace rocklab::rigs::biaxial {

using protocol::range;
using protocol::Settings;

void declareLoading(protocol::Schema& s) {
  range(s.real("loading.confining_rate_MPa_per_s", "MPa/s", 1e6, 2e4,
               "stress rate from the formation state to the confinement"),
        0, true, 1e12, false);
  range(s.real("loading.seating_stress_MPa", "MPa", 1e6, 0.1,
               "axial stress above the confinement the platens keep before loading"),
        0, false, 1e3, false);
  range(s.real("loading.axial_strain_rate_per_s", "1/s", 1, 1.0,
               "axial strain rate; its inertial number is checked"),
        0, true, 1e6, false);
  range(s.real("loading.axial_strain_max", "-", 1, 0.05,
               "axial strain since the start of loading at which loading stops"),
        0, true, 0.9, false);
  range(s.real("analysis.band_width_radii", "-", 1, 8.0,
               "width of the trial band of the localisation analysis, in mean particle radii"),
        1, false, 1e3, false);
  range(s.real("analysis.strained_fraction", "-", 1, 0.15,
               "fraction of the particles, the most strained from the critical point to the "
               "end, in which the band of the strain field is sought"),
        0, true, 1, false);
  range(s.real("loading.stop_after_drop", "-", 1, 0.0,
               "stop once the deviatoric stress has fallen this fraction below its peak "
               "(0: run to axial_strain_max)"),
        0, false, 1, false);
  range(s.real("loading.stop_after_drop_min_strain", "-", 1, 0.002,
               "the drop stops the test only past this axial strain: the first grains to "
               "break or slip under a barely loaded sample make no peak"),
        0, false, 0.9, false);
}

void validateLoading(const Settings& s) {
  // A test that stops after the peak must get past it: a drop needs room to show.
  if (s.real("loading.stop_after_drop") > 0.0 &&
      s.real("loading.axial_strain_max") <=
          std::max(1e-3, s.real("loading.stop_after_drop_min_strain"))) {
    protocol::fail(s, "loading.axial_strain_max",
                   "is too small to pass the peak that loading.stop_after_drop waits for (more "
                   "than 0.001 and than loading.stop_after_drop_min_strain)");
  }
}

void declare(protocol::Schema& s) {
  range(s.real("loading.confining_stress_MPa", "MPa", 1e6, 4.0,
               "lateral stress held by servo walls during loading (sigma_3); 0: UCS test"),
        0, false, 1e4, false);
  declareLoading(s);
}

void validate(const Settings& s) {
  validateLoading(s);
}

namespace {

template <int D>
double lateralStress(const LoadingFrame<D>& f) {
  double sum = 0.0;
  for (int a = 0; a < D - 1; ++a) sum += f.stress(a);
  return sum / (D - 1);
}

// The positions of the particles in slot order (stable through re-sorting), z = 0 in 2D.
template <int D>
std::vector<std::array<double, 3>> slotPositions(const Simulation<D>& sim) {
  const auto& P = sim.particles();
  std::vector<std::array<double, 3>> out(P.size(), {0.0, 0.0, 0.0});
  for (std::size_t s = 0; s < P.size(); ++s) {
    const auto& x = P.pos[P.indexOfSlot(static_cast<std::uint32_t>(s))];
    for (int d = 0; d < D; ++d) out[s][d] = x[d];
  }
  return out;
}

// A band (rigs/common/localisation.hpp) to the notebook as `prefix + name + "_..."`;
// `what` says in which points it was found;
// `who` names the test of a sweep in messages ("test2: ").
template <int D>
void reportBand(const Specimen<D>& sp, const Band& b, const std::string& prefix,
                const std::string& who, const std::string& name, const std::string& what,
                Recorder& rec) {
  const auto& sim = *sp.sim;
  const std::string p = prefix + name;
  rec.result(p + "_angle_deg", b.angle_to_axial_deg, "deg");
  rec.result(p + "_is_compaction", b.is_compaction() ? 1.0 : 0.0, "");
  rec.result(p + "_thickness_mm", b.thickness * 1e3, "mm");
  rec.result(p + "_contrast", b.contrast, "");
  rec.result(p + "_points", static_cast<double>(b.points), "");
  rec.message(sim.steps(), sim.time(), "info",
              who + "in the " + what + ": " + (b.is_compaction() ? "compaction" : "shear") +
                  " band at " + fmt(b.angle_to_axial_deg) + " deg to sigma_1, " +
                  fmt(b.thickness * 1e3) + " mm thick, " + fmt(b.contrast) +
                  " times the mean density");
}

template <int D>
void noBand(const Specimen<D>& sp, const std::string& who, const std::string& what, Recorder& rec) {
  rec.message(sp.sim->steps(), sp.sim->time(), "info",
              who + "fewer than 10 " + what + ": no band to find in them");
}

}  // namespace

template <int D>
void recordSample(const Specimen<D>& sp, Recorder& rec) {
  rec.result("particles", static_cast<double>(sp.sim->particles().size()), "");
  const auto& ar = sp.grain_aspect_ratios;
  if (ar.empty()) return;
  rec.result("grains", static_cast<double>(ar.size()), "");
  rec.result("grain_aspect_ratio_mean",
             std::accumulate(ar.begin(), ar.end(), 0.0) / static_cast<double>(ar.size()), "");
  rec.result("grain_aspect_ratio_max", *std::max_element(ar.begin(), ar.end()), "");
  if (sp.grain_kind) {
    rec.result("grain_bonds_installed", static_cast<double>(sp.grain_bonds.installed), "");
  }
}

template <int D>
TestOutcome confineAndLoad(Specimen<D>& sp, const Settings& s, double sigma3,
                           const std::string& branch, Recorder& rec, RunControl& control) {
  using Axis = typename LoadingFrame<D>::Axis;
  using Mode = typename LoadingFrame<D>::Mode;
  constexpr int ax = Specimen<D>::kAxial;
  auto& sim = *sp.sim;
  auto& frame = *sp.frame;
  const std::string prefix = branch.empty() ? "" : branch + ".";
  const std::string confinement = prefix + "confinement", stage = prefix + "loading";
  const std::string who = branch.empty() ? "" : branch + ": ";  // names the test in messages
  servoTo(sp, s, sigma3 + s.si("loading.seating_stress_MPa"), sigma3,
          s.si("loading.confining_rate_MPa_per_s"), confinement, rec, control);
  if (sp.grain_kind) {
    rec.result(prefix + "crushed_grains_before_loading", static_cast<double>(sp.crushedGrains()),
               "");
  }
  const double rate = s.real("loading.axial_strain_rate_per_s");
  const double strain_max = s.real("loading.axial_strain_max");
  const double drop = s.real("loading.stop_after_drop");
  const double drop_min_strain = s.real("loading.stop_after_drop_min_strain");

  recordBreaks(sp, rec, confinement);  // breaks up to here belong to the confinement
  const std::uint64_t clumps_broken_before = sp.clump_breaks;
  sp.keep_break_positions = true;
  sp.break_positions.clear();
  frame.set(ax, Axis{Mode::StrainRate, rate});
  frame.resetReference();
  sp.resetBrokenCount();
  const std::uint64_t start = sim.steps();
  double peak = -INFINITY, peak_strain = 0.0, peak_volumetric = 0.0, peak_axial = 0.0;
  double confining_error = 0.0, unbalanced_sum = 0.0, inertial_max = 0.0;
  LoadingCurve curve;
  std::vector<std::size_t> breaks_at;  // break positions kept by each record
  // States at every twentieth of the strain range, the start of the incremental strain field.
  struct State {
    double strain = 0.0;
    std::uint64_t step = 0;
    double time = 0.0;
    std::vector<std::array<double, 3>> positions;
  };
  std::vector<State> states;
  states.push_back({0.0, sim.steps(), sim.time(), slotPositions(sim)});
  // A confinement below 1 MPa is judged against 1 MPa: at zero the walls just keep clear.
  const double error_scale = std::max(sigma3, 1e6);
  bool done = false;
  while (!done) {
    frame.step();
    const double strain = frame.strain(ax);
    const double q = frame.stress(ax) - lateralStress(frame);
    if (q > peak) {
      peak = q;
      peak_strain = strain;
      peak_volumetric = frame.volumetricStrain();
      peak_axial = frame.stress(ax);
    }
    done = strain >= strain_max || (drop > 0.0 && peak > 0.0 && q < (1.0 - drop) * peak &&
                                    strain > peak_strain && strain >= drop_min_strain);
    if ((sim.steps() - start) % sp.record_every == 0 || done) {
      recordState(sp, rec, prefix, stage, rate);
      rec.series(prefix + "deviatoric_stress_MPa", sim.steps(), sim.time(), q / 1e6);
      curve.axial_strain.push_back(strain);
      curve.q.push_back(q);
      curve.volumetric_strain.push_back(frame.volumetricStrain());
      breaks_at.push_back(sp.break_positions.size());
      if (strain >= states.back().strain + strain_max / 20.0) {
        states.push_back({strain, sim.steps(), sim.time(), slotPositions(sim)});
      }
      for (int a = 0; a < D - 1; ++a) {
        confining_error =
            std::max(confining_error, std::abs(frame.stress(a) - sigma3) / error_scale);
      }
      unbalanced_sum += sim.unbalancedForceRatio();
      inertial_max = std::max(inertial_max, inertialNumber(sp, rate));
    }
    if (sp.snapshot_every > 0 && (sim.steps() - start) % sp.snapshot_every == 0) {
      snapshot(sp, s, rec, stage, "step " + std::to_string(sim.steps() - start));
    }
    if ((sim.steps() - start) % 200 == 0) {
      control.tick(stage, sim.steps(), strain / strain_max,
                   "q " + fmt(q / 1e6) + " MPa at axial strain " + fmt(strain));
    }
  }
  snapshot(sp, s, rec, stage, "final");
  auto put = [&](const std::string& name, double v, const std::string& unit) {
    rec.result(prefix + name, v, unit);
  };
  put("peak_deviatoric_stress_MPa", peak / 1e6, "MPa");
  put("axial_stress_at_peak_MPa", peak_axial / 1e6, "MPa");
  put("axial_strain_at_peak", peak_strain, "");
  put("volumetric_strain_at_peak", peak_volumetric, "");
  if (sigma3 == 0.0) put("ucs_MPa", peak_axial / 1e6, "MPa");
  put("confining_stress_MPa", sigma3 / 1e6, "MPa");
  put("confining_stress_error_max", confining_error, "");
  put("axial_strain_final", frame.strain(ax), "");
  put("volumetric_strain_final", frame.volumetricStrain(), "");
  put("broken_bonds_tensile", static_cast<double>(sp.broken(BondBreakMode::Tensile)), "");
  put("broken_bonds_shear", static_cast<double>(sp.broken(BondBreakMode::Shear)), "");
  put("broken_bonds_total",
      static_cast<double>(sp.broken(BondBreakMode::Tensile) + sp.broken(BondBreakMode::Shear)), "");
  if (sp.grain_kind) {
    put("broken_grain_bonds_tensile",
        static_cast<double>(sp.brokenInGrains(BondBreakMode::Tensile)), "");
    put("broken_grain_bonds_shear", static_cast<double>(sp.brokenInGrains(BondBreakMode::Shear)),
        "");
    put("crushed_grains", static_cast<double>(sp.crushedGrains()), "");
  }
  if (sim.clumps().size() > 0) {  // a rigid grain crushes whole, into its pebbles
    put("crushed_grains", static_cast<double>(sp.clump_breaks - clumps_broken_before), "");
  }
  const double records = static_cast<double>(std::max<std::size_t>(1, curve.q.size()));
  put("loading_steps", static_cast<double>(sim.steps() - start), "");
  put("mean_unbalanced_force_ratio", unbalanced_sum / records, "");
  put("max_inertial_number", inertial_max, "");

  TestOutcome out;
  out.sigma3 = sigma3;
  out.critical = criticalPoint(curve);
  std::size_t band_first = 0;
  double field_from = 0.0;
  if (out.critical.found) {
    put("critical_is_compaction", out.critical.compactive ? 1.0 : 0.0, "");
    put("critical_deviatoric_stress_MPa", out.critical.q / 1e6, "MPa");
    // p = (sigma_1 + sigma_2 [+ sigma_3]) / D with the lateral stresses at sigma_3.
    put("critical_mean_stress_MPa", (sigma3 + out.critical.q / D) / 1e6, "MPa");
    put("critical_axial_strain", out.critical.axial_strain, "");
    band_first = breaks_at[out.critical.index];
    field_from = out.critical.axial_strain;
  } else {
    rec.message(sim.steps(), sim.time(), "info",
                who +
                    "no critical point: the sample neither turned to dilate nor left its "
                    "elastic compaction trend; load further (loading.axial_strain_max)");
  }
  if (confining_error > 0.01) {
    rec.message(sim.steps(), sim.time(), "warning",
                who + "the confining stress strayed " + fmt(100 * confining_error) +
                    "% from its target during loading; raise numerics.servo_speed_radii_per_step "
                    "or lower the loading rate");
  }
  warnIfNotQuasiStatic(sim, s, rec, stage, unbalanced_sum / records, inertial_max);
  // The band: in the strain field after the critical point, and in the breaks from it on.
  // A dilatant test localises shear, a compactive one compaction: the band is sought in
  // that part of the strain (a compaction band is a zone of localised compaction). A shear
  // band, once formed, slips in place: its field is the whole post-critical range. A
  // compaction band migrates along the sample (Olsson 1999; Baud et al. 2004), sharp in
  // its own strain window and smeared over the whole range: its field is, of the whole
  // range and each twentieth of the strain range after the critical point, the one with
  // the most contrasted band.
  const bool compactive = out.critical.found && out.critical.compactive;
  const StrainPart part = compactive ? StrainPart::Compaction : StrainPart::Shear;
  const double width = s.real("analysis.band_width_radii") * sp.mean_radius;
  std::size_t from = 0;
  while (from + 1 < states.size() && states[from + 1].strain <= field_from) ++from;
  states.push_back({frame.strain(ax), sim.steps(), sim.time(), slotPositions(sim)});
  struct Window {
    double from = 0.0, to = 0.0;
    Band band;
  };
  std::optional<Window> best;
  auto consider = [&](std::size_t a, std::size_t b) -> std::optional<Band> {
    const auto pts =
        strainedParticles(states[a].positions, states[b].positions, D, 4.0 * sp.mean_radius,
                          s.real("analysis.strained_fraction"), part);
    if (pts.size() < 10) return std::nullopt;
    const Band band = findBand(pts, D, ax, width);
    if (!best || band.contrast > best->band.contrast) {
      best = Window{states[a].strain, states[b].strain, band};
    }
    return band;
  };
  const std::size_t last = states.size() - 1;
  consider(from, last);
  if (compactive) {
    // Each window's band, at the window's end: how the band moves and turns as the
    // compaction proceeds.
    for (std::size_t k = from; k + 1 < last; ++k) {
      if (const auto band = consider(k, k + 1)) {
        rec.series(prefix + "band_window_angle_deg", states[k + 1].step, states[k + 1].time,
                   band->angle_to_axial_deg);
        rec.series(prefix + "band_window_contrast", states[k + 1].step, states[k + 1].time,
                   band->contrast);
      }
    }
  }
  put("band_in_compaction_field", compactive ? 1.0 : 0.0, "");
  const std::string field = compactive ? "most compacted particles" : "most sheared particles";
  if (best) {
    put("band_strain_from", best->from, "");
    put("band_strain_to", best->to, "");
    reportBand(sp, best->band, prefix, who, "band", field, rec);
  } else {
    noBand(sp, who, field, rec);
  }
  const std::vector<std::array<double, 3>> breaks(sp.break_positions.begin() + band_first,
                                                  sp.break_positions.end());
  const std::string from_critical = "bond breaks from the critical point on";
  if (breaks.size() >= 10) {
    reportBand(sp, findBand(breaks, D, ax, width), prefix, who, "break_band", from_critical, rec);
  } else {
    noBand(sp, who, from_critical, rec);
  }
  return out;
}

namespace {

template <int D>
void runDimension(const Settings& s, Recorder& rec, RunControl& control) {
  Specimen<D> sp = buildSpecimen<D>(s, control);
  recordSample(sp, rec);
  formAndCement(sp, s, rec, control);
  confineAndLoad(sp, s, s.si("loading.confining_stress_MPa"), "", rec, control);
  recordTimings<D>(rec, {sp.sim.get()});
}

}  // namespace

void run(const Settings& s, Recorder& rec, RunControl& control) {
  byDimension(s, [&](auto dim) { runDimension<dim.value>(s, rec, control); });
}

template void recordSample<2>(const Specimen<2>&, Recorder&);
template void recordSample<3>(const Specimen<3>&, Recorder&);
template TestOutcome confineAndLoad<2>(Specimen<2>&, const Settings&, double, const std::string&,
                                       Recorder&, RunControl&);
template TestOutcome confineAndLoad<3>(Specimen<3>&, const Settings&, double, const std::string&,
                                       Recorder&, RunControl&);

}  // namespace rocklab::rigs::biaxial
