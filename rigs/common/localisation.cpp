#include "rigs/common/localisation.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <unordered_map>

namespace rocklab::rigs {

namespace {

struct Trial {
  std::size_t count = 0;
  double offset = 0.0;
  double density = 0.0;       // count over what a uniform cloud puts in the window
  double significance = 0.0;  // the excess over it in Poisson standard deviations
};

// The share of a uniform cloud filling a box whose projection on a direction spans the
// lengths `a` (|n_d| times the side, d < dims) below `t`, measured from the projection's
// low end: the distribution of a sum of independent uniform variables on [0, a_d],
// F(t) = sum over subsets S of (-1)^|S| (t - sum_S a_d)_+^k / (k! prod a_d) with k the
// non-zero lengths (the Irwin-Hall formula, extended to unequal widths). A length below
// 1e-3 of the longest counts as zero: the formula cancels badly there, and such a side
// moves the window's share by less than 1e-3 of its width.
double uniformShareBelow(const std::array<double, 3>& a, int dims, double t) {
  std::array<double, 3> len{};
  int k = 0;
  double longest = 0.0;
  for (int d = 0; d < dims; ++d) longest = std::max(longest, a[d]);
  for (int d = 0; d < dims; ++d) {
    if (a[d] > 1e-3 * longest) len[k++] = a[d];
  }
  if (k == 0) return t >= 0.0 ? 1.0 : 0.0;
  double sum = 0.0, norm = 1.0;
  for (int d = 0; d < k; ++d) norm *= len[d] * (d + 1);
  for (int subset = 0; subset < (1 << k); ++subset) {
    double shift = 0.0;
    int size = 0;
    for (int d = 0; d < k; ++d) {
      if (subset & (1 << d)) shift += len[d], ++size;
    }
    const double r = t - shift;
    if (r > 0.0) sum += (size % 2 ? -1.0 : 1.0) * std::pow(r, k);
  }
  return std::clamp(sum / norm, 0.0, 1.0);
}

// The window of `width` along the sorted projections `rho` where the points stand out most
// from a uniform cloud in the box from `lo` to `hi`, along the direction `n`: the largest
// excess over the uniform count in Poisson standard deviations (a scan statistic). The
// ratio alone favours short windows, whose counts scatter more: on the quick shear-band
// sample a noisy window across the axis beat the inclined band. Windows whose section
// through the box is smaller than the box's smallest cross-section (they clip a corner or
// leave the box) are not considered: a band crosses the sample.
Trial mostSignificantWindow(std::vector<double>& rho, double width, const std::array<double, 3>& n,
                            const std::array<double, 3>& lo, const std::array<double, 3>& hi,
                            int dims) {
  std::sort(rho.begin(), rho.end());
  std::array<double, 3> a{};
  double start = 0.0, longest_side = 0.0;
  for (int d = 0; d < dims; ++d) {
    a[d] = std::abs(n[d]) * (hi[d] - lo[d]);
    start += std::min(n[d] * lo[d], n[d] * hi[d]);
    longest_side = std::max(longest_side, hi[d] - lo[d]);
  }
  const double points = static_cast<double>(rho.size());
  // The box's smallest cross-section holds width / longest side of a uniform cloud.
  const double least = 0.999 * points * width / longest_side;
  Trial best;
  std::size_t first = 0;
  for (std::size_t last = 0; last < rho.size(); ++last) {
    // The window [rho[last] - width, rho[last]]: a densest one has a point at its edge.
    while (rho[last] - rho[first] > width) ++first;
    const double top = rho[last] - start;
    const double expected =
        points * (uniformShareBelow(a, dims, top) - uniformShareBelow(a, dims, top - width));
    if (expected < least) continue;
    const std::size_t count = last - first + 1;
    const double excess = (static_cast<double>(count) - expected) / std::sqrt(expected);
    if (excess > best.significance) {
      best = Trial{count, rho[last] - 0.5 * width, static_cast<double>(count) / expected, excess};
    }
  }
  return best;
}

std::vector<std::array<double, 3>> directions(int dimension) {
  std::vector<std::array<double, 3>> out;
  if (dimension == 2) {
    for (int k = 0; k < 720; ++k) {
      const double a = std::numbers::pi * k / 720.0;
      out.push_back({std::cos(a), std::sin(a), 0.0});
    }
  } else {
    // A Fibonacci lattice on the upper half sphere: a plane and its flip are one.
    const int n = 20000;
    const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
    for (int k = 0; k < n; ++k) {
      const double z = 1.0 - (k + 0.5) / n;
      const double r = std::sqrt(1.0 - z * z), a = golden * k;
      out.push_back({r * std::cos(a), r * std::sin(a), z});
    }
  }
  return out;
}

}  // namespace

Band findBand(const std::vector<std::array<double, 3>>& points, int dimension, int axial,
              double width) {
  if (points.size() < 10) throw std::invalid_argument("band detection needs at least 10 points");
  if (!(width > 0.0)) throw std::invalid_argument("band width must be positive");
  const int dims = dimension;
  auto project = [&](const std::array<double, 3>& p, const std::array<double, 3>& n) {
    double s = 0.0;
    for (int d = 0; d < dims; ++d) s += p[d] * n[d];
    return s;
  };
  // The sample's box: the points' bounding box.
  std::array<double, 3> lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (const auto& p : points) {
    for (int d = 0; d < dims; ++d) lo[d] = std::min(lo[d], p[d]), hi[d] = std::max(hi[d], p[d]);
  }
  Band best;
  double significance = 0.0;
  std::vector<double> rho(points.size());
  for (const auto& n : directions(dimension)) {
    for (std::size_t i = 0; i < points.size(); ++i) rho[i] = project(points[i], n);
    const Trial t = mostSignificantWindow(rho, width, n, lo, hi, dims);
    if (t.significance > significance) {
      significance = t.significance;
      best.contrast = t.density;
      best.points = t.count;
      best.offset = t.offset;
      best.normal = n;
    }
  }
  if (best.points == 0) throw std::invalid_argument("band detection: the points span no area");
  // Angle between the band and the sigma_1 axis: a band along the axis has its normal
  // across it (0 degrees), a band across the axis has its normal along it (90 degrees).
  best.angle_to_axial_deg =
      std::asin(std::min(1.0, std::abs(best.normal[axial]))) * 180.0 / std::numbers::pi;
  // Thickness from the points near the band (within one width of its centre).
  double sum = 0.0, sum2 = 0.0;
  std::size_t near = 0;
  for (const auto& p : points) {
    const double d = project(p, best.normal) - best.offset;
    if (std::abs(d) > width) continue;
    sum += d, sum2 += d * d, ++near;
  }
  const double mean = sum / near, var = std::max(0.0, sum2 / near - mean * mean);
  best.thickness = std::sqrt(12.0 * var);  // the width of a uniform band of that spread
  return best;
}

namespace {

// The neighbours of each point within `reach`: a hash grid of cells `reach` wide.
std::vector<std::vector<std::size_t>> neighbours(const std::vector<std::array<double, 3>>& x,
                                                 int dimension, double reach) {
  auto cell = [&](const std::array<double, 3>& p, int d) {
    return static_cast<std::int64_t>(std::floor(p[d] / reach));
  };
  auto key = [](std::int64_t a, std::int64_t b, std::int64_t c) {
    return (a * 73856093) ^ (b * 19349663) ^ (c * 83492791);
  };
  std::unordered_multimap<std::int64_t, std::size_t> grid;
  grid.reserve(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    grid.emplace(key(cell(x[i], 0), cell(x[i], 1), dimension == 3 ? cell(x[i], 2) : 0), i);
  }
  std::vector<std::vector<std::size_t>> out(x.size());
  const int dz = dimension == 3 ? 1 : 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const std::int64_t cx = cell(x[i], 0), cy = cell(x[i], 1),
                       cz = dimension == 3 ? cell(x[i], 2) : 0;
    for (int a = -1; a <= 1; ++a) {
      for (int b = -1; b <= 1; ++b) {
        for (int c = -dz; c <= dz; ++c) {
          const auto [lo, hi] = grid.equal_range(key(cx + a, cy + b, cz + c));
          for (auto it = lo; it != hi; ++it) {
            const std::size_t j = it->second;
            if (j == i) continue;
            double d2 = 0.0;
            for (int d = 0; d < dimension; ++d) d2 += (x[j][d] - x[i][d]) * (x[j][d] - x[i][d]);
            if (d2 <= reach * reach) out[i].push_back(j);
          }
        }
      }
    }
    // Hash collisions may list a point twice.
    std::sort(out[i].begin(), out[i].end());
    out[i].erase(std::unique(out[i].begin(), out[i].end()), out[i].end());
  }
  return out;
}

}  // namespace

std::vector<LocalStrain> localStrain(const std::vector<std::array<double, 3>>& before,
                                     const std::vector<std::array<double, 3>>& after, int dimension,
                                     double reach) {
  if (before.size() != after.size()) {
    throw std::invalid_argument("local strain: the two states hold different particles");
  }
  const int D = dimension;
  const auto near = neighbours(before, D, reach);
  std::vector<LocalStrain> out(before.size());
  for (std::size_t i = 0; i < before.size(); ++i) {
    if (near[i].size() < static_cast<std::size_t>(D + 1)) continue;
    // F = (sum du dx^T)(sum dx dx^T)^-1 over the neighbours (least squares).
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero(), B = Eigen::Matrix3d::Zero();
    for (std::size_t j : near[i]) {
      Eigen::Vector3d dx = Eigen::Vector3d::Zero(), du = Eigen::Vector3d::Zero();
      for (int d = 0; d < D; ++d) {
        dx[d] = before[j][d] - before[i][d];
        du[d] = (after[j][d] - after[i][d]) - dx[d];
      }
      A += du * dx.transpose();
      B += dx * dx.transpose();
    }
    const Eigen::MatrixXd Bd = B.topLeftCorner(D, D);
    Eigen::FullPivLU<Eigen::MatrixXd> lu(Bd);
    if (!lu.isInvertible()) continue;  // neighbours on a line (plane): no gradient
    const Eigen::MatrixXd F = A.topLeftCorner(D, D) * lu.inverse();
    const Eigen::MatrixXd e = 0.5 * (F + F.transpose());
    const double trace = e.trace();
    out[i].compaction = -trace;
    out[i].shear = (e - trace / D * Eigen::MatrixXd::Identity(D, D)).norm();
  }
  return out;
}

std::vector<std::array<double, 3>> strainedParticles(
    const std::vector<std::array<double, 3>>& before,
    const std::vector<std::array<double, 3>>& after, int dimension, double reach, double fraction,
    StrainPart part) {
  const std::vector<LocalStrain> strain = localStrain(before, after, dimension, reach);
  // Particles within `reach` of the sample's faces have one-sided neighbourhoods and follow
  // the platens and walls: they are left out (NaN), as are those not measured.
  std::array<double, 3> lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (const auto& x : before) {
    for (int d = 0; d < dimension; ++d) {
      lo[d] = std::min(lo[d], x[d]), hi[d] = std::max(hi[d], x[d]);
    }
  }
  std::vector<double> e(strain.size(), NAN), ranked;
  for (std::size_t i = 0; i < e.size(); ++i) {
    bool inside = strain[i].shear > 0.0 || strain[i].compaction != 0.0;
    for (int d = 0; d < dimension; ++d) {
      if (before[i][d] < lo[d] + reach || before[i][d] > hi[d] - reach) inside = false;
    }
    if (!inside) continue;
    e[i] = part == StrainPart::Shear ? strain[i].shear : strain[i].compaction;
    ranked.push_back(e[i]);
  }
  const auto k = static_cast<std::size_t>((1.0 - fraction) * static_cast<double>(ranked.size()));
  if (ranked.empty() || k >= ranked.size()) return {};
  std::nth_element(ranked.begin(), ranked.begin() + k, ranked.end());
  const double threshold = ranked[k];
  std::vector<std::array<double, 3>> out;
  for (std::size_t i = 0; i < e.size(); ++i) {
    if (e[i] >= threshold && e[i] > 0.0) out.push_back(before[i]);  // NaN compares false
  }
  return out;
}

}  // namespace rocklab::rigs
