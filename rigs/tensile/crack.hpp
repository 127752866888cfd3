#pragma once
// Where a tensile test's fracture runs: the principal axis of its bond breaks in the loading
// plane. A Brazilian disk should split along the loaded diameter (the elastic solution's
// tensile stress is largest and uniform along it, Hondros 1959): the breaks' axis then
// points along the load and passes through the centre.

#include <cmath>
#include <numbers>
#include <vector>

namespace rocklab::rigs {

// A break in the loading plane, from the disk's centre: x across, y along the load (m).
struct CrackPoint {
  double x = 0.0, y = 0.0;
};

struct Crack {
  std::size_t points = 0;
  double angle_to_axis_deg = NAN;  // the principal axis against the load, 0..90
  double offset_ratio = NAN;       // the axis's distance from the centre over the diameter
  double elongation = NAN;         // sqrt of the covariance's eigenvalues' ratio, >= 1
  // Along the loaded diameter: within 20 deg of it, within a tenth of the diameter of the
  // centre, and a line rather than a cloud (twice as long as wide).
  bool throughCentre() const {
    return angle_to_axis_deg <= 20.0 && offset_ratio <= 0.1 && elongation >= 2.0;
  }
};

inline Crack crackOf(const std::vector<CrackPoint>& pts, double diameter) {
  Crack c;
  c.points = pts.size();
  if (pts.size() < 2) return c;
  const double n = static_cast<double>(pts.size());
  double mx = 0.0, my = 0.0;
  for (const CrackPoint& p : pts) mx += p.x / n, my += p.y / n;
  double sxx = 0.0, syy = 0.0, sxy = 0.0;
  for (const CrackPoint& p : pts) {
    sxx += (p.x - mx) * (p.x - mx) / n;
    syy += (p.y - my) * (p.y - my) / n;
    sxy += (p.x - mx) * (p.y - my) / n;
  }
  // The covariance's larger eigenvalue and its eigenvector (ux, uy), the principal axis.
  const double half = 0.5 * (sxx + syy), root = std::hypot(0.5 * (sxx - syy), sxy);
  const double major = half + root, minor = std::max(half - root, 0.0);
  const double theta = 0.5 * std::atan2(2.0 * sxy, sxx - syy);  // from the x axis
  const double ux = std::cos(theta), uy = std::sin(theta);
  c.angle_to_axis_deg = std::acos(std::min(1.0, std::abs(uy))) * 180.0 / std::numbers::pi;
  c.offset_ratio = std::abs(mx * uy - my * ux) / diameter;
  c.elongation = minor > 0.0 ? std::sqrt(major / minor) : INFINITY;
  return c;
}

}  // namespace rocklab::rigs
