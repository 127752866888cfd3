// Simulation: the scene's set-up and its stepping (velocity Verlet, the neighbour list, the
// force passes). The other jobs of the class live beside it: the bond stage
// (simulation_bonds.cpp), clump dynamics (simulation_clumps.cpp), state I/O
// (simulation_state.cpp) and the read-outs and instability diagnosis (simulation_readouts.cpp).

#include "lab/core/simulation.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>

#include "lab/core/contact_laws.hpp"
#include "lab/core/errors.hpp"
#include "lab/core/local_damping.hpp"
#include "lab/core/stage_clock.hpp"

namespace rocklab {

namespace {

// Runs body(i, acc) over [0, n) in fixed blocks of kBlockRows and adds the blocks' partial
// results in block order: the total is the same whatever the thread count. Each thread takes
// the run of blocks it took in the last contact pass (`rows`, ContactModel::threadRows), so
// the particle data stays in its core's cache and a slower core keeps its smaller share;
// without such runs (one thread, no threaded pass yet, a changed count), even runs.
template <class Acc, class Body>
Acc blockedSum(std::size_t n, int threads, const std::vector<std::size_t>& rows, Body body) {
  const std::size_t blocks = (n + kBlockRows - 1) / kBlockRows;
  std::vector<Acc> part(blocks);
#pragma omp parallel num_threads(threads) if (threads > 1)
  {
    // The team may be smaller than asked (a thread limit): then even runs over the team.
    const auto team = static_cast<std::size_t>(omp_get_num_threads());
    const auto t = static_cast<std::size_t>(omp_get_thread_num());
    const bool follow = rows.size() == team + 1 && rows.back() == n;
    const std::size_t first = follow ? (rows[t] + kBlockRows - 1) / kBlockRows : t * blocks / team;
    const std::size_t last =
        follow ? (rows[t + 1] + kBlockRows - 1) / kBlockRows : (t + 1) * blocks / team;
    for (std::size_t b = first; b < last; ++b) {
      Acc a{};
      const std::size_t end = std::min(n, (b + 1) * kBlockRows);
      for (std::size_t i = b * kBlockRows; i < end; ++i) body(i, a);
      part[b] = a;
    }
  }
  Acc total{};
  for (const Acc& a : part) total.merge(a);
  return total;
}

// A threaded step pays for its fork, joins and barriers and for the buffers its threads share
// (about 40 us a step on the 2-core virtual machine of the benchmarks: the bench scene on 300
// spheres took 28-36 us a step on one thread, 53-67 on two), so on a small sample a second
// thread slows the step: two threads against one, medians of 7 alternating rounds, 1,000
// spheres 0.87x, 1,500 0.91x, 2,000 1.10x, 3,000 1.14x. The particle passes therefore take a
// thread per 1,000 particles at most. The bond pass keeps config.threads: the same limit for
// it (one thread below 40,000 bonds) left the 2D quick UCS protocol's bond pass as slow, its
// particles having last been written on the other core (132 and 146 s against 157 and 147 s).
constexpr std::size_t kParticlesPerThread = 1000;

std::uint64_t packId(ParticleId id) {
  return std::uint64_t{id.slot} << 32 | id.generation;
}
std::uint64_t pairKey(std::uint32_t a, std::uint32_t b) {
  return a < b ? (std::uint64_t{a} << 32 | b) : (std::uint64_t{b} << 32 | a);
}

// Removes candidate pairs of two pebbles of one clump: a rigid body has no inner contacts.
void dropPairsWithinBodies(const std::vector<std::uint32_t>& body, PairRows& pairs) {
  std::uint32_t out = 0, begin = 0;
  for (std::size_t i = 0; i + 1 < pairs.row.size(); ++i) {
    const std::uint32_t end = pairs.row[i + 1];
    for (std::uint32_t p = begin; p < end; ++p) {
      const std::uint32_t j = pairs.col[p];
      if (body[i] != kNoBody && body[i] == body[j]) continue;
      pairs.col[out++] = j;
    }
    begin = end;
    pairs.row[i + 1] = out;
  }
  pairs.col.resize(out);
}

}  // namespace

template <int D>
Simulation<D>::Simulation(MaterialTable materials, SimulationConfig config)
    : materials_(std::move(materials)), config_(std::move(config)) {}
template <int D>
Simulation<D>::~Simulation() = default;
template <int D>
Simulation<D>::Simulation(Simulation&&) noexcept = default;
template <int D>
Simulation<D>& Simulation<D>::operator=(Simulation&&) noexcept = default;

template <int D>
std::size_t Simulation<D>::addWall(Wall<D> w) {
  const double len = w.normal.norm();
  if (!(len > 0.0) || !std::isfinite(len)) {
    throw std::invalid_argument("wall '" + w.name + "' needs a non-zero normal");
  }
  w.normal /= len;
  walls_.push_back(std::move(w));
  wall_prev_force_.push_back(V::Zero());
  invalidateNeighbors();
  return walls_.size() - 1;
}

template <int D>
void Simulation<D>::scaleRadii(double factor) {
  if (!(factor > 0.0)) throw std::invalid_argument("radius scale factor must be positive");
  double rmax = 0.0;
  for (double& r : particles_.radius) {
    r *= factor;
    rmax = std::max(rmax, r);
  }
  // Clumps grow about their centroids: the pebbles move apart with them.
  double reach = 0.0;
  for (std::uint32_t c = 0; c < clumps_.size(); ++c) {
    if (!clumps_.alive[c]) continue;
    for (std::uint32_t k = clumps_.first[c]; k < clumps_.first[c + 1]; ++k) {
      clumps_.member_offset[k] *= factor;
      reach = std::max(reach, clumps_.member_offset[k].norm());
    }
    placePebbles(c, true);
  }
  if (factor < 1.0) return;  // shrinking never brings surfaces closer
  contacts_.radius_growth += (factor - 1.0) / factor * (rmax + reach);
}

template <int D>
void Simulation<D>::setFixedTimeStep(double dt) {
  requireRange("time step", "dt", dt, 0.0, true, INFINITY, true, "s");
  config_.timestep.automatic = false;
  config_.timestep.fixed_dt = dt;
  dt_ = dt;
}

template <int D>
void Simulation<D>::replaceMaterials(MaterialTable materials) {
  if (materials.size() < materials_.size()) {
    throw std::invalid_argument("replaceMaterials: the new table has fewer materials");
  }
  materials_ = std::move(materials);
  model_.reset();
  prepared_ = false;
}

template <int D>
void Simulation<D>::prepare() {
  const std::string where = "simulation settings";
  checkFields(config_, where);
  requireRange(where, "timestep.update_interval", config_.timestep.update_interval, 1, false, 1e9,
               false, "steps");
  requireRange(where, "guard.energy_growth", config_.guard.energy_growth, 1.0, true, INFINITY, true,
               "-");
  requireRange(where, "skin", config_.skin, 0.0, false, INFINITY, true, "m");
  if (particles_.size() == 0) throw std::invalid_argument("the scene has no particles");
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    if (particles_.material[i] >= materials_.size()) {
      throw std::invalid_argument("particle " + std::to_string(i) + " names material " +
                                  std::to_string(particles_.material[i]) + ", but only " +
                                  std::to_string(materials_.size()) + " are defined");
    }
  }
  for (const auto& w : walls_) {
    if (w.material >= materials_.size()) {
      throw std::invalid_argument("wall '" + w.name + "' names an undefined material");
    }
    if (w.servo.enabled) {
      requireRange("wall '" + w.name + "' servo", "area", w.servo.area, 0.0, true, INFINITY, true,
                   "m^2");
      requireRange("wall '" + w.name + "' servo", "max_speed", w.servo.max_speed, 0.0, true,
                   INFINITY, true, "m/s");
      requireRange("wall '" + w.name + "' servo", "alpha", w.servo.alpha, 0.0, true, 1.0, false,
                   "-");
    }
  }
  if (!model_) model_ = makeContactModel<D>(config_.contact_law, materials_);
  if (contacts_.skin <= 0.0) {
    double rsum = 0.0;
    for (double r : particles_.radius) rsum += r;
    contacts_.skin = config_.skin > 0.0
                         ? config_.skin
                         : config_.skin_ratio * (rsum / static_cast<double>(particles_.size()));
  }
  if (config_.local_damping > 0.0) {
    damp_force_.resize(particles_.size(), V::Zero());
    damp_torque_.resize(particles_.size(), angZero<A>());
  }
  if (!forces_valid_) {
    if (needsRebuild()) rebuild();
    for (auto& f : particles_.force) f.setZero();
    for (auto& t : particles_.torque) t = angZero<A>();
    computeForces(0.0);
    for (std::uint32_t c = 0; c < clumps_.size(); ++c) {
      if (clumps_.alive[c]) gatherClumpLoad(c);
    }
    for (std::size_t w = 0; w < walls_.size(); ++w) wall_prev_force_[w] = walls_[w].force;
    forces_valid_ = true;
  }
  if (dt_ <= 0.0) {
    if (config_.timestep.automatic) {
      dt_ = automaticStep();
      if (!std::isfinite(dt_)) {
        throw std::invalid_argument(
            "the automatic time step needs at least one free (not fixed) particle; set "
            "timestep.fixed_dt for a scene of driven particles only");
      }
    } else {
      requireRange(where, "timestep.fixed_dt", config_.timestep.fixed_dt, 0.0, true, INFINITY, true,
                   "s");
      dt_ = config_.timestep.fixed_dt;
    }
  }
  prepared_ = true;
  if (!ledger_.started) restartEnergyLedger();
}

template <int D>
void Simulation<D>::restartEnergyLedger() {
  if (!prepared_) prepare();  // the strain energy needs the contact model and the contacts
  ledger_ = EnergyLedger{};
  const EnergyReport e = energy();
  ledger_.initial = e.kinetic() + e.strain;
  ledger_.started = true;
  kinetic_ = e.kinetic();
}

template <int D>
int Simulation<D>::particleThreads() const {
  const auto most = static_cast<int>(std::min<std::size_t>(
      particles_.size() / kParticlesPerThread, static_cast<std::size_t>(config_.threads)));
  return std::max(most, 1);
}

template <int D>
bool Simulation<D>::computeForces(double history_dt) {
  const bool gravity = config_.gravity[0] != 0.0 || config_.gravity[1] != 0.0 ||
                       (D == 3 && config_.gravity[2] != 0.0);
  if (gravity || !applied_.empty()) {
    const StageClock clock(&stages_[kBodyForces]);
    if (gravity) applyGravity(history_dt);
    if (!applied_.empty()) applyForces(history_dt);
  }
  ContactPass<D> pass{particles_,
                      contacts_,
                      walls_,
                      history_dt,
                      particleThreads() > 1,
                      particleThreads(),
                      config_.track_energy,
                      config_.guard.overlap_limit,
                      config_.contact_lane_width};
  {
    const StageClock clock(&stages_[kContacts]);
    model_->computeForces(pass);
    ledger_.friction += pass.friction;
    ledger_.viscous += pass.viscous;
  }
  if (bonds_.size() > 0) computeBondForces(history_dt);
  return pass.overlap_exceeded;
}

template <int D>
void Simulation<D>::applyGravity(double dt) {
  V g;
  for (int d = 0; d < D; ++d) g[d] = config_.gravity[d];
  auto& P = particles_;
  struct Acc {
    double work = 0.0;
    void merge(const Acc& o) { work += o.work; }
  };
  const Acc acc = blockedSum<Acc>(
      P.size(), particleThreads(), model_->threadRows(), [&](std::size_t i, Acc& a) {
        if (P.inv_mass[i] == 0.0 || P.body[i] != kNoBody) return;  // clumps: whole bodies
        const V f = g / P.physical_inv_mass[i];  // the weight: density scaling adds only inertia
        P.force[i] += f;
        a.work += f.dot(P.vel[i]) * dt;  // exact over the drift x += v dt
      });
  ledger_.body_work += acc.work;
  ledger_.positive_input += std::max(acc.work, 0.0);
}

template <int D>
void Simulation<D>::applyForces(double dt) {
  auto& P = particles_;
  struct Acc {
    double work = 0.0;
    void merge(const Acc& o) { work += o.work; }
  };
  const Acc acc = blockedSum<Acc>(
      P.size(), particleThreads(), model_->threadRows(), [&](std::size_t i, Acc& a) {
        const std::uint32_t slot = P.slot_of[i];
        if (slot >= applied_.size() || P.inv_mass[i] == 0.0) return;
        P.force[i] += applied_[slot];  // a pebble's share reaches its clump with its force
        a.work += applied_[slot].dot(P.vel[i]) * dt;  // exact over the drift x += v dt
      });
  ledger_.body_work += acc.work;
  ledger_.positive_input += std::max(acc.work, 0.0);
}

template <int D>
void Simulation<D>::initialIntegrate() {
  auto& P = particles_;
  const double dt = dt_, h = 0.5 * dt_;
  const bool damped = config_.local_damping > 0.0;
  struct Acc {
    double vmax2 = 0.0;
    void merge(const Acc& o) { vmax2 = std::max(vmax2, o.vmax2); }
  };
  const bool clumped = hasClumps();
  const Acc acc = blockedSum<Acc>(P.size(), particleThreads(), model_->threadRows(),
                                  [&](std::size_t i, Acc& a) {
                                    if (clumped && P.body[i] != kNoBody)
                                      return;  // pebbles move with their clump
                                    V f = P.force[i];
                                    A t = P.torque[i];
                                    if (damped) {
                                      f += damp_force_[i];
                                      t += damp_torque_[i];
                                    }
                                    const V v = P.vel[i] + (h * P.inv_mass[i]) * f;
                                    P.vel[i] = v;
                                    P.spin[i] += (h * P.inv_inertia[i]) * t;
                                    P.pos[i] += dt * v;
                                    P.force[i].setZero();
                                    P.torque[i] = angZero<A>();
                                    a.vmax2 = std::max(a.vmax2, v.squaredNorm());
                                  });
  double vmax = std::sqrt(acc.vmax2);
  if (clumped) integrateClumpsFirstHalf(vmax);
  contacts_.particle_travel += vmax * dt;
  double wall_step = 0.0;
  for (auto& w : walls_) {
    w.point += dt * w.velocity;
    wall_step = std::max(wall_step, std::abs(w.velocity.dot(w.normal)) * dt);
  }
  contacts_.wall_travel += wall_step;
}

template <int D>
void Simulation<D>::finalIntegrate() {
  auto& P = particles_;
  const double dt = dt_, h = 0.5 * dt_;
  const double alpha = config_.local_damping;
  const bool damped = alpha > 0.0;
  struct Acc {
    double ke_t = 0.0, ke_r = 0.0, damping = 0.0, driven = 0.0;
    void merge(const Acc& o) {
      ke_t += o.ke_t;
      ke_r += o.ke_r;
      damping += o.damping;
      driven += o.driven;
    }
  };
  const bool clumped = hasClumps();
  const Acc acc = blockedSum<Acc>(
      P.size(), particleThreads(), model_->threadRows(), [&](std::size_t i, Acc& a) {
        if (clumped && P.body[i] != kNoBody) return;
        const double im = P.inv_mass[i], ii = P.inv_inertia[i];
        if (im == 0.0) {
          // A fixed particle moves with its prescribed velocity and works on its neighbours
          // like a wall: minus the force they exert on it, times its velocity.
          a.driven -= (P.force[i].dot(P.vel[i]) + angDot(P.torque[i], P.spin[i])) * dt;
          return;
        }
        V f = P.force[i];
        A t = P.torque[i];
        V v = P.vel[i];
        A w = P.spin[i];
        V fd = V::Zero();
        A td = angZero<A>();
        if (damped) {
          fd = localDamping(f, v, alpha);
          td = localDamping(t, w, alpha);
          damp_force_[i] = fd;
          damp_torque_[i] = td;
          f += fd;
          t += td;
        }
        v += (h * im) * f;
        w += (h * ii) * t;
        P.vel[i] = v;
        P.spin[i] = w;
        a.ke_t += 0.5 * v.squaredNorm() / im;
        a.ke_r += 0.5 * angDot(w, w) / ii;
        if (damped) a.damping -= (fd.dot(v) + angDot(td, w)) * dt;
      });
  kinetic_ = acc.ke_t + acc.ke_r;
  ledger_.local_damping += acc.damping;
  if (clumped) {
    double body_work = 0.0;
    integrateClumpsSecondHalf(kinetic_, ledger_.local_damping, body_work);
    ledger_.body_work += body_work;
    ledger_.positive_input += std::max(body_work, 0.0);
  }
  ledger_.boundary_work += acc.driven;
  ledger_.positive_input += std::max(acc.driven, 0.0);
}

template <int D>
bool Simulation<D>::needsRebuild() {
  auto& C = contacts_;
  if (!C.valid || C.ref_pos.size() != particles_.size()) return true;
  auto within = [&] {
    const double move = C.particle_travel + C.radius_growth;
    return 2.0 * move <= C.skin && move + C.wall_travel <= C.skin;
  };
  if (within()) return false;
  // The summed per-step bound tripped: measure the true largest displacement before paying
  // for a rebuild (oscillating particles, as in a wave, travel far less than the bound).
  double m2 = 0.0;
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    m2 = std::max(m2, (particles_.pos[i] - C.ref_pos[i]).squaredNorm());
  }
  C.particle_travel = std::sqrt(m2);
  return !within();
}

namespace {

// The tangential history of the last neighbour list keyed by particle slots, which outlive
// the particles' reordering, to carry into the new list.
template <int D>
class SlotHistory {
 public:
  using V = Vec<D>;
  SlotHistory(const ParticleStore<D>& P, const ContactStore<D>& C) {
    if (!C.valid || C.ids_at_build.size() != C.pairs.row.size() - 1) return;
    auto alive = [&](std::uint64_t packed) {
      return P.valid({static_cast<std::uint32_t>(packed >> 32),
                      static_cast<std::uint32_t>(packed & 0xffffffffu)});
    };
    for (std::size_t i = 0; i + 1 < C.pairs.row.size(); ++i) {
      for (std::uint32_t p = C.pairs.row[i]; p < C.pairs.row[i + 1]; ++p) {
        if (C.shear[p].isZero()) continue;
        const std::uint32_t j = C.pairs.col[p];
        if (!alive(C.ids_at_build[i]) || !alive(C.ids_at_build[j])) continue;
        const auto si = static_cast<std::uint32_t>(C.ids_at_build[i] >> 32);
        const auto sj = static_cast<std::uint32_t>(C.ids_at_build[j] >> 32);
        pairs_.push_back({pairKey(si, sj), sj > si ? C.shear[p] : V(-C.shear[p])});
      }
    }
    for (std::size_t c = 0; c < C.wall_particle.size(); ++c) {
      if (C.wall_shear[c].isZero()) continue;
      const std::uint64_t id = C.ids_at_build[C.wall_particle[c]];
      if (!alive(id)) continue;
      walls_.push_back({(id >> 32) << 16 | C.wall_index[c], C.wall_shear[c]});
    }
    std::sort(pairs_.begin(), pairs_.end(), byKey);
    std::sort(walls_.begin(), walls_.end(), byKey);
  }
  // The spring force of the pair of slots si and sj on si's partner, or zero.
  V pair(std::uint32_t si, std::uint32_t sj) const {
    const Entry* e = find(pairs_, pairKey(si, sj));
    if (!e) return V::Zero();
    return sj > si ? e->shear : V(-e->shear);
  }
  V wall(std::uint32_t slot, std::size_t w) const {
    const Entry* e = find(walls_, std::uint64_t{slot} << 16 | w);
    return e ? e->shear : V::Zero();
  }

 private:
  struct Entry {
    std::uint64_t key;
    V shear;  // force on the pair member with the larger slot (or on the wall)
  };
  static bool byKey(const Entry& a, const Entry& b) { return a.key < b.key; }
  static const Entry* find(const std::vector<Entry>& v, std::uint64_t key) {
    auto it = std::lower_bound(v.begin(), v.end(), Entry{key, V::Zero()}, byKey);
    return it != v.end() && it->key == key ? &*it : nullptr;
  }
  std::vector<Entry> pairs_, walls_;
};

// For the threaded pair pass: each particle's pairs as the partner (j), in pair order.
template <int D>
void buildPartnerRows(ContactStore<D>& C, std::size_t n) {
  C.partner_row.assign(n + 1, 0);
  for (std::uint32_t j : C.pairs.col) ++C.partner_row[j + 1];
  for (std::size_t i = 0; i < n; ++i) C.partner_row[i + 1] += C.partner_row[i];
  C.partner_pair.resize(C.pairs.pairs());
  std::vector<std::uint32_t> fill(C.partner_row.begin(), C.partner_row.end() - 1);
  for (std::uint32_t p = 0; p < C.pairs.pairs(); ++p) C.partner_pair[fill[C.pairs.col[p]]++] = p;
}

// The particle-wall contacts within the skin, with their history.
template <int D>
void findWallContacts(const ParticleStore<D>& P, const std::vector<Wall<D>>& walls,
                      ContactStore<D>& C, const SlotHistory<D>& history) {
  C.wall_particle.clear();
  C.wall_index.clear();
  C.wall_shear.clear();
  for (std::size_t i = 0; i < P.size(); ++i) {
    for (std::size_t w = 0; w < walls.size(); ++w) {
      if (walls[w].distance(P.pos[i]) < P.radius[i] + C.skin) {
        C.wall_particle.push_back(static_cast<std::uint32_t>(i));
        C.wall_index.push_back(static_cast<std::uint16_t>(w));
        C.wall_shear.push_back(history.wall(P.slot_of[i], w));
      }
    }
  }
}

}  // namespace

template <int D>
void Simulation<D>::rebuild() {
  const StageClock clock(&stages_[kNeighbors]);
  auto& P = particles_;
  auto& C = contacts_;
  const std::size_t n = P.size();
  const SlotHistory<D> history(P, C);
  if (config_.spatial_sort && n > 1) sortAlongGrid();
  grid_.build(P.pos, P.radius, C.skin, C.pairs);
  if (hasClumps()) dropPairsWithinBodies(P.body, C.pairs);
  C.shear.assign(C.pairs.pairs(), V::Zero());
  for (std::size_t i = 0; i < n; ++i) {
    for (std::uint32_t p = C.pairs.row[i]; p < C.pairs.row[i + 1]; ++p) {
      C.shear[p] = history.pair(P.slot_of[i], P.slot_of[C.pairs.col[p]]);
    }
  }
  buildPartnerRows(C, n);
  findWallContacts(P, walls_, C, history);
  C.ids_at_build.resize(n);
  for (std::size_t i = 0; i < n; ++i) C.ids_at_build[i] = packId(P.id(i));
  C.ref_pos = P.pos;
  C.particle_travel = 0.0;
  C.wall_travel = 0.0;
  C.radius_growth = 0.0;
  C.valid = true;
  ++C.rebuilds;
}

template <int D>
void Simulation<D>::placeWall(std::size_t i, const V& point) {
  walls_.at(i).point = point;
  contacts_.valid = false;
  forces_valid_ = false;
}

// Reorders the particles along the cell grid (memory order follows space) and everything
// indexed by them: the bonds' particle indices and the damping forces.
template <int D>
void Simulation<D>::sortAlongGrid() {
  auto& P = particles_;
  const std::size_t n = P.size();
  const auto order = NeighborGrid<D>::spatialOrder(P.pos, P.radius);
  P.permute(order);
  if (bonds_.size() > 0) {
    std::vector<std::uint32_t> new_index(n);
    for (std::uint32_t k = 0; k < n; ++k) new_index[order[k]] = k;
    for (std::size_t b = 0; b < bonds_.size(); ++b) {
      std::uint32_t a = new_index[bonds_.i[b]], c = new_index[bonds_.j[b]];
      if (a > c) {
        // Keep i < j: seen from the other particle, the shear force and bending moment on
        // j change sign; the normal force and the twist (a moment about n, which flips
        // too) do not.
        std::swap(a, c);
        BondLoad<D>& l = bonds_.load[b];
        l.fs = -l.fs;
        l.mb = -l.mb;
        if (!bonds_.face[b].empty()) {
          bonds_.face[b].swapSides(bond_kinds_[bonds_.kind[b]].template faceLayout<D>());
        }
      }
      bonds_.i[b] = a;
      bonds_.j[b] = c;
    }
    bond_forces_.invalidate();
  }
  if (!damp_force_.empty()) {
    auto apply = [&](auto& v) {
      std::remove_reference_t<decltype(v)> out(v.size());
      for (std::size_t k = 0; k < n; ++k) out[k] = v[order[k]];
      v.swap(out);
    };
    apply(damp_force_);
    apply(damp_torque_);
  }
}

template <int D>
void Simulation<D>::step() {
  if (contacts_.ref_pos.size() != particles_.size()) forces_valid_ = false;
  if (!prepared_ || !forces_valid_) prepare();
  {
    const StageClock clock(&stages_[kIntegrate], false);  // counted with the second half
    initialIntegrate();
  }
  if (needsRebuild()) rebuild();

  const bool overlap = computeForces(dt_);
  if (hasClumps()) breakOverloadedClumps();
  {
    const StageClock clock(&stages_[kIntegrate]);
    finalIntegrate();
  }
  {
    const StageClock clock(walls_.empty() ? nullptr : &stages_[kServo]);
    // Work of each wall over its move this step (trapezoid in the wall force), then the
    // servo sets the velocity of the next move.
    for (std::size_t w = 0; w < walls_.size(); ++w) {
      Wall<D>& wall = walls_[w];
      const double work = -0.5 * (wall_prev_force_[w] + wall.force).dot(wall.velocity) * dt_;
      ledger_.boundary_work += work;
      ledger_.positive_input += std::max(work, 0.0);
      wall_prev_force_[w] = wall.force;
    }
    time_ += dt_;
    ++step_;
    for (auto& wall : walls_) wall.updateServo(time_, dt_);
  }
  const StageClock clock(&stages_[kGuard]);
  guard(overlap);
  if (step_ % static_cast<std::uint64_t>(config_.timestep.update_interval) == 0) {
    estimateStepAgain();
  }
}

template <int D>
void Simulation<D>::estimateStepAgain() {
  if (!config_.timestep.automatic) return;
  if (!prepared_) {
    dt_ = 0.0;  // prepare() estimates it
    return;
  }
  const double dt = automaticStep();
  if (std::isfinite(dt)) dt_ = dt;  // no free particle left: the last step stays
}

template <int D>
double Simulation<D>::automaticStep() {
  const StepLimits limits = stepLimits();
  double critical = limits.bodies;
  for (const double own : limits.particle) critical = std::min(critical, own);
  const double scaling = config_.timestep.density_scaling;
  // Clumps keep their masses: they bound the target.
  const double target = scaling > 1.0 ? std::min(scaling * critical, limits.bodies) : critical;
  setInertialMasses(limits.particle, target);
  return config_.timestep.safety * target;
}

// Each free particle's inertial mass and moment: the physical ones times (target / own)^2
// where its own critical step is below the target (the step then meets its bound as the
// lightest, stiffest particles set it without scaling), else the physical ones. The
// velocities stay; the kinetic energy that changes with the masses goes to the ledger.
template <int D>
void Simulation<D>::setInertialMasses(const std::vector<double>& limits, double target) {
  auto& P = particles_;
  double added = 0.0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.inv_mass[i] == 0.0 || P.body[i] != kNoBody) continue;  // fixed, driven, pebbles
    const double own = limits[i];
    const double scale = own < target ? (target / own) * (target / own) : 1.0;
    const double inv_mass = scale == 1.0 ? P.physical_inv_mass[i] : P.physical_inv_mass[i] / scale;
    const double inv_inertia =
        scale == 1.0 ? P.physical_inv_inertia[i] : P.physical_inv_inertia[i] / scale;
    if (inv_mass == P.inv_mass[i] && inv_inertia == P.inv_inertia[i]) continue;
    added += 0.5 * (1.0 / inv_mass - 1.0 / P.inv_mass[i]) * P.vel[i].squaredNorm() +
             0.5 * (1.0 / inv_inertia - 1.0 / P.inv_inertia[i]) * angDot(P.spin[i], P.spin[i]);
    P.inv_mass[i] = inv_mass;
    P.inv_inertia[i] = inv_inertia;
  }
  ledger_.mass_scaling += added;
  ledger_.positive_input += std::max(added, 0.0);
}

template <int D>
void Simulation<D>::setDensityScaling(double factor) {
  requireRange("Simulation::setDensityScaling", "timestep.density_scaling", factor, 1.0, false,
               16.0, false, "");
  if (factor == config_.timestep.density_scaling) return;
  config_.timestep.density_scaling = factor;
  if (factor == 1.0) {  // the physical masses back, at once (no contact model needed)
    const std::vector<double> unbounded(particles_.size(), INFINITY);
    setInertialMasses(unbounded, 0.0);
  }
  estimateStepAgain();
}

template <int D>
void Simulation<D>::run(std::uint64_t steps) {
  for (std::uint64_t s = 0; s < steps; ++s) step();
}

template <int D>
void Simulation<D>::drive(const std::vector<std::uint32_t>& slots) {
  auto& P = particles_;
  for (std::uint32_t slot : slots) {
    const std::size_t i = drivenIndex(slot);
    if (P.body[i] != kNoBody) {
      throw std::invalid_argument(
          "particle " + std::to_string(slot) +
          " is a clump pebble: it moves with its body and cannot be driven");
    }
    P.inv_mass[i] = 0.0;
    P.inv_inertia[i] = 0.0;
    P.spin[i] = angZero<A>();
  }
}

template <int D>
void Simulation<D>::setDrivenVelocity(const std::vector<std::uint32_t>& slots, const V& velocity) {
  auto& P = particles_;
  for (std::uint32_t slot : slots) {
    const std::size_t i = drivenIndex(slot);
    if (P.inv_mass[i] != 0.0) {
      throw std::invalid_argument("particle " + std::to_string(slot) +
                                  " is not driven: call drive() on it first");
    }
    P.vel[i] = velocity;
  }
}

template <int D>
std::size_t Simulation<D>::drivenIndex(std::uint32_t slot) const {
  if (!particles_.occupied(slot)) {
    throw std::invalid_argument("no particle at slot " + std::to_string(slot));
  }
  return particles_.indexOfSlot(slot);
}

template class Simulation<2>;
template class Simulation<3>;

}  // namespace rocklab
