// The unconfined compression test's measurements on synthetic data with known answers
// (rigs/ucs/curve.hpp): the gauge's strains from an affine displacement field, and the
// moduli at half the peak and the crack damage stress of a curve built from a known
// elastic material that dilates past a set stress.

#include <gtest/gtest.h>

#include <random>

#include "rigs/ucs/curve.hpp"

using namespace rocklab::rigs::ucs;

namespace {

template <int D>
using Vec = Eigen::Matrix<double, D, 1>;

// Points in a box, moved by the affine field u = c + H x plus a fluctuation of `noise` (m).
template <int D>
std::vector<Vec<D>> moved(const std::vector<Vec<D>>& x, const Eigen::Matrix<double, D, D>& H,
                          double noise, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, noise);
  std::vector<Vec<D>> out;
  for (const Vec<D>& p : x) {
    Vec<D> u = H * p + Vec<D>::Constant(3e-4);  // a rigid shift the fit must ignore
    for (int d = 0; d < D; ++d) u[d] += n(rng);
    out.push_back(p + u);
  }
  return out;
}

template <int D>
std::vector<Vec<D>> box(std::size_t count, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 0.01);
  std::vector<Vec<D>> x(count);
  for (Vec<D>& p : x) {
    for (int d = 0; d < D; ++d) p[d] = u(rng);
  }
  return x;
}

TEST(GaugeStrains, AnAffineFieldIsRecoveredExactly3D) {
  std::mt19937 rng(3);
  const auto x = box<3>(500, rng);
  Eigen::Matrix3d H;
  // Compression 1e-3 along z, expansion 2e-4 and 3e-4 across it, and some shear and rotation
  // that must not leak into the normal strains.
  H << 2e-4, 5e-5, -1e-4, 2e-5, 3e-4, 4e-5, 1e-4, -3e-5, -1e-3;
  const GaugeStrains e = affineStrains<3>(x, moved<3>(x, H, 0.0, rng), 2);
  EXPECT_NEAR(e.axial, 1e-3, 1e-12);
  EXPECT_NEAR(e.lateral, -2.5e-4, 1e-12);
}

TEST(GaugeStrains, AnAffineFieldIsRecoveredExactly2D) {
  std::mt19937 rng(4);
  const auto x = box<2>(300, rng);
  Eigen::Matrix2d H;
  H << 4e-4, 1e-4, -1e-4, -2e-3;
  const GaugeStrains e = affineStrains<2>(x, moved<2>(x, H, 0.0, rng), 1);
  EXPECT_NEAR(e.axial, 2e-3, 1e-12);
  EXPECT_NEAR(e.lateral, -4e-4, 1e-12);
}

// Each particle's own fluctuation about the field (here 1 um, a tenth of the field's
// displacement across the gauge) averages out: the fit's error falls as 1 / sqrt(N).
TEST(GaugeStrains, ParticlesFluctuationsAverageOut) {
  std::mt19937 rng(5);
  const auto x = box<3>(1000, rng);
  const Eigen::Matrix3d H = Eigen::Vector3d(2e-4, 2e-4, -1e-3).asDiagonal();
  const GaugeStrains e = affineStrains<3>(x, moved<3>(x, H, 1e-6, rng), 2);
  // The slope's standard error: noise / (sqrt(N) * sd(x)), sd(x) = 0.01 / sqrt(12) m.
  const double se = 1e-6 / (std::sqrt(1000.0) * 0.01 / std::sqrt(12.0));
  EXPECT_NEAR(e.axial, 1e-3, 4.0 * se);
  EXPECT_NEAR(e.lateral, -2e-4, 4.0 * se / std::sqrt(2.0));
}

// A material of E = 10 GPa and nu = 0.2 loaded at constant stress steps to 30 MPa: linear
// until 20 MPa, then cracks open across the axis (a lateral strain growing as the square of
// the stress above 20 MPa), the volumetric strain turns at the stress where its rate
// changes sign, and the curve softens to its peak at 30 MPa.
CompressionCurve elasticThenDilating(double E, double nu, double onset, double growth) {
  CompressionCurve c;
  for (double s = 0.0; s <= 30e6 + 1.0; s += 0.25e6) {
    const double over = std::max(0.0, s - onset);
    const double axial = s / E + 0.2 * over * over / (E * 10e6);
    const double lateral = -nu * s / E - growth * over * over / (E * 10e6);
    c.push(s, axial, axial, lateral, axial + 2.0 * lateral);
  }
  return c;
}

TEST(HalfPeakModuli, AnElasticCurveGivesItsEAndNu) {
  const CompressionCurve c = elasticThenDilating(10e9, 0.2, 20e6, 1.0);
  const std::size_t peak = c.size() - 1;
  const HalfPeakModuli m = halfPeakModuli(c, peak);
  // Half the peak (15 MPa) lies in the linear part: secant and tangent are E and nu.
  EXPECT_NEAR(m.young_secant, 10e9, 1e-6 * 10e9);
  EXPECT_NEAR(m.young_tangent, 10e9, 1e-6 * 10e9);
  EXPECT_NEAR(m.poisson_secant, 0.2, 1e-9);
  EXPECT_NEAR(m.poisson_tangent, 0.2, 1e-9);
}

TEST(HalfPeakModuli, TheSecantSeesTheSeatingTheTangentDoesNot) {
  CompressionCurve c = elasticThenDilating(10e9, 0.2, 20e6, 1.0);
  for (double& a : c.axial) a += 2e-4;  // a seating closure before the first record
  const HalfPeakModuli m = halfPeakModuli(c, c.size() - 1);
  EXPECT_NEAR(m.young_secant, 15e6 / (15e6 / 10e9 + 2e-4), 1e-6 * 10e9);
  EXPECT_NEAR(m.young_tangent, 10e9, 1e-6 * 10e9);
}

// Past the onset, dv/ds = (1 - 2 nu) / E + (0.4 - 4 growth) over / (E * 10 MPa): zero at
// over = (1 - 2 nu) 10 MPa / (4 growth - 0.4), here 0.6 * 10 / 3.6 = 1.667 MPa.
TEST(CrackDamage, IsWhereTheVolumetricStrainTurns) {
  const CompressionCurve c = elasticThenDilating(10e9, 0.2, 20e6, 1.0);
  const CrackDamage d = crackDamage(c, c.size() - 1);
  EXPECT_NEAR(d.stress, 20e6 + 0.6 * 10e6 / 3.6, 0.25e6);  // within a record's stress step
  EXPECT_GT(d.volumetric, c.volumetric.back());
}

TEST(CrackDamage, AnElasticSampleHasItAtThePeak) {
  const CompressionCurve c = elasticThenDilating(10e9, 0.2, 40e6, 1.0);
  const CrackDamage d = crackDamage(c, c.size() - 1);
  EXPECT_EQ(d.index, c.size() - 1);
  EXPECT_DOUBLE_EQ(d.stress, 30e6);
}

TEST(CrackDamage, OnlyTheRecordsUpToThePeakCount) {
  CompressionCurve c = elasticThenDilating(10e9, 0.2, 40e6, 1.0);
  const std::size_t peak = c.size() - 1;
  c.push(20e6, 0.01, 0.01, 0.0, 0.05);  // post-peak: more compaction, not a turn before it
  EXPECT_EQ(crackDamage(c, peak).index, peak);
}

}  // namespace
