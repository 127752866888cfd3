// Size distributions and the random number generator.

#include <gtest/gtest.h>

#include <cmath>

#include "lab/core/errors.hpp"
#include "lab/core/packing.hpp"

namespace rocklab {
namespace {

struct Moments {
  double mean = 0, std = 0, min = INFINITY, max = -INFINITY;
};

template <class F>
Moments moments(int n, F draw) {
  Moments m;
  double s = 0, s2 = 0;
  for (int k = 0; k < n; ++k) {
    const double x = draw();
    s += x;
    s2 += x * x;
    m.min = std::min(m.min, x);
    m.max = std::max(m.max, x);
  }
  m.mean = s / n;
  m.std = std::sqrt(s2 / n - m.mean * m.mean);
  return m;
}

TEST(Rng, SameSeedSameSequenceAndUniformMoments) {
  Rng a(9), b(9), c(10);
  for (int k = 0; k < 100; ++k) EXPECT_EQ(a.next(), b.next());
  EXPECT_NE(a.next(), c.next());
  Rng r(1);
  const auto m = moments(200000, [&] { return r.uniform(); });
  EXPECT_NEAR(m.mean, 0.5, 0.003);
  EXPECT_NEAR(m.std, std::sqrt(1.0 / 12), 0.002);
  EXPECT_GE(m.min, 0.0);
  EXPECT_LT(m.max, 1.0);
  const auto g = moments(200000, [&] { return r.normal(); });
  EXPECT_NEAR(g.mean, 0.0, 0.01);
  EXPECT_NEAR(g.std, 1.0, 0.01);
}

TEST(SizeDistribution, UniformStaysInRange) {
  Rng r(2);
  const auto d = SizeDistribution::uniform(1e-3, 2e-3);
  const auto m = moments(100000, [&] { return d.sample(r); });
  EXPECT_GE(m.min, 1e-3);
  EXPECT_LE(m.max, 2e-3);
  EXPECT_NEAR(m.mean, 1.5e-3, 1e-5);
}

TEST(SizeDistribution, NormalHasItsMomentsAndIsTruncated) {
  Rng r(3);
  const auto d = SizeDistribution::normal(2e-3, 0.2e-3, 1e-3, 3e-3);  // +-5 sigma: no effect
  const auto m = moments(100000, [&] { return d.sample(r); });
  EXPECT_NEAR(m.mean, 2e-3, 5e-6);
  EXPECT_NEAR(m.std, 0.2e-3, 5e-6);
  const auto t = SizeDistribution::normal(2e-3, 1e-3, 1.5e-3, 2.5e-3);
  const auto mt = moments(20000, [&] { return t.sample(r); });
  EXPECT_GE(mt.min, 1.5e-3);
  EXPECT_LE(mt.max, 2.5e-3);
}

TEST(SizeDistribution, PhiGaussianIsGaussianInPhi) {
  EXPECT_DOUBLE_EQ(phiOfDiameter(1e-3), 0.0);
  EXPECT_DOUBLE_EQ(phiOfDiameter(0.25e-3), 2.0);
  EXPECT_DOUBLE_EQ(diameterOfPhi(-1.0), 2e-3);
  Rng r(4);
  const auto d = SizeDistribution::phiGaussian(1.0, 0.3, 0.05e-3, 5e-3);
  const auto m = moments(100000, [&] { return phiOfDiameter(d.sample(r)); });
  EXPECT_NEAR(m.mean, 1.0, 0.005);
  EXPECT_NEAR(m.std, 0.3, 0.005);
}

TEST(SizeDistribution, ImpossibleSettingsNameTheKey) {
  try {
    SizeDistribution::normal(5e-3, 1e-4, 1e-3, 2e-3).validate();
    FAIL();
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.key(), "d_mean_mm");  // its protocol key
  }
  EXPECT_THROW(SizeDistribution::uniform(2e-3, 1e-3).validate(), InvalidParameter);
  EXPECT_THROW(SizeDistribution::phiGaussian(5.0, 0.1, 1e-3, 2e-3).validate(), InvalidParameter);
}

}  // namespace
}  // namespace rocklab
