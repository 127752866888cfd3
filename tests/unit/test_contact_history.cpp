// Tangential contact history survives neighbour-list rebuilds, particle reordering and
// swaps of the pair's orientation in the list.

#include <gtest/gtest.h>

#include "tests/support.hpp"

namespace rocklab {
namespace {

using testing::addParticle;
using V3 = Eigen::Vector3d;

struct Driven {
  Simulation<3> sim;
  ParticleId a, b, anchor;
};

// Two driven (fixed) spheres in contact, and a far anchor that pins the sort grid.
Driven makePair(double skin, bool spatial_sort) {
  SimulationConfig cfg = testing::undamped();
  cfg.skin = skin;
  cfg.spatial_sort = spatial_sort;
  cfg.timestep.automatic = false;
  cfg.timestep.fixed_dt = 1e-6;
  Driven d{Simulation<3>(testing::table(testing::linearMaterial(1e6, 1e6, 10.0)), cfg), {}, {}, {}};
  const double r = 1e-3, gap = 2 * r - 2e-6;  // 2 micrometre overlap
  const V3 a(0, 2.5e-3, 0);
  const V3 b = a + gap * V3(1, -1, 0).normalized();
  for (auto [x, id] :
       {std::pair{a, &d.a}, std::pair{b, &d.b}, std::pair{V3(-1e-2, -1e-2, -1e-2), &d.anchor}}) {
    ParticleSpec<3> p;
    p.position = x;
    p.radius = r;
    p.fixed = true;
    *id = d.sim.particles().add(p);
  }
  return d;
}

void drive(Driven& d, const V3& va, const V3& vb, int steps) {
  auto& P = d.sim.particles();
  for (int s = 0; s < steps; ++s) {
    P.vel[P.index(d.a)] = va;
    P.vel[P.index(d.b)] = vb;
    d.sim.step();
  }
}

// Shear the contact, move the pair up (same sort order), then along x across a cell
// boundary, which puts a before b in the sorted order: the pair's orientation flips.
std::vector<V3> scenario(Driven& d, bool* swapped = nullptr) {
  std::vector<V3> force_on_b;
  auto record = [&] {
    const auto& P = d.sim.particles();
    force_on_b.push_back(P.force[P.index(d.b)]);
  };
  const V3 tangent = V3(1, 1, 0).normalized();
  drive(d, V3::Zero(), 0.01 * tangent, 100);  // 1 micrometre of shear
  record();
  const bool a_first_before = d.sim.particles().index(d.a) < d.sim.particles().index(d.b);
  drive(d, V3(0, 1, 0), V3(0, 1, 0), 1000);  // +1 mm in y
  record();
  drive(d, V3(1, 0, 0), V3(1, 0, 0), 800);  // +0.8 mm in x
  record();
  const bool a_first_after = d.sim.particles().index(d.a) < d.sim.particles().index(d.b);
  if (swapped) *swapped = a_first_before != a_first_after;
  return force_on_b;
}

TEST(ContactHistory, SurvivesRebuildsAndOrientationSwaps) {
  Driven reference = makePair(0.1, false);  // skin wider than the whole path: no rebuild
  const auto expected = scenario(reference);
  EXPECT_EQ(reference.sim.contacts().rebuilds, 1u);

  Driven rebuilt = makePair(2e-5, true);  // a rebuild every few steps, with reordering
  bool swapped = false;
  const auto got = scenario(rebuilt, &swapped);
  EXPECT_TRUE(swapped) << "the scenario must flip the pair's orientation in the list";
  EXPECT_GT(rebuilt.sim.contacts().rebuilds, 50u);

  ASSERT_EQ(got.size(), expected.size());
  const double shear = expected.front().norm();
  ASSERT_GT(shear, 0.5);  // the spring was loaded: 1e6 N/m * 1 um plus the normal force
  for (std::size_t k = 0; k < got.size(); ++k) {
    EXPECT_LT((got[k] - expected[k]).norm(), 1e-9 * shear) << "stage " << k;
  }
}

TEST(ContactHistory, SeparationClearsTheSpring) {
  Driven d = makePair(1e-4, true);
  const V3 tangent = V3(1, 1, 0).normalized();
  const V3 normal = V3(1, -1, 0).normalized();
  drive(d, V3::Zero(), 0.01 * tangent, 100);
  auto& P = d.sim.particles();
  auto shear = [&] {
    const V3 n = (P.pos[P.index(d.b)] - P.pos[P.index(d.a)]).normalized();
    const V3 f = P.force[P.index(d.b)];
    return (f - f.dot(n) * n).norm();
  };
  drive(d, V3::Zero(), 0.01 * normal, 10);  // 0.1 um: still touching
  EXPECT_GT(shear(), 0.4);
  drive(d, V3::Zero(), 0.01 * normal, 300);  // apart
  EXPECT_EQ(d.sim.particles().force[d.sim.particles().index(d.b)].norm(), 0.0);
  drive(d, V3::Zero(), -0.01 * normal, 300);  // back into the same overlap
  // The old shear was forgotten when the contact opened; what is left comes from the
  // slight tangential part of the approach (the normal tilted by the first shear).
  EXPECT_LT(shear(), 1e-3);
}

}  // namespace
}  // namespace rocklab
