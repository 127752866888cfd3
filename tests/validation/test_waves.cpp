// Wave speeds through particle lattices against their analytic long-wave values, measured
// the way the ultrasonic bench measures a sample (rigs/ultrasonic/wave.hpp): a driven slab,
// receiver slabs, cross-correlation picks and the slope of arrival time over distance.
//
// The lattices are bonded with a small gap, so that only the parallel bonds act: linear
// springs in tension and compression, kn = E / (2R) * A (2D: A = 2 R t, so kn = E t;
// 3D: A = pi R^2) and ks = kn / stiffness_ratio. The pulse is long (a wavelength of 40
// spacings in the chain, 20 in the lattice) so that dispersion stays well inside the
// tolerance: in the chain the phase speed is 0.1% low and the group speed 0.3% low at
// 40 spacings, and a cross-correlation pick reads between the two; in the triangular
// lattice both are within 1% at 20 spacings (phase 1% low at 11-12 spacings, group at
// 19-21, for ks / kn between 0.25 and 1).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "rigs/ultrasonic/wave.hpp"
#include "tests/support.hpp"

namespace rocklab::rigs::ultrasonic {
namespace {

constexpr double kR = 1e-3, kDensity = 2650.0, kModulus = 4e9;
constexpr double kSpacing = 2.0 * kR * (1.0 + 1e-4);  // a gap of 2e-4 R: bonds only

SimulationConfig waveConfig() {
  SimulationConfig c;
  c.local_damping = 0.0;
  return c;
}

BondKind stiffCement(double stiffness_ratio) {
  BondKind k;
  k.modulus = kModulus;
  k.stiffness_ratio = stiffness_ratio;
  k.tensile_mean = k.shear_mean = 1e11;  // never breaks
  k.tensile_std = k.shear_std = 0.0;
  return k;
}

template <int D>
void bond(Simulation<D>& sim, double stiffness_ratio) {
  const auto kind = sim.addBondKind(stiffCement(stiffness_ratio));
  sim.cement(kind, 1e-3);
}

// Bond normal stiffness (N/m) and particle mass (kg) of the lattices.
template <int D>
double bondStiffness() {
  return D == 2 ? kModulus * 1.0 : kModulus / (2.0 * kR) * std::numbers::pi * kR * kR;
}
template <int D>
double particleMass() {
  return D == 2 ? kDensity * std::numbers::pi * kR * kR * 1.0
                : kDensity * 4.0 / 3.0 * std::numbers::pi * kR * kR * kR;
}

template <class Dimension>
class Chain : public ::testing::Test {};
using Dimensions = ::testing::Types<std::integral_constant<int, 2>, std::integral_constant<int, 3>>;
TYPED_TEST_SUITE(Chain, Dimensions);

// A 1D chain: c = a sqrt(k / m) within 1%.
TYPED_TEST(Chain, PVelocityIsSpacingTimesRootOfStiffnessOverMass) {
  constexpr int D = TypeParam::value;
  Simulation<D> sim(testing::table(testing::linearMaterial(1e6, 1e6, 0.5, 0.0, kDensity)),
                    waveConfig());
  constexpr int n = 400;
  for (int k = 0; k < n; ++k) {
    Vec<D> x = Vec<D>::Zero();
    x[0] = k * kSpacing;
    testing::addParticle<D>(sim, x, kR, Vec<D>::Zero(), kDensity);
  }
  bond(sim, 2.0);
  const double c0 = kSpacing * std::sqrt(bondStiffness<D>() / particleMass<D>());
  WaveSpec spec;
  spec.name = "chain";
  spec.propagation = spec.polarisation = 0;
  spec.frequency = c0 / (40.0 * kSpacing);
  spec.amplitude = 1e-3;
  spec.path_lo = 0.0;
  spec.path_hi = (n - 1) * kSpacing;
  spec.slab = kSpacing;  // one particle per slab
  const WaveResult w = measureWave(sim, spec);
  EXPECT_EQ(w.source_particles, 1u);
  for (const ReceiverTrace& r : w.receivers) {
    EXPECT_EQ(r.particles, 1u);
    EXPECT_TRUE(r.xcorr.found);
    EXPECT_GT(r.xcorr.quality, 0.9);  // the pulse arrives nearly undistorted
  }
  EXPECT_EQ(w.xcorr.used, 4u);
  EXPECT_NEAR(w.xcorr.value / c0, 1.0, 0.01);
  // A first break reads the pulse's leading edge, which dispersion moves ahead: within 2%.
  EXPECT_NEAR(w.first_break.value / c0, 1.0, 0.02);
  EXPECT_NEAR(w.wavelength() / (40.0 * kSpacing), 1.0, 0.01);
}

// A triangular lattice of equal disks, rows along x, bonded to its six neighbours.
struct Lattice {
  Simulation<2> sim;
  int columns, rows;
  Lattice(int columns_, int rows_, double stiffness_ratio)
      : sim(testing::table(testing::linearMaterial(1e6, 1e6, 0.5, 0.0, kDensity)), waveConfig()),
        columns(columns_),
        rows(rows_) {
    const double h = kSpacing * std::sqrt(3.0) / 2.0;
    for (int j = 0; j < rows; ++j) {
      for (int i = 0; i < columns; ++i) {
        const Vec<2> x((i + 0.5 * (j % 2)) * kSpacing, j * h);
        testing::addParticle<2>(sim, x, kR, Vec<2>::Zero(), kDensity);
      }
    }
    bond(sim, stiffness_ratio);
  }
  WaveSpec along(const std::string& name, int polarisation, double speed) const {
    WaveSpec s;
    s.name = name;
    s.propagation = 0;
    s.polarisation = polarisation;
    s.frequency = speed / (20.0 * kSpacing);
    s.amplitude = 1e-3;
    s.path_lo = 0.0;
    s.path_hi = (columns - 0.5) * kSpacing;
    s.source_at = 0.1;
    s.receivers_at = {0.3, 0.4, 0.5, 0.6, 0.7};
    s.slab = kSpacing;  // one particle per row
    // The plane wave's middle: the free top and bottom send their own waves, which reach
    // the axis only after the direct pulse has passed.
    s.receiver_half_width = 10.0 * kSpacing;
    s.centre = {0.5 * s.path_hi, 0.5 * (rows - 1) * kSpacing * std::sqrt(3.0) / 2.0};
    return s;
  }
};

// vp^2 = (3/8)(3 + alpha) kn a^2 / m and vs^2 = (3/8)(1 + alpha) kn a^2 / m, alpha = ks / kn:
// the affine (uniform strain) elastic constants of the triangular lattice, C11 =
// (sqrt 3 / 4)(3 kn + ks) and C66 = (sqrt 3 / 4)(kn + ks) per unit thickness, over the
// density 2 m / (sqrt 3 a^2). Exact at long wavelength for a Bravais lattice with free
// rotations (the bonds' moments vanish in a uniform rotation).
TEST(HexagonalLattice, PAndSVelocitiesMatchTheAffineElasticConstantsWithinTwoPercent) {
  const double ratio = 2.0, alpha = 1.0 / ratio;
  const double c0 = kSpacing * std::sqrt(bondStiffness<2>() / particleMass<2>());
  const double vp = c0 * std::sqrt(3.0 / 8.0 * (3.0 + alpha));
  const double vs = c0 * std::sqrt(3.0 / 8.0 * (1.0 + alpha));
  Lattice lattice(100, 140, ratio);
  {
    Simulation<2> copy = lattice.sim.clone();
    const WaveResult p = measureWave(copy, lattice.along("px", 0, vp));
    EXPECT_EQ(p.source_particles, 140u);
    EXPECT_NEAR(p.xcorr.value / vp, 1.0, 0.02);
  }
  {
    Simulation<2> copy = lattice.sim.clone();
    const WaveResult s = measureWave(copy, lattice.along("sxy", 1, vs));
    EXPECT_NEAR(s.xcorr.value / vs, 1.0, 0.02);
    EXPECT_GT(s.xcorr.value, 0.0);
  }
}

// The receivers sampled every k steps (a digitiser's rate): the cross-correlation pick
// interpolates its peak between samples, so the velocity holds to 1% down to four samples
// per pulse period (measured on the chain: 0.15% off at 146 samples per period and at 18,
// 0.11% at 4); below four a period is refused.
TEST(WaveBench, CoarserReceiverSamplingKeepsTheVelocity) {
  auto measure = [](int every) {
    Simulation<2> sim(testing::table(testing::linearMaterial(1e6, 1e6, 0.5, 0.0, kDensity)),
                      waveConfig());
    constexpr int n = 401;
    for (int k = 0; k < n; ++k) {
      testing::addParticle<2>(sim, Vec<2>(k * kSpacing, 0.0), kR, Vec<2>::Zero(), kDensity);
    }
    bond(sim, 2.0);
    const double c0 = kSpacing * std::sqrt(bondStiffness<2>() / particleMass<2>());
    WaveSpec spec;
    spec.name = "chain";
    spec.frequency = c0 / (40.0 * kSpacing);
    spec.amplitude = 1e-3;
    spec.path_hi = (n - 1) * kSpacing;
    spec.slab = kSpacing;
    spec.sample_every = every;
    const WaveResult w = measureWave(sim, spec);
    return std::tuple{w.xcorr.value / c0, 1.0 / (spec.frequency * w.dt),
                      w.receivers[0].velocity.size()};
  };
  const auto [v1, per_period1, samples1] = measure(1);
  const auto [v8, per_period8, samples8] = measure(8);
  EXPECT_NEAR(per_period8 / per_period1, 1.0 / 8.0, 1e-12);
  EXPECT_NEAR(static_cast<double>(samples8) / samples1, 1.0 / 8.0, 0.01);
  EXPECT_NEAR(v1, 1.0, 0.01);
  EXPECT_NEAR(v8, 1.0, 0.01) << per_period8 << " samples per period";
  const auto [v36, per_period36, samples36] = measure(36);
  EXPECT_LT(per_period36, 4.5);
  EXPECT_NEAR(v36, 1.0, 0.01) << per_period36 << " samples per period";
  try {
    measure(static_cast<int>(per_period1 / 3.0));
    FAIL() << "three samples per period were accepted";
  } catch (const WaveError& e) {
    EXPECT_NE(std::string(e.what()).find("fewer than four per pulse period"), std::string::npos)
        << e.what();
  }
}

TEST(WaveBench, ABadGeometryIsRefusedWithItsReason) {
  Simulation<2> sim(testing::table(testing::linearMaterial(1e6, 1e6, 0.5)), waveConfig());
  testing::addParticle<2>(sim, Vec<2>::Zero(), kR, Vec<2>::Zero());
  WaveSpec s;
  s.name = "pz";
  s.frequency = 1e5;
  s.amplitude = 1e-3;
  s.path_hi = 0.01;
  s.slab = 1e-3;
  s.receivers_at = {0.05};
  EXPECT_THROW(measureWave(sim, s), WaveError);  // one receiver, and before the source
  s.receivers_at = {0.5, 0.7};
  try {
    measureWave(sim, s);
    FAIL() << "an empty source slab was accepted";
  } catch (const WaveError& e) {
    EXPECT_NE(std::string(e.what()).find("source slab"), std::string::npos) << e.what();
  }
}

TEST(DrivenParticles, MoveWithTheirPrescribedVelocityWhateverTheForces) {
  Simulation<2> sim(testing::table(testing::linearMaterial(1e6, 1e6, 0.5)), waveConfig());
  const auto a = testing::addParticle<2>(sim, Vec<2>(0, 0), kR, Vec<2>::Zero());
  const auto b = testing::addParticle<2>(sim, Vec<2>(2.1 * kR, 0), kR, Vec<2>::Zero());
  const std::vector<std::uint32_t> driven{a.slot};
  sim.drive(driven);
  sim.setDrivenVelocity(driven, Vec<2>(0.01, 0.0));
  for (int k = 0; k < 600; ++k) sim.step();  // a closes the gap of 0.1 R in 10 ms, then pushes
  const auto& P = sim.particles();
  EXPECT_DOUBLE_EQ(P.vel[P.index(a)].x(), 0.01);  // pushed back by b, unmoved in its course
  EXPECT_NEAR(P.pos[P.index(a)].x(), 0.01 * sim.time(), 1e-12);
  EXPECT_GT(P.vel[P.index(b)].x(), 0.0);              // b was pushed
  EXPECT_GT(sim.energy().ledger.boundary_work, 0.0);  // the source's work on b
  // The work is summed from end-of-step forces, first order in the step: 1%.
  EXPECT_NEAR(sim.energy().imbalance(), 0.0, 1e-2 * sim.energy().ledger.boundary_work);
  EXPECT_THROW(sim.setDrivenVelocity({b.slot}, Vec<2>::Zero()), std::invalid_argument);
  EXPECT_THROW(sim.drive({12345}), std::invalid_argument);
}

}  // namespace
}  // namespace rocklab::rigs::ultrasonic
