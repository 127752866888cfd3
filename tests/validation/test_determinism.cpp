// Same scene and seed give the same bits whatever the thread count (Box2D's determinism
// test, house rule 8, README.md).

#include <gtest/gtest.h>

#include <omp.h>

#include "lab/core/packing.hpp"
#include "tests/support.hpp"

namespace rocklab {
namespace {

using V3 = Eigen::Vector3d;

TEST(Determinism, PackingIsTheSameOnOneAndTwoThreads) {
  PackingSpec spec;
  spec.count = 3000;
  spec.sizes = SizeDistribution::phiGaussian(-1.0, 0.4, 0.5e-3, 6e-3);
  spec.porosity = 0.4;
  spec.seed = 17;
  spec.threads = 1;
  const auto one = generatePacking<3>(spec);
  spec.threads = 2;
  const auto two = generatePacking<3>(spec);
  ASSERT_EQ(one.centers.size(), two.centers.size());
  for (std::size_t i = 0; i < one.centers.size(); ++i) {
    ASSERT_EQ(one.centers[i], two.centers[i]) << "particle " << i;
  }
}

// 2D: the disks' packing at a porosity below jamming (growth leaves overlaps, the forces
// uneven), and a sample of two row blocks, so that the threaded pass may give one thread no
// rows at all: that thread must then compute nothing.
TEST(Determinism, TwoDimensionalPackingIsTheSameOnOneAndTwoThreads) {
  PackingSpec spec;
  spec.count = 500;
  spec.sizes = SizeDistribution::uniform(1.0e-3, 1.18e-3);
  spec.porosity = 0.22;
  spec.aspect = {1, 2, 1};
  spec.thickness = 1.1e-3;
  spec.seed = 13;
  spec.threads = 1;
  const auto one = generatePacking<2>(spec);
  for (int run = 0; run < 3; ++run) {
    spec.threads = 2;
    const auto two = generatePacking<2>(spec);
    ASSERT_EQ(one.centers.size(), two.centers.size());
    for (std::size_t i = 0; i < one.centers.size(); ++i) {
      ASSERT_EQ(one.centers[i], two.centers[i]) << "run " << run << ", particle " << i;
    }
  }
}

// The bits of a run: its state and the dissipation the contacts booked.
struct RunBits {
  std::uint64_t hash = 0;
  double friction = 0.0, viscous = 0.0;
  friend bool operator==(const RunBits&, const RunBits&) = default;
};

template <int D>
RunBits bitsOf(const Simulation<D>& sim) {
  const EnergyLedger& l = sim.energy().ledger;
  return {sim.stateHash(), l.friction, l.viscous};
}

RunBits compressed(int threads, int dim_steps, int lane_width) {
  PackingSpec spec;
  spec.count = 2500;
  spec.sizes = SizeDistribution::uniform(1.6e-3, 2.4e-3);
  spec.porosity = 0.42;
  spec.seed = 4;
  const auto p = generatePacking<3>(spec);
  SimulationConfig cfg;
  cfg.contact_law = "hertz";
  cfg.local_damping = 0.2;
  cfg.threads = threads;
  cfg.contact_lane_width = lane_width;
  cfg.gravity = {0, 0, -9.81};
  Simulation<3> sim(testing::table(testing::hertzMaterial(5e8, 0.25, 0.5, 0.1)), cfg);
  for (std::size_t i = 0; i < p.centers.size(); ++i) {
    testing::addParticle<3>(sim, p.centers[i], p.radii[i], V3::Zero());
  }
  testing::addBox<3>(sim, p.lo, p.hi);
  for (int w = 0; w < 6; ++w) sim.wall(w).velocity = 0.05 * sim.wall(w).normal;
  sim.run(dim_steps);
  EXPECT_GT(sim.contacts().rebuilds, 1u);
  return bitsOf(sim);
}

TEST(Determinism, CompressionIsTheSameOnOneAndTwoThreads) {
  // The runtime really gives the two-thread run two threads (OMP_THREAD_LIMIT or
  // OMP_DYNAMIC could make it one, and the comparison one thread against one).
  int team = 0;
#pragma omp parallel num_threads(2)
  {
#pragma omp single
    team = omp_get_num_threads();
  }
  ASSERT_EQ(team, 2);
  EXPECT_EQ(compressed(1, 3000, 8), compressed(2, 3000, 8));
}

// The contact pass four pairs per AVX register and eight per AVX-512 register
// (contact_lanes.hpp) gives the scalar pass's bits: Hertz spheres squeezed by the walls under
// gravity, damped, some contacts sliding and some sticking, on one and two threads (the
// threaded pass interleaves the lanes with the pairs other threads computed). Where the CPU
// lacks AVX-512 the width 8 runs four lanes, and the comparison repeats the four-lane one.
TEST(Determinism, HertzContactsInLanesAreTheScalarBits) {
  const RunBits scalar = compressed(1, 3000, 0);
  for (int width : {4, 8}) {
    EXPECT_EQ(compressed(1, 3000, width), scalar) << width << " lanes";
    EXPECT_EQ(compressed(2, 3000, width), scalar) << width << " lanes";
  }
  EXPECT_GT(scalar.friction, 0.0);  // contacts slid
  EXPECT_GT(scalar.viscous, 0.0);
}

// Cemented rock crushed by a wall: bonds break during the run (two-phase removal) and the
// state is still the same bits on one and two threads, and with the bonds and the linear
// contacts (stiffness from a modulus, damped) computed one at a time or four per AVX register
// (bond_lanes.hpp, contact_lanes.hpp; the bonds start unloaded, hold gaps and break, so every
// masked branch of the lanes is taken).
TEST(Determinism, BondBreaksAreTheSameOnOneAndTwoThreadsAndInLanes) {
  PackingSpec spec;
  spec.count = 2000;
  spec.sizes = SizeDistribution::uniform(1.6e-3, 2.4e-3);
  spec.porosity = 0.42;
  spec.seed = 9;
  const auto p = generatePacking<3>(spec);
  auto hash = [&](int threads, bool lanes, std::uint64_t* broken) {
    SimulationConfig cfg;
    cfg.local_damping = 0.2;
    cfg.threads = threads;
    cfg.bond_lane_width = lanes ? 8 : 0;
    cfg.contact_lane_width = lanes ? 8 : 0;
    Material m = testing::linearMaterial(0.0, 0.0, 0.5, 0.05);
    m.modulus = 1e8;
    Simulation<3> sim(testing::table(m), cfg);
    for (std::size_t i = 0; i < p.centers.size(); ++i) {
      testing::addParticle<3>(sim, p.centers[i], p.radii[i], V3::Zero());
    }
    testing::addBox<3>(sim, p.lo, p.hi);
    BondKind cement;
    cement.modulus = 1e8;
    cement.stiffness_ratio = 1.0;
    cement.tensile_mean = cement.shear_mean = 1e5;
    cement.tensile_std = cement.shear_std = 1e5;
    sim.cement(sim.addBondKind(cement), 0.05);
    sim.wall(5).velocity = 0.05 * sim.wall(5).normal;
    sim.run(4000);
    *broken = sim.brokenBonds(0, BondBreakMode::Tensile) + sim.brokenBonds(0, BondBreakMode::Shear);
    return sim.stateHash();
  };
  std::uint64_t b1 = 0, b2 = 0, scalar = 0;
  const std::uint64_t one = hash(1, true, &b1);
  EXPECT_EQ(one, hash(2, true, &b2));
  EXPECT_EQ(one, hash(1, false, &scalar));
  EXPECT_EQ(b1, b2);
  EXPECT_EQ(b1, scalar);
  EXPECT_GT(b1, 50u);
}

// Damped linear disks squeezed by the walls, with and without the energy bookkeeping (two
// instances of each pass), one and two threads, the contacts in lanes or one at a time.
RunBits squeezedDisks(int threads, int lane_width, bool track_energy) {
  PackingSpec spec;
  spec.count = 4000;
  spec.sizes = SizeDistribution::normal(2e-3, 0.4e-3, 1e-3, 3e-3);
  spec.porosity = 0.2;
  spec.threads = threads;
  const auto p = generatePacking<2>(spec);
  SimulationConfig cfg;
  cfg.local_damping = 0.1;
  cfg.threads = threads;
  cfg.contact_lane_width = lane_width;
  cfg.track_energy = track_energy;
  Simulation<2> sim(testing::table(testing::linearMaterial(1e7, 5e6, 0.5, 0.1)), cfg);
  for (std::size_t i = 0; i < p.centers.size(); ++i) {
    testing::addParticle<2>(sim, p.centers[i], p.radii[i], Eigen::Vector2d::Zero());
  }
  testing::addBox<2>(sim, p.lo, p.hi);
  for (int w = 0; w < 4; ++w) sim.wall(w).velocity = 0.05 * sim.wall(w).normal;
  sim.run(3000);
  return bitsOf(sim);
}

TEST(Determinism, DisksInLanesAreTheScalarBitsOnOneAndTwoThreads) {
  const RunBits scalar = squeezedDisks(1, 0, true);
  for (int width : {4, 8}) {
    EXPECT_EQ(squeezedDisks(1, width, true), scalar) << width << " lanes";
    EXPECT_EQ(squeezedDisks(2, width, true), scalar) << width << " lanes";
  }
  EXPECT_GT(scalar.friction, 0.0);
  EXPECT_GT(scalar.viscous, 0.0);
  EXPECT_EQ(squeezedDisks(2, 8, false).hash, squeezedDisks(1, 0, false).hash);
}

}  // namespace
}  // namespace rocklab
