#include "lab/core/clumps.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace rocklab {

namespace {

// Moments of the union of intervals along one axis: length, first and second moments.
struct ChordMoments {
  double m0 = 0.0, m1 = 0.0, m2 = 0.0;
};

ChordMoments unionMoments(std::vector<std::pair<double, double>>& chords) {
  ChordMoments m;
  if (chords.empty()) return m;
  std::sort(chords.begin(), chords.end());
  auto add = [&](double a, double b) {
    m.m0 += b - a;
    m.m1 += 0.5 * (b * b - a * a);
    m.m2 += (b * b * b - a * a * a) / 3.0;
  };
  double a = chords[0].first, b = chords[0].second;
  for (std::size_t k = 1; k < chords.size(); ++k) {
    if (chords[k].first > b) {
      add(a, b);
      a = chords[k].first;
    }
    b = std::max(b, chords[k].second);
  }
  add(a, b);
  return m;
}

void checkShape(const auto& shape, double density, int resolution) {
  if (shape.centers.empty() || shape.centers.size() != shape.radii.size()) {
    throw std::invalid_argument("a clump needs at least one pebble, each with a radius");
  }
  for (double r : shape.radii) {
    if (!(r > 0.0)) throw std::invalid_argument("clump pebble radii must be positive");
  }
  if (!(density > 0.0)) throw std::invalid_argument("clump density must be positive");
  if (resolution < 4) throw std::invalid_argument("mass property resolution must be >= 4");
}

}  // namespace

template <>
MassProperties<2> massProperties<2>(const ClumpShape<2>& shape, double density, double thickness,
                                    int resolution) {
  checkShape(shape, density, resolution);
  double lo = INFINITY, hi = -INFINITY;
  for (std::size_t k = 0; k < shape.centers.size(); ++k) {
    lo = std::min(lo, shape.centers[k].x() - shape.radii[k]);
    hi = std::max(hi, shape.centers[k].x() + shape.radii[k]);
  }
  const int n = resolution * 4;  // columns are cheap in 2D
  const double h = (hi - lo) / n;
  double area = 0.0, sx = 0.0, sy = 0.0, sxx = 0.0, syy = 0.0;
  std::vector<std::pair<double, double>> chords;
  for (int c = 0; c < n; ++c) {
    const double x = lo + (c + 0.5) * h;
    chords.clear();
    for (std::size_t k = 0; k < shape.centers.size(); ++k) {
      const double dx = x - shape.centers[k].x(), r = shape.radii[k];
      if (dx * dx >= r * r) continue;
      const double half = std::sqrt(r * r - dx * dx);
      chords.emplace_back(shape.centers[k].y() - half, shape.centers[k].y() + half);
    }
    const ChordMoments m = unionMoments(chords);
    area += h * m.m0;
    sx += h * x * m.m0;
    sy += h * m.m1;
    sxx += h * (x * x + h * h / 12.0) * m.m0;
    syy += h * m.m2;
  }
  MassProperties<2> p;
  p.volume = area * thickness;
  p.mass = density * p.volume;
  p.centroid = {sx / area, sy / area};
  const double polar = (sxx + syy) - area * p.centroid.squaredNorm();
  p.inertia = density * thickness * polar;
  return p;
}

template <>
MassProperties<3> massProperties<3>(const ClumpShape<3>& shape, double density, double,
                                    int resolution) {
  checkShape(shape, density, resolution);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (std::size_t k = 0; k < shape.centers.size(); ++k) {
    lo = lo.cwiseMin(shape.centers[k] - Eigen::Vector3d::Constant(shape.radii[k]));
    hi = hi.cwiseMax(shape.centers[k] + Eigen::Vector3d::Constant(shape.radii[k]));
  }
  const double h = std::max(hi.x() - lo.x(), hi.y() - lo.y()) / resolution;
  const int nx = std::max(1, static_cast<int>(std::ceil((hi.x() - lo.x()) / h)));
  const int ny = std::max(1, static_cast<int>(std::ceil((hi.y() - lo.y()) / h)));
  const double cell = h * h;
  // Raw moments: volume, first moments, second moments (xx yy zz xy xz yz).
  double v = 0.0;
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  double xx = 0.0, yy = 0.0, zz = 0.0, xy = 0.0, xz = 0.0, yz = 0.0;
  std::vector<std::pair<double, double>> chords;
  for (int a = 0; a < nx; ++a) {
    const double x = lo.x() + (a + 0.5) * h;
    for (int b = 0; b < ny; ++b) {
      const double y = lo.y() + (b + 0.5) * h;
      chords.clear();
      for (std::size_t k = 0; k < shape.centers.size(); ++k) {
        const auto& c = shape.centers[k];
        const double rho2 = (x - c.x()) * (x - c.x()) + (y - c.y()) * (y - c.y());
        const double r2 = shape.radii[k] * shape.radii[k];
        if (rho2 >= r2) continue;
        const double half = std::sqrt(r2 - rho2);
        chords.emplace_back(c.z() - half, c.z() + half);
      }
      if (chords.empty()) continue;
      const ChordMoments m = unionMoments(chords);
      v += cell * m.m0;
      s += cell * Eigen::Vector3d(x * m.m0, y * m.m0, m.m1);
      // The midpoint rule's in-cell variance of x and y: h^2 / 12.
      xx += cell * (x * x + h * h / 12.0) * m.m0;
      yy += cell * (y * y + h * h / 12.0) * m.m0;
      zz += cell * m.m2;
      xy += cell * x * y * m.m0;
      xz += cell * x * m.m1;
      yz += cell * y * m.m1;
    }
  }
  MassProperties<3> p;
  p.volume = v;
  p.mass = density * v;
  p.centroid = s / v;
  Eigen::Matrix3d second;
  second << xx, xy, xz, xy, yy, yz, xz, yz, zz;
  second -= v * p.centroid * p.centroid.transpose();  // about the centroid
  p.inertia = density * (second.trace() * Eigen::Matrix3d::Identity() - second);
  return p;
}

}  // namespace rocklab
