// The multi-level cell grid against brute force, for narrow and wide (10:1) size ranges.

#include <gtest/gtest.h>

#include <set>

#include "lab/core/neighbors.hpp"
#include "lab/core/random.hpp"

namespace rocklab {
namespace {

template <int D>
std::set<std::pair<std::uint32_t, std::uint32_t>> bruteForce(const std::vector<Vec<D>>& x,
                                                             const std::vector<double>& r,
                                                             double skin) {
  std::set<std::pair<std::uint32_t, std::uint32_t>> s;
  for (std::uint32_t i = 0; i < x.size(); ++i) {
    for (std::uint32_t j = i + 1; j < x.size(); ++j) {
      const double reach = r[i] + r[j] + skin;
      if ((x[i] - x[j]).squaredNorm() < reach * reach) s.insert({i, j});
    }
  }
  return s;
}

template <int D>
void checkAgainstBruteForce(double rmin, double rmax, double fraction_large, std::size_t n,
                            int expected_levels_at_least) {
  Rng rng(42);
  std::vector<Vec<D>> x(n);
  std::vector<double> r(n);
  double volume = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    r[i] = rng.uniform() < fraction_large ? rmax : rng.uniform(rmin, 2 * rmin);
    volume += std::pow(2 * r[i], D);
  }
  const double side = std::pow(volume / 0.5, 1.0 / D);  // a dense-ish random cloud
  for (auto& p : x) {
    for (int d = 0; d < D; ++d) p[d] = rng.uniform(0.0, side);
  }
  const double skin = 0.2 * rmin;
  NeighborGrid<D> grid;
  PairRows rows;
  grid.build(x, r, skin, rows);
  EXPECT_GE(grid.levels(), expected_levels_at_least);

  const auto expected = bruteForce<D>(x, r, skin);
  std::set<std::pair<std::uint32_t, std::uint32_t>> found;
  ASSERT_EQ(rows.row.size(), n + 1);
  for (std::uint32_t i = 0; i < n; ++i) {
    for (std::uint32_t p = rows.row[i]; p < rows.row[i + 1]; ++p) {
      const std::uint32_t j = rows.col[p];
      EXPECT_GT(j, i);
      if (p > rows.row[i]) {
        EXPECT_GT(j, rows.col[p - 1]);  // ascending partners
      }
      EXPECT_TRUE(found.insert({i, j}).second) << "pair found twice";
    }
  }
  EXPECT_EQ(found, expected);
}

TEST(NeighborGrid, NarrowSizesOneLevel3D) {
  checkAgainstBruteForce<3>(1e-3, 2e-3, 0.0, 3000, 1);
}
TEST(NeighborGrid, NarrowSizesOneLevel2D) {
  checkAgainstBruteForce<2>(1e-3, 2e-3, 0.0, 3000, 1);
}
TEST(NeighborGrid, SizeRatioTenToOne3D) {
  checkAgainstBruteForce<3>(1e-3, 1e-2, 0.02, 4000, 3);
}
TEST(NeighborGrid, SizeRatioTenToOne2D) {
  checkAgainstBruteForce<2>(1e-3, 1e-2, 0.05, 4000, 3);
}
TEST(NeighborGrid, SizeRatioFiftyToOne3D) {
  checkAgainstBruteForce<3>(1e-3, 5e-2, 0.002, 3000, 4);
}

TEST(NeighborGrid, DegenerateInputs) {
  NeighborGrid<3> grid;
  PairRows rows;
  grid.build({Eigen::Vector3d::Zero()}, {1.0}, 0.1, rows);
  EXPECT_EQ(rows.pairs(), 0u);
  // Particles on a line (zero extent in two axes) and coincident centres.
  std::vector<Eigen::Vector3d> x = {{0, 0, 0}, {0, 0, 0}, {1.5, 0, 0}, {10, 0, 0}};
  grid.build(x, {1.0, 1.0, 1.0, 1.0}, 0.1, rows);
  EXPECT_EQ(rows.pairs(), 3u);  // (0,1), (0,2), (1,2)
}

TEST(NeighborGrid, SpatialOrderIsAPermutation) {
  Rng rng(3);
  std::vector<Eigen::Vector3d> x(500);
  std::vector<double> r(500, 1.0);
  for (auto& p : x) p = {rng.uniform(0, 30), rng.uniform(0, 30), rng.uniform(0, 30)};
  auto order = NeighborGrid<3>::spatialOrder(x, r);
  std::sort(order.begin(), order.end());
  for (std::uint32_t k = 0; k < order.size(); ++k) EXPECT_EQ(order[k], k);
}

}  // namespace
}  // namespace rocklab
