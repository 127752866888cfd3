// Energy bookkeeping: an elastic system keeps its energy; with damping, friction and moving
// walls the ledger closes.

#include <gtest/gtest.h>

#include <cmath>

#include "lab/core/packing.hpp"
#include "tests/support.hpp"

namespace rocklab {
namespace {

using V3 = Eigen::Vector3d;

Packing<3> loosePacking(std::size_t n, double porosity, std::uint64_t seed) {
  PackingSpec spec;
  spec.count = n;
  spec.sizes = SizeDistribution::uniform(1.6e-3, 2.4e-3);
  spec.porosity = porosity;
  spec.seed = seed;
  return generatePacking<3>(spec);
}

double total(const EnergyReport& e) {
  return e.kinetic() + e.strain;
}

// A gas of frictionless particles bouncing in a closed box with elastic springs, 1e5
// steps. Drift is the change of the mean energy between the first and the last thousand
// steps (velocity Verlet's energy oscillates within a step but has no trend). The drift
// comes from contacts opening and closing between steps and shrinks with the step: safety
// 0.025 gives about 80 steps per collision (0.05 gives 1.5e-4 in 2D).
template <int D>
void checkConservation(const std::string& law, const Material& m, std::uint64_t seed) {
  PackingSpec spec;
  spec.count = D == 3 ? 200 : 300;
  spec.sizes = SizeDistribution::uniform(1.6e-3, 2.4e-3);
  spec.porosity = D == 3 ? 0.7 : 0.5;
  spec.seed = seed;
  const Packing<D> p = generatePacking<D>(spec);
  SimulationConfig cfg = testing::undamped();
  cfg.contact_law = law;
  cfg.timestep.safety = 0.025;
  Simulation<D> sim(testing::table(m), cfg);
  Rng rng(seed);
  for (std::size_t i = 0; i < p.centers.size(); ++i) {
    Vec<D> v;
    for (int d = 0; d < D; ++d) v[d] = 0.2 * rng.normal();
    testing::addParticle<D>(sim, p.centers[i], p.radii[i], v);
  }
  testing::addBox<D>(sim, p.lo, p.hi);
  const int steps = 100000, window = 1000;
  double first = 0.0, last = 0.0;
  for (int s = 0; s < steps; ++s) {
    sim.step();
    if (s < window) first += total(sim.energy()) / window;
    if (s >= steps - window) last += total(sim.energy()) / window;
  }
  EXPECT_LT(std::abs(last - first) / sim.energy().ledger.initial, 1e-4) << law;
  EXPECT_GT(sim.contacts().rebuilds, 10u);  // the gas really moved
}

TEST(Energy, ElasticLinearGasConservesEnergy) {
  checkConservation<3>("linear", testing::linearMaterial(1e5, 0.0, 0.0), 11);
}

TEST(Energy, ElasticHertzGasConservesEnergy) {
  checkConservation<3>("hertz", testing::hertzMaterial(1e8, 0.3, 0.0), 11);
}

TEST(Energy, ElasticDiskGasConservesEnergy2D) {
  // Disks are 1 m thick extrusions: a stiffness per metre of thickness.
  checkConservation<2>("linear", testing::linearMaterial(1e8, 0.0, 0.0), 21);
}

// A shaken packing squeezed by walls, with local damping, contact dashpots and friction:
// what is held (kinetic + strain) plus what was dissipated equals what came in, within 1%.
TEST(Energy, LedgerClosesWithDampingFrictionAndWalls) {
  const Packing<3> p = loosePacking(400, 0.42, 12);
  for (bool local : {false, true}) {
    SimulationConfig cfg;
    cfg.contact_law = "linear";
    cfg.local_damping = local ? 0.5 : 0.0;
    cfg.timestep.safety = 0.1;  // resolve collisions: about 20 steps each
    Simulation<3> sim(testing::table(testing::linearMaterial(1e5, 5e4, 0.4, 0.2)), cfg);
    Rng rng(5);
    for (std::size_t i = 0; i < p.centers.size(); ++i) {
      const V3 v(rng.normal(), rng.normal(), rng.normal());
      testing::addParticle<3>(sim, p.centers[i], p.radii[i], 1.0 * v);
    }
    testing::addBox<3>(sim, p.lo, p.hi);
    for (int w = 0; w < 6; ++w) sim.wall(w).velocity = 0.005 * sim.wall(w).normal;
    sim.run(40000);
    const EnergyReport e = sim.energy();
    const double in = e.ledger.initial + e.ledger.boundary_work;
    ASSERT_GT(e.ledger.boundary_work, 0.0);
    EXPECT_GT(e.ledger.friction, 0.01 * in) << "friction must take part";
    EXPECT_GT(e.ledger.viscous, 0.01 * in);
    if (local) {
      EXPECT_GT(e.ledger.local_damping, 0.01 * in);
    }
    EXPECT_LT(std::abs(e.imbalance()) / in, 0.01)
        << "local damping " << local << ": kinetic " << e.kinetic() << " strain " << e.strain
        << " friction " << e.ledger.friction << " viscous " << e.ledger.viscous << " local "
        << e.ledger.local_damping << " walls " << e.ledger.boundary_work;
  }
}

// A cemented packing squeezed until bonds break: the elastic energy the broken bonds held
// is booked, and the ledger still closes; with flat joints too, whose elements break one by
// one and then slide (their friction booked as the contacts' is).
TEST(Energy, LedgerClosesWithBondBreaks) {
  for (const BondModel model : {BondModel::Parallel, BondModel::FlatJoint}) {
    const Packing<3> p = loosePacking(600, 0.40, 14);
    SimulationConfig cfg;
    cfg.local_damping = 0.3;
    cfg.timestep.safety = 0.2;
    Material m = testing::linearMaterial(0.0, 0.0, 0.4, 0.1);
    m.modulus = 1e8;
    Simulation<3> sim(testing::table(m), cfg);
    for (std::size_t i = 0; i < p.centers.size(); ++i) {
      testing::addParticle<3>(sim, p.centers[i], p.radii[i], V3::Zero());
    }
    testing::addBox<3>(sim, p.lo, p.hi);
    BondKind cement;
    cement.model = model;
    cement.modulus = 1e8;
    cement.stiffness_ratio = 1.0;
    cement.tensile_mean = cement.shear_mean = 2e5;
    cement.tensile_std = cement.shear_std = 1e5;
    sim.cement(sim.addBondKind(cement), 0.05);
    sim.restartEnergyLedger();
    ASSERT_GT(sim.bonds().size(), 1000u);
    for (int w = 0; w < 6; ++w) sim.wall(w).velocity = (w >= 4 ? 0.02 : 0.0) * sim.wall(w).normal;
    sim.run(30000);
    const EnergyReport e = sim.energy();
    const std::uint64_t broken =
        sim.brokenBonds(0, BondBreakMode::Tensile) + sim.brokenBonds(0, BondBreakMode::Shear);
    const char* name = model == BondModel::Parallel ? "parallel" : "flat joint";
    EXPECT_GT(broken, 100u) << name;
    const double in = e.ledger.initial + e.ledger.boundary_work;
    EXPECT_GT(e.ledger.bond_breakage, 0.0) << name;
    EXPECT_LT(std::abs(e.imbalance()) / in, 0.01)
        << name << ": broken " << broken << " strain " << e.strain << " breakage "
        << e.ledger.bond_breakage << " friction " << e.ledger.friction << " viscous "
        << e.ledger.viscous << " local " << e.ledger.local_damping << " walls "
        << e.ledger.boundary_work;
  }
}

TEST(Energy, GravityWorkIsBooked) {
  SimulationConfig cfg = testing::undamped();
  cfg.gravity = {0.0, 0.0, -9.81};
  cfg.timestep.safety = 0.1;
  Simulation<3> sim(testing::table(testing::linearMaterial(1e5, 5e4, 0.3, 0.3)), cfg);
  const Packing<3> p = loosePacking(100, 0.7, 13);
  for (std::size_t i = 0; i < p.centers.size(); ++i) {
    testing::addParticle<3>(sim, p.centers[i], p.radii[i], V3::Zero());
  }
  testing::addBox<3>(sim, p.lo, p.hi);
  sim.run(20000);
  const EnergyReport e = sim.energy();
  EXPECT_GT(e.ledger.body_work, 0.0);
  EXPECT_LT(std::abs(e.imbalance()) / e.ledger.body_work, 0.01);
  const auto timings = sim.stageTimings();
  EXPECT_TRUE(std::any_of(timings.begin(), timings.end(),
                          [](const StageTiming& t) { return t.name == "body_forces"; }));
}

}  // namespace
}  // namespace rocklab
