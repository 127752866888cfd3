#pragma once
// Pore and throat geometry of the flow network (Li & Holt section 3.2): the pore is the
// space of a cell (triangle 2D, tetrahedron 3D) of particle centres minus the particles'
// sectors in it; the throat of a pipe is the facet between two cells minus the particles'
// fans and the cement in it (equation 2); its conductance is equation 3.

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "lab/core/dim.hpp"

namespace rocklab::flow {

// Interior angles of the triangle abc at a, b and c (rad). atan2 of the cross and dot
// products keeps them accurate for needle-like triangles, where acos loses digits.
template <class V>
std::array<double, 3> triangleAngles(const V& a, const V& b, const V& c) {
  auto angle = [](const V& u, const V& v) {
    double cr;
    if constexpr (V::RowsAtCompileTime == 2) {
      cr = std::abs(u.x() * v.y() - u.y() * v.x());
    } else {
      cr = u.cross(v).norm();
    }
    return std::atan2(cr, u.dot(v));
  };
  return {angle(b - a, c - a), angle(a - b, c - b), angle(a - c, b - c)};
}

template <class V>
double triangleArea(const V& a, const V& b, const V& c) {
  if constexpr (V::RowsAtCompileTime == 2) {
    return 0.5 * std::abs((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
  } else {
    return 0.5 * (b - a).cross(c - a).norm();
  }
}

// Solid angle (sr) at the origin of the triangle with corners a, b, c (Van Oosterom &
// Strackee 1983, IEEE Trans. Biomed. Eng. 30): tan(Omega / 2) = |a.(b x c)| / (|a||b||c| +
// (a.b)|c| + (a.c)|b| + (b.c)|a|), with atan2 to stay right beyond pi.
inline double solidAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& c) {
  const double la = a.norm(), lb = b.norm(), lc = c.norm();
  const double num = std::abs(a.dot(b.cross(c)));
  const double den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
  return 2.0 * std::atan2(num, den);
}

// Cement of an intact parallel bond of radius R between particles of radii ri, rj whose
// surfaces are g apart (g < 0: overlapping), as it fills the plane of a throat that contains
// the bond's axis: a strip R wide over the gap, plus the neck where the two surfaces close
// in, whose local gap at distance y from the axis is y^2 (1/ri + 1/rj) / 2, integrated over
// 0 <= y <= R. Section 3.2: the cement reduces the throat (and breakage opens it again).
inline double cementArea(double ri, double rj, double gap, double bond_radius) {
  const double R = bond_radius;
  return R * std::max(gap, 0.0) + R * R * R * (1.0 / ri + 1.0 / rj) / 6.0;
}

// Conductance of a pipe, equation 3 written as Hagen-Poiseuille's pipe of radius r_e and
// length r_av: C = alpha pi r_e^4 / (8 mu r_av), so that the factor alpha is dimensionless
// (1: a straight tube of the throat's equivalent radius) and the flux C dp is in m^3/s.
// The paper's alpha absorbs pi / (8 mu) in its unit system; ours keeps the viscosity apart
// so the permeability does not depend on it. r_e is the radius of the circle of the
// throat's fluid area S (section 3.4.1).
inline double pipeConductance(double alpha, double viscosity, double fluid_area,
                              double mean_radius) {
  const double re2 = std::max(fluid_area, 0.0) / std::numbers::pi;
  return alpha * std::numbers::pi * re2 * re2 / (8.0 * viscosity * mean_radius);
}

// The paper's 2D pipe (Figure 8): the edge between disks i and j with a virtual third
// particle out of the plane. We give it the pair's mean radius and put it at the pair's gap
// from both (a throat of three grains equally far apart); the throat is that triangle of
// centres minus the three fans. Returns the triangle's area and the fans' total area.
struct VirtualThroat {
  double triangle = 0.0, fans = 0.0;
};
inline VirtualThroat virtualThroat(double ri, double rj, double distance) {
  const double rv = 0.5 * (ri + rj);
  const double gap = std::max(distance - ri - rj, 0.0);
  const double a = distance, b = ri + rv + gap, c = rj + rv + gap;  // opposite v, j, i
  // Angles by the law of cosines (sides of a proper triangle: b + c > a always here).
  auto angle = [](double opp, double s1, double s2) {
    return std::acos(std::clamp((s1 * s1 + s2 * s2 - opp * opp) / (2.0 * s1 * s2), -1.0, 1.0));
  };
  const double ti = angle(c, a, b), tj = angle(b, a, c), tv = angle(a, b, c);
  const double s = 0.5 * (a + b + c);
  VirtualThroat t;
  t.triangle = std::sqrt(std::max(s * (s - a) * (s - b) * (s - c), 0.0));
  t.fans = 0.5 * (ri * ri * ti + rj * rj * tj + rv * rv * tv);
  return t;
}

}  // namespace rocklab::flow
