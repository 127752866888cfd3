#pragma once
// The calibration's optimisers on the unit cube (each free parameter scaled to its bounds,
// linearly or logarithmically: lab/calibration/calibration.hpp). Every target's seed mean is
// measured as an error in tolerances, e = (mean - value) / tolerance, with the variance of
// that mean over its seeds; a point is within tolerance when every |e| <= 1, and the misfit
// sum e^2 is what the optimisers minimise.
//
// - Bayesian optimisation: one Gaussian process per target (the targets' errors are
//   modelled apart and combined, a "composite" objective: B. Astudillo and P. Frazier, ICML
//   2019), batches chosen one point at a time by the expected improvement of the misfit,
//   each chosen point believed at its predicted value for the next (the kriging believer:
//   D. Ginsbourger et al., 2010).
// - The baseline: a Latin hypercube over the whole budget.
// Everything is deterministic: the same evaluations give the same proposals on any machine.

#include <cstdint>
#include <vector>

#include "lab/calibration/gaussian_process.hpp"

namespace rocklab::calibration {

// splitmix64 (S. Vigna) with Box-Muller normals: the same numbers from every standard library.
class Random {
 public:
  explicit Random(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next();
  double uniform();  // in [0, 1)
  double normal();

 private:
  std::uint64_t state_;
};

// The k-th point (k >= 1) of the Halton sequence in d <= 10 dimensions.
Point halton(std::uint64_t k, std::size_t d);

// n points, one in each of n slices of every axis (M. D. McKay, R. J. Beckman and W. J.
// Conover, Technometrics 21, 1979): of `tries` draws, the one whose closest two points are
// farthest apart.
std::vector<Point> latinHypercube(int n, std::size_t d, std::uint64_t seed, int tries = 64);

// One evaluation: where, and each target's error and its seed mean's variance, in tolerances.
struct Evaluated {
  Point u;
  std::vector<double> error, variance;
};

double misfit(const std::vector<double>& error);
bool withinTolerance(const std::vector<double>& error);

class Surrogate {
 public:
  explicit Surrogate(const std::vector<Evaluated>& done);
  std::size_t targets() const { return gp_.size(); }
  std::size_t dimensions() const { return d_; }
  std::vector<Prediction> predict(const Point& u) const;
  double meanMisfit(const Point& u) const;  // sum of the predicted errors squared
  // The chance that every target's error is within [-1, 1], the targets independent.
  double probabilityWithin(const Point& u) const;
  // E[max(0, best - misfit(u))] over the targets' posteriors, by Monte Carlo with draws
  // fixed once (the same for every point, so that points compare without noise).
  double expectedImprovement(const Point& u, double best) const;
  // Adds u to every target's data at its predicted error (the kriging believer).
  void believe(const Point& u);
  const GaussianProcess& process(std::size_t target) const { return gp_[target]; }

 private:
  std::size_t d_;
  std::vector<GaussianProcess> gp_;
  std::vector<std::vector<Point>> x_;
  std::vector<std::vector<double>> y_, noise_;
  std::vector<std::vector<double>> draws_;  // [draw][target]
};

// The next q points of a Bayesian optimisation after `done` (at least 2 evaluated), none
// closer than 0.01 of the cube to a point evaluated or chosen.
std::vector<Point> proposeBatch(const std::vector<Evaluated>& done, int q, std::uint64_t seed);

// Whether the targets can be met together inside the bounds, as the surrogates see them.
struct Reach {
  double probability = 0.0;  // the best chance over the cube that every target is within
  Point closest;             // where the predicted misfit is least
  std::vector<Prediction> at_closest;
};
Reach assessReach(const Surrogate& s, const std::vector<Evaluated>& done);

// What the surrogates say of each parameter among the points within tolerance: the mean and
// standard deviation weighted by the chance of being within, and the range of the points
// more likely within than not (`any` false: none is).
struct Spread {
  double mean = 0.0, std = 0.0, low = 0.0, high = 0.0;
  bool any = false;
};
std::vector<Spread> parameterSpread(const Surrogate& s);

// [target][parameter]: the share of the variance of a target's predicted error over the
// cube that a parameter alone explains (its first-order Sobol index, I. M. Sobol 1993, of
// the surrogate's mean).
std::vector<std::vector<double>> sensitivity(const Surrogate& s);

}  // namespace rocklab::calibration
