#pragma once
// Rigid planar walls: prescribed velocity or servo-controlled to a target normal stress.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "lab/core/dim.hpp"

namespace rocklab {

// Servo control of a wall's normal velocity to hold a compressive stress (PFC's servo,
// Itasca 1999): v = alpha * A * (sigma_target - sigma) / (k_sum * dt + c_sum), with k_sum
// the summed normal stiffness of the wall's contacts, so that a fraction alpha of the
// stress error closes per step; |v| <= max_speed. The summed dashpot coefficient c_sum of
// the contacts is our addition to PFC's gain: a wall's own speed loads its contact
// dashpots at once, and without the term a viscous wall contact turns the servo into a
// bang-bang oscillation between +-max_speed. With no contact the wall approaches at
// max_speed.
struct ServoControl {
  bool enabled = false;
  double target_stress = 0.0;  // Pa, compressive positive, at time `t0`
  double target_rate = 0.0;    // Pa/s, for a stress ramp
  double t0 = 0.0;             // s
  double area = 0.0;           // m^2 (2D: length times thickness); the rig keeps it current
  double alpha = 0.5;          // -, relaxation factor in (0, 1]
  double max_speed = 0.0;      // m/s, > 0

  double target(double t) const { return target_stress + target_rate * (t - t0); }
};

template <int D>
struct Wall {
  std::string name;
  Vec<D> normal = Vec<D>::Zero();  // unit, pointing to the side the particles are on
  Vec<D> point = Vec<D>::Zero();   // a point of the plane
  Vec<D> velocity = Vec<D>::Zero();
  std::uint16_t material = 0;
  ServoControl servo;

  // Read-out, refreshed every step: the force the particles exert on the wall, the summed
  // tangent normal stiffness and dashpot coefficients of its contacts, and their number.
  Vec<D> force = Vec<D>::Zero();
  double stiffness = 0.0;  // N/m
  double damping = 0.0;    // N s/m, summed normal dashpot coefficients
  std::uint32_t contacts = 0;

  // Signed distance of x from the plane, positive on the particles' side.
  double distance(const Vec<D>& x) const { return (x - point).dot(normal); }
  // Compressive normal stress on the wall for a given area.
  double normalStress(double area) const { return area > 0.0 ? -force.dot(normal) / area : 0.0; }

  // Sets the velocity from the servo law (if enabled) for the next step.
  void updateServo(double t, double dt) {
    if (!servo.enabled) return;
    const double err = servo.target(t) - normalStress(servo.area);
    double v;
    if (stiffness > 0.0) {
      v = servo.alpha * servo.area * err / (stiffness * dt + damping);
    } else {
      v = err > 0.0 ? servo.max_speed : (err < 0.0 ? -servo.max_speed : 0.0);
    }
    v = std::clamp(v, -servo.max_speed, servo.max_speed);
    velocity = v * normal;
  }

  template <class Archive>
  void visit(Archive& ar) {
    ar("name", name), ar("normal", normal), ar("point", point), ar("velocity", velocity);
    ar("material", material);
    ar("servo.enabled", servo.enabled), ar("servo.target_stress", servo.target_stress);
    ar("servo.target_rate", servo.target_rate), ar("servo.t0", servo.t0);
    ar("servo.area", servo.area), ar("servo.alpha", servo.alpha);
    ar("servo.max_speed", servo.max_speed);
    ar("force", force), ar("stiffness", stiffness), ar("damping", damping);
    ar("contacts", contacts);
  }
};

}  // namespace rocklab
