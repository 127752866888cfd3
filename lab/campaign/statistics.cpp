#include "lab/campaign/statistics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace rocklab::campaign {

namespace {

// The continued fraction of the regularized incomplete beta function I_x(a, b), evaluated
// by the modified Lentz method (DLMF 8.17.22; Press et al., Numerical Recipes, 6.4).
double betaFraction(double a, double b, double x) {
  constexpr double tiny = 1e-300;
  double c = 1.0, d = 1.0 - (a + b) * x / (a + 1.0);
  if (std::abs(d) < tiny) d = tiny;
  d = 1.0 / d;
  double f = d;
  for (int m = 1; m <= 10000; ++m) {
    // The even and the odd term of the fraction for this m.
    const double even = m * (b - m) * x / ((a + 2.0 * m - 1.0) * (a + 2.0 * m));
    const double odd = -(a + m) * (a + b + m) * x / ((a + 2.0 * m) * (a + 2.0 * m + 1.0));
    for (double term : {even, odd}) {
      d = 1.0 + term * d;
      if (std::abs(d) < tiny) d = tiny;
      c = 1.0 + term / c;
      if (std::abs(c) < tiny) c = tiny;
      d = 1.0 / d;
      f *= c * d;
    }
    if (std::abs(c * d - 1.0) < 1e-15) return f;
  }
  return f;
}

double regularizedBeta(double a, double b, double x) {
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 1.0;
  const double front = std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) +
                                a * std::log(x) + b * std::log1p(-x));
  // The fraction converges fast on the side of the mean; the symmetry I_x(a,b) = 1 -
  // I_{1-x}(b,a) gives the other.
  if (x < (a + 1.0) / (a + b + 2.0)) return front * betaFraction(a, b, x) / a;
  return 1.0 - front * betaFraction(b, a, 1.0 - x) / b;
}

// P(T <= t) for t >= 0 with df degrees of freedom: 1 - I_{df/(df+t^2)}(df/2, 1/2) / 2.
double studentCdf(double t, double df) {
  return 1.0 - 0.5 * regularizedBeta(df / 2.0, 0.5, df / (df + t * t));
}

}  // namespace

double studentT(double p, double df) {
  if (!(df >= 1.0)) throw std::invalid_argument("Student's t needs at least one degree of freedom");
  if (!(p >= 0.5 && p < 1.0)) throw std::invalid_argument("a quantile in [0.5, 1) of Student's t");
  // Bisection on the CDF: it rises monotonically, and t(p) of one degree of freedom,
  // tan(pi (p - 1/2)), bounds the others'.
  double lo = 0.0, hi = std::tan(std::numbers::pi * (p - 0.5)) + 1.0;
  for (int k = 0; k < 400 && hi - lo > 1e-13 * hi; ++k) {
    const double mid = 0.5 * (lo + hi);
    (studentCdf(mid, df) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double studentT975(double df) {
  return studentT(0.975, df);
}

Summary summarize(const std::vector<double>& values) {
  Summary s;
  s.n = values.size();
  if (s.n == 0) {
    s.mean = s.std = s.low = s.high = std::numeric_limits<double>::quiet_NaN();
    return s;
  }
  for (double v : values) s.mean += v;
  s.mean /= static_cast<double>(s.n);
  if (s.n < 2) {
    s.low = s.high = std::numeric_limits<double>::quiet_NaN();
    return s;
  }
  double ss = 0.0;
  for (double v : values) ss += (v - s.mean) * (v - s.mean);
  s.std = std::sqrt(ss / static_cast<double>(s.n - 1));
  const double half =
      studentT975(static_cast<double>(s.n - 1)) * s.std / std::sqrt(static_cast<double>(s.n));
  s.low = s.mean - half;
  s.high = s.mean + half;
  return s;
}

Difference compareMeans(const Summary& a, const Summary& b) {
  Difference d;
  d.delta = b.mean - a.mean;
  if (a.n < 2 || b.n < 2) return d;
  d.known = true;
  const double va = a.std * a.std / static_cast<double>(a.n);
  const double vb = b.std * b.std / static_cast<double>(b.n);
  if (va + vb == 0.0) return d;  // no scatter at all: any difference is resolved
  const double df =
      (va + vb) * (va + vb) /
      (va * va / static_cast<double>(a.n - 1) + vb * vb / static_cast<double>(b.n - 1));
  d.half = studentT975(std::max(df, 1.0)) * std::sqrt(va + vb);
  return d;
}

Proportion proportion(std::size_t k, std::size_t n) {
  if (n == 0 || k > n) throw std::invalid_argument("proportion: k of n with 0 <= k <= n, n > 0");
  const double z = 1.959963984540054;  // the normal's 97.5% quantile
  const double p = static_cast<double>(k) / n, m = static_cast<double>(n), zz = z * z / m;
  const double centre = (p + 0.5 * zz) / (1.0 + zz);
  const double half = z / (1.0 + zz) * std::sqrt(p * (1.0 - p) / m + 0.25 * zz / m);
  return {k, n, p, std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

}  // namespace rocklab::campaign
