#pragma once
// What a compression test's stress-strain records give (ISRM suggested method for the
// uniaxial compression test, Fairhurst & Hudson 1999): Young's modulus and Poisson's ratio
// at half the peak stress, secant and tangent, and the crack damage stress, where the
// volumetric strain turns from compaction to dilatancy (Bieniawski 1967; Martin & Chandler
// 1994). Strains compression positive; a lateral expansion is a negative lateral strain.

#include <Eigen/Dense>
#include <cmath>
#include <cstddef>
#include <vector>

#include "rigs/common/analysis.hpp"

namespace rocklab::rigs::ucs {

// The records of a test, in loading order: the axial stress (Pa), the specimen's axial
// strain (the platens'), and the gauge section's axial, lateral and volumetric strains.
struct CompressionCurve {
  std::vector<double> stress, axial, gauge_axial, lateral, volumetric;
  template <class Archive>
  void visit(Archive& ar) {
    ar("stress", stress), ar("axial", axial), ar("gauge_axial", gauge_axial);
    ar("lateral", lateral), ar("volumetric", volumetric);
  }
  void push(double s, double a, double ga, double l, double v) {
    stress.push_back(s), axial.push_back(a), gauge_axial.push_back(ga);
    lateral.push_back(l), volumetric.push_back(v);
  }
  std::size_t size() const { return stress.size(); }
};

struct GaugeStrains {
  double axial = 0.0, lateral = 0.0;  // compression positive
};

// A gauge's strains from its particles' positions at the start and now: the displacement
// gradient H of the affine field u = c + H x that fits their displacements in least squares,
// H = (sum u' x'^T) (sum x' x'^T)^-1 with x', u' taken from their means. The axial strain is
// -H_aa along `axis`, the lateral the mean of -H_bb across it. A gauge of hundreds of
// particles averages out each one's fluctuation about the affine field.
template <int D>
GaugeStrains affineStrains(const std::vector<Eigen::Matrix<double, D, 1>>& start,
                           const std::vector<Eigen::Matrix<double, D, 1>>& now, int axis) {
  using Vec = Eigen::Matrix<double, D, 1>;
  using Mat = Eigen::Matrix<double, D, D>;
  const double n = static_cast<double>(start.size());
  Vec mx = Vec::Zero(), mu = Vec::Zero();
  for (std::size_t k = 0; k < start.size(); ++k) {
    mx += start[k] / n;
    mu += (now[k] - start[k]) / n;
  }
  Mat xx = Mat::Zero(), ux = Mat::Zero();
  for (std::size_t k = 0; k < start.size(); ++k) {
    const Vec x = start[k] - mx, u = now[k] - start[k] - mu;
    xx += x * x.transpose();
    ux += u * x.transpose();
  }
  const Mat H = ux * xx.inverse();
  GaugeStrains e;
  e.axial = -H(axis, axis);
  for (int a = 0; a < D; ++a) {
    if (a != axis) e.lateral -= H(a, a) / (D - 1);
  }
  return e;
}

struct HalfPeakModuli {
  double young_secant = NAN, young_tangent = NAN;  // Pa
  double poisson_secant = NAN, poisson_tangent = NAN;
};

// At half the peak stress (the peak at record `peak`): the secant modulus is half the peak
// over the axial strain where the stress first reaches it (interpolated between records),
// the secant Poisson's ratio minus the lateral over the gauge's axial strain there; the
// tangents are the least-squares slopes over the records from 40% to 60% of the peak before
// it (Young's: stress against axial strain; Poisson's: minus the lateral against the gauge's
// axial strain).
inline HalfPeakModuli halfPeakModuli(const CompressionCurve& c, std::size_t peak) {
  HalfPeakModuli m;
  if (peak >= c.size()) return m;
  const double half = 0.5 * c.stress[peak];
  std::size_t k = 0;
  while (k < peak && c.stress[k] < half) ++k;
  if (k > 0 && c.stress[k] > c.stress[k - 1]) {
    const double w = (half - c.stress[k - 1]) / (c.stress[k] - c.stress[k - 1]);
    auto at = [&](const std::vector<double>& v) { return v[k - 1] + w * (v[k] - v[k - 1]); };
    if (at(c.axial) > 0.0) m.young_secant = half / at(c.axial);
    if (at(c.gauge_axial) > 0.0) m.poisson_secant = -at(c.lateral) / at(c.gauge_axial);
  }
  auto near_half = [&](std::size_t j) {
    return c.stress[j] >= 0.8 * half && c.stress[j] <= 1.2 * half;
  };
  m.young_tangent = slopeWhere(c.axial, c.stress, peak + 1, near_half);
  m.poisson_tangent = -slopeWhere(c.gauge_axial, c.lateral, peak + 1, near_half);
  return m;
}

// The crack damage stress: the stress at the largest volumetric strain (compaction) up to
// the peak, where dilatancy overtakes the elastic compaction. A sample that compacts up to
// its peak has it at the peak.
struct CrackDamage {
  double stress = NAN, volumetric = NAN;
  std::size_t index = 0;
};

inline CrackDamage crackDamage(const CompressionCurve& c, std::size_t peak) {
  CrackDamage d;
  if (peak >= c.size()) return d;
  std::size_t best = 0;
  for (std::size_t k = 1; k <= peak; ++k) {
    if (c.volumetric[k] > c.volumetric[best]) best = k;
  }
  d.index = best;
  d.stress = c.stress[best];
  d.volumetric = c.volumetric[best];
  return d;
}

}  // namespace rocklab::rigs::ucs
