#include "lab/calibration/optimizer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "lab/calibration/minimize.hpp"

namespace rocklab::calibration {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kDraws = 64;               // Monte Carlo draws of the expected improvement
constexpr double kMinSeparation = 0.01;  // no point proposed closer to another (unit cube)

double distance2(const Point& a, const Point& b) {
  double s = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) s += (a[k] - b[k]) * (a[k] - b[k]);
  return s;
}

Point clamped(Point u) {
  for (double& x : u) x = std::clamp(x, 0.0, 1.0);
  return u;
}

double normalCdf(double z) {
  return 0.5 * std::erfc(-z / std::sqrt(2.0));
}

// The points the acquisition is scanned on: a Halton set, from `start` on, and clouds around
// the given centres at two scales.
std::vector<Point> candidates(std::size_t d, std::uint64_t start, const std::vector<Point>& centres,
                              Random& rng) {
  std::vector<Point> c;
  const std::size_t n = std::min<std::size_t>(2048, 256 * d);
  for (std::size_t k = 0; k < n; ++k) c.push_back(halton(start + k, d));
  for (const Point& centre : centres) {
    for (double scale : {0.02, 0.08}) {
      for (int k = 0; k < 64; ++k) {
        Point u = centre;
        for (double& x : u) x += scale * rng.normal();
        c.push_back(clamped(u));
      }
    }
  }
  return c;
}

// The evaluated points with the least predicted misfit, at most `count`.
std::vector<Point> bestEvaluated(const Surrogate& s, const std::vector<Evaluated>& done,
                                 std::size_t count) {
  std::vector<std::pair<double, std::size_t>> order;
  for (std::size_t k = 0; k < done.size(); ++k) order.emplace_back(s.meanMisfit(done[k].u), k);
  std::sort(order.begin(), order.end());
  std::vector<Point> out;
  for (std::size_t k = 0; k < std::min(count, order.size()); ++k) {
    out.push_back(done[order[k].second].u);
  }
  return out;
}

}  // namespace

std::uint64_t Random::next() {
  std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

double Random::uniform() {
  return static_cast<double>(next() >> 11) * 0x1.0p-53;
}

double Random::normal() {
  const double u1 = 1.0 - uniform(), u2 = uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
}

Point halton(std::uint64_t k, std::size_t d) {
  static constexpr std::uint64_t kPrimes[] = {2, 3, 5, 7, 11, 13, 17, 19, 23, 29};
  if (d > std::size(kPrimes)) throw std::invalid_argument("halton: at most 10 dimensions");
  Point u(d);
  for (std::size_t j = 0; j < d; ++j) {
    double f = 1.0, r = 0.0;
    for (std::uint64_t i = k; i > 0; i /= kPrimes[j]) {
      f /= static_cast<double>(kPrimes[j]);
      r += f * static_cast<double>(i % kPrimes[j]);
    }
    u[j] = r;
  }
  return u;
}

std::vector<Point> latinHypercube(int n, std::size_t d, std::uint64_t seed, int tries) {
  Random rng(seed);
  std::vector<Point> best;
  double best_gap = -1.0;
  for (int t = 0; t < tries; ++t) {
    std::vector<Point> p(static_cast<std::size_t>(n), Point(d));
    for (std::size_t j = 0; j < d; ++j) {
      std::vector<int> slice(static_cast<std::size_t>(n));
      std::iota(slice.begin(), slice.end(), 0);
      for (std::size_t k = slice.size(); k > 1; --k) {  // Fisher-Yates
        std::swap(slice[k - 1], slice[rng.next() % k]);
      }
      for (std::size_t k = 0; k < p.size(); ++k) {
        p[k][j] = (slice[k] + rng.uniform()) / static_cast<double>(n);
      }
    }
    double gap = std::numeric_limits<double>::infinity();
    for (std::size_t a = 0; a < p.size(); ++a) {
      for (std::size_t b = a + 1; b < p.size(); ++b) gap = std::min(gap, distance2(p[a], p[b]));
    }
    if (gap > best_gap) best_gap = gap, best = std::move(p);
  }
  return best;
}

double misfit(const std::vector<double>& error) {
  return std::inner_product(error.begin(), error.end(), error.begin(), 0.0);
}

bool withinTolerance(const std::vector<double>& error) {
  return std::all_of(error.begin(), error.end(), [](double e) { return std::abs(e) <= 1.0; });
}

Surrogate::Surrogate(const std::vector<Evaluated>& done) : d_(done.at(0).u.size()) {
  const std::size_t targets = done.front().error.size();
  gp_.resize(targets);
  x_.assign(targets, {});
  y_.assign(targets, {});
  noise_.assign(targets, {});
  for (std::size_t t = 0; t < targets; ++t) {
    for (const Evaluated& e : done) {
      x_[t].push_back(e.u);
      y_[t].push_back(e.error[t]);
      noise_[t].push_back(e.variance[t]);
    }
    gp_[t].fit(x_[t], y_[t], noise_[t]);
  }
  Random rng(0x5eed);
  draws_.assign(kDraws, std::vector<double>(targets));
  for (auto& row : draws_) {
    for (double& z : row) z = rng.normal();
  }
}

std::vector<Prediction> Surrogate::predict(const Point& u) const {
  std::vector<Prediction> p;
  for (const auto& g : gp_) p.push_back(g.predict(u));
  return p;
}

double Surrogate::meanMisfit(const Point& u) const {
  double s = 0.0;
  for (const auto& g : gp_) s += std::pow(g.predict(u).mean, 2);
  return s;
}

double Surrogate::probabilityWithin(const Point& u) const {
  double p = 1.0;
  for (const auto& g : gp_) {
    const Prediction q = g.predict(u);
    const double sd = std::sqrt(std::max(q.variance, 1e-300));
    p *= normalCdf((1.0 - q.mean) / sd) - normalCdf((-1.0 - q.mean) / sd);
  }
  return p;
}

double Surrogate::expectedImprovement(const Point& u, double best) const {
  const std::vector<Prediction> p = predict(u);
  double sum = 0.0;
  for (const auto& z : draws_) {
    double j = 0.0;
    for (std::size_t t = 0; t < p.size(); ++t) {
      j += std::pow(p[t].mean + std::sqrt(p[t].variance) * z[t], 2);
    }
    sum += std::max(0.0, best - j);
  }
  return sum / static_cast<double>(draws_.size());
}

void Surrogate::believe(const Point& u) {
  for (std::size_t t = 0; t < gp_.size(); ++t) {
    const double mean_noise =
        std::accumulate(noise_[t].begin(), noise_[t].end(), 0.0) / noise_[t].size();
    x_[t].push_back(u);
    y_[t].push_back(gp_[t].predict(u).mean);
    noise_[t].push_back(mean_noise);
    gp_[t].condition(x_[t], y_[t], noise_[t], gp_[t].hyperparameters());
  }
}

std::vector<Point> proposeBatch(const std::vector<Evaluated>& done, int q, std::uint64_t seed) {
  Surrogate s(done);
  const std::size_t d = s.dimensions();
  Random rng(seed);
  // The incumbent: the least predicted misfit at an evaluated point (a noisy evaluation's own
  // value would let one lucky draw set the bar).
  double best = std::numeric_limits<double>::infinity();
  for (const Evaluated& e : done) best = std::min(best, s.meanMisfit(e.u));
  std::vector<Point> taken;
  for (const Evaluated& e : done) taken.push_back(e.u);
  std::vector<Point> out;
  for (int k = 0; k < q; ++k) {
    const std::vector<Point> c =
        candidates(d, 1 + seed % 100000 + 4096 * static_cast<std::uint64_t>(k),
                   bestEvaluated(s, done, 3), rng);
    auto free = [&](const Point& u) {
      for (const Point& t : taken) {
        if (distance2(u, t) < kMinSeparation * kMinSeparation) return false;
      }
      return true;
    };
    auto score = [&](const Point& u) { return free(u) ? s.expectedImprovement(u, best) : -1.0; };
    std::size_t arg = 0;
    double top = -2.0;
    for (std::size_t j = 0; j < c.size(); ++j) {
      const double v = score(c[j]);
      if (v > top) top = v, arg = j;
    }
    Point u = c[arg];
    if (top > 0.0) {  // refined by a simplex on the clamped cube
      const Minimum m = nelderMead([&](const Point& x) { return -score(clamped(x)); }, u, 0.02,
                                   40 * static_cast<int>(d + 1));
      if (-m.f > top) u = clamped(m.x);
    } else {
      // No improvement expected anywhere (the surrogate is sure): the most uncertain free
      // candidate, so the batch still learns.
      double most = -1.0;
      for (const Point& x : c) {
        if (!free(x)) continue;
        double v = 0.0;
        for (const Prediction& p : s.predict(x)) v += p.variance;
        if (v > most) most = v, u = x;
      }
    }
    out.push_back(u);
    taken.push_back(u);
    s.believe(u);
    best = std::min(best, s.meanMisfit(u));
  }
  return out;
}

Reach assessReach(const Surrogate& s, const std::vector<Evaluated>& done) {
  Random rng(0x4eac4);
  const std::vector<Point> c = candidates(s.dimensions(), 1, bestEvaluated(s, done, 3), rng);
  Reach r;
  double least = std::numeric_limits<double>::infinity();
  for (const Point& u : c) {
    r.probability = std::max(r.probability, s.probabilityWithin(u));
    const double m = s.meanMisfit(u);
    if (m < least) least = m, r.closest = u;
  }
  const Minimum m = nelderMead([&](const Point& x) { return s.meanMisfit(clamped(x)); }, r.closest,
                               0.02, 60 * static_cast<int>(s.dimensions() + 1));
  if (m.f < least) r.closest = clamped(m.x);
  r.probability = std::max(r.probability, s.probabilityWithin(r.closest));
  r.at_closest = s.predict(r.closest);
  return r;
}

std::vector<Spread> parameterSpread(const Surrogate& s) {
  const std::size_t d = s.dimensions();
  std::vector<Spread> out(d);
  std::vector<double> sum(d, 0.0), sum2(d, 0.0);
  double weight = 0.0;
  for (std::uint64_t k = 1; k <= 8192; ++k) {
    const Point u = halton(k, d);
    const double p = s.probabilityWithin(u);
    weight += p;
    for (std::size_t j = 0; j < d; ++j) {
      sum[j] += p * u[j];
      sum2[j] += p * u[j] * u[j];
      if (p < 0.5) continue;
      if (!out[j].any) out[j].low = out[j].high = u[j];
      out[j].any = true;
      out[j].low = std::min(out[j].low, u[j]);
      out[j].high = std::max(out[j].high, u[j]);
    }
  }
  for (std::size_t j = 0; j < d && weight > 0.0; ++j) {
    out[j].mean = sum[j] / weight;
    out[j].std = std::sqrt(std::max(0.0, sum2[j] / weight - out[j].mean * out[j].mean));
  }
  return out;
}

std::vector<std::vector<double>> sensitivity(const Surrogate& s) {
  const std::size_t d = s.dimensions();
  constexpr int kGrid = 12, kRest = 256;
  std::vector<std::vector<double>> out(s.targets(), std::vector<double>(d, 0.0));
  for (std::size_t t = 0; t < s.targets(); ++t) {
    const GaussianProcess& g = s.process(t);
    for (std::size_t j = 0; j < d; ++j) {
      // E[mean | u_j] on a grid of u_j, and the variance of all the values behind it.
      std::vector<double> conditional;
      double all = 0.0, all2 = 0.0;
      for (int a = 0; a < kGrid; ++a) {
        double m = 0.0;
        for (int b = 1; b <= kRest; ++b) {
          Point u = halton(static_cast<std::uint64_t>(b), d);
          u[j] = (a + 0.5) / kGrid;
          const double v = g.predict(u).mean;
          m += v;
          all += v;
          all2 += v * v;
        }
        conditional.push_back(m / kRest);
      }
      const double n = static_cast<double>(kGrid) * kRest;
      const double var = all2 / n - std::pow(all / n, 2);
      const double cm = std::accumulate(conditional.begin(), conditional.end(), 0.0) / kGrid;
      double cv = 0.0;
      for (double c : conditional) cv += (c - cm) * (c - cm) / kGrid;
      out[t][j] = var > 1e-300 ? std::clamp(cv / var, 0.0, 1.0) : 0.0;
    }
  }
  return out;
}

}  // namespace rocklab::calibration
