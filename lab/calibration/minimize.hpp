#pragma once
// Nelder-Mead's simplex search (J. A. Nelder and R. Mead, Computer Journal 7, 1965, with the
// standard coefficients: reflection 1, expansion 2, contraction 1/2, shrink 1/2): a few
// dimensions, no gradients, deterministic. The Gaussian process fits its hyperparameters
// with it and the optimiser refines its acquisition's maximum.

#include <algorithm>
#include <functional>
#include <numeric>
#include <vector>

namespace rocklab::calibration {

struct Minimum {
  std::vector<double> x;
  double f = 0.0;
};

// Minimises f from x0 with a first simplex of steps `step` along each axis, for at most
// `evaluations` calls of f or until the simplex's values agree within `tolerance`.
inline Minimum nelderMead(const std::function<double(const std::vector<double>&)>& f,
                          std::vector<double> x0, double step, int evaluations,
                          double tolerance = 1e-9) {
  const std::size_t n = x0.size();
  std::vector<std::vector<double>> p(n + 1, x0);
  std::vector<double> v(n + 1);
  for (std::size_t k = 0; k < n; ++k) p[k + 1][k] += step;
  int calls = 0;
  for (std::size_t k = 0; k <= n; ++k, ++calls) v[k] = f(p[k]);
  std::vector<std::size_t> order(n + 1);
  auto along = [&](const std::vector<double>& c, const std::vector<double>& w, double t) {
    std::vector<double> x(n);
    for (std::size_t k = 0; k < n; ++k) x[k] = c[k] + t * (w[k] - c[k]);
    return x;
  };
  while (calls < evaluations) {
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::sort(order.begin(), order.end(), [&](auto a, auto b) { return v[a] < v[b]; });
    const std::size_t best = order.front(), worst = order.back(), second = order[n - 1];
    if (v[worst] - v[best] <= tolerance * (1.0 + std::abs(v[best]))) break;
    std::vector<double> c(n, 0.0);  // the centroid of all but the worst
    for (std::size_t k = 0; k <= n; ++k) {
      if (k == worst) continue;
      for (std::size_t j = 0; j < n; ++j) c[j] += p[k][j] / static_cast<double>(n);
    }
    const std::vector<double> r = along(c, p[worst], -1.0);
    const double fr = f(r);
    ++calls;
    if (fr < v[best]) {
      const std::vector<double> e = along(c, p[worst], -2.0);
      const double fe = f(e);
      ++calls;
      if (fe < fr) {
        p[worst] = e, v[worst] = fe;
      } else {
        p[worst] = r, v[worst] = fr;
      }
    } else if (fr < v[second]) {
      p[worst] = r, v[worst] = fr;
    } else {
      const bool outside = fr < v[worst];
      const std::vector<double> k = along(c, outside ? r : p[worst], 0.5);
      const double fk = f(k);
      ++calls;
      if (fk < std::min(fr, v[worst])) {
        p[worst] = k, v[worst] = fk;
      } else {
        for (std::size_t j = 0; j <= n; ++j) {
          if (j == best) continue;
          p[j] = along(p[best], p[j], 0.5);
          v[j] = f(p[j]);
          ++calls;
        }
      }
    }
  }
  const auto at = static_cast<std::size_t>(std::min_element(v.begin(), v.end()) - v.begin());
  return {p[at], v[at]};
}

}  // namespace rocklab::calibration
