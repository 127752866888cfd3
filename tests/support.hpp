#pragma once
// Small scene builders shared by the tests.

#include <string>

#include "lab/core/simulation.hpp"

namespace rocklab::testing {

inline Material linearMaterial(double kn, double ks, double friction, double damping_ratio = 0.0,
                               double density = 2650.0) {
  Material m;
  m.name = "linear";
  m.kn = kn;
  m.ks = ks;
  m.modulus = 0.0;  // the particle springs alone
  m.friction = friction;
  m.damping_ratio = damping_ratio;
  m.density = density;
  return m;
}

inline Material hertzMaterial(double young, double poisson, double friction,
                              double damping_ratio = 0.0, double density = 2650.0) {
  Material m;
  m.name = "hertz";
  m.young = young;
  m.poisson = poisson;
  m.friction = friction;
  m.damping_ratio = damping_ratio;
  m.density = density;
  return m;
}

// Without local damping: tests of dynamics (collisions, waves, energy) need the motion
// undamped; the core's default (PFC's 0.7) is for quasi-static loading.
inline SimulationConfig undamped() {
  SimulationConfig c;
  c.local_damping = 0.0;
  return c;
}

inline MaterialTable table(const Material& m) {
  MaterialTable t;
  t.add(m);
  return t;
}

template <int D>
ParticleId addParticle(Simulation<D>& sim, const Vec<D>& x, double r, const Vec<D>& v,
                       double density = 2650.0, std::uint16_t material = 0) {
  ParticleSpec<D> p;
  p.position = x;
  p.velocity = v;
  p.radius = r;
  p.density = density;
  p.material = material;
  return sim.particles().add(p);
}

// Six (3D) or four (2D) walls on the faces of [lo, hi], normals pointing inward.
template <int D>
void addBox(Simulation<D>& sim, const Vec<D>& lo, const Vec<D>& hi, std::uint16_t material = 0) {
  for (int d = 0; d < D; ++d) {
    Wall<D> a, b;
    a.name = std::string(1, "xyz"[d]) + "min";
    b.name = std::string(1, "xyz"[d]) + "max";
    a.normal = Vec<D>::Unit(d);
    a.point = lo;
    b.normal = -Vec<D>::Unit(d);
    b.point = hi;
    a.material = b.material = material;
    sim.addWall(a);
    sim.addWall(b);
  }
}

}  // namespace rocklab::testing
