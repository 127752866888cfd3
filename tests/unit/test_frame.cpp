// The loading frame's read-outs and controls on a lattice whose answers are known by hand.

#include <gtest/gtest.h>

#include "lab/core/packing.hpp"
#include "rigs/common/adaptive_rate.hpp"
#include "rigs/common/frame.hpp"
#include "tests/support.hpp"

namespace rocklab::rigs {
namespace {

using V3 = Eigen::Vector3d;
constexpr double kR = 1e-3, kKn = 1e6;

// A simple cubic lattice of n^3 spheres of radius r in a box that touches the outer layer
// with a given overlap on every face.
struct Lattice {
  std::unique_ptr<Simulation<3>> sim;
  std::unique_ptr<LoadingFrame<3>> frame;
  int n;
  explicit Lattice(int n_, double wall_overlap) : n(n_) {
    MaterialTable m;
    m.add(testing::linearMaterial(kKn, kKn, 0.0));
    SimulationConfig cfg = testing::undamped();
    cfg.timestep.automatic = false;
    cfg.timestep.fixed_dt = 1e-6;
    sim = std::make_unique<Simulation<3>>(m, cfg);
    for (int x = 0; x < n; ++x) {
      for (int y = 0; y < n; ++y) {
        for (int z = 0; z < n; ++z) {
          ParticleSpec<3> p;
          p.position = kR * V3(1 + 2 * x, 1 + 2 * y, 1 + 2 * z);
          p.radius = kR;
          p.fixed = true;  // the lattice stays put: read-outs only
          sim->particles().add(p);
        }
      }
    }
    const V3 lo = V3::Constant(wall_overlap), hi = V3::Constant(2 * n * kR - wall_overlap);
    frame = std::make_unique<LoadingFrame<3>>(*sim, lo, hi, 0);
  }
};

TEST(LoadingFrame, StressIsWallForceOverTheCurrentFace) {
  const double overlap = 1e-6;
  Lattice l(4, overlap);
  l.sim->step();
  // n^2 spheres on each face, each pressed by a wall contact of kn/2 (springs in series).
  const double side = 2 * l.n * kR - 2 * overlap;
  const double expected = l.n * l.n * 0.5 * kKn * overlap / (side * side);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(l.frame->stress(a), expected, 1e-9 * expected);
  EXPECT_NEAR(l.frame->meanStress(), expected, 1e-9 * expected);
  EXPECT_NEAR(l.frame->length(2), side, 1e-15);
  EXPECT_NEAR(l.frame->faceArea(0), side * side, 1e-18);
}

TEST(LoadingFrame, PorosityFromTheBoxAndTheParticles) {
  Lattice l(5, 0.0);
  // A simple cubic packing: 1 - pi / 6.
  EXPECT_NEAR(l.frame->porosity(), 1.0 - M_PI / 6.0, 1e-12);
}

TEST(LoadingFrame, StrainRateMovesBothWallsAndStrainIsMeasuredFromTheReference) {
  Lattice l(3, 0.0);
  using Axis = LoadingFrame<3>::Axis;
  using Mode = LoadingFrame<3>::Mode;
  const double l0 = l.frame->length(2);
  l.frame->set(2, Axis{Mode::StrainRate, 10.0});  // 10 / s compression
  for (int s = 0; s < 100; ++s) l.frame->step();
  // Each wall moves at edot L / 2 with L the current length: dL/dt = -edot L.
  const double expected = l0 * std::pow(1.0 - 10.0 * 1e-6, 100);
  EXPECT_NEAR(l.frame->length(2), expected, 1e-9 * l0);
  EXPECT_NEAR(l.frame->strain(2), (l0 - l.frame->length(2)) / l0, 1e-15);
  EXPECT_NEAR(l.frame->length(0), l0, 1e-15);  // other axes fixed
  EXPECT_NEAR(l.frame->volumetricStrain(), l.frame->strain(2), 1e-15);
  l.frame->resetReference();
  EXPECT_EQ(l.frame->strain(2), 0.0);
}

TEST(LoadingFrame, StressControlHoldsATargetOnFreeParticles) {
  // Free spheres in a box: the servo brings every axis to its own target.
  PackingSpec spec;
  spec.count = 400;
  spec.sizes = SizeDistribution::uniform(1.6e-3, 2.4e-3);
  spec.porosity = 0.42;
  const auto p = generatePacking<3>(spec);
  MaterialTable m;
  Material grain = testing::linearMaterial(0.0, 0.0, 0.5);
  grain.modulus = 1e8;
  m.add(grain);
  SimulationConfig cfg;
  cfg.local_damping = 0.7;
  Simulation<3> sim(m, cfg);
  for (std::size_t i = 0; i < p.centers.size(); ++i) {
    testing::addParticle<3>(sim, p.centers[i], p.radii[i], V3::Zero());
  }
  LoadingFrame<3> frame(sim, p.lo, p.hi, 0);
  sim.prepare();
  frame.setServo(0.5, 1e-3 * 1e-3 / sim.dt());
  using Axis = LoadingFrame<3>::Axis;
  using Mode = LoadingFrame<3>::Mode;
  const std::array<double, 3> target{1e5, 1.5e5, 3e5};
  for (int a = 0; a < 3; ++a) frame.set(a, Axis{Mode::Stress, 0.0, target[a]});
  for (int s = 0; s < 30000 && !(frame.stressError() < 0.005 && sim.unbalancedForceRatio() < 0.01);
       ++s) {
    frame.step();
  }
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(frame.stress(a), target[a], 0.01 * target[a]) << a;
  EXPECT_LT(frame.stressError(), 0.01);
}

// A column of n spheres of radius kR on the bottom wall of a box twice their diameter wide
// and a radius taller: only the bottom wall touches it.
struct Column {
  std::unique_ptr<Simulation<3>> sim;
  std::unique_ptr<LoadingFrame<3>> frame;
  int n;
  Column(int n_, SimulationConfig cfg) : n(n_) {
    cfg.timestep.automatic = false;
    cfg.timestep.fixed_dt = 1e-6;
    sim = std::make_unique<Simulation<3>>(testing::table(testing::linearMaterial(kKn, kKn, 0.0)),
                                          cfg);
    for (int k = 0; k < n; ++k) {
      testing::addParticle<3>(*sim, kR * V3(2, 2, 1 + 2 * k), kR, V3::Zero());
    }
    frame = std::make_unique<LoadingFrame<3>>(*sim, V3::Zero(), kR * V3(4, 4, 2 * n + 1), 0);
  }
  double mass() const { return 1.0 / sim->particles().inv_mass[0]; }
};

// Love (1927), Weber (1966): the average stress of the contents is the sum over contacts of
// branch vector times force over the volume. A column resting under its weight carries
// (n - k) m g across its k-th contact, a diameter long, and n m g to the wall from its first
// centre, a radius above it: m g r n^2 / V in all, where the walls read half the base load.
TEST(LoadingFrame, InteriorStressOfAColumnUnderItsWeightIsItsAverageStress) {
  SimulationConfig cfg;
  cfg.local_damping = 0.7;
  cfg.gravity = {0.0, 0.0, -9.81};
  Column c(5, cfg);
  for (int s = 0; s < 20000; ++s) c.frame->step();
  ASSERT_LT(c.sim->unbalancedForceRatio(), 1e-6);  // at rest
  const double mg = c.mass() * 9.81, n = c.n;
  const double area = c.frame->faceArea(2);
  EXPECT_NEAR(c.frame->stress(2), 0.5 * n * mg / area, 1e-6 * n * mg / area);
  // The overlaps, n m g / kn at most, shorten the branches by a part in 10^5.
  const double average = mg * kR * n * n / c.frame->volume();
  EXPECT_NEAR(c.frame->interiorStress()[2], average, 1e-4 * average);
  EXPECT_NEAR(c.frame->interiorStress()[0], 0.0, 1e-12 * average);  // nothing presses sideways
}

// Struck by the bottom platen the column is far from balance: the walls read the mean of
// that platen's force and none, and the interior stress is still the Love-Weber sum over the
// contacts as they are, branch times normal force between the spheres and centre-to-wall
// times force at the walls.
TEST(LoadingFrame, InteriorStressIsTheLoveWeberSumOfAColumnStruckByAPlaten) {
  Column c(8, testing::undamped());
  using Axis = LoadingFrame<3>::Axis;
  using Mode = LoadingFrame<3>::Mode;
  c.frame->set(2, Axis{Mode::StrainRate, 50.0});  // each platen at 0.43 m/s
  for (int s = 0; s < 20; ++s) c.frame->step();   // the top one 1,000 steps away
  const auto& P = c.sim->particles();
  double sum = 0.0;
  for (const auto& f : c.sim->contactForces())
    sum += std::abs(P.pos[f.j][2] - P.pos[f.i][2]) * f.normal;
  double lowest = INFINITY, highest = -INFINITY;
  for (std::size_t i = 0; i < P.size(); ++i) {
    lowest = std::min(lowest, P.pos[i][2]);
    highest = std::max(highest, P.pos[i][2]);
  }
  const auto& bottom = c.sim->wall(4);
  const auto& top = c.sim->wall(5);
  sum += (lowest - bottom.point[2]) * bottom.force.norm() +
         (top.point[2] - highest) * top.force.norm();
  const double love_weber = sum / c.frame->volume();
  ASSERT_EQ(top.force.norm(), 0.0);
  ASSERT_GT(bottom.force.norm(), 0.0);
  EXPECT_NEAR(c.frame->interiorStress()[2], love_weber, 1e-9 * love_weber);
  EXPECT_GT(std::abs(c.frame->stress(2) - love_weber), 0.1 * love_weber);
}

// The adaptive loading rate: up by 1.25 per calm window to its cap, back to the set rate at
// once on a break or out of balance.
TEST(AdaptiveRate, FastWhileCalmTheSetRateWhileItBreaks) {
  RateBoost boost;
  boost.max = 3.0;
  boost.calm_unbalanced = 0.01;
  AdaptiveRate rate(boost);
  EXPECT_EQ(rate.factor(), 1.0);
  EXPECT_DOUBLE_EQ(rate.update(0, 0.001), 1.25);
  EXPECT_DOUBLE_EQ(rate.update(0, 0.001), 1.5625);
  for (int k = 0; k < 10; ++k) rate.update(0, 0.001);
  EXPECT_EQ(rate.factor(), 3.0);
  EXPECT_EQ(rate.update(2, 0.001), 1.0);   // two bonds broke in the window
  EXPECT_EQ(rate.update(2, 0.001), 1.25);  // none since
  EXPECT_EQ(rate.update(2, 0.02), 1.0);    // out of balance
  AdaptiveRate off{RateBoost{}};
  EXPECT_EQ(off.update(0, 0.0), 1.0);  // rate_boost_max = 1 keeps the set rate
}

}  // namespace
}  // namespace rocklab::rigs
