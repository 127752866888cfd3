// Simulation: the bond stage. Cementing installs the bonds (parallel bonds or flat joints);
// each step the bond pass (bond_forces.hpp) adds their forces and records the breaks, which
// are then logged and the broken bonds removed in bond order (two-phase mutation, house rule
// 7 in README.md). Cutting a specimen removes particles with their bonds.

#include "lab/core/simulation.hpp"

#include <algorithm>
#include <string>
#include <unordered_map>

#include "lab/core/stage_clock.hpp"

namespace rocklab {

template <int D>
void Simulation<D>::computeBondForces(double dt) {
  const StageClock clock(&stages_[kBonds]);
  auto& P = particles_;
  BondPass<D> pass{P, bonds_, dt, threaded(), config_.threads, config_.bond_breakage};
  pass.lane_width = config_.bond_lane_width;
  pass.kinds = &bond_kinds_;
  bond_forces_.compute(pass);
  ledger_.friction += pass.slip_energy;
  if (pass.broken.empty() && pass.released.empty()) return;
  // Second phase: log the breaks and remove the broken bonds, in bond order.
  std::vector<std::uint8_t> flag(bonds_.size(), 0);
  for (std::size_t k = 0; k < pass.broken.size(); ++k) {
    const std::uint32_t b = pass.broken[k];
    const std::uint32_t i = bonds_.i[b], j = bonds_.j[b];
    if (pass.removes[k]) {
      const auto section = BondSection<D>::of(bonds_.radius[b], P.thickness);
      ledger_.bond_breakage += bondEnergy<D>(section, bonds_.kn[b], bonds_.ks[b], bonds_.load[b]);
      flag[b] = 1;
    } else {
      ledger_.bond_breakage += pass.energies[k];  // a flat joint's element
    }
    const V d = P.pos[j] - P.pos[i];
    const double dist = d.norm();
    const double overlap = P.radius[i] + P.radius[j] - dist;
    BondBreak<D> e;
    e.step = step_;
    e.time = time_;
    e.position = P.pos[i] + (P.radius[i] - 0.5 * overlap) / dist * d + pass.offsets[k];
    e.mode = pass.modes[k];
    e.a = P.id(i);
    e.b = P.id(j);
    e.kind = bonds_.kind[b];
    e.stress = pass.stresses[k];
    bond_breaks_.push_back(e);
    ++broken_counts_[2 * e.kind + (e.mode == BondBreakMode::Shear ? 1 : 0)];
  }
  for (const std::uint32_t b : pass.released) flag[b] = 1;
  bonds_.removeFlagged(flag);
  bond_forces_.invalidate();
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

namespace {

// A strength from normal(mean, sd), as cement() draws it: one at or below zero is drawn again
// with Resample (counted in `redrawn`), else left for the caller to skip.
double drawStrength(Rng& rng, double mean, double sd, NegativeStrength negative,
                    std::size_t& redrawn) {
  double s = rng.normal(mean, sd);
  while (s <= 0.0 && negative == NegativeStrength::Resample) {
    ++redrawn;
    s = rng.normal(mean, sd);
  }
  return s;
}

}  // namespace

template <int D>
std::optional<std::size_t> Simulation<D>::redrawStrengths(std::uint8_t kind_index,
                                                          const BondKind& kind) {
  if (kind.model != BondModel::Parallel ||
      bond_kinds_.at(kind_index).model != BondModel::Parallel) {
    throw std::invalid_argument("redrawStrengths: parallel bonds only");
  }
  std::size_t redrawn = 0;
  std::vector<double> tensile = bonds_.tensile, shear = bonds_.shear;
  for (std::size_t b = 0; b < bonds_.size(); ++b) {
    if (bonds_.kind[b] != kind_index) continue;
    tensile[b] = drawStrength(rng_, kind.tensile_mean, kind.tensile_std, kind.negative, redrawn);
    shear[b] = drawStrength(rng_, kind.shear_mean, kind.shear_std, kind.negative, redrawn);
    if (tensile[b] <= 0.0 || shear[b] <= 0.0) return std::nullopt;
  }
  bonds_.tensile.swap(tensile);
  bonds_.shear.swap(shear);
  bond_kinds_[kind_index] = kind;
  return redrawn;
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
  const FaceLayout layout = kind.template faceLayout<D>();
  auto draw = [&](double mean, double sd, bool& skip) {
    const double s = drawStrength(rng_, mean, sd, kind.negative, report.redrawn);
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
      bonds_.face.push_back(kind.model == BondModel::FlatJoint
                                ? installFace<D>(layout, (P.pos[j] - P.pos[i]).normalized())
                                : FaceState<D>{});
      // Slit elements: drawn only when there are any, so that a face without them leaves the
      // stream of strengths as it was.
      if (kind.flat_joint_slit_fraction > 0.0) {
        for (FaceElement<D>& e : bonds_.face.back().elements) {
          if (rng_.uniform() < kind.flat_joint_slit_fraction) e.bonded = 0;
        }
      }
      ++report.installed;
    }
  }
  bond_forces_.invalidate();
  // The bonds stiffen the particles they join: the step and the inertial masses follow at
  // once (or at prepare()), not at the next estimate. Under density scaling the scaled particles
  // sit at their bound, so until then they would step beyond it (a cemented lattice went unstable
  // so).
  if (report.installed > 0) estimateStepAgain();
  return report;
}

template <int D>
void Simulation<D>::removeParticles(const std::vector<ParticleId>& ids) {
  auto& P = particles_;
  std::vector<std::uint8_t> gone(P.size(), 0);
  for (const ParticleId id : ids) {
    const std::size_t i = P.index(id);
    if (P.body[i] != kNoBody && clumps_.alive[P.body[i]]) {
      throw std::invalid_argument("removeParticles: particle " + std::to_string(id.slot) +
                                  " is a pebble of an unbroken clump");
    }
    gone[i] = 1;
  }
  std::vector<std::uint8_t> cut(bonds_.size(), 0);
  for (std::size_t b = 0; b < bonds_.size(); ++b) cut[b] = gone[bonds_.i[b]] | gone[bonds_.j[b]];
  bonds_.removeFlagged(cut);
  // Removing moves particles to other indices: the bonds and the damping of the last step
  // follow their particles by slot.
  std::vector<std::uint32_t> slot_i(bonds_.size()), slot_j(bonds_.size());
  for (std::size_t b = 0; b < bonds_.size(); ++b) {
    slot_i[b] = P.slot_of[bonds_.i[b]], slot_j[b] = P.slot_of[bonds_.j[b]];
  }
  std::unordered_map<std::uint32_t, std::pair<V, A>> damping;
  for (std::size_t i = 0; i < damp_force_.size(); ++i) {
    if (!gone[i]) damping.emplace(P.slot_of[i], std::pair{damp_force_[i], damp_torque_[i]});
  }
  for (const ParticleId id : ids) {
    if (id.slot < applied_.size()) applied_[id.slot] = V::Zero();
    P.remove(id);
  }
  for (std::size_t b = 0; b < bonds_.size(); ++b) {
    std::uint32_t i = static_cast<std::uint32_t>(P.indexOfSlot(slot_i[b]));
    std::uint32_t j = static_cast<std::uint32_t>(P.indexOfSlot(slot_j[b]));
    if (i > j) {  // keep i < j, seen from the other particle (as sortAlongGrid does)
      std::swap(i, j);
      bonds_.load[b].fs = -bonds_.load[b].fs;
      bonds_.load[b].mb = -bonds_.load[b].mb;
      if (!bonds_.face[b].empty()) {
        bonds_.face[b].swapSides(bond_kinds_[bonds_.kind[b]].template faceLayout<D>());
      }
    }
    bonds_.i[b] = i, bonds_.j[b] = j;
  }
  if (!damp_force_.empty()) {
    damp_force_.assign(P.size(), V::Zero());
    damp_torque_.assign(P.size(), angZero<A>());
    for (std::size_t i = 0; i < P.size(); ++i) {
      const auto it = damping.find(P.slot_of[i]);
      if (it != damping.end())
        damp_force_[i] = it->second.first, damp_torque_[i] = it->second.second;
    }
  }
  bond_forces_.invalidate();
  if (prepared_) rebuild();  // the contact pairs named the old indices; history follows slots
  forces_valid_ = false;
  restartEnergyLedger();
}

#define ROCKLAB_BOND_STAGE(D)                                                           \
  template void Simulation<D>::computeBondForces(double);                               \
  template std::uint8_t Simulation<D>::addBondKind(BondKind);                           \
  template std::uint64_t Simulation<D>::brokenBonds(std::uint8_t, BondBreakMode) const; \
  template CementReport Simulation<D>::cement(std::uint8_t, double);                    \
  template std::optional<std::size_t> Simulation<D>::redrawStrengths(std::uint8_t,      \
                                                                     const BondKind&);  \
  template void Simulation<D>::removeParticles(const std::vector<ParticleId>&);
ROCKLAB_BOND_STAGE(2)
ROCKLAB_BOND_STAGE(3)
#undef ROCKLAB_BOND_STAGE

}  // namespace rocklab
