#pragma once
// The linear contact law: stateless kernel (here) and its registry entry (the .cpp).

#include <algorithm>
#include <cmath>

#include "lab/core/contact_kernels.hpp"
#include "lab/core/material.hpp"

namespace rocklab {

// Linear springs (Cundall & Strack 1979): Fn = kn * overlap; shear spring ks. The
// stiffness is set by particle springs in series (PFC 3), by a contact modulus E (PFC 5's
// deformability method, kn = E A / L with the contact's A and L, ks = kn / ratio; Itasca
// 2014, linear model), or by both added. Dashpots by critical damping ratio beta:
// c = 2 beta sqrt(m* k).
struct LinearParams {
  double kn = 0.0;             // N/m, particle springs in series
  double ks = 0.0;             // N/m
  double modulus = 0.0;        // Pa, contact modulus E for the normal stiffness
  double shear_modulus = 0.0;  // Pa, E / (kn/ks ratio) for the shear stiffness
  double mu = 0.0;             // Coulomb friction coefficient
  double damp = 0.0;           // 2 * beta
};

struct LinearLaw {
  using Params = LinearParams;
  static LawState evaluate(const Params& p, double overlap, const ContactShape& g, double mstar) {
    const double a_over_l = g.area / g.length;
    const double kn = p.kn + p.modulus * a_over_l, ks = p.ks + p.shear_modulus * a_over_l;
    LawState s{kn * overlap, kn, ks, 0.0, 0.0};
    if (p.damp != 0.0) {
      s.cn = p.damp * std::sqrt(mstar * kn);
      s.cs = p.damp * std::sqrt(mstar * ks);
    }
    return s;
  }
  // Elastic energy stored in the normal spring (J).
  static double normalEnergy(const Params& p, double overlap, const ContactShape& g) {
    return 0.5 * (p.kn + p.modulus * g.area / g.length) * overlap * overlap;
  }
  // Critical step of a lone particle against one contact of its own kind: sqrt(m/kn) for
  // translation, sqrt(I/(ks r^2)) for rotation (Itasca 1999, PFC time step).
  static double freeParticleStep(const Params& self, const ContactShape& self_shape,
                                 const Material&, double radius, double mass, double inertia,
                                 double /*density*/) {
    const LawState s = evaluate(self, 0.0, self_shape, mass);
    double dt = std::sqrt(mass / s.kn);
    if (s.ks > 0.0) dt = std::min(dt, std::sqrt(inertia / (s.ks * radius * radius)));
    return dt;
  }
};

struct ContactLawEntry;
extern const ContactLawEntry kLinearLawEntry;

}  // namespace rocklab
