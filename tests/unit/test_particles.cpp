// The particle store: handles, generations, swap-removal and permutation.

#include <gtest/gtest.h>

#include "lab/core/particles.hpp"

namespace rocklab {
namespace {

ParticleSpec<3> sphere(double x, double r = 1e-3) {
  ParticleSpec<3> p;
  p.position = {x, 0, 0};
  p.radius = r;
  p.density = 2000.0;
  return p;
}

TEST(ParticleStore, MassAndInertiaFromRadiusAndDensity) {
  ParticleStore<3> s;
  const auto id = s.add(sphere(0.0, 2e-3));
  const double m = 2000.0 * 4.0 / 3.0 * M_PI * 8e-9;
  EXPECT_NEAR(s.mass(s.index(id)), m, 1e-15);
  EXPECT_NEAR(1.0 / s.inv_inertia[s.index(id)], 0.4 * m * 4e-6, 1e-20);

  ParticleStore<2> d;
  d.thickness = 0.5;
  ParticleSpec<2> p;
  p.radius = 1e-3;
  p.density = 1000.0;
  const auto id2 = d.add(p);
  const double m2 = 1000.0 * M_PI * 1e-6 * 0.5;
  EXPECT_NEAR(d.mass(d.index(id2)), m2, 1e-15);
  EXPECT_NEAR(1.0 / d.inv_inertia[d.index(id2)], 0.5 * m2 * 1e-6, 1e-20);
}

TEST(ParticleStore, FixedParticlesHaveInfiniteMass) {
  ParticleStore<3> s;
  auto p = sphere(0.0);
  p.fixed = true;
  const auto id = s.add(p);
  EXPECT_EQ(s.inv_mass[s.index(id)], 0.0);
  EXPECT_EQ(s.inv_inertia[s.index(id)], 0.0);
}

TEST(ParticleStore, RemovedIdsAreDetectedAndSlotsReusedWithNewGeneration) {
  ParticleStore<3> s;
  const auto a = s.add(sphere(1.0));
  const auto b = s.add(sphere(2.0));
  const auto c = s.add(sphere(3.0));
  s.remove(a);
  EXPECT_FALSE(s.valid(a));
  EXPECT_THROW(s.index(a), StaleParticleId);
  // The last particle took the removed one's place; its handle still finds it.
  EXPECT_DOUBLE_EQ(s.pos[s.index(c)].x(), 3.0);
  EXPECT_DOUBLE_EQ(s.pos[s.index(b)].x(), 2.0);
  const auto d = s.add(sphere(4.0));
  EXPECT_EQ(d.slot, a.slot);
  EXPECT_NE(d.generation, a.generation);
  EXPECT_FALSE(s.valid(a));
  EXPECT_DOUBLE_EQ(s.pos[s.index(d)].x(), 4.0);
}

TEST(ParticleStore, PermuteKeepsHandles) {
  ParticleStore<3> s;
  std::vector<ParticleId> ids;
  for (int k = 0; k < 5; ++k) ids.push_back(s.add(sphere(k)));
  s.permute({4, 2, 0, 1, 3});
  for (int k = 0; k < 5; ++k) EXPECT_DOUBLE_EQ(s.pos[s.index(ids[k])].x(), k);
  EXPECT_DOUBLE_EQ(s.pos[0].x(), 4.0);
}

TEST(ParticleStore, RejectsBadInput) {
  ParticleStore<3> s;
  EXPECT_THROW(s.add(sphere(0.0, -1.0)), std::invalid_argument);
  auto p = sphere(0.0);
  p.density = 0.0;
  EXPECT_THROW(s.add(p), std::invalid_argument);
  p = sphere(NAN);
  EXPECT_THROW(s.add(p), std::invalid_argument);
}

}  // namespace
}  // namespace rocklab
