// Breakable superparticles: grain shapes within the aspect limit, bonds inside and between
// grains, a single grain crushed between platens (fragments counted), and grain packings.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "lab/core/grains.hpp"
#include "tests/support.hpp"

namespace rocklab {
namespace {

using V2 = Eigen::Vector2d;
using V3 = Eigen::Vector3d;

TEST(GrainShape, FeretAspectRatioOfSimpleShapes) {
  const double r = 1e-3;
  EXPECT_NEAR(feretAspectRatio<2>({{V2(0, 0)}, {r}}), 1.0, 1e-12);
  EXPECT_NEAR(feretAspectRatio<2>({{V2(-r, 0), V2(r, 0)}, {r, r}}), 2.0, 1e-12);
  // 3D: two touching spheres, 4r long and 2r wide; the sampled directions (about 0.08 rad
  // apart) miss the axis by a little, which only shortens the longest caliper.
  const double ar = feretAspectRatio<3>({{V3(-r, 0, 0), V3(r, 0, 0)}, {r, r}});
  EXPECT_LE(ar, 2.0);
  EXPECT_GT(ar, 2.0 * (1 - 2e-3));
}

template <int D>
void shapesStayWithinTheLimits() {
  Rng rng(7);
  GrainShapeSpec spec;
  spec.pebbles_across = 4;
  const double length = 2e-3;
  double sum = 0.0, lo = INFINITY, hi = 0.0;
  for (int g = 0; g < 200; ++g) {
    const ClumpShape<D> s = makeGrainShape<D>(length, spec, rng);
    const double ar = feretAspectRatio<D>(s);
    EXPECT_LT(ar, spec.max_aspect_ratio);
    sum += ar, lo = std::min(lo, ar), hi = std::max(hi, ar);
    ASSERT_GE(s.centers.size(), 3u);
    for (std::size_t a = 0; a < s.centers.size(); ++a) {
      for (std::size_t b = a + 1; b < s.centers.size(); ++b) {
        // No two pebbles farther apart than the grain's length.
        EXPECT_LE((s.centers[a] - s.centers[b]).norm() + 2 * s.radii[a], length * (1 + 1e-9));
        // Close-packed pebbles: touching or apart, never overlapping.
        EXPECT_GE((s.centers[a] - s.centers[b]).norm(), 2 * s.radii[a] * (1 - 1e-9));
      }
    }
  }
  // Irregular: a spread of elongations, not one repeated shape.
  EXPECT_GT(hi - lo, 0.2);
  EXPECT_GT(sum / 200, 1.1);
}
TEST(GrainShape, ShapesStayWithinTheLimits2D) {
  shapesStayWithinTheLimits<2>();
}
TEST(GrainShape, ShapesStayWithinTheLimits3D) {
  shapesStayWithinTheLimits<3>();
}

BondKind bondKind(bool intragranular, double strength) {
  BondKind k;
  k.name = intragranular ? "grain" : "cement";
  k.intragranular = intragranular;
  k.modulus = 4e9;
  k.stiffness_ratio = 1.0;
  k.tensile_mean = k.shear_mean = strength;
  k.tensile_std = k.shear_std = 0.0;
  return k;
}

// Grains side by side: intragranular bonds only inside grains, cement only between.
TEST(GrainBonds, KindsRespectGrainBoundaries) {
  const double r = 1e-3;
  Simulation<2> sim(testing::table(testing::linearMaterial(1e8, 1e8, 0.5)), testing::undamped());
  for (int k = 0; k < 6; ++k) {
    ParticleSpec<2> p;
    p.position = V2(2 * r * k, 0);
    p.radius = r;
    p.density = 2650;
    p.cluster = static_cast<std::uint32_t>(k / 3);  // grains {0,1,2} and {3,4,5}
    sim.particles().add(p);
  }
  const auto intra = sim.addBondKind(bondKind(true, 1e7));
  const auto inter = sim.addBondKind(bondKind(false, 1e6));
  EXPECT_EQ(sim.cement(intra, 1e-3).installed, 4u);
  EXPECT_EQ(sim.cement(inter, 1e-3).installed, 1u);
  const auto fragments = grainFragments<2>(sim.particles(), sim.bonds(), sim.bondKinds());
  EXPECT_EQ(fragments, (std::vector<std::uint32_t>{1, 1}));
}

// One hexagonal grain of 7 disks (a centre and its ring) between two platens closing at a
// slow rate: the intragranular bonds break and the grain splits into fragments.
TEST(GrainCrushing, DiametralCompressionSplitsTheGrain) {
  const double r = 1e-3, thickness = 2e-3;
  SimulationConfig cfg;
  cfg.local_damping = 0.7;
  Simulation<2> sim(
      testing::table(testing::linearMaterial(4e9 * thickness, 4e9 * thickness, 0.5, 0.2)), cfg);
  sim.particles().thickness = thickness;
  std::vector<V2> centers{V2::Zero()};
  for (int k = 0; k < 6; ++k) {
    const double a = std::numbers::pi / 3 * k;  // two pebbles against each platen
    centers.push_back(2 * r * V2(std::cos(a), std::sin(a)));
  }
  for (const V2& c : centers) {
    ParticleSpec<2> p;
    p.position = c;
    p.radius = r;
    p.density = 2650;
    p.cluster = 0;
    sim.particles().add(p);
  }
  const auto intra = sim.addBondKind(bondKind(true, 20e6));
  ASSERT_EQ(sim.cement(intra, 1e-3).installed, 12u);  // 6 spokes and the 6-ring
  const double top = 2 * r * std::sin(std::numbers::pi / 3) + r;
  Wall<2> lo, hi;
  lo.name = "lo";
  lo.normal = V2::UnitY();
  lo.point = V2(0, -top);
  lo.velocity = V2(0, 0.02);
  hi.name = "hi";
  hi.normal = -V2::UnitY();
  hi.point = V2(0, top);
  hi.velocity = V2(0, -0.02);
  sim.addWall(lo);
  sim.addWall(hi);
  double peak = 0.0;
  std::uint32_t fragments = 1;
  while (sim.wall(1).point.y() > 0.6 * top && fragments < 2) {
    sim.run(100);
    peak = std::max(peak, sim.wall(1).force.norm());
    fragments = grainFragments<2>(sim.particles(), sim.bonds(), sim.bondKinds())[0];
  }
  EXPECT_GE(fragments, 2u);
  EXPECT_GT(
      sim.brokenBonds(intra, BondBreakMode::Tensile) + sim.brokenBonds(intra, BondBreakMode::Shear),
      0u);
  // The platens carried a load of the order of the bonds' strength times their section
  // before it split (a bond section is 2 r t = 4e-6 m^2: 20 MPa gives 80 N).
  EXPECT_GT(peak, 20.0);
  EXPECT_LT(peak, 2000.0);
  EXPECT_EQ(crushedGrains({1}, {fragments}), 1u);
}

template <int D>
void packsToTheTargetPorosity(double porosity) {
  GrainPackingSpec spec;
  spec.grains = D == 2 ? 120 : 60;
  spec.sizes = SizeDistribution::phiGaussian(1.0, 0.3, 0.3e-3, 1.2e-3);
  spec.shape.pebbles_across = D == 2 ? 4 : 3;
  spec.porosity = porosity;
  spec.thickness = 1e-3;
  spec.seed = 11;
  PackingReport report;
  const GrainPacking<D> g = generateGrainPacking<D>(spec, &report);
  ASSERT_EQ(g.grains(), spec.grains);
  EXPECT_LT(report.max_overlap, 0.05);  // the grains fit in the box
  // The porosity measured as a user's image analysis would: the share of random points in
  // the box that no pebble covers. It counts overlaps once and sees any gap the pack leaves
  // at the walls, which the nominal porosity (the box sized for it) cannot. 40,000 points
  // give a binomial sd of 0.0024; 0.01 is four of them (measured 0.3020 in 2D, 0.6165 in
  // 3D).
  std::mt19937_64 rng(5);
  int empty = 0;
  const int points = 40000;
  for (int k = 0; k < points; ++k) {
    Vec<D> x;
    for (int d = 0; d < D; ++d) {
      x[d] = std::uniform_real_distribution<double>(g.pebbles.lo[d], g.pebbles.hi[d])(rng);
    }
    bool covered = false;
    for (std::size_t i = 0; i < g.pebbles.centers.size() && !covered; ++i) {
      covered = (x - g.pebbles.centers[i]).squaredNorm() < g.pebbles.radii[i] * g.pebbles.radii[i];
    }
    empty += covered ? 0 : 1;
  }
  const double measured = static_cast<double>(empty) / points;
  EXPECT_NEAR(measured, porosity, 0.01) << "nominal " << g.pebbles.porosity();
  for (double ar : g.grain_aspect_ratio) EXPECT_LT(ar, spec.shape.max_aspect_ratio);
  // Every grain's pebbles are there, grain by grain.
  std::vector<int> count(spec.grains, 0);
  for (std::uint32_t k : g.grain) ++count.at(k);
  for (int c : count) EXPECT_GE(c, 3);
  // Pebbles inside the box.
  for (std::size_t i = 0; i < g.pebbles.centers.size(); ++i) {
    for (int d = 0; d < D; ++d) {
      EXPECT_GT(g.pebbles.centers[i][d], g.pebbles.lo[d]);
      EXPECT_LT(g.pebbles.centers[i][d], g.pebbles.hi[d]);
    }
  }
  // Seedable.
  const GrainPacking<D> again = generateGrainPacking<D>(spec);
  EXPECT_EQ(again.pebbles.centers, g.pebbles.centers);
}
TEST(GrainPacking, PacksToTheTargetPorosity2D) {
  packsToTheTargetPorosity<2>(0.30);
}
TEST(GrainPacking, PacksToTheTargetPorosity3D) {
  packsToTheTargetPorosity<3>(0.62);
}

}  // namespace
}  // namespace rocklab
