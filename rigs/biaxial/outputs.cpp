// What the biaxial frame / triaxial cell and the envelope sweep record, declared once.

#include "rigs/common/outputs.hpp"

namespace rocklab::rigs {

namespace biaxial {

const Outputs& outputs() {
  static const Outputs o =
      Outputs()
          .add(specimenOutputs())
          .prefixes({"confinement."})
          .series({
              {"deviatoric_stress_MPa", "MPa", "q: axial minus mean lateral stress"},
              {"interior_deviatoric_stress_MPa", "MPa",
               "q of the contacts inside (Love-Weber): the walls' less the grains' inertia and "
               "damping"},
              {"axial_strain_rate_per_s", "1/s",
               "the platens' strain rate (above the set one while loading.rate_boost_max > 1 "
               "and the sample is calm)"},
              {"band_window_angle_deg", "deg",
               "the band in each post-critical strain window of a compactive test"},
              {"band_window_contrast", "-", "that band's count over a uniform cloud's"},
          })
          .results({
              {"grains", "-", "grains of the sample (kind = grains or clumps)"},
              {"grain_aspect_ratio_mean", "-", "mean Feret aspect ratio of the grains"},
              {"grain_aspect_ratio_max", "-", "largest Feret aspect ratio of the grains"},
              {"grain_bonds_installed", "-", "intragranular bonds installed"},
              {"crushed_grains_before_loading", "-", "grains crushed by the confinement"},
              {"peak_deviatoric_stress_MPa", "MPa", "peak deviatoric stress of the loading"},
              {"axial_stress_at_peak_MPa", "MPa", "axial stress at the peak"},
              {"axial_strain_at_peak", "-", "axial strain since loading began, at the peak"},
              {"volumetric_strain_at_peak", "-", "volumetric strain at the peak"},
              {"ucs_MPa", "MPa", "uniaxial compressive strength (zero confinement only)"},
              {"confining_stress_MPa", "MPa", "the confinement of the test"},
              {"confining_stress_error_max", "-", "largest relative miss of the confinement"},
              {"axial_strain_final", "-", "axial strain at the end of the test"},
              {"volumetric_strain_final", "-", "volumetric strain at the end of the test"},
              {"broken_bonds_tensile", "-", "cement bonds broken in tension during the loading"},
              {"broken_bonds_shear", "-", "cement bonds broken in shear during the loading"},
              {"broken_bonds_total", "-", "cement bonds broken during the loading"},
              {"broken_grain_bonds_tensile", "-", "intragranular bonds broken in tension"},
              {"broken_grain_bonds_shear", "-", "intragranular bonds broken in shear"},
              {"crushed_grains", "-", "grains crushed during the loading"},
              {"loading_steps", "-", "steps of the loading"},
              {"mean_unbalanced_force_ratio", "-", "mean unbalanced force ratio of the loading"},
              {"max_inertial_number", "-", "largest inertial number of the loading"},
              {"critical_is_compaction", "-", "1: the critical point is the onset of compaction"},
              {"critical_deviatoric_stress_MPa", "MPa", "q at the critical point"},
              {"critical_mean_stress_MPa", "MPa", "p at the critical point"},
              {"critical_axial_strain", "-", "axial strain at the critical point"},
              {"band_in_compaction_field", "-", "1: the band was sought in the compaction"},
              {"band_strain_from", "-", "axial strain the band's field starts at"},
              {"band_strain_to", "-", "axial strain the band's field ends at"},
              {"band_angle_deg", "deg", "angle between the band and sigma_1"},
              {"band_is_compaction", "-", "1: within 20 deg of normal to sigma_1"},
              {"band_thickness_mm", "mm", "thickness of the band"},
              {"band_contrast", "-", "the band's count over a uniform cloud's"},
              {"band_points", "-", "points the band was sought in"},
              {"band_range_contrast", "-",
               "contrast of the band over the whole post-critical range (a compactive test's "
               "windows each have theirs)"},
              {"break_band_angle_deg", "deg", "the band of the bond breaks, to sigma_1"},
              {"break_band_is_compaction", "-", "1: within 20 deg of normal to sigma_1"},
              {"break_band_thickness_mm", "mm", "thickness of the break band"},
              {"break_band_contrast", "-", "its count over a uniform cloud's"},
              {"break_band_points", "-", "breaks the band was sought in"},
          })
          .keyResults({
              {"peak_deviatoric_stress_MPa", "MPa", "peak deviatoric stress of the loading"},
              {"ucs_MPa", "MPa", "uniaxial compressive strength (zero confinement only)"},
              {"axial_strain_at_peak", "-", "axial strain since loading began, at the peak"},
              {"volumetric_strain_at_peak", "-",
               "volumetric strain at the peak, compaction positive"},
              {"deviatoric_stress_at_1pct_strain_MPa", "MPa",
               "deviatoric stress when the axial strain reaches 1%"},
              {"tangent_modulus_at_1pct_strain_MPa", "MPa",
               "tangent of deviatoric stress against axial strain at 1% (fit over 0.75-1.25%)"},
              {"secant_modulus_50_MPa", "MPa",
               "secant modulus at half the peak deviatoric stress (E50)"},
              {"critical_deviatoric_stress_MPa", "MPa",
               "deviatoric stress at the critical point (peak or onset of compactive yield)"},
              {"band_angle_deg", "deg", "angle between the localisation band and sigma_1"},
              {"broken_bonds_total", "-", "cement bonds broken during the loading, both modes"},
              {"broken_bond_fraction", "-",
               "cement bonds broken during the loading over those installed (compares sample "
               "sizes)"},
              {"crushed_grains", "-", "grains crushed during the loading"},
          });
  return o;
}

}  // namespace biaxial

namespace envelope {

const Outputs& outputs() {
  static const Outputs o =
      Outputs()
          .keyResults({
              {"friction_angle_deg", "deg", "Mohr-Coulomb friction angle of the dilatant peaks"},
              {"mohr_coulomb_ucs_MPa", "MPa", "Mohr-Coulomb line's intercept: its UCS"},
          })
          .add(biaxial::outputs())
          .prefixes({"test#.", "test#.confinement."})
          .results({
              {"tests", "-", "tests of the sweep"},
              {"envelope_points_dilatant", "-", "critical points past which the sample dilated"},
              {"envelope_points_compactive", "-", "critical points of compactive yield"},
              {"friction_angle_deg", "deg", "Mohr-Coulomb friction angle of the dilatant peaks"},
              {"mohr_coulomb_ucs_MPa", "MPa", "Mohr-Coulomb line's intercept: its UCS"},
              {"mohr_coulomb_rms_residual_MPa", "MPa", "rms residual of the line's fit"},
              {"cap_confining_stress_MPa", "MPa",
               "where the cap begins: between the last dilatant and first compactive test"},
          });
  return o;
}

}  // namespace envelope

}  // namespace rocklab::rigs
