// What the unconfined compression test records, declared once.

#include "rigs/common/outputs.hpp"

namespace rocklab::rigs::ucs {

const Outputs& outputs() {
  static const Outputs o =
      Outputs()
          .add(unconfinedOutputs())
          .series({
              {"gauge_axial_strain", "-",
               "axial strain of the mid-height gauge section, from its particles"},
              {"lateral_strain", "-",
               "lateral strain of the gauge section, from its particles (expansion negative)"},
          })
          .results({
              {"particles_cut_away", "-", "particles outside the cylinder, removed"},
              {"specimen_particles", "-", "particles of the specimen between the platens"},
              {"specimen_width_mm", "mm", "the prism's smaller side, or the cylinder's diameter"},
              {"specimen_height_mm", "mm", "between the platens at the release"},
              {"cross_section_mm2", "mm^2", "the specimen's cross-section"},
              {"gauge_particles", "-", "particles of the gauge section"},
              {"ucs_MPa", "MPa",
               "uniaxial compressive strength: peak platen force over the section"},
              {"peak_force_N", "N", "peak platen force"},
              {"axial_strain_at_peak", "-", "the platens' axial strain at the peak"},
              {"young_modulus_secant_50_MPa", "MPa",
               "Young's modulus, secant from the start to half the peak"},
              {"young_modulus_tangent_50_MPa", "MPa",
               "Young's modulus, tangent: slope from 40% to 60% of the peak"},
              {"poisson_ratio_secant_50", "-",
               "Poisson's ratio at half the peak: minus lateral over axial strain of the gauge"},
              {"poisson_ratio_tangent_50", "-",
               "Poisson's ratio, tangent: minus their slope from 40% to 60% of the peak"},
              {"crack_damage_stress_MPa", "MPa",
               "axial stress at the onset of dilatancy: the gauge's largest volumetric "
               "compaction up to the peak"},
              {"crack_damage_ratio", "-", "crack damage stress over the UCS"},
              {"volumetric_strain_at_crack_damage", "-", "the gauge's volumetric strain there"},
              {"volumetric_strain_at_peak", "-", "the gauge's volumetric strain at the peak"},
              {"lateral_strain_at_peak", "-", "the gauge's lateral strain at the peak"},
          })
          .keyResults({
              {"ucs_MPa", "MPa", "uniaxial compressive strength"},
              {"young_modulus_tangent_50_MPa", "MPa", "Young's modulus, tangent at half the peak"},
              {"poisson_ratio_tangent_50", "-", "Poisson's ratio, tangent at half the peak"},
              {"crack_damage_ratio", "-", "crack damage stress over the UCS"},
              {"axial_strain_at_peak", "-", "the platens' axial strain at the peak"},
          });
  return o;
}

}  // namespace rocklab::rigs::ucs
