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
