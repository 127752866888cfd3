#include "lab/core/bond_forces.hpp"

#include <omp.h>

#include <algorithm>
#include <numeric>
#include <type_traits>

#include "lab/core/contact_model.hpp"
#include "lab/core/errors.hpp"

namespace rocklab {

void BondKind::validate() const {
  const std::string where = "bond kind '" + name + "'";
  requireRange(where, "modulus", modulus, 0.0, true, INFINITY, true, "Pa");
  requireRange(where, "stiffness_ratio", stiffness_ratio, 0.0, true, INFINITY, true, "-");
  requireRange(where, "radius_multiplier", radius_multiplier, 0.0, true, 10.0, false, "-");
  requireRange(where, "tensile_std", tensile_std, 0.0, false, INFINITY, true, "Pa");
  requireRange(where, "shear_std", shear_std, 0.0, false, INFINITY, true, "Pa");
  // A mean at or below zero with Resample would loop for ever drawing a positive strength.
  const double lo = negative == NegativeStrength::Resample ? 0.0 : -INFINITY;
  requireRange(where, "tensile_mean", tensile_mean, lo, true, INFINITY, true, "Pa");
  requireRange(where, "shear_mean", shear_mean, lo, true, INFINITY, true, "Pa");
}

template <int D>
void BondStore<D>::removeFlagged(const std::vector<std::uint8_t>& broken) {
  std::size_t out = 0;
  for (std::size_t b = 0; b < size(); ++b) {
    if (broken[b]) continue;
    if (out != b) {
      i[out] = i[b], j[out] = j[b], kind[out] = kind[b], radius[out] = radius[b];
      kn[out] = kn[b], ks[out] = ks[b], tensile[out] = tensile[b], shear[out] = shear[b];
      load[out] = load[b];
    }
    ++out;
  }
  i.resize(out), j.resize(out), kind.resize(out), radius.resize(out), kn.resize(out);
  ks.resize(out), tensile.resize(out), shear.resize(out), load.resize(out);
}

template <int D>
void BondStore<D>::sortByParticles() {
  std::vector<std::uint32_t> order(size());
  std::iota(order.begin(), order.end(), 0u);
  auto key = [&](std::uint32_t b) { return std::uint64_t{i[b]} << 32 | j[b]; };
  if (std::is_sorted(order.begin(), order.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); })) {
    return;
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
  auto apply = [&](auto& v) {
    std::remove_reference_t<decltype(v)> out(v.size());
    for (std::size_t k = 0; k < order.size(); ++k) out[k] = v[order[k]];
    v.swap(out);
  };
  apply(i), apply(j), apply(kind), apply(radius), apply(kn), apply(ks), apply(tensile);
  apply(shear), apply(load);
}

template <int D>
void BondForces<D>::buildRows(std::size_t particles, BondStore<D>& bonds) {
  bonds.sortByParticles();
  row_.assign(particles + 1, 0);
  partner_row_.assign(particles + 1, 0);
  for (std::size_t b = 0; b < bonds.size(); ++b) {
    ++row_[bonds.i[b] + 1];
    ++partner_row_[bonds.j[b] + 1];
  }
  for (std::size_t k = 0; k < particles; ++k) {
    row_[k + 1] += row_[k];
    partner_row_[k + 1] += partner_row_[k];
  }
  partner_.resize(bonds.size());
  std::vector<std::uint32_t> fill(partner_row_.begin(), partner_row_.end() - 1);
  for (std::uint32_t b = 0; b < bonds.size(); ++b) partner_[fill[bonds.j[b]]++] = b;
  rows_valid_ = true;
}

// One bond's step. A bond at or past its strength breaks now and carries nothing more (the
// larger ratio of stress to strength names the mode when both are reached).
template <int D>
typename BondForces<D>::Kept BondForces<D>::evaluate(const BondPass<D>& pass,
                                                     std::uint32_t b) const {
  const auto& P = pass.particles;
  auto& B = pass.bonds;
  const std::uint32_t i = B.i[b], j = B.j[b];
  const Vec<D> d = P.pos[j] - P.pos[i];
  const double dist = d.norm();
  BondKinematics<D> k;
  k.n = d * (1.0 / dist);
  const double overlap = P.radius[i] + P.radius[j] - dist;  // < 0: a gap
  const double li = P.radius[i] - 0.5 * overlap, lj = P.radius[j] - 0.5 * overlap;
  k.vc = P.vel[j] - P.vel[i] - cross(Ang<D>(lj * P.spin[j] + li * P.spin[i]), k.n);
  k.dspin = P.spin[j] - P.spin[i];
  if constexpr (D == 3) {
    k.spin_n = 0.5 * spinAbout(Ang<D>(P.spin[i] + P.spin[j]), k.n);
  } else {
    k.spin_n = 0.0;
  }
  const auto section = BondSection<D>::of(B.radius[b], P.thickness);
  const BondResult<D> r = bondForce<D>(section, B.kn[b], B.ks[b], k, B.load[b], pass.dt);
  Kept out;
  if (pass.breakable && (r.tensile >= B.tensile[b] || r.shear >= B.shear[b])) {
    const double rt = r.tensile / B.tensile[b], rs = r.shear / B.shear[b];
    const bool tensile = r.tensile >= B.tensile[b] && (r.shear < B.shear[b] || rt >= rs);
    out.broken = true;
    out.mode = tensile ? BondBreakMode::Tensile : BondBreakMode::Shear;
    out.stress = tensile ? r.tensile : r.shear;
    return out;
  }
  const Ang<D> ncf = cross(k.n, B.load[b].fs);
  out.force = r.force;
  out.torque_i = li * ncf + r.moment;
  out.torque_j = r.moment - lj * ncf;
  return out;
}

template <int D>
void BondForces<D>::serialPass(BondPass<D>& pass) {
  auto& P = pass.particles;
  const auto& B = pass.bonds;
  for (std::uint32_t b = 0; b < B.size(); ++b) {
    const Kept r = evaluate(pass, b);
    if (r.broken) {
      pass.broken.push_back(b);
      pass.modes.push_back(r.mode);
      pass.stresses.push_back(r.stress);
      continue;
    }
    P.force[B.i[b]] -= r.force;
    P.force[B.j[b]] += r.force;
    P.torque[B.i[b]] -= r.torque_i;
    P.torque[B.j[b]] += r.torque_j;
  }
}

template <int D>
void BondForces<D>::threadedPass(BondPass<D>& pass) {
  auto& P = pass.particles;
  const auto& B = pass.bonds;
  const std::size_t n = P.size();
  const int threads = pass.threads;
  // Runs of whole blocks of rows with about the same number of bonds each.
  const std::size_t blocks = (n + kBlockRows - 1) / kBlockRows;
  range_.assign(threads + 1, n);
  range_[0] = 0;
  std::size_t blk = 0;
  for (int t = 1; t < threads; ++t) {
    const double target = static_cast<double>(B.size()) * t / threads;
    while (blk < blocks && row_[std::min(n, blk * kBlockRows)] < target) ++blk;
    range_[t] = std::min(n, blk * kBlockRows);
  }
  own_cross_.resize(threads);
  thread_breaks_.resize(threads);
  cross_start_.assign(threads + 1, 0);

#pragma omp parallel num_threads(threads)
  {
    const int t = omp_get_thread_num();
    const std::size_t lo = range_[t], hi = range_[t + 1];
    auto& own = own_cross_[t];
    own.clear();
    for (std::size_t i = lo; i < hi; ++i) {
      std::uint32_t s = row_[i + 1];
      while (s > row_[i] && B.j[s - 1] >= hi) --s;
      for (std::uint32_t b = s; b < row_[i + 1]; ++b) own.push_back(b);
    }
#pragma omp barrier
#pragma omp single
    {
      cross_.clear();
      for (int u = 0; u < threads; ++u) {
        cross_start_[u] = cross_.size();
        cross_.insert(cross_.end(), own_cross_[u].begin(), own_cross_[u].end());
      }
      cross_start_[threads] = cross_.size();
      cross_kept_.resize(cross_.size());
    }
#pragma omp for schedule(static)
    for (std::size_t g = 0; g < cross_.size(); ++g) cross_kept_[g] = evaluate(pass, cross_[g]);

    // The partners' shares of lower threads' bonds first, then the rows in bond order.
    const std::uint32_t first = row_[lo];
    for (std::size_t k = lo; k < hi; ++k) {
      for (std::uint32_t q = partner_row_[k]; q < partner_row_[k + 1]; ++q) {
        const std::uint32_t b = partner_[q];
        if (b >= first) break;
        const auto g = std::lower_bound(cross_.begin(), cross_.end(), b) - cross_.begin();
        const Kept& r = cross_kept_[g];
        if (r.broken) continue;
        P.force[k] += r.force;
        P.torque[k] += r.torque_j;
      }
    }
    auto& breaks = thread_breaks_[t];
    breaks.clear();
    std::size_t g = cross_start_[t];
    for (std::size_t i = lo; i < hi; ++i) {
      for (std::uint32_t b = row_[i]; b < row_[i + 1]; ++b) {
        const std::uint32_t j = B.j[b];
        const bool cross = j >= hi;
        const Kept r = cross ? cross_kept_[g++] : evaluate(pass, b);
        if (r.broken) {
          breaks.push_back({b, r.mode, r.stress});
          continue;
        }
        P.force[i] -= r.force;
        P.torque[i] -= r.torque_i;
        if (cross) continue;
        P.force[j] += r.force;
        P.torque[j] += r.torque_j;
      }
    }
  }
  for (const auto& breaks : thread_breaks_) {
    for (const Break& e : breaks) {
      pass.broken.push_back(e.bond);
      pass.modes.push_back(e.mode);
      pass.stresses.push_back(e.stress);
    }
  }
}

template <int D>
void BondForces<D>::compute(BondPass<D>& pass) {
  if (!rows_valid_) buildRows(pass.particles.size(), pass.bonds);
  pass.threaded ? threadedPass(pass) : serialPass(pass);
}

template struct BondStore<2>;
template struct BondStore<3>;
template class BondForces<2>;
template class BondForces<3>;

}  // namespace rocklab
