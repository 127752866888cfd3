// Hard cases finish with bounded energy and no NaN, or stop with the right diagnosis.

#include <gtest/gtest.h>

#include "lab/core/packing.hpp"
#include "tests/support.hpp"

namespace rocklab {
namespace {

using V3 = Eigen::Vector3d;

bool allFinite(const Simulation<3>& sim) {
  for (const auto& x : sim.particles().pos) {
    if (!x.allFinite()) return false;
  }
  for (const auto& v : sim.particles().vel) {
    if (!v.allFinite()) return false;
  }
  return true;
}

// Brute-force count of touching pairs, to check the multi-level neighbour list in a run.
std::size_t bruteForceContacts(const Simulation<3>& sim) {
  const auto& P = sim.particles();
  std::size_t c = 0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    for (std::size_t j = i + 1; j < P.size(); ++j) {
      const double reach = P.radius[i] + P.radius[j];
      c += (P.pos[i] - P.pos[j]).squaredNorm() < reach * reach;
    }
  }
  return c;
}

// Coarse grains among fines, diameter ratio 10:1, squeezed by walls.
TEST(HardCases, SizeRatioTenToOne) {
  PackingSpec spec;
  spec.count = 4000;
  spec.sizes = SizeDistribution::uniform(0.5e-3, 0.6e-3);
  spec.porosity = 0.55;
  spec.aspect = {2.0, 1.0, 1.0};
  const Packing<3> fines = generatePacking<3>(spec);
  SimulationConfig cfg;
  cfg.contact_law = "hertz";
  cfg.local_damping = 0.3;
  Simulation<3> sim(testing::table(testing::hertzMaterial(1e9, 0.25, 0.5, 0.1)), cfg);
  const V3 ext = fines.hi - fines.lo;
  const double big = 10 * 0.275e-3;
  ASSERT_LT(2 * big, ext.minCoeff());
  const std::vector<V3> coarse = {fines.lo + V3(0.25 * ext.x(), 0.5 * ext.y(), 0.5 * ext.z()),
                                  fines.lo + V3(0.75 * ext.x(), 0.5 * ext.y(), 0.5 * ext.z())};
  for (const V3& c : coarse) testing::addParticle<3>(sim, c, big, V3::Zero());
  for (std::size_t i = 0; i < fines.centers.size(); ++i) {
    bool inside = false;
    for (const V3& c : coarse) inside |= (fines.centers[i] - c).norm() < big + fines.radii[i];
    if (!inside) testing::addParticle<3>(sim, fines.centers[i], fines.radii[i], V3::Zero());
  }
  testing::addBox<3>(sim, fines.lo, fines.hi);
  for (int w = 0; w < 6; ++w) sim.wall(w).velocity = 0.05 * sim.wall(w).normal;
  ASSERT_NO_THROW(sim.run(6000));
  EXPECT_TRUE(allFinite(sim));
  EXPECT_EQ(sim.particleContacts(), bruteForceContacts(sim));
  EXPECT_GT(sim.particleContacts(), sim.particles().size());
  // The coarse grains are loaded by many fines.
  const auto& C = sim.contacts();
  std::size_t coarse_contacts = 0;
  for (std::size_t i = 0; i < sim.particles().size(); ++i) {
    for (std::uint32_t p = C.pairs.row[i]; p < C.pairs.row[i + 1]; ++p) {
      const std::uint32_t j = C.pairs.col[p];
      const auto& P = sim.particles();
      const bool touching = (P.pos[i] - P.pos[j]).norm() < P.radius[i] + P.radius[j];
      coarse_contacts += touching && std::max(P.radius[i], P.radius[j]) == big;
    }
  }
  EXPECT_GT(coarse_contacts, 50u);
  const EnergyReport e = sim.energy();
  EXPECT_LT(e.kinetic() + e.strain, e.ledger.initial + e.ledger.boundary_work);
}

// Two materials whose stiffnesses differ by 10^4, mixed at random: the automatic step
// follows the stiff one.
TEST(HardCases, StiffnessContrastTenThousand) {
  PackingSpec spec;
  spec.count = 1500;
  spec.sizes = SizeDistribution::uniform(1.6e-3, 2.4e-3);
  spec.porosity = 0.45;
  const Packing<3> p = generatePacking<3>(spec);
  MaterialTable mats;
  mats.add(testing::linearMaterial(1e4, 5e3, 0.5, 0.1));
  mats.add(testing::linearMaterial(1e8, 5e7, 0.5, 0.1));
  SimulationConfig cfg;
  cfg.local_damping = 0.3;
  Simulation<3> sim(mats, cfg);
  Rng rng(2);
  for (std::size_t i = 0; i < p.centers.size(); ++i) {
    testing::addParticle<3>(sim, p.centers[i], p.radii[i], V3::Zero(), 2650.0,
                            rng.uniform() < 0.5 ? 0 : 1);
  }
  testing::addBox<3>(sim, p.lo, p.hi, 1);
  for (int w = 0; w < 6; ++w) sim.wall(w).velocity = 0.01 * sim.wall(w).normal;
  ASSERT_NO_THROW(sim.run(8000));
  EXPECT_TRUE(allFinite(sim));
  EXPECT_LT(sim.maxOverlapRatio(), 0.25);
  EXPECT_LT(sim.dt(), sim.criticalTimeStep());
}

// 800 Hertz spheres in a box, beyond jamming: every particle is loaded.
Simulation<3> densePackScene(SimulationConfig cfg) {
  PackingSpec spec;
  spec.count = 800;
  spec.sizes = SizeDistribution::uniform(1.6e-3, 2.4e-3);
  spec.porosity = 0.37;
  const Packing<3> p = generatePacking<3>(spec);
  cfg.contact_law = "hertz";
  Simulation<3> sim(testing::table(testing::hertzMaterial(1e9, 0.25, 0.5)), cfg);
  for (std::size_t i = 0; i < p.centers.size(); ++i) {
    testing::addParticle<3>(sim, p.centers[i], p.radii[i], V3::Zero());
  }
  testing::addBox<3>(sim, p.lo, p.hi);
  return sim;
}

// The dense pack undamped, at a fixed step of dt_factor times the critical one.
Simulation<3> densePack(double dt_factor) {
  Simulation<3> sim = densePackScene(testing::undamped());
  sim.step();
  sim.setFixedTimeStep(dt_factor * sim.criticalTimeStep());
  return sim;
}

TEST(HardCases, TimeStepAboveCriticalIsDiagnosedNotPropagated) {
  Simulation<3> sim = densePack(4.0);
  try {
    sim.run(100000);
    FAIL() << "an unstable step ran to the end";
  } catch (const SimulationUnstable& e) {
    const std::string why = e.what();
    EXPECT_NE(why.find("time step"), std::string::npos) << why;
    EXPECT_NE(why.find("critical"), std::string::npos) << why;
    EXPECT_TRUE(allFinite(sim)) << "the guard must stop before NaN";
  }
}

TEST(HardCases, StepNearCriticalStaysStable) {
  Simulation<3> sim = densePack(0.9);
  ASSERT_NO_THROW(sim.run(5000));
  EXPECT_TRUE(allFinite(sim));
}

TEST(HardCases, WallTooFastIsDiagnosed) {
  Simulation<3> sim = densePack(0.5);
  sim.wall(5).velocity = 0.3 * sim.particles().radius[0] / sim.dt() * sim.wall(5).normal;
  try {
    sim.run(100000);
    FAIL() << "a wall ramming the sample ran to the end";
  } catch (const SimulationUnstable& e) {
    const std::string why = e.what();
    EXPECT_NE(why.find("wall 'zmax'"), std::string::npos) << why;
    EXPECT_TRUE(allFinite(sim));
  }
}

// Hertz contacts stiffen as they load: the automatic step must shrink with them.
TEST(HardCases, AutomaticStepFollowsHertzStiffening) {
  Simulation<3> sim = densePack(0.5);
  SimulationConfig cfg = sim.config();
  ASSERT_FALSE(cfg.timestep.automatic);  // densePack fixed it; rebuild the scene automatic
  PackingSpec spec;
  spec.count = 800;
  spec.sizes = SizeDistribution::uniform(1.6e-3, 2.4e-3);
  spec.porosity = 0.45;
  const Packing<3> p = generatePacking<3>(spec);
  cfg.timestep.automatic = true;
  cfg.local_damping = 0.5;
  Simulation<3> auto_sim(testing::table(testing::hertzMaterial(1e9, 0.25, 0.5)), cfg);
  for (std::size_t i = 0; i < p.centers.size(); ++i) {
    testing::addParticle<3>(auto_sim, p.centers[i], p.radii[i], V3::Zero());
  }
  testing::addBox<3>(auto_sim, p.lo, p.hi);
  for (int w = 0; w < 6; ++w) auto_sim.wall(w).velocity = 0.05 * auto_sim.wall(w).normal;
  auto_sim.step();
  const double dt_loose = auto_sim.dt();
  double smallest_ratio = INFINITY;
  for (int k = 0; k < 60; ++k) {
    auto_sim.run(100);
    smallest_ratio = std::min(smallest_ratio, auto_sim.criticalTimeStep() / auto_sim.dt());
  }
  EXPECT_GT(auto_sim.maxOverlapRatio(), 0.01);  // really squeezed
  EXPECT_LT(auto_sim.dt(), 0.8 * dt_loose);
  // Between two estimates the stiffness grows a little: the step stays below critical.
  EXPECT_GT(smallest_ratio, 1.0);
}

// Under density scaling the scaled particles step at their own bounds times the safety
// factor, so a stiffening the step has not been estimated for takes them past it together.
// Contacts 50 times stiffer between two estimates: the run stops, and the diagnosis names
// the scaling (the physical masses' critical step, always below the scaled step, would
// mislead).
TEST(HardCases, AStiffeningUnderDensityScalingIsDiagnosedAsTheScaling) {
  SimulationConfig cfg = testing::undamped();
  cfg.timestep.density_scaling = 4.0;
  cfg.timestep.update_interval = 1000000;  // no estimate after the first
  Simulation<3> sim = densePackScene(cfg);
  ASSERT_NO_THROW(sim.run(200));
  sim.replaceMaterials(testing::table(testing::hertzMaterial(5e10, 0.25, 0.5)));
  try {
    sim.run(100000);
    FAIL() << "a step beyond the scaled particles' bounds ran to the end";
  } catch (const SimulationUnstable& e) {
    const std::string why = e.what();
    EXPECT_NE(why.find("Likely cause: density scaling (numerics.density_scaling = 4)"),
              std::string::npos)
        << why;
    EXPECT_EQ(why.find("above the critical estimate"), std::string::npos) << why;
    EXPECT_TRUE(allFinite(sim));
  }
}

// A brittle sample at high stress: cemented while squeezed (every contact overlapping), with
// strengths of little scatter, then unloaded at once (the walls move away). The bonds take
// the strain energy the contacts release and fail in a cascade, most of them within a few
// hundred steps; the broken bonds' energy becomes motion. The run must take it: finite
// state, and the energy ledger balanced.
TEST(HardCases, BrittleSampleAtHighStressBreaksInACascade) {
  PackingSpec spec;
  spec.count = 1200;
  spec.sizes = SizeDistribution::uniform(1.6e-3, 2.4e-3);
  spec.porosity = 0.36;  // beyond jamming: the contacts hold a high stress
  const Packing<3> p = generatePacking<3>(spec);
  SimulationConfig cfg;
  cfg.contact_law = "hertz";
  cfg.local_damping = 0.0;  // nothing soaks up the cascade but the contacts' dashpots
  Simulation<3> sim(testing::table(testing::hertzMaterial(1e9, 0.25, 0.5, 0.05)), cfg);
  for (std::size_t i = 0; i < p.centers.size(); ++i) {
    testing::addParticle<3>(sim, p.centers[i], p.radii[i], V3::Zero());
  }
  testing::addBox<3>(sim, p.lo, p.hi);
  BondKind brittle;
  brittle.modulus = 1e9;
  brittle.stiffness_ratio = 1.0;
  brittle.tensile_mean = brittle.shear_mean = 2e6;
  brittle.tensile_std = brittle.shear_std = 0.05e6;
  const CementReport cement = sim.cement(sim.addBondKind(brittle), 0.0);
  ASSERT_GT(cement.installed, 2 * p.centers.size());
  for (int w = 0; w < 6; ++w) sim.wall(w).velocity = -2.0 * sim.wall(w).normal;
  auto broken = [&] {
    return sim.brokenBonds(0, BondBreakMode::Tensile) + sim.brokenBonds(0, BondBreakMode::Shear);
  };
  std::uint64_t most_in_a_window = 0, before = 0;
  for (int k = 0; k < 20; ++k) {
    ASSERT_NO_THROW(sim.run(100));
    ASSERT_TRUE(allFinite(sim)) << "after " << sim.steps() << " steps";
    most_in_a_window = std::max(most_in_a_window, broken() - before);
    before = broken();
  }
  // A cascade: most bonds broke, a large share of them within 100 steps.
  EXPECT_GT(broken(), cement.installed / 2);
  EXPECT_GT(most_in_a_window, cement.installed / 5);
  const EnergyReport e = sim.energy();
  EXPECT_GT(e.ledger.bond_breakage, 0.0);
  // The ledger closes to 1% of the energy in play: what the leapfrog scheme's first-order
  // work sums allow (the same bound as the impact and energy validation tests).
  EXPECT_LT(std::abs(e.imbalance()), 0.01 * (e.ledger.initial + std::abs(e.ledger.boundary_work)));
  EXPECT_LT(e.kinetic(), e.ledger.initial + std::abs(e.ledger.boundary_work));
}

TEST(HardCases, OneParticleAndEmptyScenes) {
  Simulation<3> one(testing::table(testing::linearMaterial(1e6, 1e6, 0.5)), testing::undamped());
  testing::addParticle<3>(one, V3::Zero(), 1e-3, V3(0.1, 0, 0));
  ASSERT_NO_THROW(one.run(100));
  EXPECT_NEAR(one.particles().pos[0].x(), 0.1 * one.time(), 1e-12);
  Simulation<3> none(testing::table(testing::linearMaterial(1e6, 1e6, 0.5)), testing::undamped());
  EXPECT_THROW(none.step(), std::invalid_argument);
}

}  // namespace
}  // namespace rocklab
