#pragma once
// The shared, stateless contact kernel.
//
// A law (contact_law_*.hpp) supplies the normal elastic force and the tangent stiffnesses
// and dashpot coefficients at an overlap (`evaluate`); `contactForce` adds the
// dashpots, the incremental tangential spring with Coulomb sliding, and objectivity.
// Sign conventions: n points from particle i to particle j (or from a particle to a wall);
// forces returned act on j, i receives the opposite.

#include <algorithm>
#include <cmath>
#include <numbers>

#include "lab/core/dim.hpp"

namespace rocklab {

// What a law returns at an overlap: elastic normal force (N, repulsive positive), tangent
// normal and shear stiffness (N/m) and dashpot coefficients (N s/m).
struct LawState {
  double fn_elastic;
  double kn;
  double ks;
  double cn;
  double cs;
};

// The size of a contact as the laws see it: the effective radius R* = r1 r2 / (r1 + r2)
// (Hertz), and a cross-section A over a length L for laws set by a modulus (the
// "deformability" of PFC 5's linear model, k = E A / L): A = pi min(r1, r2)^2 in 3D or
// 2 min(r1, r2) t in 2D (t the disk thickness), L = r1 + r2; for a particle on a wall
// R* = r and L = r.
struct ContactShape {
  double rstar = 0.0;   // m
  double area = 0.0;    // m^2
  double length = 0.0;  // m
};

template <int D>
ContactShape pairShape(double ri, double rj, double thickness) {
  const double rmin = std::min(ri, rj);
  return {ri * rj / (ri + rj), D == 3 ? std::numbers::pi * rmin * rmin : 2.0 * rmin * thickness,
          ri + rj};
}

template <int D>
ContactShape wallShape(double r, double thickness) {
  return {r, D == 3 ? std::numbers::pi * r * r : 2.0 * r * thickness, r};
}

// Energy dissipated in one contact during one step (J).
struct ContactDissipation {
  double friction = 0.0;
  double viscous = 0.0;
};

template <int D>
struct ContactResult {
  Vec<D> force;       // on j
  Ang<D> n_cross_ft;  // n x (tangential force on j), to build torques with the lever arms
  double kn;          // tangent normal stiffness, for servo gains and the time step
  double cn;          // normal dashpot coefficient, for servo gains
};

// Relative kinematics of one contact.
template <int D>
struct ContactKinematics {
  Vec<D> n;        // unit normal from i to j
  double overlap;  // > 0
  Vec<D> vc;       // velocity of j's contact point relative to i's
  double spin_n;   // mean spin of the two bodies about n (3D twist; 0 in 2D)
  ContactShape shape;
  double mstar;  // effective mass
};

// Keeps a vector stored with a contact (a spring force, a bond moment) in the contact's
// tangent plane as the contact turns: turned with the bodies' mean spin about the normal,
// then projected on the new tangent plane with its magnitude kept (Cundall & Strack 1979;
// cf. Yade ScGeom::rotate). First order in the angle turned per step. bond_lanes.hpp repeats
// it, in this order, four bonds at a time.
template <int D>
inline void followContactFrame(Vec<D>& v, const Vec<D>& n, double spin_n, double dt) {
  const double m2 = v.squaredNorm();
  if (m2 == 0.0) return;
  if constexpr (D == 3) v += (dt * spin_n) * n.cross(v);
  v -= v.dot(n) * n;
  const double m2_new = v.squaredNorm();
  if (m2_new > 0.0) v *= std::sqrt(m2 / m2_new);
}

// The shared contact kernel. `fs` is the contact's tangential spring force on j (its
// history); it is rotated with the contact (objectivity), incremented by -ks * vt * dt,
// and capped at mu * Fn (Coulomb). When sliding, the shear dashpot is inactive so that
// |Ft| <= mu Fn holds exactly.
template <int D, class Law, bool kTrackEnergy>
[[gnu::always_inline]] inline ContactResult<D> contactForce(const typename Law::Params& p,
                                                            const ContactKinematics<D>& k,
                                                            Vec<D>& fs, double dt,
                                                            ContactDissipation& diss) {
  const LawState s = Law::evaluate(p, k.overlap, k.shape, k.mstar);
  const Vec<D>& n = k.n;
  const double vn = k.vc.dot(n);
  const Vec<D> vt = k.vc - vn * n;
  const double fn = s.fn_elastic - s.cn * vn;

  // A rigidly rotated contact keeps its force.
  followContactFrame<D>(fs, n, k.spin_n, dt);
  const Vec<D> fs_rotated = fs;
  fs -= (s.ks * dt) * vt;

  // Each total receives one term per contact (its dissipation alone), so a contact's
  // share can be kept and added later in the serial order with the same bits.
  Vec<D> ft;
  double viscous = 0.0;
  const double limit = p.mu * std::max(s.fn_elastic, 0.0);
  const double fs2 = fs.squaredNorm();
  if (fs2 > limit * limit) {
    fs *= fs2 > 0.0 ? limit / std::sqrt(fs2) : 0.0;
    ft = fs;
    if constexpr (kTrackEnergy) {
      // Slip = relative displacement minus the elastic spring extension increment.
      Vec<D> slip = vt * dt;
      if (s.ks > 0.0) slip += (fs - fs_rotated) / s.ks;
      diss.friction -= fs.dot(slip);
    }
  } else {
    ft = fs - s.cs * vt;
    if constexpr (kTrackEnergy) viscous = s.cs * vt.squaredNorm() * dt;
  }
  if constexpr (kTrackEnergy) diss.viscous += viscous + s.cn * vn * vn * dt;

  ContactResult<D> r;
  r.force = fn * n + ft;
  r.n_cross_ft = cross(n, ft);
  r.kn = s.kn;
  r.cn = s.cn;
  return r;
}

// Strain energy stored in a contact: the law's normal energy plus the shear spring's.
template <class Law>
inline double contactStrainEnergy(const typename Law::Params& p, double overlap,
                                  const ContactShape& g, double shear_force2, double mstar) {
  const LawState s = Law::evaluate(p, overlap, g, mstar);
  const double es = s.ks > 0.0 ? 0.5 * shear_force2 / s.ks : 0.0;
  return Law::normalEnergy(p, overlap, g) + es;
}

}  // namespace rocklab
