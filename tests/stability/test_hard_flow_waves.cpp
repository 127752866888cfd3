// Hard cases of the pore network and the ultrasonic bench: tiny pores and throats, pores of
// no volume, inputs no triangulation can be built from, a wave source above what the
// particles can carry, and a receiver slab with nothing in it. Each ends with bounded,
// finite values or stops with the right diagnosis.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "lab/flow/solver.hpp"
#include "rigs/ultrasonic/wave.hpp"
#include "tests/flow_support.hpp"
#include "tests/support.hpp"

namespace rocklab {
namespace {

using namespace flow;

// A lattice pack made hard: every fourth grain 30% larger, so that it overlaps its
// neighbours (throats closed or three orders of magnitude below the median, pores filled to
// no volume), and grains doubled 1e-3 of their radius apart (cells of next to no volume).
PackView<3> hardPack() {
  PackView<3> p = latticePack<3>({5, 5, 10}, 0.36, 0.05, 21);
  const std::size_t grains = p.centre.size();
  for (std::size_t k = 0; k < grains; k += 4) p.radius[k] *= 1.3;
  for (std::size_t k = 1; k < grains; k += 17) {
    p.centre.push_back(p.centre[k] + Vec<3>(1e-3 * p.radius[k], 0.0, 0.0));
    p.radius.push_back(p.radius[k]);
  }
  return p;
}

TEST(HardFlow, TinyPoresThroatsAndEmptyPoresKeepTheSteadyFlowBounded) {
  const PackView<3> p = hardPack();
  const Network<3> net = networkOf<3>(p);
  // The scene is as hard as meant: pores of no volume, throats far below the median.
  std::vector<double> throats;
  for (double s : net.throat()) {
    if (s > 0.0) throats.push_back(s);
  }
  std::sort(throats.begin(), throats.end());
  EXPECT_GT(std::count(net.volume().begin(), net.volume().end(), 0.0), 0);
  EXPECT_LT(throats.front(), 2e-3 * throats[throats.size() / 2]);

  double top = 0.0;
  for (const auto& x : p.centre) top = std::max(top, x[2]);
  const auto boundary = endLayers<3>(net, 1.0, top - 1.0);
  const Pressures bc{2.0e4, 1.0e4};
  // Every pore on its own, and with the small-pore rule the explicit scheme needs.
  for (const MergeRule rule : {MergeRule{0.0, 0.0}, MergeRule{0.0, 0.05}}) {
    const Clusters c = mergePores<3>(net, boundary, rule);
    const SteadyFlow f = solveImplicit(c, bc, {}, {});
    ASSERT_TRUE(f.converged);
    // The discrete maximum principle: no pore above the inlet or below the outlet.
    for (double pr : f.pressure) {
      ASSERT_TRUE(std::isfinite(pr));
      EXPECT_GE(pr, bc.outlet - 1e-9 * (bc.inlet - bc.outlet));
      EXPECT_LE(pr, bc.inlet + 1e-9 * (bc.inlet - bc.outlet));
    }
    EXPECT_GT(f.inflow, 0.0);
    EXPECT_NEAR(f.outflow / f.inflow, 1.0, 1e-9);
  }
  // Pores of no volume make the explicit step zero: refused by name, not run forever.
  const Clusters all = mergePores<3>(net, boundary, {0.0, 0.0});
  EXPECT_EQ(criticalFlowStep(all, 2.2e9), 0.0);
  ExplicitSettings ex;
  ex.virtual_volume = false;  // the real volumes, whose step is bounded
  ex.dt = 1e-12;
  EXPECT_THROW(solveExplicit(all, bc, ex, {}), FlowStepTooLarge);
  // Merged by the small-pore rule, the explicit scheme runs and agrees with the implicit.
  const Clusters merged = mergePores<3>(net, boundary, {0.0, 0.05});
  EXPECT_GT(criticalFlowStep(merged, 2.2e9), 0.0);
  ExplicitSettings virt;
  virt.virtual_volume = true;
  virt.tolerance = 1e-11;
  const SteadyFlow e = solveExplicit(merged, bc, virt, {});
  const SteadyFlow i = solveImplicit(merged, bc, {}, {});
  ASSERT_TRUE(e.converged);
  EXPECT_NEAR(e.inflow / i.inflow, 1.0, 1e-6);
}

TEST(HardFlow, InputsNoNetworkCanBeBuiltFromAreRefusedWithTheReason) {
  std::vector<Vec<3>> plane;
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) plane.push_back({double(i), double(j), 0.0});
  }
  try {
    triangulate<3>(plane, std::vector<double>(plane.size(), 0.4));
    FAIL() << "co-planar centres were accepted";
  } catch (const DegenerateNetwork& e) {
    EXPECT_NE(std::string(e.what()).find("one plane"), std::string::npos) << e.what();
  }
  std::vector<Vec<2>> line{{0, 0}, {1, 1}, {2, 2}, {3, 3}};
  EXPECT_THROW(triangulate<2>(line, std::vector<double>(4, 0.4)), DegenerateNetwork);
  std::vector<Vec<3>> line3{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}};
  EXPECT_THROW(triangulate<3>(line3, std::vector<double>(4, 0.4)), DegenerateNetwork);
  std::vector<Vec<3>> one{{0, 0, 0}};
  EXPECT_THROW(triangulate<3>(one, {0.5}), DegenerateNetwork);
  EXPECT_THROW(triangulate<3>({}, {}), DegenerateNetwork);
  // Nearly co-planar (1e-9 out of the plane): a thin but valid network, or a refusal; never
  // a non-finite volume or throat.
  plane.push_back({1.5, 1.5, 1e-9});
  try {
    auto t = triangulate<3>(plane, std::vector<double>(plane.size(), 0.4));
    Network<3> net(std::move(t), 1.0);
    PackView<3> pack{plane, std::vector<double>(plane.size(), 0.4), {}, {}};
    net.measure(pack, {});
    for (double v : net.volume()) EXPECT_TRUE(std::isfinite(v) && v >= 0.0);
    for (double s : net.throat()) EXPECT_TRUE(std::isfinite(s) && s >= 0.0);
  } catch (const DegenerateNetwork&) {
  }
}

using rigs::ultrasonic::measureWave;
using rigs::ultrasonic::WaveError;
using rigs::ultrasonic::WaveResult;
using rigs::ultrasonic::WaveSpec;

constexpr double kR = 1e-3, kSpacing = 2.0 * kR * (1.0 + 1e-4);

// A bonded chain of equal disks (bonds only, as in validation/test_waves.cpp); returns its
// long-wave speed a sqrt(k / m).
double chain(Simulation<2>& sim, int n, int gap_at = -1) {
  for (int k = 0; k < n; ++k) {
    if (k == gap_at) continue;
    testing::addParticle<2>(sim, Vec<2>(k * kSpacing, 0.0), kR, Vec<2>::Zero());
  }
  BondKind cement;
  cement.modulus = 4e9;
  cement.stiffness_ratio = 2.0;
  cement.tensile_mean = cement.shear_mean = 1e11;
  cement.tensile_std = cement.shear_std = 0.0;
  sim.cement(sim.addBondKind(cement), 1e-3);
  const double mass = 2650.0 * M_PI * kR * kR * 1.0;
  return kSpacing * std::sqrt(4e9 * 1.0 / mass);
}

WaveSpec pulse(double frequency, int n) {
  WaveSpec s;
  s.name = "pz";
  s.frequency = frequency;
  s.amplitude = 1e-3;
  s.path_hi = (n - 1) * kSpacing;
  s.slab = kSpacing;
  s.max_steps = 40000;
  return s;
}

// The chain carries frequencies up to f_max = sqrt(k / m) / pi (a wavelength of two
// spacings). A quarter of it (twelve diameters) is still measured, within 2% of the
// long-wave speed (dispersion). At half of it and at f_max the one-period pulse spreads as it
// goes: its shape no longer matches at the receivers, the cross-correlation picks fall below
// their quality threshold and no velocity is given rather than a wrong one (the rig then
// records none, with a warning); the state stays finite and the waves hold no more energy
// than the source put in. At three times f_max the step samples the pulse fewer than four
// times a period: refused by name before any step.
TEST(HardWaves, HighFrequencySourceStaysBoundedAndGivesNoFalseVelocity) {
  for (const double fraction : {0.25, 0.5, 1.0, 3.0}) {
    Simulation<2> sim(testing::table(testing::linearMaterial(1e6, 1e6, 0.5, 0.0)),
                      testing::undamped());
    const int n = 301;
    const double c0 = chain(sim, n);
    const double f_max = c0 / (M_PI * kSpacing);
    if (fraction > 2.0) {
      try {
        measureWave(sim, pulse(fraction * f_max, n));
        FAIL() << "a pulse sampled under four times a period was measured";
      } catch (const WaveError& e) {
        EXPECT_NE(std::string(e.what()).find("fewer than four per pulse period"), std::string::npos)
            << e.what();
      }
      EXPECT_EQ(sim.steps(), 0u);
      continue;
    }
    const WaveResult w = measureWave(sim, pulse(fraction * f_max, n));
    for (const auto& r : w.receivers) {
      for (double v : r.velocity) ASSERT_TRUE(std::isfinite(v)) << fraction;
    }
    const EnergyReport e = sim.energy();
    EXPECT_LE(e.kinetic() + e.strain, 1.001 * e.ledger.boundary_work) << fraction;
    if (fraction < 0.5) {
      EXPECT_NEAR(w.xcorr.value / c0, 1.0, 0.02);
      EXPECT_GT(w.wavelength() / (2.0 * kR), 4.0);
    } else {
      EXPECT_LT(w.xcorr.used, 2u) << fraction;
      EXPECT_EQ(w.xcorr.value, 0.0) << fraction;
    }
  }
}

TEST(HardWaves, EmptyReceiverGroupIsRefusedByName) {
  Simulation<2> sim(testing::table(testing::linearMaterial(1e6, 1e6, 0.5, 0.0)),
                    testing::undamped());
  const int n = 101;
  const WaveSpec s = pulse(1e4, n);
  chain(sim, n, static_cast<int>(std::lround(s.receivers_at[1] * (n - 1))));
  try {
    measureWave(sim, s);
    FAIL() << "a receiver slab with no particle was accepted";
  } catch (const WaveError& e) {
    EXPECT_NE(std::string(e.what()).find("no particle in the receiver slab"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace rocklab
