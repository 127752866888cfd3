#pragma once
// Small analysis helpers for rig results.

#include <cmath>
#include <vector>

namespace rocklab::rigs {

// Least-squares slope of y over x; NaN with fewer than two distinct x.
inline double slope(const std::vector<double>& x, const std::vector<double>& y) {
  const std::size_t n = x.size();
  if (n < 2) return NAN;
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < n; ++i) mx += x[i] / n, my += y[i] / n;
  double sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
  }
  return sxx > 0 ? sxy / sxx : NAN;
}

// The same over the points [0, end) where take(k) holds; NaN with fewer than 3 of them (two
// points make a line whatever the noise).
template <class Take>
double slopeWhere(const std::vector<double>& x, const std::vector<double>& y, std::size_t end,
                  Take take) {
  std::vector<double> xs, ys;
  for (std::size_t k = 0; k < end && k < x.size(); ++k) {
    if (take(k)) xs.push_back(x[k]), ys.push_back(y[k]);
  }
  return xs.size() >= 3 ? slope(xs, ys) : NAN;
}

}  // namespace rocklab::rigs
