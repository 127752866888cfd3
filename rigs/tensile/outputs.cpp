// What the tensile tests record, declared once.

#include "rigs/common/outputs.hpp"

namespace rocklab::rigs::tensile {

namespace {

// What both tests record: what every test out of its box records, and the fracture.
const Outputs& outputs() {
  static const Outputs o =
      Outputs()
          .add(unconfinedOutputs())
          .results({
              {"fracture_breaks", "-", "bonds broken from the peak to the end: the fracture"},
          });
  return o;
}

}  // namespace

}  // namespace rocklab::rigs::tensile

namespace rocklab::rigs::brazilian {

const Outputs& outputs() {
  static const Outputs o =
      Outputs()
          .add(tensile::outputs())
          .series({
              {"platen_force_N", "N", "mean force of the two platens on the disk"},
              {"platen_closure_mm", "mm", "closure of the platens since loading began"},
              {"diametral_strain", "-", "platen closure over the disk's diameter"},
              {"tensile_stress_MPa", "MPa", "nominal tensile stress at the centre, 2F / (pi D t)"},
          })
          .results({
              {"disk_particles", "-", "particles of the disk cut from the sample"},
              {"particles_cut_away", "-", "particles outside the disk, removed"},
              {"disk_diameter_mm", "mm", "diameter D of the disk"},
              {"disk_thickness_mm", "mm",
               "thickness t: the disks' (2D), the cylinder's length (3D)"},
              {"bonds_in_disk", "-", "bonds left in the disk after the cut"},
              {"tensile_strength_MPa", "MPa", "sigma_t = 2 F_peak / (pi D t)"},
              {"peak_force_N", "N", "peak platen force"},
              {"diametral_strain_at_peak", "-", "platen closure over the diameter at the peak"},
              {"fracture_angle_to_loading_deg", "deg",
               "principal axis of the fracture's breaks against the loaded diameter"},
              {"fracture_offset_ratio", "-",
               "that axis's distance from the disk's centre over the diameter"},
              {"fracture_elongation", "-", "length over width of the fracture's breaks"},
              {"fracture_through_centre", "-",
               "1: the fracture runs along the loaded diameter through the centre (within 20 "
               "deg and D / 10, twice as long as wide)"},
          })
          .keyResults({
              {"tensile_strength_MPa", "MPa", "sigma_t = 2 F_peak / (pi D t)"},
              {"peak_force_N", "N", "peak platen force"},
              {"broken_bonds_at_peak", "-", "cement bonds broken in the loading by the peak"},
              {"fracture_angle_to_loading_deg", "deg",
               "the fracture's axis against the loaded diameter"},
              {"fracture_through_centre", "-",
               "1: the fracture runs along the loaded diameter through the centre"},
          });
  return o;
}

}  // namespace rocklab::rigs::brazilian

namespace rocklab::rigs::direct_tension {

const Outputs& outputs() {
  static const Outputs o =
      Outputs()
          .add(tensile::outputs())
          .series({
              {"pull_force_N", "N", "mean force the specimen pulls its two glued layers back with"},
              {"axial_strain", "-", "extension of the gauge between the glued layers"},
              {"tensile_stress_MPa", "MPa", "pull force over the cross-section"},
          })
          .results({
              {"glued_particles_bottom", "-", "particles glued to the bottom platen"},
              {"glued_particles_top", "-", "particles glued to the top platen"},
              {"gauge_length_mm", "mm", "between the glued layers' mean positions"},
              {"cross_section_mm2", "mm^2", "the specimen's cross-section"},
              {"tensile_strength_MPa", "MPa", "peak pull force over the cross-section"},
              {"peak_force_N", "N", "peak pull force"},
              {"axial_strain_at_peak", "-", "gauge extension at the peak"},
              {"tensile_modulus_MPa", "MPa",
               "modulus in tension: slope of stress against strain from 10% to 50% of the peak"},
              {"fracture_angle_to_loading_deg", "deg",
               "principal axis of the fracture's breaks against the load (90: across it)"},
              {"fracture_height_ratio", "-",
               "where the fracture lies along the specimen, 0 bottom to 1 top"},
          })
          .keyResults({
              {"tensile_strength_MPa", "MPa", "peak pull force over the cross-section"},
              {"tensile_modulus_MPa", "MPa", "modulus in tension (10% to 50% of the peak)"},
              {"axial_strain_at_peak", "-", "gauge extension at the peak"},
              {"broken_bonds_at_peak", "-", "cement bonds broken in the loading by the peak"},
              {"fracture_height_ratio", "-", "where the fracture lies, 0 bottom to 1 top"},
              {"fracture_angle_to_loading_deg", "deg",
               "the fracture's axis against the load (90: across it)"},
          });
  return o;
}

}  // namespace rocklab::rigs::direct_tension
