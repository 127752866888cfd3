#include "rigs/hydrostatic/hydrostatic.hpp"

#include <cmath>

#include "rigs/common/specimen.hpp"

namespace rocklab::rigs::hydrostatic {

using protocol::range;
using protocol::Settings;

void declare(protocol::Schema& s) {
  range(s.real("loading.stress_max_MPa", "MPa", 1e6, 60.0, "peak hydrostatic stress"), 0, true, 1e5,
        false);
  range(s.real("loading.stress_rate_MPa_per_s", "MPa/s", 1e6, 2e4, "stress rate of the ramps"), 0,
        true, 1e12, false);
  range(s.real("loading.unload_to_MPa", "MPa", 1e6, 0.0,
               "after the peak, unload to this stress (0: no unloading)"),
        0, false, 1e5, false);
}

void validate(const Settings& s) {
  if (s.real("loading.stress_max_MPa") <= s.real("formation.axial_stress_MPa") ||
      s.real("loading.stress_max_MPa") <= s.real("formation.lateral_stress_MPa")) {
    protocol::fail(s, "loading.stress_max_MPa", "must exceed the formation stresses");
  }
  if (s.real("loading.unload_to_MPa") >= s.real("loading.stress_max_MPa")) {
    protocol::fail(s, "loading.unload_to_MPa", "must be below loading.stress_max_MPa");
  }
}

namespace {

template <int D>
void runDimension(const Settings& s, Recorder& rec, RunControl& control) {
  Specimen<D> sp = buildSpecimen<D>(s, control);
  rec.result("particles", static_cast<double>(sp.sim->particles().size()), "");
  formAndCement(sp, s, rec, control);
  auto& frame = *sp.frame;
  const double p0 = frame.meanStress();
  const double rate = s.si("loading.stress_rate_MPa_per_s");

  // The ramp up and the hold at the peak are recorded as series (stresses, volumetric
  // strain, porosity, broken bonds) under the stage names.
  servoTo(sp, s, s.si("loading.stress_max_MPa"), s.si("loading.stress_max_MPa"), rate, "loading",
          rec, control);
  snapshot(sp, s, rec, "loading", "peak");
  rec.result("mean_stress_peak_MPa", frame.meanStress() / 1e6, "MPa");
  rec.result("volumetric_strain_at_peak", frame.volumetricStrain(), "");
  rec.result("secant_bulk_modulus_MPa", (frame.meanStress() - p0) / frame.volumetricStrain() / 1e6,
             "MPa");
  rec.result("porosity_at_peak", frame.porosity(), "");
  rec.result(
      "broken_bonds_at_peak",
      static_cast<double>(sp.broken(BondBreakMode::Tensile) + sp.broken(BondBreakMode::Shear)), "");
  if (s.real("loading.unload_to_MPa") > 0.0) {
    servoTo(sp, s, s.si("loading.unload_to_MPa"), s.si("loading.unload_to_MPa"), rate, "unloading",
            rec, control);
    rec.result("volumetric_strain_after_unloading", frame.volumetricStrain(), "");
    snapshot(sp, s, rec, "unloading", "final");
  }
  recordTimings<D>(rec, {sp.sim.get()});
}

}  // namespace

void run(const Settings& s, Recorder& rec, RunControl& control) {
  byDimension(s, [&](auto dim) { runDimension<dim.value>(s, rec, control); });
}

}  // namespace rocklab::rigs::hydrostatic
