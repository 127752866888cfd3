#pragma once
// Dimension traits: one code base for 2D disks and 3D spheres.
//
// Positions, velocities and forces are D-vectors. Angular quantities (spin, torque) are a
// scalar in 2D (rotation about the out-of-plane axis) and a 3-vector in 3D; the helpers
// below give the cross products and per-component operations both need.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

namespace rocklab {

template <int D>
struct Dim;

template <>
struct Dim<2> {
  using Vec = Eigen::Vector2d;
  using Ang = double;
  static constexpr int kAngComponents = 1;
};

template <>
struct Dim<3> {
  using Vec = Eigen::Vector3d;
  using Ang = Eigen::Vector3d;
  static constexpr int kAngComponents = 3;
};

template <int D>
using Vec = typename Dim<D>::Vec;
template <int D>
using Ang = typename Dim<D>::Ang;

// w x r for an angular quantity w and a vector r.
inline Eigen::Vector2d cross(double w, const Eigen::Vector2d& r) {
  return {-w * r.y(), w * r.x()};
}
// a x b for two in-plane vectors: the out-of-plane component.
inline double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}
inline Eigen::Vector3d cross(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return a.cross(b);
}

inline double angDot(double a, double b) {
  return a * b;
}
inline double angDot(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return a.dot(b);
}
inline double angNorm(double a) {
  return std::abs(a);
}
inline double angNorm(const Eigen::Vector3d& a) {
  return a.norm();
}

template <class A>
A angZero() {
  if constexpr (std::is_same_v<A, double>) {
    return 0.0;
  } else {
    return A::Zero();
  }
}

template <int D>
Vec<D> vecZero() {
  return Vec<D>::Zero();
}

// Component of the angular quantity w about the unit normal n (3D), or w itself (2D, where
// the only rotation axis is normal to every in-plane contact normal).
inline double spinAbout(double, const Eigen::Vector2d&) {
  return 0.0;
}
inline double spinAbout(const Eigen::Vector3d& w, const Eigen::Vector3d& n) {
  return w.dot(n);
}

// Volume (3D) or area times the out-of-plane thickness (2D) of a particle of radius r.
template <int D>
double particleVolume(double r, double thickness) {
  if constexpr (D == 2) {
    return std::numbers::pi * r * r * thickness;
  } else {
    (void)thickness;
    return 4.0 / 3.0 * std::numbers::pi * r * r * r;
  }
}

// Moment of inertia about a diameter (sphere, 2/5 m r^2) or about the axis of a disk of
// unit-thickness extrusion (cylinder, 1/2 m r^2).
template <int D>
double particleInertia(double mass, double r) {
  return (D == 2 ? 0.5 : 0.4) * mass * r * r;
}

}  // namespace rocklab
