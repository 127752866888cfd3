#pragma once
// The force loops of a contact model, templated on the law. Included only by the law
// files (contact_law_*.cpp), which instantiate them once per dimension.
//
// Determinism: the serial pass scatters each pair's force to both particles in pair
// order. The threaded pass gives each thread a run of whole blocks of rows and the same
// order: a thread scatters directly within its rows; a pair reaching past its last row (a
// "cross" pair, near the boundary between runs) is computed first into a buffer, its
// partner's share added by the partner's thread before anything else (those pairs belong
// to lower rows, so they come first in pair order) and its own share in its place in the
// row. Pairs have j > i and rows list partners ascending (neighbors.cpp).

#include <omp.h>

#include <algorithm>
#include <bit>
#include <cmath>

#include "lab/core/contact_lanes.hpp"
#include "lab/core/contact_model.hpp"

namespace rocklab {

template <int D, class Law>
class ContactModelImpl final : public ContactModel<D> {
 public:
  using Params = typename Law::Params;
  ContactModelImpl(std::string_view name, PairTable<Params> table, std::vector<Material> materials)
      : name_(name), table_(std::move(table)), materials_(std::move(materials)) {}

  std::string_view law() const override { return name_; }
  const std::vector<std::size_t>& threadRows() const override { return buffers_.range; }

  void computeForces(ContactPass<D>& pass) override {
    if (pass.threaded) {
      pass.track_energy ? threadedPairLoop<true>(pass) : threadedPairLoop<false>(pass);
    } else {
      pass.track_energy ? serialPairLoop<true>(pass) : serialPairLoop<false>(pass);
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
  using V = Vec<D>;
  using A = Ang<D>;

  // What the pair loops read, as plain pointers (hoisted out of the loops).
  struct PairView {
    const V* pos;
    const V* vel;
    const A* spin;
    const double* radius;
    const double* inv_mass;
    const std::uint16_t* material;
    const std::uint32_t* col;
    V* shear;
    double dt, thickness, overlap_limit;
  };

  static PairView viewOf(ContactPass<D>& pass) {
    const auto& P = pass.particles;
    auto& C = pass.contacts;
    return {P.pos.data(),      P.vel.data(),      P.spin.data(),      P.radius.data(),
            P.inv_mass.data(), P.material.data(), C.pairs.col.data(), C.shear.data(),
            pass.dt,           P.thickness,       pass.overlap_limit};
  }

  // Particle i of a row, read once for all its pairs (the force stores could alias the
  // arrays, so the compiler would read them again for every pair).
  struct RowParticle {
    V x, v;
    A w;
    double r, inv_mass;
    std::uint16_t material;
  };

  static RowParticle rowParticle(const PairView& v, std::size_t i) {
    return {v.pos[i], v.vel[i], v.spin[i], v.radius[i], v.inv_mass[i], v.material[i]};
  }

  // Pair p of row i: hands j, its force on j and its torques on i and j to `apply`; false (and
  // the history cleared) when the pair does not touch.
  template <bool kEnergy, class Apply>
  [[gnu::always_inline]] bool interact(const PairView& v, const RowParticle& a, std::uint32_t p,
                                       ContactDissipation& diss, bool& over, Apply&& apply) const {
    const std::uint32_t j = v.col[p];
    const V d = v.pos[j] - a.x;
    const double dist2 = d.squaredNorm();
    const double ri = a.r, rj = v.radius[j];
    const double reach = ri + rj;
    if (dist2 >= reach * reach) {
      v.shear[p].setZero();
      return false;
    }
    const double dist = std::sqrt(dist2);
    ContactKinematics<D> k;
    k.n = d / dist;
    k.overlap = reach - dist;
    const double li = ri - 0.5 * k.overlap, lj = rj - 0.5 * k.overlap;
    const A wj = v.spin[j];
    // Velocity of j's contact point relative to i's: v_j - v_i - (lj wj + li wi) x n.
    k.vc = v.vel[j] - a.v - cross(A(lj * wj + li * a.w), k.n);
    if constexpr (D == 3) {
      k.spin_n = 0.5 * spinAbout(A(a.w + wj), k.n);
    } else {
      k.spin_n = 0.0;
    }
    k.shape = pairShape<D>(ri, rj, v.thickness);
    const double imsum = a.inv_mass + v.inv_mass[j];
    k.mstar = imsum > 0.0 ? 1.0 / imsum : 0.0;
    over |= k.overlap > v.overlap_limit * std::min(ri, rj);
    const ContactResult<D> r =
        contactForce<D, Law, kEnergy>(table_(a.material, v.material[j]), k, v.shear[p], v.dt, diss);
    const A ti = li * r.n_cross_ft, tj = lj * r.n_cross_ft;
    apply(j, r.force, ti, tj);
    return true;
  }

  // A pair's force and torques onto both particles, in the serial pass's order.
  [[gnu::always_inline]] static void scatter(V* force, A* torque, std::size_t i, std::uint32_t j,
                                             const V& f, const A& ti, const A& tj) {
    force[i] -= f;
    force[j] += f;
    torque[i] -= ti;
    torque[j] -= tj;
  }

  // Touching pairs gathered for the lane pass, in pair order, as many as the lanes take.
  struct LaneGroup {
    std::uint32_t is[8], js[8], ps[8];
    const Params* params[8];
    int n = 0;
  };

  // The lanes the pass runs its touching pairs in: 8, 4, or 0 (one pair at a time), the
  // widest the law, the CPU and the pass allow.
  int laneWidth(const ContactPass<D>& pass) const {
    if (!lanes::LaneLaw<Law>::value) return 0;
    if (pass.lane_width >= 8 && lanes::wide()) return 8;
    if (pass.lane_width >= 4 && lanes::available()) return 4;
    return 0;
  }

  // Pair p of row i (particle a) into the group's next slot; it counts (the group grows)
  // only if it touches, by the scalar path's test, so both paths take the same pairs. A pair
  // out of reach loses its history. Nothing branches on the touch: about half the candidates
  // touch, in no order a predictor learns, and the mispredicted branch per candidate cost
  // more than its test (perf on the bench scene).
  [[gnu::always_inline]] bool collect(LaneGroup& g, const PairView& v, const RowParticle& a,
                                      std::size_t i, std::uint32_t p, std::uint32_t j) const {
    const V d = v.pos[j] - a.x;
    const double reach = a.r + v.radius[j];
    const bool touch = !(d.squaredNorm() >= reach * reach);
    keepOnly(v.shear[p], touch);
    g.is[g.n] = static_cast<std::uint32_t>(i);
    g.js[g.n] = j;
    g.ps[g.n] = p;
    g.params[g.n] = &table_(a.material, v.material[j]);
    g.n += touch;
    return touch;
  }

  // v where keep, else +0 in every component (as setZero), without a branch.
  [[gnu::always_inline]] static void keepOnly(V& v, bool keep) {
    const std::uint64_t mask = 0 - static_cast<std::uint64_t>(keep);
    for (int c = 0; c < D; ++c) {
      v[c] = std::bit_cast<double>(std::bit_cast<std::uint64_t>(v[c]) & mask);
    }
  }

  // The group's pairs in `width` lanes, then each applied in order, with its dissipation, as
  // interact() would have (a short group repeats its first pair in the empty lanes). Only
  // called where laneWidth() is not 0.
  template <bool kEnergy, class Apply>
  void flush(const PairView& v, LaneGroup& g, int width, ContactDissipation& diss, bool& over,
             Apply&& apply) const {
    lanePass<kEnergy>(
        v, g, width, [&](int) -> ContactDissipation& { return diss; }, over,
        [&](int, std::uint32_t i, std::uint32_t j, const V& f, const A& ti, const A& tj) {
          apply(i, j, f, ti, tj);
        });
  }

  // The same for pairs kept apart (the threaded pass's cross pairs): lane k's dissipation
  // goes to dissOf(k) and its force to apply(k, ...).
  template <bool kEnergy, class DissOf, class Apply>
  void lanePass(const PairView& v, LaneGroup& g, int width, DissOf&& dissOf, bool& over,
                Apply&& apply) const {
    if constexpr (lanes::LaneLaw<Law>::value) {
      if (g.n == 0) return;
      if (width == 8) {
        inLanes<lanes::avx512::ContactsOut, kEnergy>(v, g, dissOf, over, apply);
      } else {
        inLanes<lanes::avx::ContactsOut, kEnergy>(v, g, dissOf, over, apply);
      }
    }
  }

  template <class Out, bool kEnergy, class DissOf, class Apply>
  void inLanes(const PairView& v, LaneGroup& g, DissOf&& dissOf, bool& over, Apply&& apply) const {
    for (int k = g.n; k < Out::width; ++k) {
      g.is[k] = g.is[0], g.js[k] = g.js[0], g.ps[k] = g.ps[0], g.params[k] = g.params[0];
    }
    Out out;
    if constexpr (Out::width == 8) {
      lanes::avx512::contacts<D, Law, kEnergy>(v, g.is, g.js, g.ps, g.params, g.n, out);
    } else {
      lanes::avx::contacts<D, Law, kEnergy>(v, g.is, g.js, g.ps, g.params, g.n, out);
    }
    for (int k = 0; k < g.n; ++k) {
      if constexpr (kEnergy) {
        ContactDissipation& diss = dissOf(k);
        if ((out.sliding >> k) & 1) diss.friction -= out.friction[k];
        diss.viscous += out.viscous[k];
      }
      over |= ((out.over >> k) & 1) != 0;
      V f;
      A ti, tj;
      for (int c = 0; c < D; ++c) f[c] = out.force[c][k];
      if constexpr (D == 3) {
        ti = A(out.ti[0][k], out.ti[1][k], out.ti[2][k]);
        tj = A(out.tj[0][k], out.tj[1][k], out.tj[2][k]);
      } else {
        ti = out.ti[0][k];
        tj = out.tj[0][k];
      }
      apply(k, g.is[k], g.js[k], f, ti, tj);
    }
    g.n = 0;
  }

  void storeBlock(std::size_t b, const ContactDissipation& diss, bool over) {
    buffers_.block_friction[b] = diss.friction;
    buffers_.block_viscous[b] = diss.viscous;
    buffers_.block_over[b] = over;
  }

  void addBlockSums(ContactPass<D>& pass, std::size_t blocks) const {
    const auto& B = buffers_;
    for (std::size_t b = 0; b < blocks; ++b) {
      pass.friction += B.block_friction[b];
      pass.viscous += B.block_viscous[b];
      pass.overlap_exceeded |= B.block_over[b] != 0;
    }
  }

  void resetBlockSums(std::size_t blocks) {
    buffers_.block_friction.assign(blocks, 0.0);
    buffers_.block_viscous.assign(blocks, 0.0);
    buffers_.block_over.assign(blocks, 0);
  }

  // Rows [r0, r1) of a block in pair order, `width` pairs at a time (0: one at a time, by
  // interact()); a pair whose partner is at or past `cross_from` was computed apart (by the
  // threaded pass) and hands its row to crossPair(i, diss) in its place. Returns the touching
  // pairs, cross pairs apart.
  template <bool kEnergy, class CrossPair>
  std::uint32_t blockRows(const PairView& v, const std::uint32_t* row, std::size_t r0,
                          std::size_t r1, std::size_t cross_from, int width,
                          ContactDissipation& diss, bool& over, V* force, A* torque,
                          CrossPair&& crossPair) const {
    const bool lanes_on = width > 0;
    LaneGroup group;
    const auto apply = [&](std::uint32_t i, std::uint32_t j, const V& f, const A& ti, const A& tj) {
      scatter(force, torque, i, j, f, ti, tj);
    };
    std::uint32_t touching = 0;
    for (std::size_t i = r0; i < r1; ++i) {
      const RowParticle a = rowParticle(v, i);
      for (std::uint32_t p = row[i]; p < row[i + 1]; ++p) {
        const std::uint32_t j = v.col[p];
        if (j >= cross_from) {
          // The pending pairs come first in pair order: theirs before this one's share.
          if (lanes_on) flush<kEnergy>(v, group, width, diss, over, apply);
          crossPair(i, diss);
          continue;
        }
        if (lanes_on) {
          touching += collect(group, v, a, i, p, j);
          if (group.n == width) flush<kEnergy>(v, group, width, diss, over, apply);
          continue;
        }
        touching += interact<kEnergy>(v, a, p, diss, over,
                                      [&](std::uint32_t, const V& f, const A& ti, const A& tj) {
                                        scatter(force, torque, i, j, f, ti, tj);
                                      });
      }
    }
    if (lanes_on) flush<kEnergy>(v, group, width, diss, over, apply);
    return touching;
  }

  template <bool kEnergy>
  void serialPairLoop(ContactPass<D>& pass) {
    auto& P = pass.particles;
    const std::uint32_t* row = pass.contacts.pairs.row.data();
    const std::size_t n = P.size();
    const std::size_t blocks = (n + kBlockRows - 1) / kBlockRows;
    resetBlockSums(blocks);
    const PairView v = viewOf(pass);
    V* force = P.force.data();
    A* torque = P.torque.data();
    const int width = laneWidth(pass);
    for (std::size_t b = 0; b < blocks; ++b) {
      ContactDissipation diss;
      bool over = false;  // not a uint8_t: a char store may alias anything
      blockRows<kEnergy>(v, row, b * kBlockRows, std::min(n, (b + 1) * kBlockRows), n, width, diss,
                         over, force, torque, [](std::size_t, ContactDissipation&) {});
      storeBlock(b, diss, over);
    }
    addBlockSums(pass, blocks);
  }

  // Runs of whole blocks, one per thread, each of the cost its thread's pace gets through in
  // the same time. A touching pair costs some 25 times a pair out of reach, so a block's cost
  // is its touching pairs of the last step (its pair count when there is none). The paces are
  // measured: on a shared machine one core runs slower than the other for seconds at a time
  // (on the 2-core virtual machine of the benchmarks, either of them by up to 40%), and an
  // even split left the faster thread waiting at the end of every pass. Where the runs meet
  // changes nothing in the results, only who computes what.
  void splitRows(std::size_t n, std::size_t blocks, int threads, const std::uint32_t* row) {
    auto& B = buffers_;
    std::vector<double>& cost = B.block_cost;
    if (B.block_touching.size() != blocks) B.block_touching.assign(blocks, 0);
    cost.assign(blocks + 1, 0.0);
    for (std::size_t b = 0; b < blocks; ++b) {
      const double pairs = row[std::min(n, (b + 1) * kBlockRows)] - row[b * kBlockRows];
      cost[b + 1] = cost[b] + 0.04 * pairs + B.block_touching[b];
    }
    // Unmeasured (the first threaded step, or a new thread count): even shares.
    if (B.thread_pace.size() != static_cast<std::size_t>(threads)) {
      B.thread_pace.assign(threads, 0.0);
    }
    const bool measured = std::ranges::all_of(B.thread_pace, [](double p) { return p > 0.0; });
    const auto paceOf = [&](int t) { return measured ? B.thread_pace[t] : 1.0; };
    double pace = 0.0;
    for (int t = 0; t < threads; ++t) pace += paceOf(t);
    B.range.assign(threads + 1, n);
    B.range[0] = 0;
    std::size_t b = 0;
    double share = 0.0;
    for (int t = 1; t < threads; ++t) {
      share += paceOf(t - 1) / pace;
      const double target = cost[blocks] * share;
      while (b < blocks && cost[b] < target) ++b;
      B.range[t] = std::min(n, b * kBlockRows);
    }
  }

  // Each thread's pace from the cost of its run (splitRows) and the step's seconds in it: a
  // fifth of the new reading, so a step the system interrupted moves the split little.
  void updatePace(int threads) {
    auto& B = buffers_;
    const auto block = [](std::size_t r) { return (r + kBlockRows - 1) / kBlockRows; };
    for (int t = 0; t < threads; ++t) {
      const double cost = B.block_cost[block(B.range[t + 1])] - B.block_cost[block(B.range[t])];
      if (cost <= 0.0 || B.thread_seconds[t] <= 0.0) continue;
      const double measured = cost / B.thread_seconds[t];
      double& pace = B.thread_pace[t];
      pace = pace > 0.0 ? 0.8 * pace + 0.2 * measured : measured;
    }
  }

  template <bool kEnergy>
  void threadedPairLoop(ContactPass<D>& pass) {
    auto& P = pass.particles;
    const auto& C = pass.contacts;
    const std::uint32_t* row = C.pairs.row.data();
    const std::uint32_t* col = C.pairs.col.data();
    const std::size_t n = P.size();
    const std::size_t blocks = (n + kBlockRows - 1) / kBlockRows;
    const int threads = pass.threads;
    auto& B = buffers_;
    resetBlockSums(blocks);
    splitRows(n, blocks, threads, row);
    B.own_cross.resize(threads);
    B.own_cross_row.resize(threads);
    B.cross_start.assign(threads + 1, 0);
    B.thread_over.assign(threads, 0);
    B.thread_seconds.assign(threads, 0.0);
    const PairView v = viewOf(pass);
    V* force = P.force.data();
    A* torque = P.torque.data();
    const int width = laneWidth(pass);
    const bool lanes_on = width > 0;

    // Each thread its own copy of what the loops read: through the shared frame the compiler
    // read them again for every pair (the stores into the pairs' springs could alias them).
#pragma omp parallel num_threads(threads) firstprivate(v, force, torque, row, col, width, lanes_on)
    {
      const int t = omp_get_thread_num();
      const std::size_t lo = B.range[t], hi = B.range[t + 1];
      // The cross pairs of this thread's rows: the tail of each row (partners ascend).
      auto& own = B.own_cross[t];
      auto& own_row = B.own_cross_row[t];
      own.clear();
      own_row.clear();
      for (std::size_t i = lo; i < hi; ++i) {
        std::uint32_t s = row[i + 1];
        while (s > row[i] && col[s - 1] >= hi) --s;
        for (std::uint32_t p = s; p < row[i + 1]; ++p) {
          own.push_back(p);
          own_row.push_back(static_cast<std::uint32_t>(i));
        }
      }
#pragma omp barrier
#pragma omp single
      {
        B.cross.clear();
        B.cross_row.clear();
        for (int u = 0; u < threads; ++u) {
          B.cross_start[u] = B.cross.size();
          B.cross.insert(B.cross.end(), B.own_cross[u].begin(), B.own_cross[u].end());
          B.cross_row.insert(B.cross_row.end(), B.own_cross_row[u].begin(),
                             B.own_cross_row[u].end());
        }
        B.cross_start[threads] = B.cross.size();
        B.cross_result.resize(B.cross.size());
        B.cross_index.resize(C.pairs.pairs());  // only the cross pairs' entries are read
      }
      // The cross pairs first, shared out evenly (the runs' boundaries hold most of them),
      // the touching ones four per register like the rows' (a pair's result does not depend
      // on the pairs it shares the register with).
      bool cross_over = false;
      {
        const std::size_t m = B.cross.size();
        const std::size_t first = m * t / threads, last = m * (t + 1) / threads;
        LaneGroup group;
        std::size_t slot[8];  // the group's pairs in cross_result
        const auto dissOf = [&](int k) -> ContactDissipation& {
          return B.cross_result[slot[k]].diss;
        };
        const auto store = [](KeptContact<D>& c, const V& f, const A& ti, const A& tj) {
          c.f.force = f;
          c.f.torque_i = ti;
          c.f.torque_j = tj;
        };
        const auto keep = [&](int k, std::uint32_t, std::uint32_t, const V& f, const A& ti,
                              const A& tj) { store(B.cross_result[slot[k]], f, ti, tj); };
        for (std::size_t g = first; g < last; ++g) {
          B.cross_index[B.cross[g]] = static_cast<std::uint32_t>(g);
          KeptContact<D>& c = B.cross_result[g];
          c.diss = {};
          const std::uint32_t i = B.cross_row[g], p = B.cross[g];
          const RowParticle a = rowParticle(v, i);
          if (lanes_on) {
            slot[group.n] = g;
            c.touching = collect(group, v, a, i, p, col[p]);
            if (group.n == width) lanePass<kEnergy>(v, group, width, dissOf, cross_over, keep);
            continue;
          }
          c.touching = interact<kEnergy>(
              v, a, p, c.diss, cross_over,
              [&](std::uint32_t, const V& f, const A& ti, const A& tj) { store(c, f, ti, tj); });
        }
        lanePass<kEnergy>(v, group, width, dissOf, cross_over, keep);
      }
      B.thread_over[t] = cross_over;
#pragma omp barrier  // every cross pair is ready before the partners' shares are read

      // The partners' shares of lower threads' cross pairs come first ...
      const double rows_start = omp_get_wtime();
      const std::uint32_t first_pair = row[lo];
      for (std::size_t k = lo; k < hi; ++k) {
        for (std::uint32_t q = C.partner_row[k]; q < C.partner_row[k + 1]; ++q) {
          const std::uint32_t p = C.partner_pair[q];
          if (p >= first_pair) break;
          const KeptContact<D>& c = B.cross_result[B.cross_index[p]];
          if (!c.touching) continue;
          force[k] += c.f.force;
          torque[k] -= c.f.torque_j;
        }
      }
      // ... then the rows in order, as the serial pass. A thread may have no rows (the cost
      // split gave them all to the others); its empty run starts at n, which need not be a
      // block boundary, so it must not be rounded down into the last thread's block.
      std::size_t g = B.cross_start[t];
      for (std::size_t b = lo / kBlockRows; lo < hi && b * kBlockRows < hi; ++b) {
        ContactDissipation diss;
        bool over = false;
        // A cross pair's own share, in its place in pair order.
        const auto crossPair = [&](std::size_t i, ContactDissipation& d) {
          const KeptContact<D>& kept = B.cross_result[g++];
          if (!kept.touching) return;
          if constexpr (kEnergy) {
            d.friction += kept.diss.friction;
            d.viscous += kept.diss.viscous;
          }
          force[i] -= kept.f.force;
          torque[i] -= kept.f.torque_i;
        };
        const std::uint32_t touching =
            blockRows<kEnergy>(v, row, b * kBlockRows, std::min(hi, (b + 1) * kBlockRows), hi,
                               width, diss, over, force, torque, crossPair);
        storeBlock(b, diss, over);
        B.block_touching[b] = touching;
      }
      B.thread_seconds[t] = omp_get_wtime() - rows_start;
    }
    updatePace(threads);
    addBlockSums(pass, blocks);
    for (std::uint8_t over : B.thread_over) pass.overlap_exceeded |= over != 0;
  }

  // Particle-wall contacts. The list holds a particle's contacts together; each thread
  // takes a run of whole particles and applies their forces in list order, and the walls'
  // sums are then made in list order on one thread, so no total depends on the thread
  // count.
  template <bool kEnergy>
  void wallLoop(ContactPass<D>& pass) {
    auto& P = pass.particles;
    auto& C = pass.contacts;
    auto& B = buffers_;
    const std::size_t m = C.wall_particle.size();
    const int threads = pass.threaded ? pass.threads : 1;
    B.wall_result.resize(m);
    B.wall_split.assign(threads + 1, m);
    B.wall_split[0] = 0;
    for (int t = 1; t < threads; ++t) {
      std::size_t c = std::max(B.wall_split[t - 1], m * t / threads);
      while (c > 0 && c < m && C.wall_particle[c] == C.wall_particle[c - 1]) ++c;
      B.wall_split[t] = c;
    }
    B.thread_over.assign(threads, 0);

#pragma omp parallel num_threads(threads) if (threads > 1)
    {
      const int t = omp_get_thread_num();
      std::uint8_t over = 0;
      for (std::size_t c = B.wall_split[t]; c < B.wall_split[t + 1]; ++c) {
        KeptContact<D>& kept = B.wall_result[c];
        kept.diss = {};
        const std::uint32_t i = C.wall_particle[c];
        const Wall<D>& w = pass.walls[C.wall_index[c]];
        const double ri = P.radius[i];
        const double overlap = ri - w.distance(P.pos[i]);
        kept.touching = overlap > 0.0;
        if (!kept.touching) {
          C.wall_shear[c].setZero();
          continue;
        }
        ContactKinematics<D> k;
        k.n = -w.normal;
        k.overlap = overlap;
        const double li = ri - overlap;  // the contact point lies on the rigid plane
        k.vc = w.velocity - P.vel[i] - cross(A(li * P.spin[i]), k.n);
        if constexpr (D == 3) {
          k.spin_n = 0.5 * spinAbout(P.spin[i], k.n);
        } else {
          k.spin_n = 0.0;
        }
        k.shape = wallShape<D>(ri, P.thickness);
        k.mstar = P.inv_mass[i] > 0.0 ? 1.0 / P.inv_mass[i] : 0.0;
        over |= static_cast<std::uint8_t>(overlap > pass.overlap_limit * ri);
        const ContactResult<D> r = contactForce<D, Law, kEnergy>(
            table_(P.material[i], w.material), k, C.wall_shear[c], pass.dt, kept.diss);
        P.force[i] -= r.force;
        P.torque[i] -= li * r.n_cross_ft;
        kept.f.force = r.force;
        kept.kn = r.kn;
        kept.cn = r.cn;
      }
      B.thread_over[t] = over;
    }

    for (auto& w : pass.walls) {
      w.force.setZero();
      w.stiffness = 0.0;
      w.damping = 0.0;
      w.contacts = 0;
    }
    ContactDissipation diss;
    for (std::size_t c = 0; c < m; ++c) {
      const KeptContact<D>& kept = B.wall_result[c];
      if (!kept.touching) continue;
      Wall<D>& w = pass.walls[C.wall_index[c]];
      w.force += kept.f.force;
      w.stiffness += kept.kn;
      w.damping += kept.cn;
      ++w.contacts;
      if constexpr (kEnergy) {
        diss.friction += kept.diss.friction;
        diss.viscous += kept.diss.viscous;
      }
    }
    for (std::uint8_t over : B.thread_over) pass.overlap_exceeded |= over != 0;
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
