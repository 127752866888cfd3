#pragma once
// The force loops of a contact model, templated on the law. Included only by the law
// files (contact_law_*.cpp), which instantiate them once per dimension.
//
// Determinism: the serial pass scatters each pair's force to both particles in pair
// order. The threaded pass computes the same per-pair results into buffers and each
// particle then sums them in the same pair order (first the pairs where it is the partner,
// which belong to lower rows, then its own row), so both give identical bits.

#include <cmath>

#include "lab/core/contact_model.hpp"

namespace rocklab {

template <int D, class Law>
class ContactModelImpl final : public ContactModel<D> {
 public:
  using Params = typename Law::Params;
  ContactModelImpl(std::string_view name, PairTable<Params> table, std::vector<Material> materials)
      : name_(name), table_(std::move(table)), materials_(std::move(materials)) {}

  std::string_view law() const override { return name_; }

  void computeForces(ContactPass<D>& pass) override {
    if (pass.threaded) {
      pass.track_energy ? pairLoop<true, true>(pass) : pairLoop<false, true>(pass);
      gather(pass);
    } else {
      pass.track_energy ? pairLoop<true, false>(pass) : pairLoop<false, false>(pass);
    }
    pass.track_energy ? wallLoop<true>(pass) : wallLoop<false>(pass);
  }

  std::pair<double, double> stiffness(std::uint16_t mi, std::uint16_t mj, double overlap,
                                      const ContactShape& g, double mstar) const override {
    const LawState s = Law::evaluate(table_(mi, mj), overlap, g, mstar);
    return {s.kn, s.ks};
  }

  double normalForce(std::uint16_t mi, std::uint16_t mj, double overlap,
                     const ContactShape& g) const override {
    return Law::evaluate(table_(mi, mj), overlap, g, 0.0).fn_elastic;
  }

  double strainEnergy(std::uint16_t mi, std::uint16_t mj, double overlap, const ContactShape& g,
                      double mstar, double shear_force2) const override {
    return contactStrainEnergy<Law>(table_(mi, mj), overlap, g, shear_force2, mstar);
  }

  double freeParticleStep(std::uint16_t material, const ContactShape& self, double radius,
                          double mass, double inertia, double density) const override {
    return Law::freeParticleStep(table_(material, material), self, materials_[material], radius,
                                 mass, inertia, density);
  }

 private:
  template <bool kEnergy, bool kThreaded>
  void pairLoop(ContactPass<D>& pass) {
    using V = Vec<D>;
    using A = Ang<D>;
    auto& P = pass.particles;
    auto& C = pass.contacts;
    const std::size_t n = P.size();
    const std::size_t blocks = (n + kBlockRows - 1) / kBlockRows;
    const V* pos = P.pos.data();
    const V* vel = P.vel.data();
    const A* spin = P.spin.data();
    const double* rad = P.radius.data();
    const double* im = P.inv_mass.data();
    const std::uint16_t* mat = P.material.data();
    V* force = P.force.data();
    A* torque = P.torque.data();
    const std::uint32_t* row = C.pairs.row.data();
    const std::uint32_t* col = C.pairs.col.data();
    V* shear = C.shear.data();
    const double dt = pass.dt;
    const double thickness = P.thickness;
    const double limit = pass.overlap_limit;

    auto& B = buffers_;
    B.block_friction.assign(blocks, 0.0);
    B.block_viscous.assign(blocks, 0.0);
    B.block_over.assign(blocks, 0);
    if constexpr (kThreaded) {
      const std::size_t np = C.pairs.pairs();
      B.touching.resize(np);
      B.force.resize(np);
      B.torque_i.resize(np);
      B.torque_j.resize(np);
    }

#pragma omp parallel for schedule(dynamic, 1) num_threads(pass.threads) if (kThreaded)
    for (std::size_t b = 0; b < blocks; ++b) {
      ContactDissipation diss;
      std::uint8_t over = 0;
      const std::size_t i_end = std::min(n, (b + 1) * kBlockRows);
      for (std::size_t i = b * kBlockRows; i < i_end; ++i) {
        const V xi = pos[i];
        const double ri = rad[i];
        const V vi = vel[i];
        const A wi = spin[i];
        const double imi = im[i];
        const std::uint16_t mi = mat[i];
        for (std::uint32_t p = row[i]; p < row[i + 1]; ++p) {
          const std::uint32_t j = col[p];
          const V d = pos[j] - xi;
          const double dist2 = d.squaredNorm();
          const double rj = rad[j];
          const double reach = ri + rj;
          if (dist2 >= reach * reach) {
            shear[p].setZero();
            if constexpr (kThreaded) B.touching[p] = 0;
            continue;
          }
          const double dist = std::sqrt(dist2);
          ContactKinematics<D> k;
          k.n = d / dist;
          k.overlap = reach - dist;
          const double li = ri - 0.5 * k.overlap, lj = rj - 0.5 * k.overlap;
          const A wj = spin[j];
          // Velocity of j's contact point relative to i's: v_j - v_i - (lj wj + li wi) x n.
          k.vc = vel[j] - vi - cross(A(lj * wj + li * wi), k.n);
          if constexpr (D == 3) {
            k.spin_n = 0.5 * spinAbout(A(wi + wj), k.n);
          } else {
            k.spin_n = 0.0;
          }
          k.shape = pairShape<D>(ri, rj, thickness);
          const double imsum = imi + im[j];
          k.mstar = imsum > 0.0 ? 1.0 / imsum : 0.0;
          over |= static_cast<std::uint8_t>(k.overlap > limit * std::min(ri, rj));
          const ContactResult<D> r =
              contactForce<D, Law, kEnergy>(table_(mi, mat[j]), k, shear[p], dt, diss);
          const A ti = li * r.n_cross_ft, tj = lj * r.n_cross_ft;
          if constexpr (kThreaded) {
            B.touching[p] = 1;
            B.force[p] = r.force;
            B.torque_i[p] = ti;
            B.torque_j[p] = tj;
          } else {
            force[i] -= r.force;
            force[j] += r.force;
            torque[i] -= ti;
            torque[j] -= tj;
          }
        }
      }
      B.block_friction[b] = diss.friction;
      B.block_viscous[b] = diss.viscous;
      B.block_over[b] = over;
    }
    for (std::size_t b = 0; b < blocks; ++b) {
      pass.friction += B.block_friction[b];
      pass.viscous += B.block_viscous[b];
      pass.overlap_exceeded |= B.block_over[b] != 0;
    }
  }

  void gather(ContactPass<D>& pass) {
    auto& P = pass.particles;
    auto& C = pass.contacts;
    const auto& B = buffers_;
    const std::size_t n = P.size();
#pragma omp parallel for schedule(static) num_threads(pass.threads)
    for (std::size_t k = 0; k < n; ++k) {
      Vec<D> f = P.force[k];
      Ang<D> t = P.torque[k];
      for (std::uint32_t q = C.partner_row[k]; q < C.partner_row[k + 1]; ++q) {
        const std::uint32_t p = C.partner_pair[q];
        if (!B.touching[p]) continue;
        f += B.force[p];
        t -= B.torque_j[p];
      }
      for (std::uint32_t p = C.pairs.row[k]; p < C.pairs.row[k + 1]; ++p) {
        if (!B.touching[p]) continue;
        f -= B.force[p];
        t -= B.torque_i[p];
      }
      P.force[k] = f;
      P.torque[k] = t;
    }
  }

  // Particle-wall contacts, in list order on one thread: they are few (the sample's
  // surface) and each wall's force sum must not depend on the thread count.
  template <bool kEnergy>
  void wallLoop(ContactPass<D>& pass) {
    auto& P = pass.particles;
    auto& C = pass.contacts;
    for (auto& w : pass.walls) {
      w.force.setZero();
      w.stiffness = 0.0;
      w.damping = 0.0;
      w.contacts = 0;
    }
    ContactDissipation diss;
    for (std::size_t c = 0; c < C.wall_particle.size(); ++c) {
      const std::uint32_t i = C.wall_particle[c];
      Wall<D>& w = pass.walls[C.wall_index[c]];
      const double ri = P.radius[i];
      const double overlap = ri - w.distance(P.pos[i]);
      if (overlap <= 0.0) {
        C.wall_shear[c].setZero();
        continue;
      }
      ContactKinematics<D> k;
      k.n = -w.normal;
      k.overlap = overlap;
      const double li = ri - overlap;  // the contact point lies on the rigid plane
      k.vc = w.velocity - P.vel[i] - cross(Ang<D>(li * P.spin[i]), k.n);
      if constexpr (D == 3) {
        k.spin_n = 0.5 * spinAbout(P.spin[i], k.n);
      } else {
        k.spin_n = 0.0;
      }
      k.shape = wallShape<D>(ri, P.thickness);
      k.mstar = P.inv_mass[i] > 0.0 ? 1.0 / P.inv_mass[i] : 0.0;
      pass.overlap_exceeded |= overlap > pass.overlap_limit * ri;
      const ContactResult<D> r = contactForce<D, Law, kEnergy>(table_(P.material[i], w.material), k,
                                                               C.wall_shear[c], pass.dt, diss);
      P.force[i] -= r.force;
      P.torque[i] -= li * r.n_cross_ft;
      w.force += r.force;
      w.stiffness += r.kn;
      w.damping += r.cn;
      ++w.contacts;
    }
    pass.friction += diss.friction;
    pass.viscous += diss.viscous;
  }

  std::string name_;
  PairTable<Params> table_;
  std::vector<Material> materials_;
  PairBuffers<D> buffers_;
};

template <int D, class Law>
std::unique_ptr<ContactModel<D>> bindContactLaw(std::string_view name,
                                                PairTable<typename Law::Params> table,
                                                std::vector<Material> materials) {
  return std::make_unique<ContactModelImpl<D, Law>>(name, std::move(table), std::move(materials));
}

}  // namespace rocklab
