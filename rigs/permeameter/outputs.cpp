// What the permeameter records, declared once.

#include "rigs/common/outputs.hpp"

namespace rocklab::rigs::permeameter {

const Outputs& outputs() {
  static const Outputs o =
      Outputs()
          .add(biaxial::outputs())  // its biaxial mode runs the biaxial test
          .prefixes({"loading."})
          .series({
              {"k_over_k0", "-", "permeability over the initial (the primary flow direction)"},
              {"permeability_m2", "m^2", "Darcy permeability (the primary flow direction)"},
              {"k_over_k0_along", "-", "k / k0 of the flow along the axis (both directions)"},
              {"k_over_k0_normal", "-", "k / k0 of the flow across the axis (both directions)"},
              {"kozeny_carman_over_k0", "-", "Kozeny-Carman's k over its initial (equation 8)"},
              {"flow.porosity", "-", "the porosity Kozeny-Carman follows"},
              {"flow.mean_stress_MPa", "MPa", "mean stress at the solve"},
              {"flow.axial_stress_MPa", "MPa", "axial stress at the solve"},
              {"flow.lateral_stress_MPa", "MPa", "lateral stress (x) at the solve"},
              {"flow.axial_strain", "-", "axial strain at the solve"},
              {"flow.volumetric_strain", "-", "volumetric strain at the solve"},
              {"flow.solve_seconds", "s", "wall time of the solve"},
              {"flow.solve_iterations", "-",
               "conjugate-gradient iterations of the solve (0: a direct solve)"},
              {"flow.triangulations", "-", "triangulations so far"},
          })
          .results({
              {"conductance_alpha", "-", "alpha of equation 3 (after calibration)"},
              {"porosity_initial", "-", "porosity before loading"},
              {"kozeny_carman_porosity_initial", "-", "the porosity Kozeny-Carman starts from"},
              {"kozeny_carman_initial_m2", "m^2", "Kozeny-Carman's permeability before loading"},
              {"permeability_initial_m2", "m^2", "Darcy permeability before loading"},
              {"permeability_initial_*_m2", "m^2", "before loading, by direction (both measured)"},
              {"pores", "-", "pores of the network"},
              {"pipes", "-", "pipes of the network"},
              {"pores_merged", "-", "pore clusters after merging"},
              {"pipes_merged", "-", "pipes between the clusters"},
              {"hidden_particles", "-", "particles no cell touches"},
              {"isolated_pores", "-", "clusters no conducting path links to a boundary"},
              {"hydraulic_length_mm", "mm", "distance between the inlet and outlet layers"},
              {"flow_section_mm2", "mm^2", "the flow's cross-section"},
              {"explicit_critical_step_s", "s", "the explicit scheme's critical step (equation 6)"},
              {"flow_balance_error", "-", "|outflow - inflow| / inflow of the first solve"},
              {"solver_*_seconds", "s", "a solver's wall time on the network before loading"},
              {"solver_*_iterations", "-", "its iterations"},
              {"solver_*_max_difference", "-", "its largest difference from Cholesky's"},
              {"solver_*_converged", "-", "1: it converged"},
              {"solver_*_predicted_iterations", "-",
               "an explicit scheme given up before flow.explicit_max_steps: the steps its "
               "rate so far needs at least"},
              {"k_over_k0_final", "-", "permeability at the end over the initial"},
              {"k_over_k0_final_*", "-", "the same by direction (both measured)"},
              {"triangulations", "-", "triangulations of the run"},
              {"flow_solves_factorised", "-", "solves on a new pattern: ordered and factorised"},
              {"flow_solves_refactorised", "-", "solves factorised again on a kept ordering"},
              {"flow_solves_iterated", "-", "solves by iterations on the kept factor"},
              {"mean_stress_peak_MPa", "MPa", "mean stress at the end of hydrostatic loading"},
              {"porosity_at_peak", "-", "porosity at the end of hydrostatic loading"},
          })
          .events({{"pore_pressure", "Pa", "a pore's steady pressure at its centroid"}})
          .keyResults({
              {"permeability_initial_m2", "m^2", "Darcy permeability before loading"},
              {"k_over_k0_final", "-", "permeability at the end over the initial"},
              {"k_over_k0_final_along", "-",
               "the same, flow along the axis (both directions measured)"},
              {"k_over_k0_final_normal", "-",
               "the same, flow across the axis (both directions measured)"},
              {"k_over_k0_at_peak_stress", "-",
               "permeability over the initial at the peak axial stress (before it: what the "
               "stress did; after it: what the failure did)"},
              {"k_over_k0_at_peak_stress_along", "-",
               "the same, flow along the axis (both directions measured)"},
              {"k_over_k0_at_peak_stress_normal", "-",
               "the same, flow across the axis (both directions measured)"},
              {"k_over_kozeny_carman_final", "-",
               "k / k0 at the end over Kozeny-Carman's from the same porosity (equation 8)"},
              {"k_over_k0_at_half_peak_stress", "-",
               "permeability over the initial when the mean stress first reaches half its peak"},
              {"porosity_initial", "-", "porosity before loading"},
              {"mean_stress_peak_MPa", "MPa", "mean stress at the end of hydrostatic loading"},
              {"flow_balance_error", "-", "|outflow - inflow| / inflow of the first steady solve"},
          });
  return o;
}

}  // namespace rocklab::rigs::permeameter
