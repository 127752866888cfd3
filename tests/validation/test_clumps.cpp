// Rigid clumps: mass properties of overlapping pebbles against closed forms, torque-free
// rotation against Euler's solution for a symmetric top, conservation in collisions,
// gravity through the body, breakage, and checkpoints.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>

#include "tests/support.hpp"

namespace rocklab {
namespace {

using V3 = Eigen::Vector3d;
using V2 = Eigen::Vector2d;
constexpr double kPi = std::numbers::pi;
constexpr double kRho = 2650.0;

// Integral of a polynomial of degree <= 5 over [a, b] by 3-point Gauss-Legendre (exact).
template <class F>
double gauss3(F f, double a, double b) {
  const double m = 0.5 * (a + b), h = 0.5 * (b - a), x = std::sqrt(0.6);
  return h * (5.0 / 9.0 * f(m - h * x) + 8.0 / 9.0 * f(m) + 5.0 / 9.0 * f(m + h * x));
}

TEST(ClumpMass, TwoTouchingSpheres) {
  const double r = 1e-3;
  ClumpShape<3> s{{V3(-r, 0, 0), V3(r, 0, 0)}, {r, r}};
  const auto p = massProperties<3>(s, kRho, 1.0);
  const double m = kRho * 4.0 / 3.0 * kPi * r * r * r;
  // Tolerances: the quadrature's error at the default resolution (measured 2.2e-4 on the
  // mass, see massProperties), with a margin of two.
  EXPECT_NEAR(p.mass / (2 * m), 1.0, 5e-4);
  EXPECT_NEAR(p.centroid.norm() / r, 0.0, 1e-9);
  EXPECT_NEAR(p.inertia(0, 0) / (2 * 0.4 * m * r * r), 1.0, 1e-3);
  EXPECT_NEAR(p.inertia(1, 1) / (2 * (0.4 * m * r * r + m * r * r)), 1.0, 1e-3);
  EXPECT_NEAR(p.inertia(2, 2) / p.inertia(1, 1), 1.0, 3e-4);
  EXPECT_NEAR(p.inertia(0, 1) / p.inertia(1, 1), 0.0, 1e-9);
}

// Two equal spheres a distance d apart along z, overlapping: the union's cross-section at
// height z > 0 is the upper sphere's, a^2 = r^2 - (z - d/2)^2, so the volume and moments
// are integrals of polynomials, exact by Gauss-Legendre.
TEST(ClumpMass, TwoOverlappingSpheresCountTheLensOnce) {
  const double r = 1e-3, d = r;  // half a diameter of overlap
  ClumpShape<3> s{{V3(0, 0, -0.5 * d), V3(0, 0, 0.5 * d)}, {r, r}};
  const auto p = massProperties<3>(s, kRho, 1.0, 96);
  auto a2 = [&](double z) { return r * r - (z - 0.5 * d) * (z - 0.5 * d); };
  const double top = 0.5 * d + r;
  const double volume = 2.0 * gauss3([&](double z) { return kPi * a2(z); }, 0.0, top);
  const double izz =
      2.0 * kRho * gauss3([&](double z) { return kPi * a2(z) * a2(z) / 2; }, 0.0, top);
  const double ixx =
      2.0 * kRho *
      gauss3([&](double z) { return kPi * a2(z) * a2(z) / 4 + kPi * a2(z) * z * z; }, 0.0, top);
  EXPECT_LT(volume, 2 * 4.0 / 3.0 * kPi * r * r * r * 0.9);  // the lens is a real share
  EXPECT_NEAR(p.volume / volume, 1.0, 3e-4);
  EXPECT_NEAR(p.inertia(2, 2) / izz, 1.0, 5e-4);
  EXPECT_NEAR(p.inertia(0, 0) / ixx, 1.0, 5e-4);
  EXPECT_NEAR(p.inertia(1, 1) / ixx, 1.0, 5e-4);
}

TEST(ClumpMass, TwoOverlappingDisks) {
  const double r = 1e-3, d = 1.2e-3, t = 2e-3;
  ClumpShape<2> s{{V2(-0.5 * d, 0), V2(0.5 * d, 0)}, {r, r}};
  const auto p = massProperties<2>(s, kRho, t);
  const double lens = 2 * r * r * std::acos(d / (2 * r)) - 0.5 * d * std::sqrt(4 * r * r - d * d);
  EXPECT_NEAR(p.volume / ((2 * kPi * r * r - lens) * t), 1.0, 2e-4);
  // Touching disks: the parallel-axis sum.
  ClumpShape<2> touching{{V2(-r, 0), V2(r, 0)}, {r, r}};
  const auto q = massProperties<2>(touching, kRho, t);
  const double m = kRho * kPi * r * r * t;
  EXPECT_NEAR(q.inertia / (2 * (0.5 * m * r * r + m * r * r)), 1.0, 2e-4);
}

SimulationConfig freeConfig(double dt) {
  SimulationConfig c = testing::undamped();
  c.timestep.automatic = false;
  c.timestep.fixed_dt = dt;
  return c;
}

// Pebbles turning rigidly at w about the origin, made a clump.
std::uint32_t spinningClump(Simulation<3>& sim, const std::vector<V3>& centers,
                            const std::vector<double>& radii, const V3& w) {
  std::vector<ParticleId> ids;
  for (std::size_t k = 0; k < centers.size(); ++k) {
    ParticleSpec<3> p;
    p.position = centers[k];
    p.velocity = w.cross(centers[k]);
    p.spin = w;
    p.radius = radii[k];
    p.density = kRho;
    ids.push_back(sim.particles().add(p));
  }
  return sim.addClump(ids);
}

// A symmetric top (two touching spheres along x) spinning about a tilted axis, no torque:
// L stays fixed and the symmetry axis turns about it at the rate |L| / I_perp (Euler's
// torque-free solution; Landau & Lifshitz, Mechanics, section 33).
TEST(ClumpMotion, FreeSymmetricTopPrecessesAsEulerSays) {
  const double r = 1e-3, dt = 2e-6;
  Simulation<3> sim(testing::table(testing::linearMaterial(1e5, 1e5, 0.0)), freeConfig(dt));
  const V3 w0(60.0, 100.0, 0.0);  // rad/s, tilted from the symmetry axis
  const auto c = spinningClump(sim, {V3(-r, 0, 0), V3(r, 0, 0)}, {r, r}, w0);
  sim.prepare();
  const auto& K = sim.clumps();
  const V3 L = K.momentum[c];
  // The pebbles' own angular momentum, summed by hand, is what the body took over.
  const double m = kRho * 4.0 / 3.0 * kPi * r * r * r;
  const double i_axis = 2 * 0.4 * m * r * r, i_perp = 2 * (0.4 * m * r * r + m * r * r);
  EXPECT_NEAR((L - V3(i_axis * w0.x(), i_perp * w0.y(), 0)).norm() / L.norm(), 0.0, 1e-9);
  const double e0 = rotationalEnergy(K.spin[c], K.momentum[c]);
  const int steps = 50000;  // 0.1 s: several turns of the axis
  sim.run(steps);
  const double t = steps * dt;
  EXPECT_NEAR((K.momentum[c] - L).norm() / L.norm(), 0.0, 1e-12);
  EXPECT_NEAR(rotationalEnergy(K.spin[c], K.momentum[c]) / e0, 1.0, 1e-6);
  // The axis: the first pebble's direction from the centroid.
  const auto& P = sim.particles();
  const V3 axis = (P.pos[P.index({0, 0})] - K.pos[c]).normalized();
  const double precession = L.norm() / K.principal[c].maxCoeff() * t;
  const V3 expected = Eigen::AngleAxisd(precession, L.normalized()) * V3(-1, 0, 0);
  EXPECT_GT(precession, 2 * kPi);
  EXPECT_LT((axis - expected).norm(), 2e-3)
      << "axis " << axis.transpose() << " expected " << expected.transpose();
}

// An asymmetric clump tumbling freely: angular momentum exact, energy bounded.
TEST(ClumpMotion, FreeAsymmetricClumpConservesAngularMomentum) {
  const double r = 1e-3;
  Simulation<3> sim(testing::table(testing::linearMaterial(1e5, 1e5, 0.0)), freeConfig(2e-6));
  const auto c = spinningClump(sim, {V3(0, 0, 0), V3(1.6 * r, 0.4 * r, 0), V3(0, 1.3 * r, 0.9 * r)},
                               {r, 0.8 * r, 0.6 * r}, V3(40, -25, 60));
  sim.prepare();
  const auto& K = sim.clumps();
  const V3 L = K.momentum[c];
  const V3 w_start = K.spin[c];
  const double e0 = sim.energy().kinetic();
  sim.run(100000);
  EXPECT_NEAR((K.momentum[c] - L).norm() / L.norm(), 0.0, 1e-12);
  EXPECT_NEAR(sim.energy().kinetic() / e0, 1.0, 1e-5);
  EXPECT_GT((K.spin[c] - w_start).norm() / w_start.norm(), 0.05);  // it does tumble
}

// Two clumps collide off-centre with friction: momentum and angular momentum about the
// origin are conserved to rounding, and the energy balance closes within 1%: what is left
// is the integration's collision error, O(dt^2), mostly the tangential spring energy a
// contact still holds on the step it opens (single spheres colliding the same way at the
// same step show the same share).
template <int D>
void collide() {
  const double r = 1e-3;
  SimulationConfig cfg = testing::undamped();
  cfg.timestep.safety = 0.05;  // some 60 steps per contact
  Simulation<D> sim(testing::table(testing::linearMaterial(D == 3 ? 1e5 : 1e8, 5e4, 0.5)), cfg);
  auto pebble = [&](const Vec<D>& x, const Vec<D>& v) {
    return testing::addParticle<D>(sim, x, r, v);
  };
  Vec<D> ex = Vec<D>::Unit(0), ey = Vec<D>::Unit(1);
  const Vec<D> va = 0.5 * ex, vb = -0.3 * ex + 0.05 * ey;
  sim.addClump({pebble(Vec<D>::Zero(), va), pebble(2 * r * ey, va), pebble(2 * r * ex, va)});
  const Vec<D> o = 7 * r * ex + 1.2 * r * ey;
  sim.addClump({pebble(o, vb), pebble(o + 2 * r * ex, vb), pebble(o + 2 * r * ey, vb)});
  sim.prepare();
  auto totals = [&] {
    const auto& K = sim.clumps();
    Vec<D> p = Vec<D>::Zero();
    Ang<D> l = angZero<Ang<D>>();
    for (std::size_t c = 0; c < K.size(); ++c) {
      p += K.mass[c] * K.vel[c];
      l += K.mass[c] * cross(K.pos[c], K.vel[c]) + K.momentum[c];
    }
    return std::pair{p, l};
  };
  const auto [p0, l0] = totals();
  const double e0 = sim.energy().kinetic();
  sim.run(100000);
  const auto [p1, l1] = totals();
  EXPECT_LT((p1 - p0).norm() / p0.norm(), 1e-12);
  EXPECT_LT(angNorm(Ang<D>(l1 - l0)) / angNorm(l0), 1e-9);
  EXPECT_GT(angNorm(sim.clumps().spin[0]), 1.0);  // the off-centre hit set them turning
  const EnergyReport e = sim.energy();
  EXPECT_LT(std::abs(e.imbalance()) / e0, 1e-2);
}
TEST(ClumpMotion, CollisionConservesMomentum2D) {
  collide<2>();
}
TEST(ClumpMotion, CollisionConservesMomentum3D) {
  collide<3>();
}

// A clump settles on the floor under gravity: the floor carries its weight, whatever the
// pebbles' share, and no pebble pair inside it ever meets.
TEST(ClumpMotion, GravityActsOnTheBodyAndRestsOnTheFloor) {
  const double r = 1e-3;
  SimulationConfig cfg;
  cfg.gravity = {0.0, 0.0, -9.81};
  cfg.local_damping = 0.7;
  Simulation<3> sim(testing::table(testing::linearMaterial(1e4, 1e4, 0.5, 0.3)), cfg);
  std::vector<ParticleId> ids;
  for (const V3& x : {V3(0, 0, 2 * r), V3(1.5 * r, 0, 2.2 * r), V3(0.5 * r, 1.2 * r, 2.5 * r)}) {
    ids.push_back(testing::addParticle<3>(sim, x, r, V3::Zero()));
  }
  const auto c = sim.addClump(ids);
  Wall<3> floor;
  floor.name = "floor";
  floor.normal = V3::UnitZ();
  sim.addWall(floor);
  sim.run(200000);
  const double weight = sim.clumps().mass[c] * 9.81;
  EXPECT_NEAR(sim.wall(0).force.z() / -weight, 1.0, 1e-3);
  EXPECT_EQ(sim.particleContacts(), 0u);
  EXPECT_LT(sim.clumps().vel[c].norm(), 1e-4);
}

// A breakable clump squeezed between two walls breaks when the contact force reaches
// strength d^2, and its pebbles go on as free particles.
TEST(ClumpBreakage, BreaksAtItsCharacteristicStress) {
  const double r = 1e-3, kn = 1e6;
  Simulation<2> sim(testing::table(testing::linearMaterial(kn, kn, 0.5, 0.5)), testing::undamped());
  sim.particles().thickness = 2 * r;
  std::vector<ParticleId> ids;
  for (const V2& x : {V2(0, 0), V2(2 * r, 0), V2(r, std::sqrt(3.0) * r)}) {
    ids.push_back(testing::addParticle<2>(sim, x, r, V2::Zero()));
  }
  const double strength = 2e5;  // Pa
  const auto c = sim.addClump(ids, strength);
  const double d = sim.clumps().diameter[c];
  Wall<2> lo, hi;
  lo.name = "lo";
  lo.normal = V2::UnitY();
  lo.point = V2(0, -r);
  lo.velocity = V2(0, 0.01);
  hi.name = "hi";
  hi.normal = -V2::UnitY();
  hi.point = V2(0, (1 + std::sqrt(3.0)) * r);
  hi.velocity = V2(0, -0.01);
  sim.addWall(lo);
  sim.addWall(hi);
  for (int s = 0; s < 2000000 && sim.clumps().alive[c]; ++s) sim.step();
  ASSERT_FALSE(sim.clumps().alive[c]);
  const auto& breaks = sim.clumpBreaks();
  ASSERT_EQ(breaks.size(), 1u);
  EXPECT_EQ(breaks[0].pebbles, 3u);
  // The break comes on the first step the largest contact force reaches strength d^2:
  // within one step's force increment (under 1% here).
  EXPECT_GE(breaks[0].stress, strength);
  EXPECT_LT(breaks[0].stress / strength, 1.02);
  EXPECT_GT(d, 2 * r);
  const auto& P = sim.particles();
  for (std::size_t i = 0; i < P.size(); ++i) EXPECT_EQ(P.body[i], kNoBody);
  sim.run(100);
  EXPECT_GT(sim.particleContacts(), 0u);  // the pebbles now touch each other
}

TEST(ClumpBreakage, OverlappingPebblesCannotMakeABreakableClump) {
  Simulation<2> sim(testing::table(testing::linearMaterial(1e6, 1e6, 0.5)), testing::undamped());
  auto a = testing::addParticle<2>(sim, V2(0, 0), 1e-3, V2::Zero());
  auto b = testing::addParticle<2>(sim, V2(1.5e-3, 0), 1e-3, V2::Zero());
  EXPECT_THROW(sim.addClump({a, b}, 1e6), std::invalid_argument);
  EXPECT_NO_THROW(sim.addClump({a, b}, 0.0));
  EXPECT_THROW(sim.addClump({a}), std::invalid_argument);  // already in one
}

// Clumps in a box, restarted from a checkpoint, continue bit for bit.
TEST(ClumpCheckpoint, RestartContinuesBitForBit) {
  const double r = 1e-3;
  Simulation<3> sim(testing::table(testing::linearMaterial(1e5, 5e4, 0.5, 0.2)),
                    testing::undamped());
  Rng rng(5);
  for (int g = 0; g < 8; ++g) {
    const V3 o(3 * r * (g % 2), 3 * r * ((g / 2) % 2), 3 * r * (g / 4));
    std::vector<ParticleId> ids;
    for (const V3& x : {V3(0, 0, 0), V3(1.4 * r, 0, 0), V3(0, 1.4 * r, 0)}) {
      ids.push_back(testing::addParticle<3>(
          sim, o + x, 0.8 * r, V3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1))));
    }
    sim.addClump(ids);
  }
  testing::addBox<3>(sim, V3::Constant(-r), V3::Constant(6 * r));
  sim.run(3000);
  const auto path = std::filesystem::temp_directory_path() / "rocklab-clump.ckpt";
  sim.saveCheckpoint(path.string());
  sim.run(3000);
  auto restarted = Simulation<3>::loadCheckpoint(path.string());
  restarted.run(3000);
  EXPECT_EQ(restarted.stateHash(), sim.stateHash());
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace rocklab
