#include "lab/core/simulation.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "lab/core/archive.hpp"
#include "lab/core/contact_laws.hpp"
#include "lab/core/errors.hpp"

namespace rocklab {

namespace {

// Runs body(i, acc) over [0, n) in fixed blocks of kBlockRows and adds the blocks' partial
// results in block order: the total is the same whatever the thread count.
template <class Acc, class Body>
Acc blockedSum(std::size_t n, int threads, Body body) {
  const std::size_t blocks = (n + kBlockRows - 1) / kBlockRows;
  std::vector<Acc> part(blocks);
#pragma omp parallel for schedule(static) num_threads(threads) if (threads > 1)
  for (std::size_t b = 0; b < blocks; ++b) {
    Acc a{};
    const std::size_t end = std::min(n, (b + 1) * kBlockRows);
    for (std::size_t i = b * kBlockRows; i < end; ++i) body(i, a);
    part[b] = a;
  }
  Acc total{};
  for (const Acc& a : part) total.merge(a);
  return total;
}

double signOf(double v) {
  return v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0);
}

// PFC local damping (Itasca 1999; Cundall 1987): a force opposing each velocity component,
// proportional to the unbalanced force, F_d = -alpha |F| sign(v), component by component.
double localDamping(double f, double v, double alpha) {
  return -alpha * std::abs(f) * signOf(v);
}
template <int R>
Eigen::Matrix<double, R, 1> localDamping(const Eigen::Matrix<double, R, 1>& f,
                                         const Eigen::Matrix<double, R, 1>& v, double alpha) {
  Eigen::Matrix<double, R, 1> d;
  for (int k = 0; k < R; ++k) d[k] = localDamping(f[k], v[k], alpha);
  return d;
}

constexpr char kMagic[8] = {'R', 'K', 'L', 'B', 'C', 'K', 'P', 'T'};
constexpr char kTrailer[8] = {'R', 'K', 'L', 'B', 'E', 'N', 'D', '!'};

std::uint64_t fnv1a(const void* data, std::size_t n, std::uint64_t h = 1469598103934665603ull) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
  return h;
}

template <class T>
std::uint64_t hashVector(const std::vector<T>& v, std::uint64_t h) {
  return v.empty() ? h : fnv1a(v.data(), v.size() * sizeof(T), h);
}

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

struct OverrideRow {
  std::uint16_t a = 0, b = 0;
  double friction = NAN, damping_ratio = NAN;  // NaN: not overridden
  template <class Archive>
  void visit(Archive& ar) {
    ar("a", a), ar("b", b), ar("friction", friction), ar("damping_ratio", damping_ratio);
  }
};

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
Simulation<D> Simulation<D>::clone() const {
  ArchiveWriter w;
  const_cast<Simulation*>(this)->visit(w);
  Simulation copy(MaterialTable{}, SimulationConfig{});
  ArchiveReader r(w.bytes().data(), w.bytes().size());
  copy.visit(r);
  return copy;
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
      dt_ = config_.timestep.safety * criticalTimeStep();
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
bool Simulation<D>::computeForces(double history_dt) {
  const auto t0 = std::chrono::steady_clock::now();
  const bool gravity = config_.gravity[0] != 0.0 || config_.gravity[1] != 0.0 ||
                       (D == 3 && config_.gravity[2] != 0.0);
  if (gravity) {
    V g;
    for (int d = 0; d < D; ++d) g[d] = config_.gravity[d];
    auto& P = particles_;
    struct Acc {
      double work = 0.0;
      void merge(const Acc& o) { work += o.work; }
    };
    const double dt = history_dt;
    const Acc acc = blockedSum<Acc>(P.size(), config_.threads, [&](std::size_t i, Acc& a) {
      if (P.inv_mass[i] == 0.0 || P.body[i] != kNoBody) return;  // clumps: whole bodies
      const V f = g / P.inv_mass[i];
      P.force[i] += f;
      a.work += f.dot(P.vel[i]) * dt;  // exact over the drift x += v dt
    });
    ledger_.body_work += acc.work;
    ledger_.positive_input += std::max(acc.work, 0.0);
  }
  if (!applied_.empty()) applyForces(history_dt);
  const auto t1 = std::chrono::steady_clock::now();
  ContactPass<D> pass{particles_,
                      contacts_,
                      walls_,
                      history_dt,
                      threaded(),
                      config_.threads,
                      config_.track_energy,
                      config_.guard.overlap_limit};
  model_->computeForces(pass);
  ledger_.friction += pass.friction;
  ledger_.viscous += pass.viscous;
  const auto t2 = std::chrono::steady_clock::now();
  if (bonds_.size() > 0) computeBondForces(history_dt);
  if (gravity || !applied_.empty()) {
    stage_seconds_[kBodyForces] += std::chrono::duration<double>(t1 - t0).count();
    ++stage_calls_[kBodyForces];
  }
  stage_seconds_[kContacts] += std::chrono::duration<double>(t2 - t1).count();
  ++stage_calls_[kContacts];
  return pass.overlap_exceeded;
}

template <int D>
void Simulation<D>::applyForces(double dt) {
  auto& P = particles_;
  struct Acc {
    double work = 0.0;
    void merge(const Acc& o) { work += o.work; }
  };
  const Acc acc = blockedSum<Acc>(P.size(), config_.threads, [&](std::size_t i, Acc& a) {
    const std::uint32_t slot = P.slot_of[i];
    if (slot >= applied_.size() || P.inv_mass[i] == 0.0) return;
    P.force[i] += applied_[slot];  // a pebble's share reaches its clump with its force
    a.work += applied_[slot].dot(P.vel[i]) * dt;  // exact over the drift x += v dt
  });
  ledger_.body_work += acc.work;
  ledger_.positive_input += std::max(acc.work, 0.0);
}

template <int D>
void Simulation<D>::computeBondForces(double dt) {
  const auto t0 = std::chrono::steady_clock::now();
  auto& P = particles_;
  BondPass<D> pass{P,  bonds_, dt, threaded(),         config_.threads, config_.bond_breakage,
                   {}, {},     {}, config_.bond_lanes, &bond_kinds_};
  bond_forces_.compute(pass);
  if (!pass.broken.empty()) {
    // Second phase: log and remove the broken bonds in bond order.
    std::vector<std::uint8_t> flag(bonds_.size(), 0);
    for (std::size_t k = 0; k < pass.broken.size(); ++k) {
      const std::uint32_t b = pass.broken[k];
      const std::uint32_t i = bonds_.i[b], j = bonds_.j[b];
      const auto section = BondSection<D>::of(bonds_.radius[b], P.thickness);
      ledger_.bond_breakage += bondEnergy<D>(section, bonds_.kn[b], bonds_.ks[b], bonds_.load[b]);
      const V d = P.pos[j] - P.pos[i];
      const double dist = d.norm();
      const double overlap = P.radius[i] + P.radius[j] - dist;
      BondBreak<D> e;
      e.step = step_;
      e.time = time_;
      e.position = P.pos[i] + (P.radius[i] - 0.5 * overlap) / dist * d;
      e.mode = pass.modes[k];
      e.a = P.id(i);
      e.b = P.id(j);
      e.kind = bonds_.kind[b];
      e.stress = pass.stresses[k];
      bond_breaks_.push_back(e);
      ++broken_counts_[2 * e.kind + (e.mode == BondBreakMode::Shear ? 1 : 0)];
      flag[b] = 1;
    }
    bonds_.removeFlagged(flag);
    bond_forces_.invalidate();
  }
  stage_seconds_[kBonds] +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ++stage_calls_[kBonds];
}

template <int D>
std::uint8_t Simulation<D>::addBondKind(BondKind kind) {
  checkFields(kind, "bond kind '" + kind.name + "'");
  if (bond_kinds_.size() >= 255) throw std::invalid_argument("at most 255 bond kinds");
  bond_kinds_.push_back(std::move(kind));
  broken_counts_.resize(2 * bond_kinds_.size(), 0);
  return static_cast<std::uint8_t>(bond_kinds_.size() - 1);
}

template <int D>
std::uint64_t Simulation<D>::brokenBonds(std::uint8_t kind, BondBreakMode mode) const {
  return broken_counts_.at(2 * kind + (mode == BondBreakMode::Shear ? 1 : 0));
}

template <int D>
CementReport Simulation<D>::cement(std::uint8_t kind_index, double gap_ratio) {
  const BondKind& kind = bond_kinds_.at(kind_index);
  requireRange("cementing", "gap_ratio", gap_ratio, 0.0, false, 1.0, false, "-");
  auto& P = particles_;
  CementReport report;
  if (P.size() < 2) return report;
  double rmax = 0.0;
  for (double r : P.radius) rmax = std::max(rmax, r);
  PairRows rows;
  NeighborGrid<D> grid;
  grid.build(P.pos, P.radius, gap_ratio * rmax, rows);

  std::vector<std::uint64_t> existing;
  for (std::size_t b = 0; b < bonds_.size(); ++b) {
    existing.push_back(std::uint64_t{bonds_.i[b]} << 32 | bonds_.j[b]);
  }
  std::sort(existing.begin(), existing.end());
  auto draw = [&](double mean, double sd, bool& skip) {
    double s = rng_.normal(mean, sd);
    while (s <= 0.0 && kind.negative == NegativeStrength::Resample) {
      ++report.redrawn;
      s = rng_.normal(mean, sd);
    }
    skip = skip || s <= 0.0;
    return s;
  };
  for (std::uint32_t i = 0; i + 1 < rows.row.size(); ++i) {
    for (std::uint32_t p = rows.row[i]; p < rows.row[i + 1]; ++p) {
      const std::uint32_t j = rows.col[p];
      const double gap = (P.pos[j] - P.pos[i]).norm() - P.radius[i] - P.radius[j];
      const double rmin = std::min(P.radius[i], P.radius[j]);
      if (gap >= gap_ratio * rmin) continue;
      if (P.body[i] != kNoBody && P.body[i] == P.body[j]) continue;  // one rigid body
      // Intragranular bonds join particles of one grain, intergranular bonds the others.
      const bool same_grain = P.cluster[i] != kNoCluster && P.cluster[i] == P.cluster[j];
      if (same_grain != kind.intragranular) continue;
      ++report.candidates;
      if (std::binary_search(existing.begin(), existing.end(), std::uint64_t{i} << 32 | j)) {
        continue;
      }
      bool skip = false;
      const double tensile = draw(kind.tensile_mean, kind.tensile_std, skip);
      const double shear = draw(kind.shear_mean, kind.shear_std, skip);
      if (skip) {
        ++report.skipped_nonpositive;
        continue;
      }
      bonds_.i.push_back(i);
      bonds_.j.push_back(j);
      bonds_.kind.push_back(kind_index);
      bonds_.radius.push_back(kind.radius_multiplier * rmin);
      // Stiffness per area from the bond modulus over the pair's length (PFC 5's linear
      // parallel bond, deformability method: kn = E / L, L = r1 + r2).
      const double kn = kind.modulus / (P.radius[i] + P.radius[j]);
      bonds_.kn.push_back(kn);
      bonds_.ks.push_back(kn / kind.stiffness_ratio);
      bonds_.tensile.push_back(tensile);
      bonds_.shear.push_back(shear);
      bonds_.load.push_back(BondLoad<D>{});
      ++report.installed;
    }
  }
  bond_forces_.invalidate();
  return report;
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
  const Acc acc = blockedSum<Acc>(P.size(), config_.threads, [&](std::size_t i, Acc& a) {
    if (clumped && P.body[i] != kNoBody) return;  // pebbles move with their clump
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
  const Acc acc = blockedSum<Acc>(P.size(), config_.threads, [&](std::size_t i, Acc& a) {
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

template <int D>
void Simulation<D>::rebuild() {
  const auto t0 = std::chrono::steady_clock::now();
  auto& P = particles_;
  auto& C = contacts_;
  const std::size_t n = P.size();

  // Keep the old history keyed by particle slots.
  struct Entry {
    std::uint64_t key;
    V shear;  // force on the pair member with the larger slot (or on the wall)
  };
  std::vector<Entry> old_pairs, old_walls;
  const bool history_usable = C.valid && C.ids_at_build.size() == C.pairs.row.size() - 1;
  if (history_usable) {
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
        old_pairs.push_back({pairKey(si, sj), sj > si ? C.shear[p] : V(-C.shear[p])});
      }
    }
    for (std::size_t c = 0; c < C.wall_particle.size(); ++c) {
      if (C.wall_shear[c].isZero()) continue;
      const std::uint64_t id = C.ids_at_build[C.wall_particle[c]];
      if (!alive(id)) continue;
      old_walls.push_back({(id >> 32) << 16 | C.wall_index[c], C.wall_shear[c]});
    }
  }
  auto by_key = [](const Entry& a, const Entry& b) { return a.key < b.key; };
  std::sort(old_pairs.begin(), old_pairs.end(), by_key);
  std::sort(old_walls.begin(), old_walls.end(), by_key);
  auto find = [&](const std::vector<Entry>& v, std::uint64_t key) -> const Entry* {
    auto it = std::lower_bound(v.begin(), v.end(), Entry{key, V::Zero()}, by_key);
    return it != v.end() && it->key == key ? &*it : nullptr;
  };

  if (config_.spatial_sort && n > 1) {
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
  grid_.build(P.pos, P.radius, C.skin, C.pairs);
  if (hasClumps()) dropPairsWithinBodies(P.body, C.pairs);

  C.shear.assign(C.pairs.pairs(), V::Zero());
  for (std::size_t i = 0; i < n; ++i) {
    for (std::uint32_t p = C.pairs.row[i]; p < C.pairs.row[i + 1]; ++p) {
      const std::uint32_t si = P.slot_of[i], sj = P.slot_of[C.pairs.col[p]];
      if (const Entry* e = find(old_pairs, pairKey(si, sj))) {
        C.shear[p] = sj > si ? e->shear : V(-e->shear);
      }
    }
  }

  C.partner_row.assign(n + 1, 0);
  for (std::uint32_t j : C.pairs.col) ++C.partner_row[j + 1];
  for (std::size_t i = 0; i < n; ++i) C.partner_row[i + 1] += C.partner_row[i];
  C.partner_pair.resize(C.pairs.pairs());
  {
    std::vector<std::uint32_t> fill(C.partner_row.begin(), C.partner_row.end() - 1);
    for (std::uint32_t p = 0; p < C.pairs.pairs(); ++p) C.partner_pair[fill[C.pairs.col[p]]++] = p;
  }

  C.wall_particle.clear();
  C.wall_index.clear();
  C.wall_shear.clear();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t w = 0; w < walls_.size(); ++w) {
      if (walls_[w].distance(P.pos[i]) < P.radius[i] + C.skin) {
        C.wall_particle.push_back(static_cast<std::uint32_t>(i));
        C.wall_index.push_back(static_cast<std::uint16_t>(w));
        const Entry* e = find(old_walls, std::uint64_t{P.slot_of[i]} << 16 | w);
        C.wall_shear.push_back(e ? e->shear : V::Zero());
      }
    }
  }

  C.ids_at_build.resize(n);
  for (std::size_t i = 0; i < n; ++i) C.ids_at_build[i] = packId(P.id(i));
  C.ref_pos = P.pos;
  C.particle_travel = 0.0;
  C.wall_travel = 0.0;
  C.radius_growth = 0.0;
  C.valid = true;
  ++C.rebuilds;
  stage_seconds_[kNeighbors] +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ++stage_calls_[kNeighbors];
}

template <int D>
void Simulation<D>::step() {
  if (contacts_.ref_pos.size() != particles_.size()) forces_valid_ = false;
  if (!prepared_ || !forces_valid_) prepare();
  auto t0 = std::chrono::steady_clock::now();
  initialIntegrate();
  auto t1 = std::chrono::steady_clock::now();
  stage_seconds_[kIntegrate] += std::chrono::duration<double>(t1 - t0).count();
  if (needsRebuild()) rebuild();

  const bool overlap = computeForces(dt_);
  if (hasClumps()) breakOverloadedClumps();

  t0 = std::chrono::steady_clock::now();
  finalIntegrate();
  t1 = std::chrono::steady_clock::now();
  stage_seconds_[kIntegrate] += std::chrono::duration<double>(t1 - t0).count();
  ++stage_calls_[kIntegrate];

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
  if (!walls_.empty()) {
    for (auto& wall : walls_) wall.updateServo(time_, dt_);
    stage_seconds_[kServo] +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
    ++stage_calls_[kServo];
  }

  t0 = std::chrono::steady_clock::now();
  guard(overlap);
  if (config_.timestep.automatic &&
      step_ % static_cast<std::uint64_t>(config_.timestep.update_interval) == 0) {
    const double dt = config_.timestep.safety * criticalTimeStep();
    if (std::isfinite(dt)) dt_ = dt;
  }
  stage_seconds_[kGuard] +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ++stage_calls_[kGuard];
}

template <int D>
void Simulation<D>::run(std::uint64_t steps) {
  for (std::uint64_t s = 0; s < steps; ++s) step();
}

template <int D>
void Simulation<D>::guard(bool overlap_exceeded) {
  if (!std::isfinite(kinetic_)) {
    fail(SimulationUnstable::Cause::NonFinite, "a particle velocity is no longer finite");
  }
  if (overlap_exceeded) {
    std::ostringstream s;
    s << "an overlap exceeded " << config_.guard.overlap_limit
      << " of the smaller radius (guard.overlap_limit)";
    fail(SimulationUnstable::Cause::Overlap, s.str());
  }
  // Kinetic energy cannot exceed what the sample held plus what was put in; a few times
  // more means the integration itself is creating energy.
  const double budget = ledger_.initial + ledger_.positive_input;
  if (config_.guard.energy_runaway && kinetic_ > config_.guard.energy_growth * budget &&
      kinetic_ > 1e-300) {
    std::ostringstream s;
    s << "kinetic energy " << kinetic_ << " J exceeds " << config_.guard.energy_growth
      << " times the energy put into the sample (" << budget << " J)";
    fail(SimulationUnstable::Cause::EnergyRunaway, s.str());
  }
}

template <int D>
void Simulation<D>::fail(SimulationUnstable::Cause cause, const std::string& what) const {
  std::ostringstream s;
  s << "the run became unstable at step " << step_ << " (t = " << time_ << " s): " << what << ".\n"
    << diagnose();
  throw SimulationUnstable(cause, step_, s.str());
}

template <int D>
std::string Simulation<D>::diagnose() const {
  const auto& P = particles_;
  std::ostringstream s;
  s.precision(3);
  double rmin = INFINITY;
  for (double r : P.radius) rmin = std::min(rmin, r);
  int causes = 0;

  const double crit = criticalTimeStep();
  if (std::isfinite(crit) && dt_ > crit) {
    ++causes;
    s << "Likely cause: the time step " << dt_ << " s is above the critical estimate " << crit
      << " s (particle mass and contact stiffness); use automatic stepping or lower the "
         "fixed step or the safety factor.\n";
  }
  for (const auto& w : walls_) {
    const double per_step = w.velocity.norm() * dt_;
    if (per_step > 0.01 * rmin) {
      ++causes;
      s << "Likely cause: wall '" << w.name << "' moves " << 100.0 * per_step / rmin
        << "% of the smallest radius per step (" << w.velocity.norm()
        << " m/s); lower its velocity or servo max_speed.\n";
    }
  }
  double vmax = 0.0;
  std::size_t fastest = 0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    const double v = P.vel[i].norm();
    if (!(v <= vmax)) vmax = v, fastest = i;
  }
  if (!std::isfinite(vmax) || vmax * dt_ > 0.05 * rmin) {
    ++causes;
    s << "Particle " << P.slot_of[fastest] << " at (" << P.pos[fastest].transpose() << ") moves "
      << vmax * dt_ / rmin << " smallest radii per step.\n";
  }
  if (causes == 0) {
    s << "No single cause stands out: check the stiffness contrast between materials, the "
         "loading rate and guard.overlap_limit.\n";
  }
  // The deepest contact as it stands: where to look, and how fast it closed.
  Touching deepest;
  double ratio = 0.0;
  forEachTouching([&](const Touching& t) {
    if (t.overlap / t.min_radius > ratio) ratio = t.overlap / t.min_radius, deepest = t;
  });
  if (ratio > 0.0) {
    const std::size_t i = deepest.i, j = deepest.j;
    const Vec<D> n =
        deepest.wall ? Vec<D>(-deepest.wall->normal) : Vec<D>((P.pos[j] - P.pos[i]).normalized());
    const Vec<D> vj = deepest.wall ? deepest.wall->velocity : P.vel[j];
    const double closing = (P.vel[i] - vj).dot(n);
    s << "Deepest contact: particle " << P.slot_of[i] << " (radius " << P.radius[i] << " m, at ("
      << P.pos[i].transpose() << ")) and ";
    if (deepest.wall) {
      s << "wall '" << deepest.wall->name << "'";
    } else {
      s << "particle " << P.slot_of[j] << " (radius " << P.radius[j] << " m)";
    }
    const double per_step = closing * dt_ / deepest.min_radius;
    s << ": overlap " << ratio << " of the smaller radius, closing at " << closing << " m/s ("
      << per_step << " of that radius per step).\n";
    // A contact that closed slowly carries a load too high for its stiffness: the model's
    // limit, not the integration's.
    if (ratio >= config_.guard.overlap_limit && std::abs(per_step) < 1e-4) {
      s << "It closed slowly: a static load too high for the contact stiffness, not an "
           "instability. Stiffen the contacts, or raise guard.overlap_limit if an overlap this "
           "deep is acceptable for the smallest particles.\n";
    }
  }
  return s.str();
}

template <int D>
template <class F>
void Simulation<D>::forEachTouching(F&& visit) const {
  const auto& P = particles_;
  const auto& C = contacts_;
  if (!C.valid || C.pairs.row.size() != P.size() + 1) return;
  Touching t;
  for (std::size_t i = 0; i < P.size(); ++i) {
    for (std::uint32_t p = C.pairs.row[i]; p < C.pairs.row[i + 1]; ++p) {
      const std::uint32_t j = C.pairs.col[p];
      const double reach = P.radius[i] + P.radius[j];
      t.overlap = reach - (P.pos[j] - P.pos[i]).norm();
      if (!(t.overlap > 0.0)) continue;
      const double imsum = P.inv_mass[i] + P.inv_mass[j];
      t.i = i, t.j = j, t.wall = nullptr;
      t.mi = P.material[i], t.mj = P.material[j];
      t.shape = pairShape<D>(P.radius[i], P.radius[j], P.thickness);
      t.mstar = imsum > 0.0 ? 1.0 / imsum : 0.0;
      t.li = P.radius[i] - 0.5 * t.overlap, t.lj = P.radius[j] - 0.5 * t.overlap;
      t.min_radius = std::min(P.radius[i], P.radius[j]);
      t.shear2 = C.shear[p].squaredNorm();
      visit(t);
    }
  }
  for (std::size_t c = 0; c < C.wall_particle.size(); ++c) {
    const std::uint32_t i = C.wall_particle[c];
    const Wall<D>& w = walls_[C.wall_index[c]];
    t.overlap = P.radius[i] - w.distance(P.pos[i]);
    if (!(t.overlap > 0.0)) continue;
    t.i = i, t.j = i, t.wall = &w;
    t.mi = P.material[i], t.mj = w.material;
    t.shape = wallShape<D>(P.radius[i], P.thickness);
    t.mstar = P.inv_mass[i] > 0.0 ? 1.0 / P.inv_mass[i] : 0.0;
    t.li = P.radius[i] - t.overlap, t.lj = 0.0;
    t.min_radius = P.radius[i];
    t.shear2 = C.wall_shear[c].squaredNorm();
    visit(t);
  }
}

template <int D>
double Simulation<D>::criticalTimeStep() const {
  const auto& P = particles_;
  const std::size_t n = P.size();
  if (!model_) throw std::logic_error("criticalTimeStep() before the simulation is prepared");
  std::vector<double> kt(n, 0.0), kr(n, 0.0);
  forEachTouching([&](const Touching& t) {
    const auto [kn, ks] = model_->stiffness(t.mi, t.mj, t.overlap, t.shape, t.mstar);
    kt[t.i] += kn;
    kr[t.i] += ks * t.li * t.li;
    if (!t.wall) {
      kt[t.j] += kn;
      kr[t.j] += ks * t.lj * t.lj;
    }
  });
  // Bonds add their normal stiffness to translation, shear and bending to rotation.
  for (std::size_t b = 0; b < bonds_.size(); ++b) {
    const auto s = BondSection<D>::of(bonds_.radius[b], P.thickness);
    const double kn = bonds_.kn[b] * s.area, ks = bonds_.ks[b] * s.area;
    const double moment = bonds_.kn[b] * s.inertia + bonds_.ks[b] * s.polar;
    for (const std::uint32_t p : {bonds_.i[b], bonds_.j[b]}) {
      kt[p] += kn;
      kr[p] += ks * P.radius[p] * P.radius[p] + moment;
    }
  }
  double dt = INFINITY;
  // A clump's pebbles act in parallel on the body: their stiffnesses add up, the rotational
  // ones with the arm from the centroid (bounded by distance plus radius).
  const auto& K = clumps_;
  for (std::uint32_t c = 0; c < K.size(); ++c) {
    if (!K.alive[c]) continue;
    double kt_body = 0.0, kr_body = 0.0;
    const double density = K.mass[c] / K.volume[c];
    for (std::uint32_t k = K.first[c]; k < K.first[c + 1]; ++k) {
      const std::size_t i = P.indexOfSlot(K.member_slot[k]);
      const double arm = (P.pos[i] - K.pos[c]).norm() + P.radius[i];
      kt_body += kt[i];
      kr_body += kr[i] + kt[i] * arm * arm;
      // A pebble meeting something new moves at most its own mass (conservative bound).
      const double m = density * P.volume(i);
      dt = std::min(dt, model_->freeParticleStep(
                            P.material[i], pairShape<D>(P.radius[i], P.radius[i], P.thickness),
                            P.radius[i], m, particleInertia<D>(m, P.radius[i]), density));
    }
    double imin = 0.0;
    if constexpr (D == 2) {
      imin = K.principal[c];
    } else {
      imin = K.principal[c].minCoeff();
    }
    if (kt_body > 0.0) dt = std::min(dt, std::sqrt(K.mass[c] / kt_body));
    if (kr_body > 0.0) dt = std::min(dt, std::sqrt(imin / kr_body));
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (P.inv_mass[i] == 0.0 || P.body[i] != kNoBody) continue;
    const double m = 1.0 / P.inv_mass[i], inertia = 1.0 / P.inv_inertia[i];
    dt = std::min(dt, model_->freeParticleStep(P.material[i],
                                               pairShape<D>(P.radius[i], P.radius[i], P.thickness),
                                               P.radius[i], m, inertia, m / P.volume(i)));
    if (kt[i] > 0.0) dt = std::min(dt, std::sqrt(m / kt[i]));
    if (kr[i] > 0.0) dt = std::min(dt, std::sqrt(inertia / kr[i]));
  }
  return dt;
}

template <int D>
EnergyReport Simulation<D>::energy() const {
  const auto& P = particles_;
  EnergyReport e;
  e.ledger = ledger_;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.inv_mass[i] == 0.0 || P.body[i] != kNoBody) continue;
    e.kinetic_translation += 0.5 * P.vel[i].squaredNorm() / P.inv_mass[i];
    e.kinetic_rotation += 0.5 * angDot(P.spin[i], P.spin[i]) / P.inv_inertia[i];
  }
  const auto& K = clumps_;
  for (std::size_t c = 0; c < K.size(); ++c) {
    if (!K.alive[c]) continue;
    e.kinetic_translation += 0.5 * K.mass[c] * K.vel[c].squaredNorm();
    e.kinetic_rotation += rotationalEnergy(K.spin[c], K.momentum[c]);
  }
  if (!model_) return e;
  forEachTouching([&](const Touching& t) {
    e.strain += model_->strainEnergy(t.mi, t.mj, t.overlap, t.shape, t.mstar, t.shear2);
  });
  for (std::size_t b = 0; b < bonds_.size(); ++b) {
    const auto s = BondSection<D>::of(bonds_.radius[b], P.thickness);
    e.strain += bondEnergy<D>(s, bonds_.kn[b], bonds_.ks[b], bonds_.load[b]);
  }
  return e;
}

template <int D>
std::size_t Simulation<D>::particleContacts() const {
  std::size_t count = 0;
  forEachTouching([&](const Touching& t) { count += t.wall == nullptr; });
  return count;
}

template <int D>
double Simulation<D>::maxOverlapRatio() const {
  double worst = 0.0;
  forEachTouching([&](const Touching& t) { worst = std::max(worst, t.overlap / t.min_radius); });
  return worst;
}

template <int D>
std::vector<typename Simulation<D>::ContactForce> Simulation<D>::contactForces() const {
  std::vector<ContactForce> out;
  if (!model_) return out;
  forEachTouching([&](const Touching& t) {
    if (t.wall) return;
    out.push_back(
        {t.i, t.j, model_->normalForce(t.mi, t.mj, t.overlap, t.shape), std::sqrt(t.shear2)});
  });
  return out;
}

template <int D>
double Simulation<D>::coordinationNumber() const {
  return particles_.size() ? 2.0 * static_cast<double>(particleContacts()) /
                                 static_cast<double>(particles_.size())
                           : 0.0;
}

template <int D>
double Simulation<D>::unbalancedForceRatio() const {
  const auto& P = particles_;
  if (!model_) return 0.0;
  double unbalanced = 0.0, contact = 0.0;
  std::size_t free = 0, count = 0;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.inv_mass[i] == 0.0 || P.body[i] != kNoBody) continue;
    unbalanced += P.force[i].norm();
    ++free;
  }
  for (std::size_t c = 0; c < clumps_.size(); ++c) {
    if (!clumps_.alive[c]) continue;
    unbalanced += clumps_.force[c].norm();
    ++free;
  }
  forEachTouching([&](const Touching& t) {
    if (t.wall) return;
    const double fn = model_->normalForce(t.mi, t.mj, t.overlap, t.shape);
    contact += std::sqrt(fn * fn + t.shear2);
    ++count;
  });
  if (count == 0 || free == 0) return 0.0;
  return (unbalanced / static_cast<double>(free)) / (contact / static_cast<double>(count));
}

template <int D>
std::vector<StageTiming> Simulation<D>::stageTimings() const {
  static constexpr const char* kNames[kStages] = {
      "integrate", "neighbors", "body_forces", "contacts", "bonds", "wall_servo", "guard"};
  std::vector<StageTiming> out;
  for (int s = 0; s < kStages; ++s) {
    if (stage_calls_[s] == 0) continue;  // a stage the scene does not call for never ran
    out.push_back({kNames[s], stage_seconds_[s], stage_calls_[s]});
  }
  return out;
}

template <int D>
std::uint64_t Simulation<D>::stateHash() const {
  const auto& P = particles_;
  std::uint64_t h = 1469598103934665603ull;
  h = hashVector(P.pos, h);
  h = hashVector(P.vel, h);
  h = hashVector(P.spin, h);
  h = hashVector(P.force, h);
  h = hashVector(P.torque, h);
  h = hashVector(contacts_.shear, h);
  h = hashVector(contacts_.wall_shear, h);
  h = hashVector(clumps_.momentum, h);
  for (const BondLoad<D>& l : bonds_.load) {
    h = fnv1a(&l.fn, sizeof l.fn, h);
    h = fnv1a(l.fs.data(), sizeof(double) * D, h);
    if constexpr (D == 3) {
      h = fnv1a(l.mb.data(), sizeof(double) * 3, h);
      h = fnv1a(&l.mt, sizeof l.mt, h);
    } else {
      h = fnv1a(&l.mb, sizeof l.mb, h);
    }
  }
  for (const auto& w : walls_) {
    h = fnv1a(w.point.data(), sizeof(double) * D, h);
    h = fnv1a(w.velocity.data(), sizeof(double) * D, h);
    h = fnv1a(w.force.data(), sizeof(double) * D, h);
  }
  const double scalars[] = {time_,
                            dt_,
                            ledger_.boundary_work,
                            ledger_.body_work,
                            ledger_.friction,
                            ledger_.viscous,
                            ledger_.local_damping};
  return fnv1a(scalars, sizeof scalars, h);
}

template <int D>
template <class Archive>
void Simulation<D>::visit(Archive& ar) {
  ar("config.contact_law", config_.contact_law), ar("config.skin", config_.skin);
  ar("config.skin_ratio", config_.skin_ratio);
  ar("config.local_damping", config_.local_damping);
  ar("config.timestep.automatic", config_.timestep.automatic);
  ar("config.timestep.fixed_dt", config_.timestep.fixed_dt);
  ar("config.timestep.safety", config_.timestep.safety);
  ar("config.timestep.update_interval", config_.timestep.update_interval);
  ar("config.guard.overlap_limit", config_.guard.overlap_limit);
  ar("config.guard.energy_growth", config_.guard.energy_growth);
  ar("config.guard.energy_runaway", config_.guard.energy_runaway);
  ar("config.threads", config_.threads), ar("config.track_energy", config_.track_energy);
  ar("config.spatial_sort", config_.spatial_sort), ar("config.gravity", config_.gravity);
  ar("config.bond_breakage", config_.bond_breakage);

  std::vector<Material> mats = materials_.all();
  std::vector<OverrideRow> rows;
  for (const auto& [k, o] : materials_.overrides()) {
    rows.push_back({k.first, k.second, o.friction.value_or(NAN), o.damping_ratio.value_or(NAN)});
  }
  ar("materials", mats), ar("material_overrides", rows);
  if constexpr (Archive::kReading) {
    materials_ = MaterialTable{};
    for (auto& m : mats) materials_.add(std::move(m));
    for (const auto& r : rows) {
      PairOverride o;
      if (!std::isnan(r.friction)) o.friction = r.friction;
      if (!std::isnan(r.damping_ratio)) o.damping_ratio = r.damping_ratio;
      materials_.setPair(r.a, r.b, o);
    }
  }

  particles_.visit(ar);
  ar("walls", walls_), ar("wall_prev_force", wall_prev_force_);
  contacts_.visit(ar);
  rng_.visit(ar);
  ar("ledger.initial", ledger_.initial), ar("ledger.boundary_work", ledger_.boundary_work);
  ar("ledger.body_work", ledger_.body_work), ar("ledger.friction", ledger_.friction);
  ar("ledger.viscous", ledger_.viscous), ar("ledger.local_damping", ledger_.local_damping);
  ar("ledger.positive_input", ledger_.positive_input), ar("ledger.started", ledger_.started);
  ar("ledger.bond_breakage", ledger_.bond_breakage);
  ar("ledger.clump_release", ledger_.clump_release);
  clumps_.visit(ar);
  ar("clump_breaks", clump_breaks_);
  ar("bond_kinds", bond_kinds_), ar("bonds", bonds_), ar("bond_breaks", bond_breaks_);
  ar("broken_counts", broken_counts_);
  ar("time", time_), ar("dt", dt_), ar("step", step_), ar("kinetic", kinetic_);
  ar("forces_valid", forces_valid_);
  ar("damp_force", damp_force_), ar("damp_torque", damp_torque_);
}

template <int D>
void Simulation<D>::saveCheckpoint(const std::string& path) const {
  ArchiveWriter w;
  const_cast<Simulation*>(this)->visit(w);
  std::string file(kMagic, sizeof kMagic);
  const std::uint32_t version = kCheckpointVersion, dim = D;
  file.append(reinterpret_cast<const char*>(&version), sizeof version);
  file.append(reinterpret_cast<const char*>(&dim), sizeof dim);
  file += w.bytes();
  const std::uint64_t sum = fnv1a(file.data(), file.size());
  file.append(reinterpret_cast<const char*>(&sum), sizeof sum);
  file.append(kTrailer, sizeof kTrailer);
  // Write beside the target and rename: a crash never leaves a half-written checkpoint.
  const std::string tmp = path + ".partial";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw CheckpointError("cannot write checkpoint '" + tmp + "'");
    out.write(file.data(), static_cast<std::streamsize>(file.size()));
    if (!out) throw CheckpointError("writing checkpoint '" + tmp + "' failed");
  }
  std::filesystem::rename(tmp, path);
}

template <int D>
Simulation<D> Simulation<D>::loadCheckpoint(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw CheckpointError("cannot open checkpoint '" + path + "'");
  const std::string file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t head = sizeof kMagic + 8, tail = 8 + sizeof kTrailer;
  if (file.size() < sizeof kMagic || std::memcmp(file.data(), kMagic, sizeof kMagic) != 0) {
    throw CheckpointError("'" + path + "' is not a rocklab checkpoint");
  }
  if (file.size() < head + tail ||
      std::memcmp(file.data() + file.size() - sizeof kTrailer, kTrailer, sizeof kTrailer) != 0) {
    throw CheckpointError("checkpoint '" + path + "' is truncated (its end marker is missing)");
  }
  std::uint32_t version, dim;
  std::memcpy(&version, file.data() + sizeof kMagic, 4);
  std::memcpy(&dim, file.data() + sizeof kMagic + 4, 4);
  if (version != kCheckpointVersion) {
    throw CheckpointError("checkpoint '" + path + "' has format version " +
                          std::to_string(version) + "; this rocklab reads version " +
                          std::to_string(kCheckpointVersion) +
                          " only: resume it with the rocklab that wrote it");
  }
  if (dim != D) {
    throw CheckpointError("checkpoint '" + path + "' holds a " + std::to_string(dim) +
                          "D scene, not " + std::to_string(D) + "D");
  }
  std::uint64_t sum;
  std::memcpy(&sum, file.data() + file.size() - tail, sizeof sum);
  if (fnv1a(file.data(), file.size() - tail) != sum) {
    throw CheckpointError("checkpoint '" + path + "' is damaged (checksum mismatch)");
  }
  Simulation sim(MaterialTable{}, SimulationConfig{});
  ArchiveReader r(file.data() + head, file.size() - head - tail);
  sim.visit(r);
  if (!r.atEnd()) throw CheckpointError("checkpoint '" + path + "' has trailing data");
  return sim;
}

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
    if (P.inv_mass[i] == 0.0) throw std::invalid_argument("a fixed particle cannot join a clump");
    const double m = 1.0 / P.inv_mass[i], rho = m / P.volume(i);
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
    const double m = 1.0 / P.inv_mass[i];
    L += m * cross(V(P.pos[i] - mp.centroid), V(P.vel[i] - v)) + P.spin[i] / P.inv_inertia[i];
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
    P.inv_mass[i] = 1.0 / mp.mass;
    P.inv_inertia[i] = 1.0 / imin;
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
    P.inv_mass[i] = 1.0 / m;
    P.inv_inertia[i] = 1.0 / inertia;
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

template class Simulation<2>;
template class Simulation<3>;

}  // namespace rocklab
