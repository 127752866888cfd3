// What every specimen records (measurements.hpp, formation.hpp), declared once.

#include "rigs/common/outputs.hpp"

namespace rocklab::rigs {

const Outputs& specimenOutputs() {
  static const Outputs o =
      Outputs()
          .prefixes({"densification.", "formation."})
          .series({
              {"axial_stress_MPa", "MPa", "axial wall stress, compression positive"},
              {"lateral_stress_MPa", "MPa", "mean lateral wall stress"},
              {"lateral_stress_x_MPa", "MPa", "lateral wall stress along x (3D)"},
              {"lateral_stress_y_MPa", "MPa", "lateral wall stress along y (3D)"},
              {"axial_strain", "-",
               "axial strain since the stage's reference, compression positive"},
              {"volumetric_strain", "-",
               "volumetric strain since the reference, compaction positive"},
              {"porosity", "-", "1 - particle volume / box volume"},
              {"coordination_number", "-", "mean particle-particle contacts per particle"},
              {"broken_bonds_tensile", "-", "cement bonds broken in tension since the stage began"},
              {"broken_bonds_shear", "-", "cement bonds broken in shear since the stage began"},
              {"broken_bonds_total", "-", "cement bonds broken since the stage began"},
              {"broken_fraction_axial_bonds", "-",
               "broken fraction of the cement within 30 deg of the sigma_1 axis"},
              {"broken_fraction_lateral_bonds", "-",
               "broken fraction of the cement within 30 deg of the plane normal to sigma_1"},
              {"broken_fraction_inclined_bonds", "-",
               "broken fraction of the cement 30-60 deg from the sigma_1 axis"},
              {"broken_grain_bonds_tensile", "-", "intragranular bonds broken in tension"},
              {"broken_grain_bonds_shear", "-", "intragranular bonds broken in shear"},
              {"crushed_grains", "-", "grains in more fragments than at the stage's start"},
              {"grain_fragments", "-",
               "connected pieces of intact intragranular bonds, all grains"},
              {"unbalanced_force_ratio", "-", "mean unbalanced force over mean contact force"},
              {"inertial_number", "-", "edot d sqrt(rho / p) of a strain-driven stage"},
          })
          .results({
              {"particles", "-", "particles of the sample"},
              {"formation_steps", "-", "steps to densify and form the sample"},
              {"porosity_after_formation", "-", "porosity of the formed sample"},
              {"coordination_after_formation", "-", "coordination number of the formed sample"},
              {"axial_stress_after_formation_MPa", "MPa", "axial stress of the formed sample"},
              {"bonds_installed", "-", "cement bonds installed"},
              {"bonds_skipped_nonpositive", "-", "strength draws <= 0 left uncemented"},
              {"bonds_redrawn", "-", "strength draws <= 0 drawn again"},
              {"cement_candidates", "-", "pairs touching or within the gap tolerance"},
          })
          .events({
              {"bond_break", "Pa",
               "a bond broke: mode tensile or shear, inter or intra, its stress"},
              {"clump_break", "Pa",
               "a rigid grain broke into its pebbles: the stress that broke it"},
          });
  return o;
}

const Outputs& unconfinedOutputs() {
  static const Outputs o =
      Outputs()
          .add(specimenOutputs())
          .prefixes({"unloading."})
          .results({
              {"relaxation_steps", "-", "steps the released specimen settled for"},
              {"relaxation_unbalanced_force_ratio", "-", "its unbalanced force ratio then"},
              {"broken_bonds_at_peak", "-", "cement bonds broken in the loading by the peak"},
              {"broken_bonds_tensile_at_peak", "-", "of them in tension"},
              {"broken_bonds_shear_at_peak", "-", "of them in shear"},
              {"broken_bonds_total", "-", "cement bonds broken during the loading"},
              {"loading_steps", "-", "steps of the loading"},
              {"mean_unbalanced_force_ratio", "-", "mean unbalanced force ratio of the loading"},
              {"inertial_number_at_peak", "-",
               "inertial number at the peak, at the test's stress (a disk's nominal stress)"},
          });
  return o;
}

}  // namespace rocklab::rigs
