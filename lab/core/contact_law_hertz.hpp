#pragma once
// The Hertz-Mindlin contact law: stateless kernel (here) and its registry entry (the .cpp).

#include <cmath>
#include <numbers>

#include "lab/core/contact_kernels.hpp"
#include "lab/core/material.hpp"

namespace rocklab {

// Hertz normal force with Mindlin's no-slip tangential stiffness (Mindlin 1949; the form
// of Di Renzo & Di Maio 2004): a = sqrt(R* overlap), Fn = 4/3 E* a overlap, kn = 2 E* a,
// ks = 8 G* a. Dashpots in Tsuji's form (Tsuji et al. 1992, as LIGGGHTS and Yade use):
// c = 2 sqrt(5/6) beta sqrt(m* k), k the tangent stiffness, which makes the coefficient of
// restitution independent of impact speed.
struct HertzParams {
  double estar = 0.0;  // Pa, E* = 1 / ((1-nu1^2)/E1 + (1-nu2^2)/E2)
  double gstar = 0.0;  // Pa, G* = 1 / ((2-nu1)/G1 + (2-nu2)/G2)
  double mu = 0.0;
  double damp = 0.0;  // 2 sqrt(5/6) beta
  // damp sqrt(2 E*) and damp sqrt(8 G*), mixed once: the dashpots are these times sqrt(a m*).
  double cn_per_am = 0.0, cs_per_am = 0.0;
};

struct HertzLaw {
  using Params = HertzParams;
  static LawState evaluate(const Params& p, double overlap, const ContactShape& g, double mstar) {
    const double a = std::sqrt(g.rstar * overlap);
    LawState s{4.0 / 3.0 * p.estar * a * overlap, 2.0 * p.estar * a, 8.0 * p.gstar * a, 0.0, 0.0};
    if (p.damp != 0.0) {
      const double am = std::sqrt(a * mstar);
      s.cn = p.cn_per_am * am;
      s.cs = p.cs_per_am * am;
    }
    return s;
  }
  static double normalEnergy(const Params& p, double overlap, const ContactShape& g) {
    return 8.0 / 15.0 * p.estar * std::sqrt(g.rstar) * overlap * overlap * std::sqrt(overlap);
  }
  // Rayleigh wave time across the particle, T_R = pi r sqrt(rho/G) / (0.1631 nu + 0.8766)
  // (Li, Xu & Thornton 2005): the usual bound before contact stiffness is known.
  static double freeParticleStep(const Params&, const ContactShape&, const Material& m,
                                 double radius, double, double, double density) {
    const double g = m.young / (2.0 * (1.0 + m.poisson));
    return std::numbers::pi * radius * std::sqrt(density / g) / (0.1631 * m.poisson + 0.8766);
  }
};

struct ContactLawEntry;
extern const ContactLawEntry kHertzLawEntry;

}  // namespace rocklab
