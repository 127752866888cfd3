// Simulation: clump dynamics (rigid bodies of pebbles, PFC's clumps): building a clump from
// its pebbles, integrating the bodies (velocity Verlet on the angular momentum, quaternion
// orientation), and breaking overloaded clumps back into their pebbles.

#include "lab/core/simulation.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "lab/core/errors.hpp"
#include "lab/core/local_damping.hpp"
#include "lab/core/simulation_touching.hpp"

namespace rocklab {

template <int D>
std::uint32_t Simulation<D>::addClump(const std::vector<ParticleId>& pebbles, double strength,
                                      int resolution) {
  auto& P = particles_;
  auto& K = clumps_;
  if (pebbles.empty()) throw std::invalid_argument("a clump needs at least one pebble");
  requireRange("clump", "strength", strength, 0.0, false, INFINITY, true, "Pa");
  ClumpShape<D> shape;
  std::vector<std::size_t> members;
  double density = -1.0, msum = 0.0;
  V momentum = V::Zero();
  for (const ParticleId id : pebbles) {
    const std::size_t i = P.index(id);
    if (P.body[i] != kNoBody || std::find(members.begin(), members.end(), i) != members.end()) {
      throw std::invalid_argument("particle slot " + std::to_string(id.slot) +
                                  " is already a pebble of a clump");
    }
    if (P.inv_mass[i] == 0.0) {
      throw std::invalid_argument("a fixed or driven particle cannot join a clump");
    }
    const double m = 1.0 / P.physical_inv_mass[i], rho = m / P.volume(i);
    if (density < 0.0) density = rho;
    if (std::abs(rho - density) > 1e-9 * density) {
      throw std::invalid_argument("the pebbles of a clump must have one density");
    }
    shape.centers.push_back(P.pos[i]);
    shape.radii.push_back(P.radius[i]);
    momentum += m * P.vel[i];
    msum += m;
    members.push_back(i);
  }
  if (strength > 0.0) {
    // Released pebbles interact again: overlapping ones would fly apart.
    for (std::size_t a = 0; a < members.size(); ++a) {
      for (std::size_t b = a + 1; b < members.size(); ++b) {
        const double gap =
            (shape.centers[a] - shape.centers[b]).norm() - shape.radii[a] - shape.radii[b];
        if (gap < -0.01 * std::min(shape.radii[a], shape.radii[b])) {
          throw std::invalid_argument(
              "a breakable clump (strength > 0) needs pebbles that overlap by at most 1% of "
              "the smaller radius: released, overlapping pebbles would repel each other");
        }
      }
    }
  }
  const MassProperties<D> mp = massProperties<D>(shape, density, P.thickness, resolution);
  const auto c = static_cast<std::uint32_t>(K.size());
  Orientation<D> q;
  A principal;
  Eigen::Matrix<double, D, D> R = Eigen::Matrix<double, D, D>::Identity();
  double diameter;
  if constexpr (D == 2) {
    q = 0.0;
    principal = mp.inertia;
    diameter = 2.0 * std::sqrt(mp.volume / P.thickness / std::numbers::pi);
  } else {
    // Principal frame: the eigenvectors of the inertia tensor, right-handed.
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(mp.inertia);
    R = es.eigenvectors();
    if (R.determinant() < 0.0) R.col(2) *= -1.0;
    principal = es.eigenvalues();
    const Eigen::Quaterniond qq(R);
    q = {qq.w(), qq.x(), qq.y(), qq.z()};
    diameter = std::cbrt(6.0 * mp.volume / std::numbers::pi);
  }
  // The body takes the pebbles' momentum and their angular momentum about its centroid.
  const V v = momentum / msum;
  A L = angZero<A>();
  for (const std::size_t i : members) {
    const double m = 1.0 / P.physical_inv_mass[i];
    L += m * cross(V(P.pos[i] - mp.centroid), V(P.vel[i] - v)) +
         P.spin[i] / P.physical_inv_inertia[i];
  }
  K.pos.push_back(mp.centroid);
  K.vel.push_back(v);
  K.spin.push_back(spinOf(L, principal, q));
  K.momentum.push_back(L);
  K.orientation.push_back(q);
  K.principal.push_back(principal);
  K.mass.push_back(mp.mass);
  K.volume.push_back(mp.volume);
  K.strength.push_back(strength);
  K.diameter.push_back(diameter);
  K.alive.push_back(1);
  K.force.push_back(V::Zero());
  K.damp_force.push_back(V::Zero());
  K.torque.push_back(angZero<A>());
  K.damp_torque.push_back(angZero<A>());
  double imin;
  if constexpr (D == 2) {
    imin = principal;
  } else {
    imin = principal.minCoeff();
  }
  for (const std::size_t i : members) {
    K.member_slot.push_back(P.slot_of[i]);
    K.member_offset.push_back(R.transpose() * (P.pos[i] - mp.centroid));
    P.body[i] = c;
    // The body's mass and smallest moment: what a contact on the pebble moves (viscous
    // damping's effective mass).
    P.setMass(i, mp.mass, imin);
  }
  K.first.push_back(static_cast<std::uint32_t>(K.member_slot.size()));
  placePebbles(c, false);
  invalidateNeighbors();
  return c;
}

template <int D>
void Simulation<D>::placePebbles(std::uint32_t c, bool positions) {
  auto& P = particles_;
  const auto& K = clumps_;
  const auto R = rotationOf(K.orientation[c]);
  for (std::uint32_t k = K.first[c]; k < K.first[c + 1]; ++k) {
    const std::size_t i = P.indexOfSlot(K.member_slot[k]);
    const V r = R * K.member_offset[k];
    if (positions) P.pos[i] = K.pos[c] + r;
    P.vel[i] = K.vel[c] + cross(K.spin[c], r);
    P.spin[i] = K.spin[c];
  }
}

template <int D>
void Simulation<D>::integrateClumpsFirstHalf(double& max_speed) {
  auto& P = particles_;
  auto& K = clumps_;
  const double dt = dt_, h = 0.5 * dt_;
  for (std::uint32_t c = 0; c < K.size(); ++c) {
    if (!K.alive[c]) continue;
    K.vel[c] += (h / K.mass[c]) * V(K.force[c] + K.damp_force[c]);
    K.momentum[c] += h * (K.torque[c] + K.damp_torque[c]);
    K.orientation[c] = advanceOrientation(K.orientation[c], K.momentum[c], K.principal[c], dt);
    K.pos[c] += dt * K.vel[c];
    K.spin[c] = spinOf(K.momentum[c], K.principal[c], K.orientation[c]);
    placePebbles(c, true);
    double reach = 0.0;
    for (std::uint32_t k = K.first[c]; k < K.first[c + 1]; ++k) {
      const std::size_t i = P.indexOfSlot(K.member_slot[k]);
      reach = std::max(reach, K.member_offset[k].norm());
      P.force[i].setZero();
      P.torque[i] = angZero<A>();
    }
    max_speed = std::max(max_speed, K.vel[c].norm() + angNorm(K.spin[c]) * reach);
  }
}

template <int D>
void Simulation<D>::gatherClumpLoad(std::uint32_t c) {
  const auto& P = particles_;
  auto& K = clumps_;
  V f = V::Zero();
  for (int d = 0; d < D; ++d) f[d] = K.mass[c] * config_.gravity[d];
  A t = angZero<A>();
  for (std::uint32_t k = K.first[c]; k < K.first[c + 1]; ++k) {
    const std::size_t i = P.indexOfSlot(K.member_slot[k]);
    f += P.force[i];
    t += P.torque[i] + cross(V(P.pos[i] - K.pos[c]), P.force[i]);
  }
  K.force[c] = f;
  K.torque[c] = t;
}

template <int D>
void Simulation<D>::integrateClumpsSecondHalf(double& kinetic, double& damping, double& body_work) {
  auto& K = clumps_;
  const double h = 0.5 * dt_, alpha = config_.local_damping;
  V g = V::Zero();
  for (int d = 0; d < D; ++d) g[d] = config_.gravity[d];
  for (std::uint32_t c = 0; c < K.size(); ++c) {
    if (!K.alive[c]) continue;
    gatherClumpLoad(c);
    const V f = K.force[c];
    const A t = K.torque[c];
    body_work += (K.mass[c] * g).dot(K.vel[c]) * dt_;  // over the drift x += v dt
    V fd = V::Zero();
    A td = angZero<A>();
    if (alpha > 0.0) {
      fd = localDamping(f, K.vel[c], alpha);
      td = localDamping(t, K.spin[c], alpha);
    }
    K.damp_force[c] = fd;
    K.damp_torque[c] = td;
    K.vel[c] += (h / K.mass[c]) * V(f + fd);
    K.momentum[c] += h * (t + td);
    K.spin[c] = spinOf(K.momentum[c], K.principal[c], K.orientation[c]);
    placePebbles(c, false);
    kinetic +=
        0.5 * K.mass[c] * K.vel[c].squaredNorm() + rotationalEnergy(K.spin[c], K.momentum[c]);
    if (alpha > 0.0) damping -= (fd.dot(K.vel[c]) + angDot(td, K.spin[c])) * dt_;
  }
}

template <int D>
void Simulation<D>::breakOverloadedClumps() {
  auto& K = clumps_;
  bool breakable = false;
  for (std::uint32_t c = 0; c < K.size() && !breakable; ++c) {
    breakable = K.alive[c] && K.strength[c] > 0.0;
  }
  if (!breakable) return;
  const auto& P = particles_;
  std::vector<double> fmax(K.size(), 0.0);
  forEachTouching([&](const Touching& t) {
    const double fn = model_->normalForce(t.mi, t.mj, t.overlap, t.shape);
    for (const std::size_t i : {t.i, t.j}) {
      if (P.body[i] != kNoBody) fmax[P.body[i]] = std::max(fmax[P.body[i]], fn);
    }
  });
  for (std::uint32_t c = 0; c < K.size(); ++c) {
    if (!K.alive[c] || K.strength[c] <= 0.0) continue;
    const double stress = fmax[c] / (K.diameter[c] * K.diameter[c]);
    if (stress < K.strength[c]) continue;
    clump_breaks_.push_back({step_, time_, K.pos[c], c, K.first[c + 1] - K.first[c], stress});
    releaseClump(c);
  }
}

template <int D>
void Simulation<D>::releaseClump(std::uint32_t c) {
  auto& P = particles_;
  auto& K = clumps_;
  if (c >= K.size() || !K.alive[c]) {
    throw std::invalid_argument("clump " + std::to_string(c) + " does not exist or is broken");
  }
  placePebbles(c, false);
  const double density = K.mass[c] / K.volume[c];
  double after = 0.0;
  for (std::uint32_t k = K.first[c]; k < K.first[c + 1]; ++k) {
    const std::size_t i = P.indexOfSlot(K.member_slot[k]);
    const double m = density * P.volume(i), inertia = particleInertia<D>(m, P.radius[i]);
    P.body[i] = kNoBody;
    P.setMass(i, m, inertia);
    if (!damp_force_.empty()) {
      damp_force_[i].setZero();
      damp_torque_[i] = angZero<A>();
    }
    after += 0.5 * m * P.vel[i].squaredNorm() + 0.5 * inertia * angDot(P.spin[i], P.spin[i]);
  }
  const double before =
      0.5 * K.mass[c] * K.vel[c].squaredNorm() + rotationalEnergy(K.spin[c], K.momentum[c]);
  ledger_.clump_release += before - after;
  K.alive[c] = 0;
  contacts_.valid = false;  // the pebbles now meet each other: new candidate pairs
}

#define ROCKLAB_CLUMPS(D)                                                                      \
  template std::uint32_t Simulation<D>::addClump(const std::vector<ParticleId>&, double, int); \
  template void Simulation<D>::placePebbles(std::uint32_t, bool);                              \
  template void Simulation<D>::integrateClumpsFirstHalf(double&);                              \
  template void Simulation<D>::gatherClumpLoad(std::uint32_t);                                 \
  template void Simulation<D>::integrateClumpsSecondHalf(double&, double&, double&);           \
  template void Simulation<D>::breakOverloadedClumps();                                        \
  template void Simulation<D>::releaseClump(std::uint32_t);
ROCKLAB_CLUMPS(2)
ROCKLAB_CLUMPS(3)
#undef ROCKLAB_CLUMPS

}  // namespace rocklab
