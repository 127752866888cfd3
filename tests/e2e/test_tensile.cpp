// The tensile tests end to end (rigs/tensile): a quick protocol run by the command into a
// notebook, its key results held to the physics they are named for and to their regression
// reference.

#include <gtest/gtest.h>

#include <algorithm>
#include <numbers>

#include "tests/e2e/protocol_support.hpp"

namespace rocklab::testing {
namespace {

// A disk cut from a cemented pack and split between platens: its tensile strength is
// 2 F / (pi D t) at the peak of the platen force recorded in the notebook (computed here
// from the series, independently of the rig's own peak), the disk splits in tension, and
// the fracture runs along the loaded diameter through the centre (Hondros 1959).
TEST(QuickProtocols, BrazilianDiskSplitsAlongTheLoadedDiameter) {
  Lab lab("brazilian");
  nb::Notebook n = runQuick(lab, "brazilian-2d-quick");
  EXPECT_EQ(scalar(n, "SELECT status FROM runs"), "completed");
  const double d = result(n, "disk_diameter_mm") * 1e-3, t = result(n, "disk_thickness_mm") * 1e-3;
  EXPECT_GT(result(n, "particles_cut_away"), 0.0);
  EXPECT_LT(result(n, "bonds_in_disk"), result(n, "bonds_installed"));
  const auto force = seriesValues(n, "platen_force_N");
  ASSERT_GT(force.size(), 20u);
  const double f_peak = *std::max_element(force.begin(), force.end());
  const double sigma_t = 2.0 * f_peak / (std::numbers::pi * d * t) / 1e6;
  EXPECT_NEAR(result(n, "tensile_strength_MPa"), sigma_t, 0.1 * sigma_t);
  EXPECT_NEAR(result(n, "peak_force_N"), f_peak, 0.1 * f_peak);
  // The force fell by half after its peak: the test ran through the failure.
  EXPECT_LT(force.back(), 0.55 * f_peak);
  // A bonded pack is weaker in tension than its cement (8 MPa): the disk fails through many
  // bonds, not one.
  EXPECT_GT(sigma_t, 0.05 * 8.0);
  EXPECT_LT(sigma_t, 8.0);
  EXPECT_GT(result(n, "broken_bonds_tensile_at_peak"), result(n, "broken_bonds_shear_at_peak"));
  EXPECT_EQ(result(n, "fracture_through_centre"), 1.0)
      << "angle " << result(n, "fracture_angle_to_loading_deg") << " deg, offset "
      << result(n, "fracture_offset_ratio") << " D, elongation "
      << result(n, "fracture_elongation");
}

// A prism whose end layers are glued to the platens and pulled apart: its tensile strength is
// the peak pull force recorded in the notebook over the cross-section; it is brittle, so its
// secant modulus at the peak lies between half its modulus in tension and that modulus; and
// its fracture runs across the load.
TEST(QuickProtocols, DirectTensionBreaksAcrossTheLoad) {
  Lab lab("direct-tension");
  nb::Notebook n = runQuick(lab, "direct-tension-2d-quick");
  EXPECT_EQ(scalar(n, "SELECT status FROM runs"), "completed");
  EXPECT_GT(result(n, "glued_particles_bottom"), 10.0);
  EXPECT_GT(result(n, "glued_particles_top"), 10.0);
  const double area = result(n, "cross_section_mm2") * 1e-6;
  const auto force = seriesValues(n, "pull_force_N");
  ASSERT_GT(force.size(), 20u);
  const double f_peak = *std::max_element(force.begin(), force.end());
  const double sigma_t = f_peak / area / 1e6;
  EXPECT_NEAR(result(n, "tensile_strength_MPa"), sigma_t, 0.1 * sigma_t);
  EXPECT_LT(force.back(), 0.55 * f_peak);  // it ran through the failure
  const double modulus = result(n, "tensile_modulus_MPa");
  const double secant = result(n, "tensile_strength_MPa") / result(n, "axial_strain_at_peak");
  EXPECT_GT(secant, 0.5 * modulus);
  EXPECT_LT(secant, 1.1 * modulus);
  EXPECT_GT(sigma_t, 0.05 * 8.0);  // weaker than its cement, through many bonds
  EXPECT_LT(sigma_t, 8.0);
  EXPECT_GT(result(n, "fracture_angle_to_loading_deg"), 45.0);
}

}  // namespace
}  // namespace rocklab::testing
