// What the hydrostatic cell records, declared once.

#include "rigs/common/outputs.hpp"

namespace rocklab::rigs::hydrostatic {

const Outputs& outputs() {
  static const Outputs o =
      Outputs()
          .add(specimenOutputs())
          .prefixes({"loading.", "unloading."})
          .results({
              {"mean_stress_peak_MPa", "MPa", "mean stress at the peak of the ramp"},
              {"volumetric_strain_at_peak", "-", "volumetric strain at the peak"},
              {"secant_bulk_modulus_MPa", "MPa", "secant bulk modulus from cementing to the peak"},
              {"porosity_at_peak", "-", "porosity at the peak"},
              {"broken_bonds_at_peak", "-", "cement bonds broken by the peak"},
              {"volumetric_strain_after_unloading", "-", "volumetric strain left after unloading"},
          })
          .keyResults({
              {"mean_stress_peak_MPa", "MPa", "mean stress at the peak of the ramp"},
              {"volumetric_strain_at_peak", "-", "volumetric strain at the peak"},
              {"secant_bulk_modulus_MPa", "MPa", "secant bulk modulus from cementing to the peak"},
              {"porosity_at_peak", "-", "porosity at the peak"},
              {"volumetric_strain_after_unloading", "-", "volumetric strain left after unloading"},
              {"broken_bonds_at_peak", "-", "cement bonds broken by the peak"},
              {"broken_bond_fraction_at_peak", "-",
               "cement bonds broken by the peak over those installed (compares sample sizes)"},
          });
  return o;
}

}  // namespace rocklab::rigs::hydrostatic
