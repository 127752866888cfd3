#include "rigs/common/localisation.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace rocklab::rigs {

namespace {

struct Trial {
  std::size_t count = 0;
  double offset = 0.0;
};

// The window of `width` along the sorted projections holding the most points.
Trial densestWindow(std::vector<double>& rho, double width) {
  std::sort(rho.begin(), rho.end());
  Trial best;
  std::size_t lo = 0;
  for (std::size_t hi = 0; hi < rho.size(); ++hi) {
    while (rho[hi] - rho[lo] > width) ++lo;
    const std::size_t n = hi - lo + 1;
    if (n > best.count) {
      best.count = n;
      best.offset = 0.5 * (rho[hi] + rho[lo]);
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
  Band best;
  std::vector<double> rho(points.size());
  for (const auto& n : directions(dimension)) {
    for (std::size_t i = 0; i < points.size(); ++i) rho[i] = project(points[i], n);
    const Trial t = densestWindow(rho, width);
    if (t.count > best.points) {
      best.points = t.count;
      best.offset = t.offset;
      best.normal = n;
    }
  }
  // Angle between the band and the sigma_1 axis: a band along the axis has its normal
  // across it (0 degrees), a band across the axis has its normal along it (90 degrees).
  best.angle_to_axial_deg =
      std::asin(std::min(1.0, std::abs(best.normal[axial]))) * 180.0 / std::numbers::pi;
  // Thickness and contrast from the points near the band (within two widths).
  double sum = 0.0, sum2 = 0.0;
  std::size_t near = 0;
  for (const auto& p : points) {
    const double d = project(p, best.normal) - best.offset;
    if (std::abs(d) > width) continue;
    sum += d, sum2 += d * d, ++near;
  }
  const double mean = sum / near, var = std::max(0.0, sum2 / near - mean * mean);
  best.thickness = std::sqrt(12.0 * var);  // the width of a uniform band of that spread
  // Contrast: against the median count of windows placed along the central half of the
  // cloud across the band (robust to the band itself; about 1.3 for uniform damage, the
  // best of many noisy windows).
  for (std::size_t i = 0; i < points.size(); ++i) rho[i] = project(points[i], best.normal);
  std::sort(rho.begin(), rho.end());
  const double span = rho.back() - rho.front();
  std::vector<double> counts;
  for (int k = 0; k <= 20; ++k) {
    const double c = rho.front() + span * (0.25 + 0.5 * k / 20.0);
    const auto lo = std::lower_bound(rho.begin(), rho.end(), c - 0.5 * width);
    const auto hi = std::upper_bound(rho.begin(), rho.end(), c + 0.5 * width);
    counts.push_back(static_cast<double>(hi - lo));
  }
  std::nth_element(counts.begin(), counts.begin() + 10, counts.end());
  best.contrast = static_cast<double>(best.points) / std::max(1.0, counts[10]);
  return best;
}

}  // namespace rocklab::rigs
