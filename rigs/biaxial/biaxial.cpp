#include "rigs/biaxial/biaxial.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

#include "rigs/common/localisation.hpp"
#include "rigs/common/specimen.hpp"

namespace rocklab::rigs::biaxial {

using protocol::range;
using protocol::Settings;

void declare(protocol::Schema& s) {
  range(s.real("loading.confining_stress_MPa", "MPa", 1e6, 4.0,
               "lateral stress held by servo walls during loading (sigma_3); 0: UCS test"),
        0, false, 1e4, false);
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
  range(s.real("loading.stop_after_drop", "-", 1, 0.0,
               "stop once the deviatoric stress has fallen this fraction below its peak "
               "(0: run to axial_strain_max)"),
        0, false, 1, false);
}

void validate(const Settings& s) {
  // A test that stops after the peak must get past it: a drop needs room to show.
  if (s.real("loading.stop_after_drop") > 0.0 && s.real("loading.axial_strain_max") < 1e-3) {
    protocol::fail(s, "loading.axial_strain_max",
                   "is too small to pass the peak that loading.stop_after_drop waits for "
                   "(at least 0.001)");
  }
}

namespace {

std::string fmt(double v) {
  std::ostringstream o;
  o.precision(3);
  o << v;
  return o.str();
}

template <int D>
double lateralStress(const LoadingFrame<D>& f) {
  double sum = 0.0;
  for (int a = 0; a < D - 1; ++a) sum += f.stress(a);
  return sum / (D - 1);
}

// The failure band in the loading's break positions (rigs/common/localisation.hpp).
template <int D>
void reportBand(Specimen<D>& sp, const Settings& s, Recorder& rec) {
  auto& sim = *sp.sim;
  if (sp.break_positions.size() < 10) {
    rec.message(sim.steps(), sim.time(), "info",
                "fewer than 10 bonds broke during loading: no band to find");
    return;
  }
  const double width = s.real("analysis.band_width_radii") * sp.mean_radius;
  const Band b = findBand(sp.break_positions, D, Specimen<D>::kAxial, width);
  rec.result("band_angle_deg", b.angle_to_axial_deg, "deg");
  rec.result("band_is_compaction", b.is_compaction() ? 1.0 : 0.0, "");
  rec.result("band_thickness_mm", b.thickness * 1e3, "mm");
  rec.result("band_contrast", b.contrast, "");
  rec.result("band_breaks", static_cast<double>(b.points), "");
  rec.message(sim.steps(), sim.time(), "info",
              std::string(b.is_compaction() ? "compaction" : "shear") + " band at " +
                  fmt(b.angle_to_axial_deg) + " deg to sigma_1, " + fmt(b.thickness * 1e3) +
                  " mm thick, " + fmt(b.contrast) + " times the mean break density");
}

template <int D>
void load(Specimen<D>& sp, const Settings& s, Recorder& rec, RunControl& control) {
  using Axis = typename LoadingFrame<D>::Axis;
  using Mode = typename LoadingFrame<D>::Mode;
  constexpr int ax = Specimen<D>::kAxial;
  auto& sim = *sp.sim;
  auto& frame = *sp.frame;
  const double sigma3 = s.si("loading.confining_stress_MPa");
  const double rate = s.real("loading.axial_strain_rate_per_s");
  const double strain_max = s.real("loading.axial_strain_max");
  const double drop = s.real("loading.stop_after_drop");
  const std::string stage = "loading";

  recordBreaks(sp, rec, "confinement");  // breaks up to here belong to the confinement
  sp.keep_break_positions = true;
  sp.break_positions.clear();
  frame.set(ax, Axis{Mode::StrainRate, rate});
  frame.resetReference();
  sp.resetBrokenCount();
  const std::uint64_t start = sim.steps();
  double peak = -INFINITY, peak_strain = 0.0, peak_volumetric = 0.0, peak_axial = 0.0;
  double confining_error = 0.0, unbalanced_sum = 0.0, inertial_max = 0.0;
  std::size_t records = 0;
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
    done = strain >= strain_max ||
           (drop > 0.0 && peak > 0.0 && q < (1.0 - drop) * peak && strain > peak_strain);
    if ((sim.steps() - start) % sp.record_every == 0 || done) {
      recordState(sp, rec, "", stage, rate);
      rec.series("deviatoric_stress_MPa", sim.steps(), sim.time(), q / 1e6);
      for (int a = 0; a < D - 1; ++a) {
        confining_error =
            std::max(confining_error, std::abs(frame.stress(a) - sigma3) / error_scale);
      }
      unbalanced_sum += sim.unbalancedForceRatio();
      inertial_max = std::max(inertial_max, inertialNumber(sp, rate));
      ++records;
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
    rec.result(name, v, unit);
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
  if (sp.grain_kind) {
    put("broken_grain_bonds_tensile",
        static_cast<double>(sp.brokenInGrains(BondBreakMode::Tensile)), "");
    put("broken_grain_bonds_shear", static_cast<double>(sp.brokenInGrains(BondBreakMode::Shear)),
        "");
    put("crushed_grains", static_cast<double>(sp.crushedGrains()), "");
  }
  const double mean_unbalanced = records ? unbalanced_sum / static_cast<double>(records) : 0.0;
  put("loading_steps", static_cast<double>(sim.steps() - start), "");
  put("mean_unbalanced_force_ratio", mean_unbalanced, "");
  put("max_inertial_number", inertial_max, "");
  if (confining_error > 0.01) {
    rec.message(sim.steps(), sim.time(), "warning",
                "the confining stress strayed " + fmt(100 * confining_error) +
                    "% from its target during loading; raise numerics.servo_speed_radii_per_step "
                    "or lower the loading rate");
  }
  warnIfNotQuasiStatic(sim, s, rec, stage, mean_unbalanced, inertial_max);
  reportBand(sp, s, rec);
}

template <int D>
void runDimension(const Settings& s, Recorder& rec, RunControl& control) {
  Specimen<D> sp = buildSpecimen<D>(s, control);
  rec.result("particles", static_cast<double>(sp.sim->particles().size()), "");
  if (sp.grain_kind) {
    const auto& ar = sp.grain_aspect_ratios;
    rec.result("grains", static_cast<double>(ar.size()), "");
    rec.result("grain_aspect_ratio_mean",
               std::accumulate(ar.begin(), ar.end(), 0.0) / static_cast<double>(ar.size()), "");
    rec.result("grain_aspect_ratio_max", *std::max_element(ar.begin(), ar.end()), "");
    rec.result("grain_bonds_installed", static_cast<double>(sp.grain_bonds.installed), "");
  }
  formAndCement(sp, s, rec, control);
  const double sigma3 = s.si("loading.confining_stress_MPa");
  servoTo(sp, s, sigma3 + s.si("loading.seating_stress_MPa"), sigma3,
          s.si("loading.confining_rate_MPa_per_s"), "confinement", rec, control);
  if (sp.grain_kind) {
    rec.result("crushed_grains_before_loading", static_cast<double>(sp.crushedGrains()), "");
  }
  load(sp, s, rec, control);
  recordTimings<D>(rec, {sp.sim.get()});
}

}  // namespace

void run(const Settings& s, Recorder& rec, RunControl& control) {
  if (s.integer("protocol.dimension") == 2) {
    runDimension<2>(s, rec, control);
  } else {
    runDimension<3>(s, rec, control);
  }
}

}  // namespace rocklab::rigs::biaxial
