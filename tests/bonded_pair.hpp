#pragma once
// Two driven particles joined by one bond, for the bond and flat-joint unit tests: only the
// bond acts (a small gap keeps the contact law out), loaded by prescribed velocities and
// spins.

#include <gtest/gtest.h>

#include "tests/support.hpp"

namespace rocklab::testing::bonded {

using V3 = Eigen::Vector3d;
using V2 = Eigen::Vector2d;
constexpr double kR = 1e-3, kGap = 2e-6, kModulus = 4e9, kRatio = 0.5, kDt = 1e-7;

inline BondKind cement(double tensile, double shear, double lambda = 1.0) {
  BondKind k;
  k.modulus = kModulus;
  k.stiffness_ratio = kRatio;
  k.radius_multiplier = lambda;
  k.tensile_mean = tensile;
  k.shear_mean = shear;
  k.tensile_std = k.shear_std = 0.0;
  return k;
}

// Two driven (fixed) particles with a small gap, so that only the bond acts, then bonded.
template <int D>
struct BondedPair {
  Simulation<D> sim;
  ParticleId a, b;
  Vec<D> n;
  explicit BondedPair(const BondKind& kind)
      : sim(testing::table(testing::linearMaterial(1e6, 1e6, 0.5)), config()) {
    n = Vec<D>::Zero();
    n[0] = 1.0;
    ParticleSpec<D> p;
    p.radius = kR;
    p.fixed = true;
    a = sim.particles().add(p);
    p.position = (2 * kR + kGap) * n;
    b = sim.particles().add(p);
    const auto k = sim.addBondKind(kind);
    const CementReport r = sim.cement(k, 0.01);
    EXPECT_EQ(r.installed, 1u);
  }
  static SimulationConfig config() {
    SimulationConfig c = testing::undamped();
    c.timestep.automatic = false;
    c.timestep.fixed_dt = kDt;
    return c;
  }
  ParticleStore<D>& P() { return sim.particles(); }
  // Drives a and b with these velocities and spins for `steps` steps.
  void drive(const Vec<D>& va, const Vec<D>& vb, const Ang<D>& wa, const Ang<D>& wb, int steps) {
    for (int s = 0; s < steps; ++s) {
      P().vel[P().index(a)] = va, P().vel[P().index(b)] = vb;
      P().spin[P().index(a)] = wa, P().spin[P().index(b)] = wb;
      sim.step();
    }
  }
  Vec<D> force() { return P().force[P().index(b)]; }
  Ang<D> torque() { return P().torque[P().index(b)]; }
  double kn() const { return kModulus / (2 * kR); }
  double ks() const { return kn() / kRatio; }
  BondSection<D> section(double lambda = 1.0) const { return BondSection<D>::of(lambda * kR, 1.0); }
};

}  // namespace rocklab::testing::bonded
