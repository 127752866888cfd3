// What the oedometer cell records, declared once.

#include "rigs/common/outputs.hpp"

namespace rocklab::rigs::oedometer {

const Outputs& outputs() {
  static const Outputs o =
      Outputs()
          .add(specimenOutputs())
          .prefixes({"virgin.", "cored.", "coring.", "reloading."})
          .series({{"phase", "-", "0 loading, 1 unloading, 2 reloading of a cycle"},
                   {"axial_strain_rate_per_s", "1/s",
                    "the axial walls' strain rate under strain control (above the set one "
                    "while loading.rate_boost_max > 1 and the sample is calm; negative "
                    "while a cycle unloads)"}})
          .results({
              {"tangent_modulus_initial_MPa", "MPa", "oedometric tangent modulus at the start"},
              {"tangent_modulus_final_MPa", "MPa", "oedometric tangent modulus at the end"},
              {"tangent_modulus_ratio", "-", "final over initial tangent modulus"},
              {"stress_path_slope_initial", "-", "d(lateral)/d(axial) stress at the start"},
              {"stress_path_slope_final", "-", "d(lateral)/d(axial) stress at the end"},
              {"axial_strain_final", "-", "axial strain at the end of loading"},
              {"axial_stress_final_MPa", "MPa", "axial stress at the end of loading"},
              {"lateral_stress_final_MPa", "MPa", "lateral stress at the end of loading"},
              {"broken_bonds_tensile", "-", "cement bonds broken in tension during the loading"},
              {"broken_bonds_shear", "-", "cement bonds broken in shear during the loading"},
              {"broken_bonds_total", "-", "cement bonds broken during the loading"},
              {"axial_strain_at_first_break", "-", "axial strain at the first bond break"},
              {"broken_bonds_by_tenth_of_loading", "-", "bonds broken in the first tenth"},
              {"cycle#_at_axial_strain", "-", "where the cycle began"},
              {"cycle#_loading_modulus_MPa", "MPa", "loading tangent just before the cycle"},
              {"cycle#_unloading_modulus_MPa", "MPa", "secant of the cycle's unloading"},
              {"cycle#_modulus_ratio", "-", "loading tangent over unloading secant"},
              {"loading_steps", "-", "steps of the loading"},
              {"mean_unbalanced_force_ratio", "-", "mean unbalanced force ratio of the loading"},
              {"max_inertial_number", "-", "largest inertial number of the loading"},
              {"broken_bonds_by_coring", "-", "bonds broken by unloading the core"},
              {"axial_strain_after_coring_and_reloading", "-",
               "axial strain the core kept after it was reloaded to the formation state"},
              {"cored_to_virgin_initial_modulus_ratio", "-",
               "initial modulus of the cored sample over the virgin's"},
          })
          .keyResults({
              {"tangent_modulus_initial_MPa", "MPa", "oedometric tangent modulus at the start"},
              {"tangent_modulus_final_MPa", "MPa", "oedometric tangent modulus at the end"},
              {"tangent_modulus_ratio", "-", "final over initial tangent modulus"},
              {"axial_stress_final_MPa", "MPa", "axial stress at the end of loading"},
              {"lateral_stress_final_MPa", "MPa", "lateral stress at the end of loading"},
              {"stress_path_slope_final", "-", "d(lateral)/d(axial) stress at the end"},
              {"axial_stress_at_1pct_strain_MPa", "MPa",
               "axial stress when the axial strain reaches 1%"},
              {"broken_bonds_total", "-", "cement bonds broken during the loading"},
              {"broken_bond_fraction", "-",
               "cement bonds broken during the loading over those installed (compares sample "
               "sizes)"},
              {"cycle#_modulus_ratio", "-",
               "cycle N (cycle1_, cycle2_, ...): loading tangent over unloading secant"},
              {"cored_to_virgin_initial_modulus_ratio", "-",
               "initial modulus of the cored sample over the virgin's"},
              {"broken_bonds_by_coring", "-", "bonds broken by unloading the core"},
              {"porosity_after_formation", "-",
               "porosity of the formed sample, before it is cemented (what a campaign over the "
               "packing varies)"},
          });
  return o;
}

}  // namespace rocklab::rigs::oedometer
