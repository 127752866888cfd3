#pragma once
// PFC local damping (Itasca 1999; Cundall 1987): a force opposing each velocity component,
// proportional to the unbalanced force, F_d = -alpha |F| sign(v), component by component.
// Non-viscous: it damps the approach to equilibrium of quasi-static loading without a
// rate, and vanishes at rest.

#include <bit>
#include <cmath>
#include <cstdint>

#include <Eigen/Core>

namespace rocklab {

// -alpha |f| sign(v) without a branch: the sign of a velocity component is a coin toss in a
// settling sample, and a mispredicted branch per component cost more than the rest of the
// integration (perf, 2D biaxial test). The same bits as the product: -alpha |f| where v > 0,
// +alpha |f| where v < 0, and -0.0 where v is zero or not a number (-alpha |f| times 0), for
// any finite force.
inline double localDamping(double f, double v, double alpha) {
  const double magnitude = alpha * std::abs(f);
  const std::uint64_t opposed = std::bit_cast<std::uint64_t>(std::copysign(magnitude, -v));
  const std::uint64_t moving = 0 - static_cast<std::uint64_t>((v > 0.0) | (v < 0.0));
  constexpr std::uint64_t kNegativeZero = std::uint64_t{1} << 63;
  return std::bit_cast<double>((opposed & moving) | (kNegativeZero & ~moving));
}

template <int R>
Eigen::Matrix<double, R, 1> localDamping(const Eigen::Matrix<double, R, 1>& f,
                                         const Eigen::Matrix<double, R, 1>& v, double alpha) {
  Eigen::Matrix<double, R, 1> d;
  for (int k = 0; k < R; ++k) d[k] = localDamping(f[k], v[k], alpha);
  return d;
}

}  // namespace rocklab
