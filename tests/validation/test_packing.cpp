// The packing generator reaches its target porosity, measured independently by Monte Carlo
// sampling of the box (which counts overlaps and parts outside the walls correctly).

#include <gtest/gtest.h>

#include "lab/core/packing.hpp"

namespace rocklab {
namespace {

// Fraction of random points of the box outside every particle, using a cell grid.
template <int D>
double monteCarloPorosity(const Packing<D>& p, int samples, std::uint64_t seed) {
  double rmax = 0;
  for (double r : p.radii) rmax = std::max(rmax, r);
  const double cell = 2 * rmax;
  std::array<int, D> dims;
  for (int d = 0; d < D; ++d) dims[d] = std::max(1, static_cast<int>((p.hi[d] - p.lo[d]) / cell));
  auto index = [&](const std::array<int, D>& c) {
    std::size_t k = c[D - 1];
    for (int d = D - 2; d >= 0; --d) k = k * dims[d] + c[d];
    return k;
  };
  auto cellOf = [&](const Vec<D>& x) {
    std::array<int, D> c;
    for (int d = 0; d < D; ++d) {
      c[d] = std::clamp(static_cast<int>((x[d] - p.lo[d]) / cell), 0, dims[d] - 1);
    }
    return c;
  };
  std::size_t cells = 1;
  for (int d = 0; d < D; ++d) cells *= dims[d];
  std::vector<std::vector<int>> grid(cells);
  for (std::size_t i = 0; i < p.centers.size(); ++i) grid[index(cellOf(p.centers[i]))].push_back(i);
  Rng rng(seed);
  int void_points = 0;
  for (int s = 0; s < samples; ++s) {
    Vec<D> x;
    for (int d = 0; d < D; ++d) x[d] = rng.uniform(p.lo[d], p.hi[d]);
    const auto c = cellOf(x);
    std::array<int, D> lo, hi;
    for (int d = 0; d < D; ++d)
      lo[d] = std::max(0, c[d] - 1), hi[d] = std::min(dims[d] - 1, c[d] + 1);
    bool solid = false;
    std::array<int, D> k = lo;
    for (;;) {
      for (int i : grid[index(k)]) {
        if ((p.centers[i] - x).squaredNorm() < p.radii[i] * p.radii[i]) {
          solid = true;
          break;
        }
      }
      int d = 0;
      while (d < D && ++k[d] > hi[d]) k[d] = lo[d], ++d;
      if (solid || d == D) break;
    }
    void_points += !solid;
  }
  return static_cast<double>(void_points) / samples;
}

template <int D>
void checkTarget(const PackingSpec& spec) {
  PackingReport report;
  const Packing<D> p = generatePacking<D>(spec, &report);
  ASSERT_EQ(p.centers.size(), spec.count);
  EXPECT_NEAR(p.porosity(), spec.porosity, 1e-9);  // the box was sized for it
  // 400k samples: standard error sqrt(n(1-n)/N) < 1e-3.
  const double measured = monteCarloPorosity<D>(p, 400000, 99);
  EXPECT_NEAR(measured, spec.porosity, 0.005) << "max overlap/r " << report.max_overlap;
  EXPECT_LT(report.max_overlap, 0.01);
  for (std::size_t i = 0; i < p.centers.size(); ++i) {
    for (int d = 0; d < D; ++d) {
      EXPECT_GT(p.centers[i][d], p.lo[d]);
      EXPECT_LT(p.centers[i][d], p.hi[d]);
    }
  }
}

TEST(Packing, ReachesTargetPorosity3D) {
  PackingSpec spec;
  spec.count = 1500;
  spec.sizes = SizeDistribution::uniform(1.5e-3, 2.5e-3);
  spec.porosity = 0.42;
  checkTarget<3>(spec);
}

TEST(Packing, ReachesTargetPorosity3DPhiGaussian) {
  PackingSpec spec;
  spec.count = 1500;
  spec.sizes = SizeDistribution::phiGaussian(-1.0, 0.3, 0.8e-3, 5e-3);
  spec.porosity = 0.41;
  spec.seed = 2;
  checkTarget<3>(spec);
}

TEST(Packing, ReachesTargetPorosity2D) {
  PackingSpec spec;
  spec.count = 2000;
  spec.sizes = SizeDistribution::normal(2e-3, 0.3e-3, 1e-3, 3e-3);
  spec.porosity = 0.20;
  spec.aspect = {1.0, 2.0, 1.0};
  checkTarget<2>(spec);
}

TEST(Packing, SeedDecides) {
  PackingSpec spec;
  spec.count = 200;
  spec.sizes = SizeDistribution::uniform(1.5e-3, 2.5e-3);
  spec.porosity = 0.5;
  const auto a = generatePacking<3>(spec), b = generatePacking<3>(spec);
  spec.seed = 2;
  const auto c = generatePacking<3>(spec);
  EXPECT_EQ(a.centers, b.centers);
  EXPECT_NE(a.centers, c.centers);
}

}  // namespace
}  // namespace rocklab
