// Walls: force read-out, prescribed motion and servo control.

#include <gtest/gtest.h>

#include "tests/support.hpp"

namespace rocklab {
namespace {

using testing::addParticle;
using V3 = Eigen::Vector3d;

Wall<3> plane(const V3& normal, const V3& point, const std::string& name) {
  Wall<3> w;
  w.name = name;
  w.normal = normal;
  w.point = point;
  return w;
}

TEST(Walls, ForceReadOutIsTheContactForce) {
  const double kn = 2e6, r = 1e-3, overlap = 3e-6;
  SimulationConfig cfg = testing::undamped();
  cfg.timestep.automatic = false;
  cfg.timestep.fixed_dt = 1e-6;
  Simulation<3> sim(testing::table(testing::linearMaterial(kn, kn, 0.5)), cfg);
  ParticleSpec<3> p;
  p.position = {0, 0, r - overlap};
  p.radius = r;
  p.fixed = true;
  sim.particles().add(p);
  sim.addWall(plane(V3::UnitZ(), V3::Zero(), "floor"));
  sim.step();
  const Wall<3>& w = sim.wall(0);
  // Series springs: the wall has the same material, k = kn / 2.
  EXPECT_NEAR(w.force.z(), -0.5 * kn * overlap, 1e-12);
  EXPECT_NEAR(w.normalStress(1e-4), 0.5 * kn * overlap / 1e-4, 1e-6);
  EXPECT_EQ(w.contacts, 1u);
  EXPECT_DOUBLE_EQ(w.stiffness, 0.5 * kn);
}

TEST(Walls, PrescribedVelocityMovesTheWall) {
  SimulationConfig cfg;
  cfg.timestep.automatic = false;
  cfg.timestep.fixed_dt = 1e-5;
  Simulation<3> sim(testing::table(testing::linearMaterial(1e6, 1e6, 0.5)), cfg);
  addParticle<3>(sim, V3(0, 0, 0.5), 1e-3, V3::Zero());
  auto w = plane(V3::UnitZ(), V3::Zero(), "floor");
  w.velocity = {0, 0, 0.1};
  sim.addWall(w);
  sim.run(1000);
  EXPECT_NEAR(sim.wall(0).point.z(), 0.1 * 1e-2, 1e-12);
}

// A particle between a fixed floor and a servo-controlled lid: the lid settles where the
// contact force equals the target stress times the area.
TEST(Walls, ServoHoldsTheTargetStress) {
  const double kn = 1e6, r = 1e-3, area = 4e-6, target = 2e5;  // 0.8 N
  SimulationConfig cfg;
  cfg.local_damping = 0.7;
  Simulation<3> sim(testing::table(testing::linearMaterial(kn, kn, 0.5)), cfg);
  addParticle<3>(sim, V3(0, 0, r), r, V3::Zero());
  sim.addWall(plane(V3::UnitZ(), V3::Zero(), "floor"));
  auto lid = plane(-V3::UnitZ(), V3(0, 0, 2 * r + 1e-4), "lid");
  lid.servo.enabled = true;
  lid.servo.target_stress = target;
  lid.servo.area = area;
  lid.servo.alpha = 0.5;
  lid.servo.max_speed = 0.05;
  sim.addWall(lid);
  sim.run(20000);
  EXPECT_NEAR(sim.wall(1).normalStress(area), target, 0.01 * target);
  // Two contacts in series, each k = kn / 2: overlap per contact = F / (kn / 2).
  const double f = target * area, each = f / (0.5 * kn);
  EXPECT_NEAR(sim.wall(1).point.z(), 2 * r - 2 * each, 0.02 * 2 * each);
  EXPECT_LT(std::abs(sim.wall(1).velocity.z()), 1e-4);
}

TEST(Walls, ServoFollowsARamp) {
  const double kn = 1e6, r = 1e-3, area = 4e-6;
  SimulationConfig cfg;
  cfg.local_damping = 0.7;
  Simulation<3> sim(testing::table(testing::linearMaterial(kn, kn, 0.5)), cfg);
  addParticle<3>(sim, V3(0, 0, r), r, V3::Zero());
  sim.addWall(plane(V3::UnitZ(), V3::Zero(), "floor"));
  auto lid = plane(-V3::UnitZ(), V3(0, 0, 2 * r - 1e-7), "lid");
  lid.servo.enabled = true;
  lid.servo.target_stress = 1e4;
  lid.servo.target_rate = 1e4 / 1e-3;  // +1e4 Pa per millisecond
  lid.servo.area = area;
  lid.servo.max_speed = 0.05;
  sim.addWall(lid);
  sim.run(10000);
  const double t = sim.time();
  const double want = 1e4 + 1e7 * t;
  EXPECT_NEAR(sim.wall(1).normalStress(area), want, 0.02 * want);
}

TEST(Walls, ServoSettingsAreValidated) {
  Simulation<3> sim(testing::table(testing::linearMaterial(1e6, 1e6, 0.5)), testing::undamped());
  addParticle<3>(sim, V3(0, 0, 1e-3), 1e-3, V3::Zero());
  auto lid = plane(-V3::UnitZ(), V3(0, 0, 2e-3), "lid");
  lid.servo.enabled = true;
  lid.servo.area = 1e-6;
  lid.servo.max_speed = 0.0;
  sim.addWall(lid);
  try {
    sim.step();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_speed"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("m/s"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rocklab
