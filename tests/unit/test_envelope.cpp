// The failure envelope's pieces on synthetic curves with known answers: the critical point
// of a dilatant and of a compactive test, the Mohr-Coulomb fit (Li & Holt, equation 1), and
// when a test stops after its peak.

#include <gtest/gtest.h>

#include <cmath>

#include "rigs/biaxial/loading.hpp"
#include "rigs/common/envelope.hpp"

using namespace rocklab::rigs;

namespace {

// q and volumetric strain sampled every 1e-4 of axial strain up to `end`.
LoadingCurve sample(double end, double (*q)(double), double (*ev)(double)) {
  LoadingCurve c;
  for (double e = 0.0; e <= end + 1e-12; e += 1e-4) {
    c.axial_strain.push_back(e);
    c.q.push_back(q(e));
    c.volumetric_strain.push_back(ev(e));
  }
  return c;
}

}  // namespace

TEST(CriticalPoint, ADilatantTestGivesItsPeak) {
  // Peak of q at 1% strain; compaction to 0.2% then dilation well past the noise margin.
  const LoadingCurve c = sample(
      0.02, [](double e) { return 20e6 * (1.0 - (e - 0.01) * (e - 0.01) / 1e-4); },
      [](double e) { return 0.3 * e - 15.0 * e * e; });
  const CriticalPoint p = criticalPoint(c);
  ASSERT_TRUE(p.found);
  EXPECT_FALSE(p.compactive);
  EXPECT_NEAR(p.axial_strain, 0.01, 1e-9);
  EXPECT_NEAR(p.q, 20e6, 1.0);
}

TEST(CriticalPoint, ACompactiveTestGivesTheOnsetOfCompaction) {
  // Elastic compaction at slope 0.5, accelerating by a further slope 1 from 1% strain: the
  // volumetric strain passes 1.1 times the trend at 0.01 / 0.95 = 1.0526%.
  const LoadingCurve c = sample(
      0.03, [](double e) { return 1e9 * e; },
      [](double e) { return 0.5 * e + (e > 0.01 ? e - 0.01 : 0.0); });
  const CriticalPoint p = criticalPoint(c);
  ASSERT_TRUE(p.found);
  EXPECT_TRUE(p.compactive);
  EXPECT_NEAR(p.axial_strain, 0.01 / 0.95, 1e-4);  // within one sample
  EXPECT_NEAR(p.q, 1e9 * p.axial_strain, 1.0);
}

TEST(CriticalPoint, ACompactiveTestThatYieldsWithoutFasterCompaction) {
  // q softens from 1% strain (tangent halves) while the compaction rate stays: q falls 10%
  // below its trend where 1e9 (e - 0.01) / 2 = 0.1e9 e, at e = 0.0125.
  const LoadingCurve c = sample(
      0.03, [](double e) { return e < 0.01 ? 1e9 * e : 1e7 + 0.5e9 * (e - 0.01); },
      [](double e) { return 0.5 * e; });
  const CriticalPoint p = criticalPoint(c);
  ASSERT_TRUE(p.found);
  EXPECT_TRUE(p.compactive);
  EXPECT_NEAR(p.axial_strain, 0.0125, 1e-4);
}

TEST(CriticalPoint, PurelyElasticCompactionHasNone) {
  const LoadingCurve c = sample(
      0.02, [](double e) { return 1e9 * e; }, [](double e) { return 0.5 * e; });
  EXPECT_FALSE(criticalPoint(c).found);
}

TEST(MohrCoulomb, RecoversFrictionAngleAndUcsAndIgnoresTheCap) {
  const double phi = 30.0, ucs = 10e6;
  const double N = std::pow(std::tan((45.0 + phi / 2.0) * M_PI / 180.0), 2);  // 3
  std::vector<EnvelopePoint> pts;
  for (double s3 : {0.0, 2e6, 4e6, 8e6}) pts.push_back({s3, N * s3 + ucs, false});
  pts.push_back({18e6, 30e6, true});  // a cap point far below the line
  const MohrCoulomb m = fitMohrCoulomb(pts);
  ASSERT_TRUE(m.fitted);
  EXPECT_EQ(m.points, 4u);
  EXPECT_NEAR(m.friction_angle_deg, phi, 1e-9);
  EXPECT_NEAR(m.ucs, ucs, 1e-3);
  EXPECT_NEAR(m.rms_residual, 0.0, 1e-3);
}

TEST(MohrCoulomb, NeedsTwoDilatantConfinements) {
  EXPECT_FALSE(fitMohrCoulomb({{0.0, 10e6, false}, {18e6, 30e6, true}}).fitted);
  // sigma_1 falling with sigma_3 is no friction angle
  EXPECT_FALSE(fitMohrCoulomb({{0.0, 10e6, false}, {4e6, 9e6, false}}).fitted);
}

// The drop stop of a test (loading.stop_after_drop): a dilatant failure whose load has fallen
// 30% below its peak ends the test; a compacting sample's drop at a burst of crushing ends it
// only where the key that tells the two apart is off.
TEST(DropStop, EndsADilatantFailureAndLetsACompactingSampleHarden) {
  rocklab::rigs::biaxial::LoadingTest test;
  test.axial_strain_max = 0.025;
  test.stop_after_drop = 0.3;
  const double peak = 20e6, peak_strain = 0.004, peak_volumetric = 0.006;
  // Past the peak, 35% below it: dilated since (0.004 < 0.006), compacted further (0.009), or
  // swollen by the elastic unloading of the drop alone (0.0056).
  const double strain = 0.006, load = 13e6, dilated = 0.004, compacted = 0.009, swollen = 0.0056;
  EXPECT_TRUE(test.ends(strain, load, dilated, peak, peak_strain, peak_volumetric));
  EXPECT_TRUE(test.ends(strain, load, compacted, peak, peak_strain, peak_volumetric));
  test.stop_after_drop_dilating = true;
  EXPECT_TRUE(test.ends(strain, load, dilated, peak, peak_strain, peak_volumetric));
  EXPECT_FALSE(test.ends(strain, load, compacted, peak, peak_strain, peak_volumetric));
  EXPECT_FALSE(test.ends(strain, load, swollen, peak, peak_strain, peak_volumetric));
  // Not yet 30% below the peak, or before stop_after_drop_min_strain: the test goes on; at
  // the strain limit it ends whatever the load.
  EXPECT_FALSE(test.ends(strain, 15e6, dilated, peak, peak_strain, peak_volumetric));
  EXPECT_FALSE(test.ends(0.0019, load, dilated, peak, 0.0015, peak_volumetric));
  EXPECT_TRUE(test.ends(0.025, 25e6, compacted, peak, peak_strain, peak_volumetric));
  test.stop_after_drop = 0.0;
  EXPECT_FALSE(test.ends(strain, 1e6, dilated, peak, peak_strain, peak_volumetric));
}
