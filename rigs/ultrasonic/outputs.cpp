// What the ultrasonic bench records, declared once.

#include "rigs/common/outputs.hpp"

namespace rocklab::rigs::ultrasonic {

const Outputs& outputs() {
  static const Outputs o =
      Outputs()
          .add(specimenOutputs())
          .prefixes({"loading.", "confinement.", "stage.", "stage#."})
          .series({
              {"density_kg_per_m3", "kg/m^3", "bulk density of the sample at a stage (stage.)"},
              {"vp_z", "m/s", "P-wave velocity along the axis (cross-correlation picks)"},
              {"vp_x", "m/s", "P-wave velocity across the axis"},
              {"vs_zx", "m/s", "S-wave along the axis, polarised across"},
              {"vs_xy", "m/s", "S-wave across the axis, polarised across"},
              {"v*_first_break", "m/s", "the same wave's velocity from first-break picks"},
              {"v*_error", "m/s", "standard error of the velocity fit"},
              {"modulus_z_dynamic_MPa", "MPa", "rho vp_z^2"},
              {"modulus_x_dynamic_MPa", "MPa", "rho vp_x^2"},
              {"shear_modulus_zx_dynamic_MPa", "MPa", "rho vs_zx^2"},
              {"shear_modulus_xy_dynamic_MPa", "MPa", "rho vs_xy^2"},
              {"modulus_*_static_MPa", "MPa", "static constrained modulus, unloading slope"},
              {"modulus_*_static_loading_MPa", "MPa", "static constrained modulus, loading slope"},
          })
          .results({
              {"density_kg_per_m3", "kg/m^3", "bulk density at the last stage (stage.)"},
              {"vp_z", "m/s", "P-wave velocity along the axis at the last stage"},
              {"vp_x", "m/s", "P-wave velocity across the axis at the last stage"},
              {"vs_zx", "m/s", "S-wave along the axis, polarised across, at the last stage"},
              {"vs_xy", "m/s", "S-wave across the axis, polarised across, at the last stage"},
              {"v*_first_break", "m/s", "first-break velocities at the last stage"},
              {"v*_error", "m/s", "their fits' standard errors"},
              {"modulus_z_dynamic_MPa", "MPa", "rho vp_z^2 at the last stage"},
              {"modulus_x_dynamic_MPa", "MPa", "rho vp_x^2 at the last stage"},
              {"shear_modulus_zx_dynamic_MPa", "MPa", "rho vs_zx^2 at the last stage"},
              {"shear_modulus_xy_dynamic_MPa", "MPa", "rho vs_xy^2 at the last stage"},
              {"modulus_*_static_MPa", "MPa", "static moduli at the last stage"},
              {"modulus_*_static_loading_MPa", "MPa", "their loading slopes"},
              {"stages", "-", "stages measured"},
              {"wavelength_min_diameters", "-", "shortest wavelength, in particle diameters"},
              {"pick_disagreement_max", "-",
               "largest (first break - cross-correlation) / cross-correlation velocity"},
          })
          .keyResults({
              {"vp_z", "m/s",
               "P-wave velocity along the axis (at the last stage; stageN.NAME at "
               "stage N)"},
              {"vp_x", "m/s", "P-wave velocity across the axis (at the last stage; stageN.NAME)"},
              {"vs_zx", "m/s",
               "S-wave along the axis, polarised across (at the last stage; stageN.NAME)"},
              {"vs_xy", "m/s",
               "S-wave across the axis, polarised across (at the last stage; stageN.NAME)"},
              {"modulus_z_dynamic_MPa", "MPa", "rho vp_z^2 (at the last stage; stageN.NAME)"},
              {"shear_modulus_zx_dynamic_MPa", "MPa",
               "rho vs_zx^2 (at the last stage; stageN.NAME)"},
              {"modulus_z_static_MPa", "MPa",
               "static constrained modulus along the axis (at the last stage; stageN.NAME)"},
              {"static_over_dynamic_modulus", "-",
               "modulus_z_static_MPa / modulus_z_dynamic_MPa (at the last stage; stageN.NAME)"},
          });
  return o;
}

}  // namespace rocklab::rigs::ultrasonic
