#include "rigs/common/envelope.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "rigs/common/analysis.hpp"

namespace rocklab::rigs {

namespace {

double mean(const std::vector<double>& x) {
  double m = 0.0;
  for (double v : x) m += v;
  return m / static_cast<double>(x.size());
}

}  // namespace

CriticalPoint criticalPoint(const LoadingCurve& c) {
  const std::size_t n = c.axial_strain.size();
  if (c.q.size() != n || c.volumetric_strain.size() != n) {
    throw std::invalid_argument("critical point: the curves differ in length");
  }
  CriticalPoint p;
  if (n < 8) return p;
  const auto& ev = c.volumetric_strain;
  const double ev_max = *std::max_element(ev.begin(), ev.end());
  p.compactive = ev.back() >= ev_max - std::max(1e-4, 0.1 * std::abs(ev_max));
  std::size_t at = n;
  if (!p.compactive) {
    at = static_cast<std::size_t>(std::max_element(c.q.begin(), c.q.end()) - c.q.begin());
  } else {
    // Elastic trends of volumetric strain and of q over the early part of the test.
    const double end = c.axial_strain.back();
    std::vector<double> x, v, q;
    for (std::size_t i = 0; i < n; ++i) {
      if (c.axial_strain[i] >= 0.05 * end && c.axial_strain[i] <= 0.25 * end) {
        x.push_back(c.axial_strain[i]);
        v.push_back(ev[i]);
        q.push_back(c.q[i]);
      }
    }
    const double kv = slope(x, v), kq = slope(x, q);
    if (x.size() < 2) return p;
    const double mx = mean(x), mv = mean(v), mq = mean(q);
    for (std::size_t i = 0; i < n && at == n; ++i) {
      if (c.axial_strain[i] <= 0.25 * end) continue;
      const double v_trend = mv + kv * (c.axial_strain[i] - mx);
      const double q_trend = mq + kq * (c.axial_strain[i] - mx);
      const bool compacts = kv > 0.0 && v_trend > 0.0 && ev[i] > 1.1 * v_trend;
      const bool yields = kq > 0.0 && q_trend > 0.0 && c.q[i] < 0.9 * q_trend;
      if (compacts || yields) at = i;
    }
  }
  if (at == n) return p;
  p.found = true;
  p.index = at;
  p.axial_strain = c.axial_strain[at];
  p.q = c.q[at];
  p.volumetric_strain = ev[at];
  return p;
}

MohrCoulomb fitMohrCoulomb(const std::vector<EnvelopePoint>& points) {
  std::vector<double> s3, s1;
  for (const EnvelopePoint& e : points) {
    if (e.compactive) continue;
    s3.push_back(e.sigma3);
    s1.push_back(e.sigma1);
  }
  MohrCoulomb m;
  m.points = s3.size();
  const double N = slope(s3, s1);
  if (!std::isfinite(N) || N < 1.0) return m;
  double m3 = 0.0, m1 = 0.0;
  for (std::size_t i = 0; i < s3.size(); ++i) m3 += s3[i], m1 += s1[i];
  m3 /= s3.size(), m1 /= s3.size();
  m.fitted = true;
  m.passive_factor = N;
  m.ucs = m1 - N * m3;
  // N = tan^2(45 + phi/2)  =>  phi = 2 atan(sqrt N) - 90 degrees.
  m.friction_angle_deg = 2.0 * std::atan(std::sqrt(N)) * 180.0 / std::numbers::pi - 90.0;
  double ss = 0.0;
  for (std::size_t i = 0; i < s3.size(); ++i) {
    const double r = s1[i] - (m.ucs + N * s3[i]);
    ss += r * r;
  }
  m.rms_residual = std::sqrt(ss / s3.size());
  return m;
}

}  // namespace rocklab::rigs
