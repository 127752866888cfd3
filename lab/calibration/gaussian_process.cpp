#include "lab/calibration/gaussian_process.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "lab/calibration/minimize.hpp"

namespace rocklab::calibration {

namespace {

constexpr double kPi = 3.14159265358979323846;

// The hyperparameters' box, in y's standard deviation and the unit cube: lengths from a
// thirtieth of a bound's range (finer is not resolved by a few dozen evaluations) to ten
// ranges (flat), a nugget at most y's whole variance.
constexpr double kSignalLow = 0.05, kSignalHigh = 20.0;
constexpr double kLengthLow = 0.03, kLengthHigh = 10.0;
constexpr double kNuggetLow = 1e-8, kNuggetHigh = 1.0;

}  // namespace

double GaussianProcess::kernel(const Point& a, const Point& b) const {
  double r2 = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    const double d = (a[k] - b[k]) / h_.length[k];
    r2 += d * d;
  }
  // Matern 5/2 (R&W eq. 4.17): twice differentiable, rougher than the squared exponential,
  // as responses that break bonds are.
  const double s5r = std::sqrt(5.0 * r2);
  return h_.signal * h_.signal * (1.0 + s5r + 5.0 * r2 / 3.0) * std::exp(-s5r);
}

bool GaussianProcess::factor() {
  const auto n = static_cast<Eigen::Index>(x_.size());
  Eigen::MatrixXd K(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j <= i; ++j) {
      K(i, j) = K(j, i) = kernel(x_[static_cast<std::size_t>(i)], x_[static_cast<std::size_t>(j)]);
    }
    K(i, i) += noise_(i) + h_.nugget;
  }
  llt_.compute(K);
  if (llt_.info() != Eigen::Success) return false;
  const Eigen::VectorXd r = y_.array() - mean_;
  alpha_ = llt_.solve(r);
  // R&W eq. 2.30 with the Cholesky factor: -r'K^-1 r / 2 - sum log L_ii - n log(2 pi) / 2.
  const Eigen::MatrixXd& L = llt_.matrixLLT();
  log_ml_ = -0.5 * r.dot(alpha_) - L.diagonal().array().log().sum() -
            0.5 * static_cast<double>(n) * std::log(2.0 * kPi);
  return std::isfinite(log_ml_);
}

void GaussianProcess::condition(const std::vector<Point>& x, const std::vector<double>& y,
                                const std::vector<double>& noise, const Hyperparameters& h) {
  x_ = x;
  y_ = Eigen::Map<const Eigen::VectorXd>(y.data(), static_cast<Eigen::Index>(y.size()));
  noise_ = Eigen::Map<const Eigen::VectorXd>(noise.data(), static_cast<Eigen::Index>(noise.size()));
  mean_ = y_.mean();
  h_ = h;
  if (!factor()) {  // a jitter that makes it positive definite, at worst y's variance
    for (double jitter = 1e-10; jitter < 1e6 && !factor(); jitter *= 10.0) h_.nugget += jitter;
  }
}

void GaussianProcess::fit(const std::vector<Point>& x, const std::vector<double>& y,
                          const std::vector<double>& noise) {
  const std::size_t d = x.front().size();
  const double n = static_cast<double>(y.size());
  const double mean = std::accumulate(y.begin(), y.end(), 0.0) / n;
  double var = 0.0;
  for (double v : y) var += (v - mean) * (v - mean);
  var = y.size() > 1 ? var / (n - 1.0) : 0.0;
  const double mean_noise = std::accumulate(noise.begin(), noise.end(), 0.0) / n;
  // y's spread sets the scale; a flat y (or one point) falls back on its noise or on 1.
  const double sy = std::sqrt(std::max({var, mean_noise, 1e-12}));
  Hyperparameters h{sy, std::vector<double>(d, 0.5), 1e-4 * sy * sy};
  if (y.size() < 3) {
    condition(x, y, noise, h);
    return;
  }
  // theta = log(signal / sy), log(length_k), log(nugget / sy^2): each clamped to its box,
  // with a penalty outside it so the simplex comes back.
  const std::vector<double> lo = [&] {
    std::vector<double> v{std::log(kSignalLow)};
    v.insert(v.end(), d, std::log(kLengthLow));
    v.push_back(std::log(kNuggetLow));
    return v;
  }();
  const std::vector<double> hi = [&] {
    std::vector<double> v{std::log(kSignalHigh)};
    v.insert(v.end(), d, std::log(kLengthHigh));
    v.push_back(std::log(kNuggetHigh));
    return v;
  }();
  auto unpack = [&](const std::vector<double>& t, double& penalty) {
    Hyperparameters u{sy, std::vector<double>(d), 0.0};
    penalty = 0.0;
    std::vector<double> c(t.size());
    for (std::size_t k = 0; k < t.size(); ++k) {
      c[k] = std::clamp(t[k], lo[k], hi[k]);
      penalty += (t[k] - c[k]) * (t[k] - c[k]);
    }
    u.signal = sy * std::exp(c[0]);
    for (std::size_t k = 0; k < d; ++k) u.length[k] = std::exp(c[k + 1]);
    u.nugget = sy * sy * std::exp(c[d + 1]);
    return u;
  };
  auto objective = [&](const std::vector<double>& t) {
    double penalty = 0.0;
    const Hyperparameters u = unpack(t, penalty);
    x_ = x;
    y_ = Eigen::Map<const Eigen::VectorXd>(y.data(), static_cast<Eigen::Index>(y.size()));
    noise_ =
        Eigen::Map<const Eigen::VectorXd>(noise.data(), static_cast<Eigen::Index>(noise.size()));
    mean_ = mean;
    h_ = u;
    if (!factor()) return 1e30;
    return -log_ml_ + 1e3 * penalty;
  };
  // Starts from short, middling and long lengths: the likelihood has local optima (a
  // wiggly fit through every point against a smooth one through their trend).
  Minimum best{{}, 1e300};
  for (double length : {0.15, 0.5, 2.0}) {
    std::vector<double> t0{0.0};
    t0.insert(t0.end(), d, std::log(length));
    t0.push_back(std::log(1e-3));
    const Minimum m = nelderMead(objective, t0, 0.7, 120 * static_cast<int>(d + 2));
    if (m.f < best.f) best = m;
  }
  double penalty = 0.0;
  condition(x, y, noise, unpack(best.x, penalty));
}

Prediction GaussianProcess::predict(const Point& u) const {
  const auto n = static_cast<Eigen::Index>(x_.size());
  Eigen::VectorXd k(n);
  for (Eigen::Index i = 0; i < n; ++i) k(i) = kernel(u, x_[static_cast<std::size_t>(i)]);
  const Eigen::VectorXd v = llt_.matrixL().solve(k);
  // R&W eqs. 2.25-2.26.
  return {mean_ + k.dot(alpha_), std::max(0.0, h_.signal * h_.signal - v.squaredNorm())};
}

}  // namespace rocklab::calibration
