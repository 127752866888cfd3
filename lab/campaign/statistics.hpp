#pragma once
// An ensemble's statistics: what a key result is over the seeds of one campaign point.

#include <cmath>
#include <cstddef>
#include <vector>

namespace rocklab::campaign {

// The p quantile (0.5 <= p < 1) of Student's t distribution with `df` degrees of freedom
// (df >= 1, not necessarily whole: Welch's are not).
double studentT(double p, double df);
// Its 97.5% quantile: the half-width factor of a two-sided 95% interval.
double studentT975(double df);

struct Summary {
  std::size_t n = 0;
  double mean = 0.0;
  double std = 0.0;  // sample standard deviation (n - 1); 0 for one value
  // 95% confidence interval of the mean, mean -+ t(0.975, n - 1) std / sqrt(n); NaN for n < 2.
  double low = 0.0, high = 0.0;
};

Summary summarize(const std::vector<double>& values);

// A fraction of seeds (k of n samples showed something) with its 95% Wilson score interval
// (E. B. Wilson, JASA 22, 1927; method 3 of R. G. Newcombe, Statistics in Medicine 17, 1998,
// which stays inside [0, 1] and keeps its coverage at 0 of 5 or 5 of 5). n > 0.
struct Proportion {
  std::size_t k = 0, n = 0;
  double fraction = 0.0, low = 0.0, high = 0.0;
};

Proportion proportion(std::size_t k, std::size_t n);

// Two ensembles' means compared: b.mean - a.mean with the half-width of Welch's 95% interval
// of that difference (B. L. Welch, Biometrika 34, 1947: t at the Welch-Satterthwaite degrees
// of freedom). A difference inside its interval is not resolved by the seeds: the two could
// be one material. Needs two values in each (`known` false otherwise).
struct Difference {
  double delta = 0.0, half = 0.0;
  bool known = false;
  bool resolved() const { return known && std::abs(delta) > half; }
};

Difference compareMeans(const Summary& a, const Summary& b);

}  // namespace rocklab::campaign
