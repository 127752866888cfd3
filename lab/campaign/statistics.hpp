#pragma once
// An ensemble's statistics: what a key result is over the seeds of one campaign point.

#include <cstddef>
#include <vector>

namespace rocklab::campaign {

// The 97.5% quantile of Student's t distribution with `df` degrees of freedom (df >= 1): the
// half-width factor of a two-sided 95% confidence interval.
double studentT975(std::size_t df);

struct Summary {
  std::size_t n = 0;
  double mean = 0.0;
  double std = 0.0;  // sample standard deviation (n - 1); 0 for one value
  // 95% confidence interval of the mean, mean -+ t(0.975, n - 1) std / sqrt(n); NaN for n < 2.
  double low = 0.0, high = 0.0;
};

Summary summarize(const std::vector<double>& values);

}  // namespace rocklab::campaign
