// Parallel bonds: stiffness in each mode against the beam formulas of Potyondy & Cundall
// (2004), breaks at the strength within one step's increment, strength draws, and bonds
// through particle reordering.

#include <gtest/gtest.h>

#include <memory>
#include <numbers>
#include <optional>
#include <tuple>

#include "lab/core/errors.hpp"
#include "lab/core/random.hpp"
#include "tests/bonded_pair.hpp"

namespace rocklab {
namespace {

using namespace testing::bonded;

TEST(BondStiffness, Normal3D) {
  BondedPair<3> p(cement(1e11, 1e11));
  const double v = 0.01;
  p.drive(V3::Zero(), v * p.n, V3::Zero(), V3::Zero(), 100);  // 0.1 um apart
  const double stretch = 100 * v * kDt;
  EXPECT_NEAR(p.force().x(), -p.kn() * p.section().area * stretch, 1e-9 * p.force().norm());
  EXPECT_NEAR(p.force().y(), 0.0, 1e-12);
}

TEST(BondStiffness, Shear3D) {
  BondedPair<3> p(cement(1e11, 1e11));
  const double v = 0.01;
  p.drive(V3::Zero(), V3(0, v, 0), V3::Zero(), V3::Zero(), 100);
  const double slide = 100 * v * kDt;  // 0.1 um, the normal turns by 5e-5 rad
  EXPECT_NEAR(p.force().y(), -p.ks() * p.section().area * slide, 1e-3 * p.force().norm());
}

TEST(BondStiffness, BendingAndTwist3D) {
  const double w = 10.0;  // rad/s each, opposite: a relative turn of 2 w t, no slip at the centre
  {
    BondedPair<3> p(cement(1e11, 1e11));
    p.drive(V3::Zero(), V3::Zero(), V3(0, 0, -w), V3(0, 0, w), 100);
    const double theta = 2 * w * 100 * kDt;
    EXPECT_NEAR(p.torque().z(), -p.kn() * p.section().inertia * theta, 1e-9 * p.torque().norm());
    EXPECT_LT(p.force().norm(), 1e-9 * p.torque().norm() / kR);
  }
  {
    BondedPair<3> p(cement(1e11, 1e11));
    p.drive(V3::Zero(), V3::Zero(), V3(-w, 0, 0), V3(w, 0, 0), 100);
    const double theta = 2 * w * 100 * kDt;
    EXPECT_NEAR(p.torque().x(), -p.ks() * p.section().polar * theta, 1e-9 * p.torque().norm());
  }
}

TEST(BondStiffness, NormalShearBending2D) {
  const double v = 0.01, w = 10.0;
  {
    BondedPair<2> p(cement(1e11, 1e11));
    p.drive(V2::Zero(), V2(v, 0), 0.0, 0.0, 100);
    const double area = 2 * kR * 1.0;  // unit thickness
    EXPECT_NEAR(p.force().x(), -p.kn() * area * 100 * v * kDt, 1e-9 * p.force().norm());
  }
  {
    BondedPair<2> p(cement(1e11, 1e11));
    p.drive(V2::Zero(), V2(0, v), 0.0, 0.0, 100);
    EXPECT_NEAR(p.force().y(), -p.ks() * 2 * kR * 100 * v * kDt, 1e-3 * p.force().norm());
  }
  {
    BondedPair<2> p(cement(1e11, 1e11));
    p.drive(V2::Zero(), V2::Zero(), -w, w, 100);
    const double inertia = 2 * kR * kR * kR / 3;  // 2 R^3 t / 3
    EXPECT_NEAR(p.torque(), -p.kn() * inertia * 2 * w * 100 * kDt, 1e-9 * std::abs(p.torque()));
  }
}

// Loads a bond at a steady rate until it breaks; checks the break came at the first step
// whose stress reached the strength (so within one step's increment of it).
template <int D, class Drive>
void breaksAtStrength(const BondKind& kind, Drive drive, BondBreakMode mode, double strength,
                      double increment_per_step) {
  BondedPair<D> p(kind);
  std::vector<BondBreak<D>> breaks;
  int steps = 0;
  while (breaks.empty() && steps < 100000) {
    drive(p);
    ++steps;
    breaks = p.sim.bondBreaks();
  }
  ASSERT_EQ(breaks.size(), 1u);
  EXPECT_EQ(breaks[0].mode, mode);
  EXPECT_GE(breaks[0].stress, strength);
  EXPECT_LT(breaks[0].stress, strength + 1.0001 * increment_per_step);
  EXPECT_EQ(p.sim.bonds().size(), 0u);
  EXPECT_EQ(p.sim.brokenBonds(0, mode), 1u);
  // Broken: nothing holds the pair in tension any more.
  drive(p);
  EXPECT_EQ(p.force().norm(), 0.0);
}

TEST(BondBreaks, PureTension) {
  const double strength = 8e6, v = 0.01;
  BondedPair<3> probe(cement(strength, 1e11));
  const double increment = probe.kn() * v * kDt;  // tensile stress per step
  breaksAtStrength<3>(
      cement(strength, 1e11),
      [&](BondedPair<3>& p) { p.drive(V3::Zero(), v * p.n, V3::Zero(), V3::Zero(), 1); },
      BondBreakMode::Tensile, strength, increment);
}

TEST(BondBreaks, PureShear) {
  const double strength = 8e6, v = 0.01;
  BondedPair<3> probe(cement(1e11, strength));
  // |Fs| / A grows by ks v dt per step (the pair also turns a little: allow 1% more).
  const double increment = 1.01 * probe.ks() * v * kDt;
  breaksAtStrength<3>(
      cement(1e11, strength),
      [&](BondedPair<3>& p) { p.drive(V3::Zero(), V3(0, v, 0), V3::Zero(), V3::Zero(), 1); },
      BondBreakMode::Shear, strength, increment);
}

TEST(BondBreaks, Bending) {
  const double strength = 8e6, w = 10.0;
  BondedPair<3> probe(cement(strength, 1e11));
  const auto s = probe.section();
  const double increment = probe.kn() * s.inertia * 2 * w * kDt * s.radius / s.inertia;
  breaksAtStrength<3>(
      cement(strength, 1e11),
      [&](BondedPair<3>& p) { p.drive(V3::Zero(), V3::Zero(), V3(0, 0, -w), V3(0, 0, w), 1); },
      BondBreakMode::Tensile, strength, increment);
}

// A moment factor beta (PFC 5's pb_mcf) scales the bending moment's share of the peak
// tensile stress: bent at a steady rate, a bond with beta = 0.5 holds past the moment that
// breaks a full beam and breaks at twice it; in 2D likewise.
template <int D>
void bendsToTwiceTheMoment() {
  const double strength = 8e6, w = 10.0, beta = 0.5;
  BondKind kind = cement(strength, 1e11);
  kind.moment_factor = beta;
  BondedPair<D> p(kind);
  const auto s = p.section();
  const double per_step = p.kn() * 2 * w * kDt * s.radius;  // |Mb| R / I per step, unscaled
  const int full_beam = static_cast<int>(std::ceil(strength / per_step));
  Ang<D> wa, wb;
  if constexpr (D == 3) {
    wa = V3(0, 0, -w), wb = V3(0, 0, w);
  } else {
    wa = -w, wb = w;
  }
  std::vector<BondBreak<D>> breaks;
  int steps = 0;
  for (; steps < 3 * full_beam && breaks.empty(); ++steps) {
    p.drive(Vec<D>::Zero(), Vec<D>::Zero(), wa, wb, 1);
    breaks = p.sim.bondBreaks();
  }
  ASSERT_EQ(breaks.size(), 1u);
  EXPECT_EQ(breaks[0].mode, BondBreakMode::Tensile);
  EXPECT_NEAR(steps, 2 * full_beam, 2) << "full beam: " << full_beam << " steps";
  EXPECT_GE(breaks[0].stress, strength);
  EXPECT_LT(breaks[0].stress, strength + 1.0001 * beta * per_step);
}

TEST(BondBreaks, MomentFactorScalesTheBendingStress) {
  bendsToTwiceTheMoment<3>();
  bendsToTwiceTheMoment<2>();
  BondKind k = cement(8e6, 8e6);
  k.moment_factor = 1.5;
  Simulation<3> sim(testing::table(testing::linearMaterial(1e6, 1e6, 0.5)), testing::undamped());
  EXPECT_THROW(sim.addBondKind(k), InvalidParameter);
}

TEST(BondBreaks, TwoDimensionalTension) {
  const double strength = 8e6, v = 0.01;
  BondedPair<2> probe(cement(strength, 1e11));
  breaksAtStrength<2>(
      cement(strength, 1e11), [&](BondedPair<2>& p) { p.drive(V2::Zero(), V2(v, 0), 0.0, 0.0, 1); },
      BondBreakMode::Tensile, strength, probe.kn() * v * kDt);
}

// A friction angle phi (PFC 5's pb_fa): sheared while it carries a compressive normal stress
// sigma_n, a bond breaks at c + sigma_n tan(phi); while it carries tension, at c.
TEST(BondBreaks, FrictionAngleRaisesTheShearStrengthUnderCompressionOnly) {
  const double c = 2e6, phi = 40.0 * std::numbers::pi / 180.0, v = 0.01;
  for (const double approach : {0.5e-6, -0.2e-6}) {  // m: compressed, then stretched
    BondKind kind = cement(1e11, c);
    kind.friction_angle = phi;
    BondedPair<3> p(kind);
    const int steps = 1000;  // the normal load, applied slowly (within the 2 um gap)
    p.drive(V3::Zero(), -approach / (steps * kDt) * p.n, V3::Zero(), V3::Zero(), steps);
    const double sigma_n = p.sim.bonds().load[0].fn / p.section().area;
    EXPECT_NEAR(sigma_n, p.kn() * approach, 1e-6 * std::abs(p.kn() * approach));
    const double strength = sigma_n > 0 ? c + sigma_n * std::tan(phi) : c;
    std::vector<BondBreak<3>> breaks;
    for (int s = 0; s < 100000 && breaks.empty(); ++s) {
      p.drive(V3::Zero(), V3(0, v, 0), V3::Zero(), V3::Zero(), 1);
      breaks = p.sim.bondBreaks();
    }
    ASSERT_EQ(breaks.size(), 1u) << "approach " << approach;
    EXPECT_EQ(breaks[0].mode, BondBreakMode::Shear);
    EXPECT_GE(breaks[0].stress, strength);
    EXPECT_LT(breaks[0].stress, strength + 1.01 * p.ks() * v * kDt) << "approach " << approach;
  }
  BondKind k = cement(8e6, 8e6);
  k.friction_angle = std::numbers::pi / 2;  // tan infinite
  Simulation<3> sim(testing::table(testing::linearMaterial(1e6, 1e6, 0.5)), testing::undamped());
  EXPECT_THROW(sim.addBondKind(k), InvalidParameter);
}

TEST(BondBreaks, CompressionDoesNotBreakAndTheContactRemains) {
  BondedPair<3> p(cement(1e3, 1e3));                               // weak
  p.drive(V3::Zero(), -0.01 * p.n, V3::Zero(), V3::Zero(), 3000);  // 1 um into contact
  EXPECT_EQ(p.sim.bonds().size(), 1u);
  EXPECT_GT(
      p.force().x(),
      0.0);  // pushed back by bond and contact
             // Pull apart past the gap the bond was made at: the weak bond breaks in tension, and
  // nothing holds the pair any more.
  p.drive(V3::Zero(), 0.01 * p.n, V3::Zero(), V3::Zero(), 5000);
  EXPECT_EQ(p.sim.bonds().size(), 0u);
  EXPECT_EQ(p.force().norm(), 0.0);
  // And pushed together again, the frictional contact alone still carries compression.
  p.drive(V3::Zero(), -0.01 * p.n, V3::Zero(), V3::Zero(), 5000);
  EXPECT_GT(p.force().x(), 0.0);
}

// Cementing a packing: strengths drawn from normal(8, 8) MPa; draws <= 0 handled as set.
TEST(Cementing, StrengthDrawsAndNegativeHandling) {
  // A simple cubic lattice of touching spheres: 3 x 14 x 15^2 = 9450 candidate pairs.
  std::vector<V3> lattice;
  for (int x = 0; x < 15; ++x) {
    for (int y = 0; y < 15; ++y) {
      for (int z = 0; z < 15; ++z) lattice.push_back(2 * kR * V3(x, y, z));
    }
  }
  for (NegativeStrength mode : {NegativeStrength::Skip, NegativeStrength::Resample}) {
    SimulationConfig cfg = testing::undamped();
    Simulation<3> sim(testing::table(testing::linearMaterial(1e6, 1e6, 0.5)), cfg);
    for (const V3& x : lattice) testing::addParticle<3>(sim, x, kR, V3::Zero());
    BondKind k = cement(8e6, 8e6);
    k.tensile_std = k.shear_std = 8e6;
    k.negative = mode;
    const CementReport r = sim.cement(sim.addBondKind(k), 0.05);
    ASSERT_EQ(r.candidates, 9450u);
    EXPECT_EQ(r.installed + r.skipped_nonpositive, r.candidates);
    const auto& B = sim.bonds();
    double mean = 0;
    for (double s : B.tensile) {
      EXPECT_GT(s, 0.0);
      mean += s / static_cast<double>(B.size());
    }
    // P(normal draw <= 0) = Phi(-1) = 0.1587 for each of the two strengths.
    const double p0 = 0.158655;
    if (mode == NegativeStrength::Skip) {
      const double skipped = 1.0 - (1.0 - p0) * (1.0 - p0);
      EXPECT_NEAR(static_cast<double>(r.skipped_nonpositive) / r.candidates, skipped, 0.015);
      EXPECT_EQ(r.redrawn, 0u);
    } else {
      EXPECT_EQ(r.skipped_nonpositive, 0u);
      EXPECT_NEAR(static_cast<double>(r.redrawn) / (2.0 * r.candidates), p0 / (1 - p0), 0.015);
    }
    // Mean of the kept draws: for the truncated normal 8 + 8 phi(1)/(1 - Phi(-1)) = 11.4 MPa.
    EXPECT_NEAR(mean, 8e6 + 8e6 * 0.241971 / (1 - p0), 0.2e6);
    // Bonds start unloaded.
    for (const auto& l : B.load) EXPECT_EQ(l.fn, 0.0);
  }
}

// The peak stresses a bond carried (BondForces::trackPeaks) are exactly what its strengths
// must exceed for it to hold: loaded along the same path, a bond a hair stronger than its
// peaks holds, one a hair weaker breaks. In tension and in shear with a friction angle (the
// cohesion it needed under compression).
TEST(BondPeaks, AStrengthAboveThePeakHoldsAndOneBelowBreaks) {
  const double phi = 30.0 * std::numbers::pi / 180.0, v = 0.01;
  auto load = [&](BondedPair<3>& p) {
    p.drive(V3::Zero(), -0.5e-6 / (500 * kDt) * p.n, V3::Zero(), V3::Zero(), 500);  // compress
    p.drive(V3::Zero(), V3(0, v, 0), V3::Zero(), V3::Zero(), 300);                  // shear
    p.drive(V3::Zero(), v * p.n, V3::Zero(), V3::Zero(), 900);                      // pull
  };
  auto kind = [&](double tensile, double cohesion) {
    BondKind k = cement(tensile, cohesion);
    k.friction_angle = phi;
    return k;
  };
  BondedPair<3> probe(kind(1e11, 1e11));
  probe.sim.trackBondPeaks(true);
  load(probe);
  ASSERT_NE(probe.sim.bondPeaks(), nullptr);
  const double tensile = probe.sim.bondPeaks()->tensile[0];
  const double cohesion = probe.sim.bondPeaks()->cohesion[0];
  EXPECT_GT(tensile, 0.0);
  EXPECT_GT(cohesion, 0.0);
  const double up = 1.0 + 1e-9, down = 1.0 - 1e-9;
  for (const auto& [t, c, holds] : {std::tuple{tensile * up, cohesion * up, true},
                                    std::tuple{tensile * down, cohesion * up, false},
                                    std::tuple{tensile * up, cohesion * down, false}}) {
    BondedPair<3> p(kind(t, c));
    load(p);
    EXPECT_EQ(p.sim.bonds().size(), holds ? 1u : 0u) << t << " " << c;
  }
  // A bond removed: the peaks name other bonds, and are gone.
  BondedPair<3> weak(kind(tensile * down, cohesion * up));
  weak.sim.trackBondPeaks(true);
  load(weak);
  EXPECT_EQ(weak.sim.bondPeaks(), nullptr);
}

// Strengths drawn again (redrawStrengths) from the stream reseeded as cementing began are the
// draws cementing with the new kind makes, bit for bit, and the stream ends where it would.
TEST(Cementing, StrengthsDrawnAgainAreThoseOfCementingWithTheNewKind) {
  std::vector<V3> lattice;
  for (int x = 0; x < 6; ++x) {
    for (int y = 0; y < 6; ++y) lattice.push_back(2 * kR * V3(x, y, 0));
  }
  auto kind = [](double mean, NegativeStrength negative) {
    BondKind k = cement(mean, 0.5 * mean);
    k.tensile_std = k.shear_std = 4e6;
    k.negative = negative;
    return k;
  };
  auto cemented = [&](const BondKind& k) {
    auto sim = std::make_unique<Simulation<3>>(
        testing::table(testing::linearMaterial(1e6, 1e6, 0.5)), testing::undamped());
    for (const V3& x : lattice) testing::addParticle<3>(*sim, x, kR, V3::Zero());
    sim->rng().reseed(7);
    sim->cement(sim->addBondKind(k), 0.05);
    return sim;
  };
  const BondKind weak = kind(4e6, NegativeStrength::Resample);
  const BondKind strong = kind(9e6, NegativeStrength::Resample);
  auto redrawn = cemented(weak);
  redrawn->rng().reseed(7);
  const std::optional<std::size_t> again = redrawn->redrawStrengths(0, strong);
  ASSERT_TRUE(again.has_value());
  EXPECT_GT(*again, 0u);  // the weak mean's draws <= 0 drawn again: the counts differ
  const auto fresh = cemented(strong);
  EXPECT_EQ(redrawn->bonds().tensile, fresh->bonds().tensile);
  EXPECT_EQ(redrawn->bonds().shear, fresh->bonds().shear);
  EXPECT_EQ(redrawn->rng().uniform(), fresh->rng().uniform());
  EXPECT_EQ(redrawn->bondKinds()[0].tensile_mean, 9e6);
  // A kind that skips draws <= 0 would have left a bond out: nothing changes.
  const std::vector<double> before = redrawn->bonds().tensile;
  redrawn->rng().reseed(7);
  EXPECT_FALSE(redrawn->redrawStrengths(0, kind(1e6, NegativeStrength::Skip)).has_value());
  EXPECT_EQ(redrawn->bonds().tensile, before);
  EXPECT_EQ(redrawn->bondKinds()[0].tensile_mean, 9e6);
}

// A bonded pair whose order in the particle arrays flips (reordering at neighbour rebuilds)
// keeps its load: compare with a run that never reorders.
// A flat joint too: its elements are seen in mirror order from the other particle.
TEST(Bonds, SurviveReorderingAndOrientationSwaps) {
  auto run = [](bool reorder, BondModel model) {
    SimulationConfig cfg = testing::undamped();
    cfg.timestep.automatic = false;
    cfg.timestep.fixed_dt = kDt;
    cfg.spatial_sort = reorder;
    cfg.skin = reorder ? 2e-5 : 0.1;
    Simulation<3> sim(testing::table(testing::linearMaterial(1e6, 1e6, 0.5)), cfg);
    ParticleSpec<3> p;
    p.radius = kR;
    p.fixed = true;
    // The same geometry as the contact-history test: crossing a sort-cell boundary swaps
    // the pair's order. The anchor pins the grid.
    p.position = V3(0, 2.5e-3, 0);
    const auto a = sim.particles().add(p);
    p.position = V3(0, 2.5e-3, 0) + (2 * kR + kGap) * V3(1, -1, 0).normalized();
    const auto b = sim.particles().add(p);
    p.position = V3(-1e-2, -1e-2, -1e-2);
    sim.particles().add(p);
    BondKind kind = cement(1e11, 1e11);
    kind.model = model;
    sim.cement(sim.addBondKind(kind), 0.01);
    auto& P = sim.particles();
    auto drive = [&](const V3& va, const V3& vb, const V3& wb, int steps) {
      for (int s = 0; s < steps; ++s) {
        P.vel[P.index(a)] = va, P.vel[P.index(b)] = vb, P.spin[P.index(b)] = wb;
        sim.step();
      }
    };
    drive(V3::Zero(), V3(0.01, 0.01, 0.0), V3(1, 2, 3), 100);  // load in every mode
    const bool before = P.index(a) < P.index(b);

    drive(V3(0, 10, 0), V3(0, 10, 0), V3::Zero(), 1000);  // +1 mm in y
    drive(V3(10, 0, 0), V3(10, 0, 0), V3::Zero(), 800);   // +0.8 mm in x

    EXPECT_EQ(reorder, before != (P.index(a) < P.index(b)));
    return std::pair{V3(P.force[P.index(b)]), V3(P.torque[P.index(b)])};
  };
  for (const BondModel model : {BondModel::Parallel, BondModel::FlatJoint}) {
    const auto [f0, t0] = run(false, model);
    const auto [f1, t1] = run(true, model);
    ASSERT_GT(f0.norm(), 0.0);
    EXPECT_LT((f1 - f0).norm(), 1e-9 * f0.norm());
    EXPECT_LT((t1 - t0).norm(), 1e-9 * t0.norm());
  }
}

// What a shaken bonded sample ends in, to compare the bond lanes with the scalar pass.
template <int D>
struct LaneOutcome {
  std::vector<Vec<D>> pos, vel;
  std::vector<Ang<D>> spin;
  std::vector<BondLoad<D>> loads;
  std::uint64_t broken = 0;
  std::vector<double> break_stress;  // the stress that broke each bond, in order
};

template <int D>
LaneOutcome<D> outcomeOf(const Simulation<D>& sim, std::uint32_t kind) {
  LaneOutcome<D> o;
  for (const auto& e : sim.bondBreaks()) o.break_stress.push_back(e.stress);
  const auto& P = sim.particles();
  for (std::size_t i = 0; i < P.size(); ++i) {
    o.pos.push_back(P.pos[i]), o.vel.push_back(P.vel[i]), o.spin.push_back(P.spin[i]);
  }
  o.loads = sim.bonds().load;
  o.broken =
      sim.brokenBonds(kind, BondBreakMode::Tensile) + sim.brokenBonds(kind, BondBreakMode::Shear);
  EXPECT_GT(sim.brokenBonds(kind, BondBreakMode::Tensile), 0u);
  EXPECT_GT(sim.brokenBonds(kind, BondBreakMode::Shear), 0u);
  return o;
}

template <int D>
void expectSameBits(const LaneOutcome<D>& scalar, const LaneOutcome<D>& lanes) {
  EXPECT_GT(scalar.broken, 10u);
  EXPECT_EQ(lanes.broken, scalar.broken);
  EXPECT_EQ(lanes.break_stress, scalar.break_stress);
  ASSERT_EQ(lanes.pos.size(), scalar.pos.size());
  for (std::size_t i = 0; i < scalar.pos.size(); ++i) {
    ASSERT_EQ(lanes.pos[i], scalar.pos[i]) << "particle " << i;
    ASSERT_EQ(lanes.vel[i], scalar.vel[i]) << "particle " << i;
    ASSERT_EQ(lanes.spin[i], scalar.spin[i]) << "particle " << i;
  }
  ASSERT_EQ(lanes.loads.size(), scalar.loads.size());
  for (std::size_t b = 0; b < scalar.loads.size(); ++b) {
    const BondLoad<D>&l = lanes.loads[b], &r = scalar.loads[b];
    ASSERT_TRUE(l.fn == r.fn && l.fs == r.fs && l.mb == r.mb && l.mt == r.mt) << "bond " << b;
  }
}

// The bond pass four and eight per register (bond_lanes.hpp) against bonds one at a time, bit
// for bit: a jittered lattice of 7 x 5 x 4 spheres (bonds with gaps and overlaps, a count that
// leaves a scalar tail after the groups), shaken with random velocities and spins so that
// every mode loads and bonds break. Runs under the sanitizers too (the lanes read particles
// with masked loads). With a friction angle and a moment factor, the shear strengths and
// the peak stresses come from the loads the lanes stored.
TEST(BondLanes, FourAndEightPerRegisterGiveTheScalarBits) {
  auto run = [](int width) {
    SimulationConfig cfg = testing::undamped();
    cfg.timestep.automatic = false;
    cfg.timestep.fixed_dt = kDt;
    cfg.bond_lane_width = width;
    Simulation<3> sim(testing::table(testing::linearMaterial(1e6, 1e6, 0.5)), cfg);
    Rng rng(5);
    for (int x = 0; x < 7; ++x) {
      for (int y = 0; y < 5; ++y) {
        for (int z = 0; z < 4; ++z) {
          const V3 jitter(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
          const V3 at = 2 * kR * V3(x, y, z) + 0.02 * kR * jitter;
          testing::addParticle<3>(sim, at, kR * rng.uniform(0.98, 1.02), V3::Zero());
        }
      }
    }
    BondKind cemented = cement(2e6, 3e6);
    cemented.friction_angle = 0.5;  // rad: the shear strength read from the lanes' loads
    cemented.moment_factor = 0.7;   // the peak stresses recomputed from them
    const auto kind = sim.addBondKind(cemented);
    const std::size_t installed = sim.cement(kind, 0.1).installed;
    EXPECT_GT(installed, 300u);
    EXPECT_GT(installed % 4, 0u) << "no scalar tail after the groups of four: change the seed";
    auto& P = sim.particles();
    for (std::size_t i = 0; i < P.size(); ++i) {
      P.vel[i] = 0.05 * V3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
      P.spin[i] = 50 * V3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    }
    for (int s = 0; s < 400; ++s) sim.step();
    return outcomeOf(sim, kind);
  };
  const auto scalar = run(0);
  expectSameBits(scalar, run(4));
  expectSameBits(scalar, run(8));  // four again where the CPU lacks AVX-512
}

// The 2D lanes against bonds one at a time, bit for bit, as the 3D ones above: a jittered
// lattice of 11 x 9 disks shaken so that bonds break in both modes.
TEST(BondLanes, FourAndEightPerRegisterGiveTheScalarBitsIn2D) {
  auto run = [](int width) {
    SimulationConfig cfg = testing::undamped();
    cfg.timestep.automatic = false;
    cfg.timestep.fixed_dt = kDt;
    cfg.bond_lane_width = width;
    Simulation<2> sim(testing::table(testing::linearMaterial(1e6, 1e6, 0.5)), cfg);
    sim.particles().thickness = 2 * kR;
    Rng rng(7);
    for (int x = 0; x < 11; ++x) {
      for (int y = 0; y < 9; ++y) {
        const V2 jitter(rng.uniform(-1, 1), rng.uniform(-1, 1));
        testing::addParticle<2>(sim, V2(2 * kR * V2(x, y) + 0.02 * kR * jitter),
                                kR * rng.uniform(0.98, 1.02), V2::Zero());
      }
    }
    BondKind cemented = cement(2e6, 3e6);
    cemented.friction_angle = 0.5;
    cemented.moment_factor = 0.7;
    const auto kind = sim.addBondKind(cemented);
    const std::size_t installed = sim.cement(kind, 0.1).installed;
    EXPECT_GT(installed, 150u);
    EXPECT_GT(installed % 4, 0u) << "no scalar tail after the groups of four: change the seed";
    auto& P = sim.particles();
    for (std::size_t i = 0; i < P.size(); ++i) {
      P.vel[i] = 0.2 * V2(rng.uniform(-1, 1), rng.uniform(-1, 1));
      P.spin[i] = 200 * rng.uniform(-1, 1);
    }
    for (int s = 0; s < 400; ++s) sim.step();
    return outcomeOf(sim, kind);
  };
  const auto scalar = run(0);
  expectSameBits(scalar, run(4));
  expectSameBits(scalar, run(8));
}

TEST(Bonds, KindsAreValidated) {
  BondKind k = cement(8e6, 8e6);
  k.modulus = -1;
  Simulation<3> sim(testing::table(testing::linearMaterial(1e6, 1e6, 0.5)), testing::undamped());
  EXPECT_THROW(sim.addBondKind(k), InvalidParameter);
  k = cement(-1e6, 8e6);
  k.negative = NegativeStrength::Resample;
  EXPECT_THROW(sim.addBondKind(k), InvalidParameter);
}

}  // namespace
}  // namespace rocklab
