// The band detector on synthetic damage: a band of known angle in a uniform background.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "lab/core/random.hpp"
#include "rigs/common/localisation.hpp"

namespace rocklab::rigs {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// 2D: a 10 x 20 mm sample (sigma_1 along y), 300 uniform points and 300 in a band 1 mm
// thick through the centre at `angle` to the y axis.
std::vector<std::array<double, 3>> synthetic2D(double angle, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<std::array<double, 3>> p;
  for (int k = 0; k < 300; ++k) p.push_back({rng.uniform(0, 0.01), rng.uniform(0, 0.02), 0});
  const double dx = std::sin(angle * kDeg), dy = std::cos(angle * kDeg);
  for (int k = 0; k < 300; ++k) {
    const double s = rng.uniform(-0.008, 0.008), t = rng.uniform(-0.0005, 0.0005);
    p.push_back({0.005 + s * dx + t * dy, 0.01 + s * dy - t * dx, 0});
  }
  return p;
}

TEST(Localisation, RecoversTheAngleOfASyntheticBand2D) {
  for (double angle : {0.0, 20.0, 35.0, 50.0, 80.0, 90.0}) {
    const Band b = findBand(synthetic2D(angle, 3), 2, 1, 0.001);
    EXPECT_NEAR(b.angle_to_axial_deg, angle, 2.0) << angle;
    EXPECT_GT(b.contrast, 3.0) << angle;
    EXPECT_NEAR(b.thickness, 0.001, 0.0005) << angle;
    EXPECT_EQ(b.is_compaction(), angle >= 70.0) << angle;
  }
}

TEST(Localisation, RecoversTheAngleOfASyntheticBand3D) {
  Rng rng(5);
  for (double angle : {30.0, 85.0}) {
    std::vector<std::array<double, 3>> p;
    for (int k = 0; k < 400; ++k) {
      p.push_back({rng.uniform(0, 0.01), rng.uniform(0, 0.01), rng.uniform(0, 0.02)});
    }
    // A plane through the centre containing the y axis, at `angle` to z.
    const double dx = std::sin(angle * kDeg), dz = std::cos(angle * kDeg);
    for (int k = 0; k < 400; ++k) {
      const double s = rng.uniform(-0.006, 0.006), u = rng.uniform(-0.005, 0.005);
      const double t = rng.uniform(-0.0005, 0.0005);
      p.push_back({0.005 + s * dx + t * dz, 0.005 + u, 0.01 + s * dz - t * dx});
    }
    const Band b = findBand(p, 3, 2, 0.001);
    EXPECT_NEAR(b.angle_to_axial_deg, angle, 2.0) << angle;
    EXPECT_EQ(b.is_compaction(), angle >= 70.0);
  }
}

TEST(Localisation, UniformDamageHasNoContrast) {
  Rng rng(9);
  std::vector<std::array<double, 3>> p;
  for (int k = 0; k < 600; ++k) p.push_back({rng.uniform(0, 0.01), rng.uniform(0, 0.02), 0});
  EXPECT_LT(findBand(p, 2, 1, 0.001).contrast, 2.0);
  EXPECT_THROW(findBand({{0, 0, 0}}, 2, 1, 0.001), std::invalid_argument);
}

}  // namespace
}  // namespace rocklab::rigs
