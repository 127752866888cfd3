#pragma once
// The linear contact law: stateless kernel (here) and its registry entry (the .cpp).

#include <algorithm>
#include <cmath>

#include "lab/core/contact_kernels.hpp"
#include "lab/core/material.hpp"

namespace rocklab {

// Linear springs (Cundall & Strack 1979): Fn = kn * overlap; shear spring ks.
// Dashpots by critical damping ratio beta: c = 2 beta sqrt(m* k).
struct LinearParams {
  double kn = 0.0;    // N/m, contact normal stiffness (particle springs in series)
  double ks = 0.0;    // N/m
  double mu = 0.0;    // Coulomb friction coefficient
  double damp = 0.0;  // 2 * beta
};

struct LinearLaw {
  using Params = LinearParams;
  static LawState evaluate(const Params& p, double overlap, double /*rstar*/, double mstar) {
    LawState s{p.kn * overlap, p.kn, p.ks, 0.0, 0.0};
    if (p.damp != 0.0) {
      s.cn = p.damp * std::sqrt(mstar * p.kn);
      s.cs = p.damp * std::sqrt(mstar * p.ks);
    }
    return s;
  }
  // Elastic energy stored in the normal spring (J).
  static double normalEnergy(const Params& p, double overlap, double /*rstar*/) {
    return 0.5 * p.kn * overlap * overlap;
  }
  // Critical step of a lone particle against one contact of its own kind: sqrt(m/kn) for
  // translation, sqrt(I/(ks r^2)) for rotation (Itasca 1999, PFC time step).
  static double freeParticleStep(const Params& self, const Material&, double radius, double mass,
                                 double inertia, double /*density*/) {
    double dt = std::sqrt(mass / self.kn);
    if (self.ks > 0.0) dt = std::min(dt, std::sqrt(inertia / (self.ks * radius * radius)));
    return dt;
  }
};

struct ContactLawEntry;
extern const ContactLawEntry kLinearLawEntry;

}  // namespace rocklab
