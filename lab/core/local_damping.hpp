#pragma once
// PFC local damping (Itasca 1999; Cundall 1987): a force opposing each velocity component,
// proportional to the unbalanced force, F_d = -alpha |F| sign(v), component by component.
// Non-viscous: it damps the approach to equilibrium of quasi-static loading without a
// rate, and vanishes at rest.

#include <cmath>

#include <Eigen/Core>

namespace rocklab {

inline double localDamping(double f, double v, double alpha) {
  const double sign = v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0);
  return -alpha * std::abs(f) * sign;
}

template <int R>
Eigen::Matrix<double, R, 1> localDamping(const Eigen::Matrix<double, R, 1>& f,
                                         const Eigen::Matrix<double, R, 1>& v, double alpha) {
  Eigen::Matrix<double, R, 1> d;
  for (int k = 0; k < R; ++k) d[k] = localDamping(f[k], v[k], alpha);
  return d;
}

}  // namespace rocklab
