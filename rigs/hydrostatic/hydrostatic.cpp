#include "rigs/hydrostatic/hydrostatic.hpp"

#include "rigs/common/formation.hpp"
#include "rigs/common/measurements.hpp"

namespace rocklab::rigs::hydrostatic {

void Settings::validate() const {
  const FormationSettings& f = specimen.formation;
  if (stress_max <= f.axial_stress || stress_max <= f.lateral_stress) {
    throw InvalidParameter("", "loading.stress_max_MPa", "must exceed the formation stresses");
  }
  if (unload_to >= stress_max) {
    throw InvalidParameter("", "loading.unload_to_MPa", "must be below loading.stress_max_MPa");
  }
}

namespace {

template <int D>
void runDimension(const Settings& s, Recorder& rec, RunControl& control) {
  Specimen<D> sp = buildSpecimen<D>(s.specimen, control);
  rec.result("particles", static_cast<double>(sp.sim->particles().size()), "");
  formAndCement(sp, rec, control);
  auto& frame = *sp.frame;
  const double p0 = frame.meanStress();

  // The ramp up and the hold at the peak are recorded as series (stresses, volumetric
  // strain, porosity, broken bonds) under the stage names.
  servoTo(sp, s.stress_max, s.stress_max, s.stress_rate, "loading", rec, control);
  snapshot(sp, rec, "loading", "peak");
  rec.result("mean_stress_peak_MPa", frame.meanStress() / 1e6, "MPa");
  rec.result("volumetric_strain_at_peak", frame.volumetricStrain(), "");
  rec.result("secant_bulk_modulus_MPa", (frame.meanStress() - p0) / frame.volumetricStrain() / 1e6,
             "MPa");
  rec.result("porosity_at_peak", frame.porosity(), "");
  rec.result(
      "broken_bonds_at_peak",
      static_cast<double>(sp.broken(BondBreakMode::Tensile) + sp.broken(BondBreakMode::Shear)), "");
  if (s.unload_to > 0.0) {
    servoTo(sp, s.unload_to, s.unload_to, s.stress_rate, "unloading", rec, control);
    rec.result("volumetric_strain_after_unloading", frame.volumetricStrain(), "");
    snapshot(sp, rec, "unloading", "final");
  }
  recordTimings<D>(rec, {sp.sim.get()});
}

}  // namespace

void run(const Settings& s, Recorder& rec, RunControl& control) {
  byDimension(s.specimen.protocol.dimension,
              [&](auto dim) { runDimension<dim.value>(s, rec, control); });
}

}  // namespace rocklab::rigs::hydrostatic
