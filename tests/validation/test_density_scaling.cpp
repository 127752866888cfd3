// Density scaling (numerics.density_scaling): the step it gives, the stability it keeps, the
// equilibrium it must not change, and the physical masses it gives back.

#include <gtest/gtest.h>

#include "lab/core/packing.hpp"
#include "rigs/common/frame.hpp"
#include "tests/support.hpp"

namespace rocklab {
namespace {

using V3 = Eigen::Vector3d;
using Frame = rigs::LoadingFrame<3>;

// Spheres of radii 1:3 in a servo box (the spread of the oedometer sample, whose lightest
// particles have about 1/1.6 of the median's own critical step), linear contacts set by a
// modulus so that the small spheres are the light and relatively stiff ones.
struct Cell {
  std::unique_ptr<Simulation<3>> sim;
  std::unique_ptr<Frame> frame;
  explicit Cell(double scaling) {
    PackingSpec spec;
    spec.count = 500;
    spec.sizes = SizeDistribution::uniform(0.6e-3, 1.8e-3);
    spec.porosity = 0.5;
    const Packing<3> p = generatePacking<3>(spec);
    Material grain = testing::linearMaterial(0.0, 0.0, 0.5);
    grain.modulus = 1e9;
    SimulationConfig cfg;
    cfg.local_damping = 0.7;
    cfg.timestep.density_scaling = scaling;
    sim = std::make_unique<Simulation<3>>(testing::table(grain), cfg);
    for (std::size_t i = 0; i < p.centers.size(); ++i) {
      testing::addParticle<3>(*sim, p.centers[i], p.radii[i], V3::Zero());
    }
    frame = std::make_unique<Frame>(*sim, p.lo, p.hi, 0);
    sim->prepare();
    // The servo's speed cap in radii per step of the unscaled step, for both cells alike.
    frame->setServo(0.5, 1e-3 * 1e-3 * 0.5 / sim->criticalTimeStep());
    for (int a = 0; a < 3; ++a) frame->set(a, Frame::Axis{Frame::Mode::Stress, 0.0, 1e6});
  }
  // Steps until the stresses hold and the sample is in equilibrium (formation's criterion).
  std::uint64_t settle() {
    const std::uint64_t start = sim->steps();
    for (int s = 0; s < 200000; ++s) {
      frame->step();
      if (s % 100 == 0 && frame->stressError() < 0.005 && sim->unbalancedForceRatio() < 0.005) {
        break;
      }
    }
    return sim->steps() - start;
  }
};

// The critical step of the system as it is integrated: the inertial masses taken as physical.
double scaledCriticalStep(const Simulation<3>& sim) {
  Simulation<3> copy = sim.clone();
  auto& P = copy.particles();
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.inv_mass[i] > 0.0) P.setMass(i, 1.0 / P.inv_mass[i], 1.0 / P.inv_inertia[i]);
  }
  copy.prepare();
  return copy.criticalTimeStep();
}

TEST(DensityScaling, TheStepIsTheFactorTimesTheCriticalOneAndNoParticleIsLessStable) {
  Cell c(2.5);
  c.settle();  // loaded contacts: the stiffness sums differ from particle to particle
  auto& sim = *c.sim;
  while (sim.steps() % 100 != 0) sim.step();  // at a step that set the step and the masses
  const double critical = sim.criticalTimeStep(), target = 2.5 * critical;
  EXPECT_DOUBLE_EQ(sim.dt(), sim.config().timestep.safety * target);
  // Every particle at least as stable as the least stable one would be unscaled at the target.
  EXPECT_NEAR(scaledCriticalStep(sim), target, 1e-9 * target);
  const auto& P = sim.particles();
  std::size_t scaled = 0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    EXPECT_LE(P.inv_mass[i], P.physical_inv_mass[i]);
    EXPECT_DOUBLE_EQ(P.inv_mass[i] / P.physical_inv_mass[i],
                     P.inv_inertia[i] / P.physical_inv_inertia[i]);
    scaled += P.inv_mass[i] < P.physical_inv_mass[i];
  }
  // Only the particles that need it: some, not all.
  EXPECT_GT(scaled, P.size() / 20);
  EXPECT_LT(scaled, P.size());
  EXPECT_GT(sim.inertialMassRatio(), 1.0);
}

// Cement put in after the step was set stiffens every bonded particle: the step and the
// inertial masses are estimated again at once, not at the next update (every 100 steps). A
// sample cemented under density scaling stepped until then at the bound of its contacts
// alone, its scaled particles all at that bound: a lattice of equal disks (the test of
// samples from files, density-scaled 4 times) went unstable 11 steps into its loading.
// `before` runs between the settling and the cementing.
template <class Before>
void expectTheBondedStepAfterCementing(Before before) {
  Cell c(4.0);
  c.settle();
  auto& sim = *c.sim;
  const double contacts_only = sim.dt();
  before(sim);
  BondKind cement;
  cement.modulus = 2e9;  // twice the contacts' modulus: the bonds carry most of the stiffness
  ASSERT_GT(sim.cement(sim.addBondKind(cement), 0.05).installed, 500u);
  sim.prepare();  // a prepared simulation: nothing; else the estimate comes here
  const double target = 4.0 * sim.criticalTimeStep();  // of the physical masses, bonds and all
  EXPECT_LT(sim.dt(), 0.8 * contacts_only);
  EXPECT_DOUBLE_EQ(sim.dt(), sim.config().timestep.safety * target);
  EXPECT_NEAR(scaledCriticalStep(sim), target, 1e-9 * target);
}

TEST(DensityScaling, CementingEstimatesTheStepAgainAtOnce) {
  expectTheBondedStepAfterCementing([](Simulation<3>&) {});
}

// The same when the simulation is not prepared as the bonds go in: a rig gives the grains
// their own friction just before it cements them (Simulation::replaceMaterials), and the
// contact model the estimate needs is gone until the next step prepares it. That step is the
// bonded sample's, not the one the contacts alone allowed.
TEST(DensityScaling, CementingWhileUnpreparedLeavesTheStepToPrepare) {
  expectTheBondedStepAfterCementing([](Simulation<3>& sim) {
    MaterialTable own;
    for (const Material& m : sim.materials().all()) own.add(m);
    own[0].friction = 0.3;
    sim.replaceMaterials(std::move(own));
  });
}

// Equilibrium does not depend on inertia: the servo-held sample settles to the same porosity
// and stresses in fewer steps.
TEST(DensityScaling, TheSampleSettlesToTheSameEquilibriumInFewerSteps) {
  Cell plain(1.0), scaled(4.0);
  const std::uint64_t n_plain = plain.settle(), n_scaled = scaled.settle();
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(plain.frame->stress(a), 1e6, 0.01e6);
    EXPECT_NEAR(scaled.frame->stress(a), 1e6, 0.01e6);
  }
  // Two draws of one jammed state: their porosities agree to the servo's 0.5% tolerance on a
  // bulk strain of about 1e-4 (the contact stiffness over 1 MPa), far below 1e-3.
  EXPECT_NEAR(scaled.frame->porosity(), plain.frame->porosity(), 1e-3);
  EXPECT_LT(static_cast<double>(n_scaled), 0.6 * static_cast<double>(n_plain))
      << n_scaled << " steps scaled, " << n_plain << " unscaled";
  // The energy the changing masses added is booked: the ledger still balances.
  const EnergyReport e = scaled.sim->energy();
  const double input = e.ledger.initial + e.ledger.boundary_work;
  EXPECT_LT(std::abs(e.imbalance()), 0.02 * input);
}

TEST(DensityScaling, OffGivesThePhysicalMassesBackExactly) {
  Cell c(4.0);
  c.sim->run(2000);
  c.sim->setDensityScaling(1.0);
  const auto& P = c.sim->particles();
  for (std::size_t i = 0; i < P.size(); ++i) {
    EXPECT_EQ(P.inv_mass[i], P.physical_inv_mass[i]);
    EXPECT_EQ(P.inv_inertia[i], P.physical_inv_inertia[i]);
  }
  EXPECT_DOUBLE_EQ(c.sim->dt(), c.sim->config().timestep.safety * c.sim->criticalTimeStep());
  EXPECT_EQ(c.sim->inertialMassRatio(), 1.0);
  EXPECT_THROW(c.sim->setDensityScaling(0.5), InvalidParameter);
}

// A checkpoint holds the inertial and physical masses: the copy goes on bit for bit.
TEST(DensityScaling, ACheckpointContinuesBitForBit) {
  Cell c(3.0);
  c.sim->run(1500);
  Simulation<3> copy = Simulation<3>::fromStateBytes(c.sim->stateBytes());
  Frame copy_frame(copy, Frame::Restored{});
  {
    ArchiveWriter w;
    c.frame->visit(w);
    const std::string bytes = w.bytes();
    ArchiveReader r(bytes.data(), bytes.size());
    copy_frame.visit(r);
  }
  for (int s = 0; s < 1000; ++s) {
    c.frame->step();
    copy_frame.step();
  }
  EXPECT_EQ(copy.stateHash(), c.sim->stateHash());
  EXPECT_EQ(copy.dt(), c.sim->dt());
}

}  // namespace
}  // namespace rocklab
