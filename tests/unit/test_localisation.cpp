// The band detector on synthetic damage: a band of known angle in a uniform background;
// bonds counted by their orientation to sigma_1; and a Brazilian disk's fracture located.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "lab/core/random.hpp"
#include "rigs/common/localisation.hpp"
#include "rigs/common/specimen.hpp"
#include "rigs/tensile/crack.hpp"
#include "tests/support.hpp"

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

// A band normal to sigma_1 across a sample twice as tall as wide, with twice the
// background's density, in uniform damage (2,700 points, as the most compacted 15% of a
// full 2D sample): counted raw, a window along the axis holds more points than the band
// (the sample is twice as long that way), and the band was missed; normalised by the
// window's share of the sample, the band is found, at 90 degrees.
TEST(Localisation, FindsABandAcrossATallSampleAgainstLongerWindows) {
  for (std::uint64_t seed : {1, 2, 3}) {
    Rng rng(seed);
    std::vector<std::array<double, 3>> p;
    for (int k = 0; k < 2700; ++k) p.push_back({rng.uniform(0, 0.0145), rng.uniform(0, 0.029), 0});
    for (int k = 0; k < 50; ++k) {
      p.push_back({rng.uniform(0, 0.0145), 0.018 + rng.uniform(-0.00025, 0.00025), 0});
    }
    const Band b = findBand(p, 2, 1, 0.0005);
    EXPECT_NEAR(b.angle_to_axial_deg, 90.0, 2.0) << seed;
    EXPECT_NEAR(b.offset, 0.018, 0.0005) << seed;
    EXPECT_GT(b.contrast, 1.6) << seed;
  }
}

// A lattice under a homogeneous strain: every interior particle measures it exactly.
TEST(StrainField, AHomogeneousStrainIsMeasuredExactly) {
  std::vector<std::array<double, 3>> before, after;
  const double exx = -1e-3, eyy = 2e-3, exy = 5e-4;  // symmetric gradient
  for (int i = 0; i < 20; ++i) {
    for (int j = 0; j < 40; ++j) {
      const double x = 1e-4 * (i + 0.5 * (j % 2)), y = 0.866e-4 * j;
      before.push_back({x, y, 0});
      after.push_back({x + exx * x + exy * y, y + exy * x + eyy * y, 0});
    }
  }
  const std::vector<LocalStrain> e = localStrain(before, after, 2, 1.5e-4);
  // Deviatoric part: exx - m, eyy - m with m the mean; compaction: minus the trace.
  const double m = 0.5 * (exx + eyy);
  const double shear = std::sqrt((exx - m) * (exx - m) + (eyy - m) * (eyy - m) + 2 * exy * exy);
  std::size_t unmeasured = 0;  // corners: fewer than three neighbours
  for (std::size_t k = 0; k < e.size(); ++k) {
    if (e[k].shear == 0.0) {
      ++unmeasured;
      continue;
    }
    EXPECT_NEAR(e[k].shear, shear, 1e-12) << k;
    EXPECT_NEAR(e[k].compaction, -(exx + eyy), 1e-12) << k;
  }
  EXPECT_LE(unmeasured, 2u);
  EXPECT_THROW(localStrain(before, {}, 2, 1e-4), std::invalid_argument);
}

// Two blocks sliding past each other along a band at 30 degrees to y (sigma_1): the most
// strained particles lie in the band and the detector finds its angle; the platens (the
// faces) are left out.
TEST(StrainField, TheMostStrainedParticlesLieInTheSlipBand) {
  Rng rng(11);
  const double angle = 30.0 * kDeg;
  const std::array<double, 2> t{std::sin(angle), std::cos(angle)};   // along the band
  const std::array<double, 2> n{std::cos(angle), -std::sin(angle)};  // its normal
  std::vector<std::array<double, 3>> before, after;
  for (int k = 0; k < 4000; ++k) {
    const double x = rng.uniform(0, 0.01), y = rng.uniform(0, 0.02);
    const double d = (x - 0.005) * n[0] + (y - 0.01) * n[1];  // signed distance to the band
    // Slip of 2e-5 m across a band 0.3 mm thick, a smooth ramp inside it.
    const double slip = 2e-5 * std::clamp(d / 0.0003 + 0.5, 0.0, 1.0);
    before.push_back({x, y, 0});
    // with a background jitter, as in any granular sample, 1% of the slip
    after.push_back(
        {x + slip * t[0] + 2e-7 * rng.normal(), y + slip * t[1] + 2e-7 * rng.normal(), 0});
  }
  const auto pts = strainedParticles(before, after, 2, 3e-4, 0.05, StrainPart::Shear);
  ASSERT_GT(pts.size(), 150u);  // 5% of the ~3,500 particles off the faces
  std::size_t in_band = 0;      // the rest: the jitter's strongest spots
  for (const auto& p : pts) {
    in_band += std::abs((p[0] - 0.005) * n[0] + (p[1] - 0.01) * n[1]) < 0.00015 + 3e-4;
    EXPECT_GE(p[0], 3e-4);  // off the faces
    EXPECT_LE(p[1], 0.02 - 3e-4);
  }
  EXPECT_GT(in_band, pts.size() / 2);
  EXPECT_NEAR(findBand(pts, 2, 1, 0.001).angle_to_axial_deg, 30.0, 2.0);
}

// A layer normal to sigma_1 (y) that compacts while the rest moves rigidly: the most
// compacted particles lie in it, and the band found is a compaction band.
TEST(StrainField, TheMostCompactedParticlesLieInTheCompactionBand) {
  Rng rng(13);
  std::vector<std::array<double, 3>> before, after;
  for (int k = 0; k < 4000; ++k) {
    const double x = rng.uniform(0, 0.01), y = rng.uniform(0, 0.02);
    // Shortening of 2e-5 m inside 0.3 mm about y = 12 mm: the part above moves down.
    const double dy = -2e-5 * std::clamp((y - 0.012) / 0.0003 + 0.5, 0.0, 1.0);
    before.push_back({x, y, 0});
    after.push_back({x + 2e-7 * rng.normal(), y + dy + 2e-7 * rng.normal(), 0});
  }
  const auto pts = strainedParticles(before, after, 2, 3e-4, 0.05, StrainPart::Compaction);
  ASSERT_GT(pts.size(), 150u);  // 5% of the ~3,500 particles off the faces
  std::size_t in_band = 0;
  for (const auto& p : pts) in_band += std::abs(p[1] - 0.012) < 0.00015 + 3e-4;
  EXPECT_GT(in_band, pts.size() / 2);
  const Band b = findBand(pts, 2, 1, 0.001);
  EXPECT_NEAR(b.angle_to_axial_deg, 90.0, 2.0);
  EXPECT_TRUE(b.is_compaction());
}

// Bonds by orientation to sigma_1 (the damage anisotropy of Li & Holt Figure 18b): five
// bonded pairs of spheres, far apart, at 0, 20, 45, 70 and 90 degrees from the z axis; 0
// and 20 are axial (within 30 degrees of the axis), 70 and 90 lateral, 45 neither; another
// kind's bonds are not counted.
TEST(BondOrientations, CountsBondsNearTheAxisAndNearItsNormalPlane) {
  Simulation<3> sim(testing::table(testing::linearMaterial(1e6, 1e6, 0.5)), {});
  ParticleSpec<3> p;
  p.radius = 1e-3;
  p.density = 2650.0;
  double x = 0.0;
  for (const double deg : {0.0, 20.0, 45.0, 70.0, 90.0}) {
    p.position = Eigen::Vector3d(x, 0.0, 0.0);
    sim.particles().add(p);
    p.position += 2e-3 * Eigen::Vector3d(std::sin(deg * kDeg), 0.0, std::cos(deg * kDeg));
    sim.particles().add(p);
    x += 10e-3;
  }
  BondKind cement;
  cement.modulus = 1e9;
  cement.stiffness_ratio = 1.0;
  cement.tensile_mean = cement.shear_mean = 1e6;
  cement.tensile_std = cement.shear_std = 0.0;
  const std::uint8_t kind = sim.addBondKind(cement);
  ASSERT_EQ(sim.cement(kind, 0.01).installed, 5u);
  const BondOrientations n = bondOrientations(sim, kind, 2);
  EXPECT_EQ(n.axial, 2u);
  EXPECT_EQ(n.lateral, 2u);
  // About the x axis instead, 90 and 70 are axial and 0 and 20 lateral.
  const BondOrientations about_x = bondOrientations(sim, kind, 0);
  EXPECT_EQ(about_x.axial, 2u);
  EXPECT_EQ(about_x.lateral, 2u);
  cement.name = "other";
  EXPECT_EQ(bondOrientations(sim, sim.addBondKind(cement), 2).axial, 0u);
  // A bond turning across a class boundary stays in the class it had at the reference: the
  // 20-degree bond turned to 45 degrees is still counted axial, not inclined (else the
  // axial class would seem to have lost a bond, and the inclined one to have more intact
  // bonds than it started with).
  const BondClasses reference = bondClasses(sim, kind, 2);
  auto& P = sim.particles();  // the 20-degree pair: slots 2 and 3
  P.pos[P.indexOfSlot(3)] =
      P.pos[P.indexOfSlot(2)] + 2e-3 * Eigen::Vector3d(std::sin(45 * kDeg), 0, std::cos(45 * kDeg));
  EXPECT_EQ(bondOrientations(sim, kind, 2).axial, 1u);  // by the present orientation
  const BondOrientations held = intactByClass(sim, kind, reference);
  EXPECT_EQ(held.axial, 2u);
  EXPECT_EQ(held.inclined, 1u);
  EXPECT_EQ(held.lateral, 2u);
}

// A Brazilian disk's fracture (rigs/tensile/crack.hpp): breaks scattered along a line of
// known angle and offset give that angle and offset back; a round cloud is no line.
TEST(Fracture, ItsAxisAngleAndOffsetFromTheCentre) {
  Rng rng(4);
  const double d = 0.01;  // m, the disk's diameter
  for (const double angle : {0.0, 15.0, 50.0}) {
    for (const double offset : {0.0, 0.002}) {
      std::vector<CrackPoint> pts;
      const double ux = std::sin(angle * kDeg), uy = std::cos(angle * kDeg);  // along the crack
      for (int k = 0; k < 400; ++k) {
        const double s = rng.uniform(-0.45, 0.45) * d, w = rng.uniform(-0.02, 0.02) * d;
        // A line through (offset, 0) perpendicular to it, shifted across by w.
        pts.push_back({offset * uy + s * ux + w * uy, -offset * ux + s * uy - w * ux});
      }
      const Crack c = crackOf(pts, d);
      EXPECT_NEAR(c.angle_to_axis_deg, angle, 1.0) << angle << " " << offset;
      EXPECT_NEAR(c.offset_ratio, offset / d, 0.01) << angle << " " << offset;
      EXPECT_GT(c.elongation, 5.0);
      EXPECT_EQ(c.throughCentre(), angle <= 20.0 && offset / d <= 0.1) << angle << " " << offset;
    }
  }
  std::vector<CrackPoint> cloud;
  for (int k = 0; k < 400; ++k) cloud.push_back({rng.uniform(-1, 1) * d, rng.uniform(-1, 1) * d});
  EXPECT_LT(crackOf(cloud, d).elongation, 1.5);
  EXPECT_FALSE(crackOf(cloud, d).throughCentre());
}

}  // namespace
}  // namespace rocklab::rigs
