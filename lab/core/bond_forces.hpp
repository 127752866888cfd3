#pragma once
// The bond stage: one force pass over all parallel bonds, serial or threaded with the same
// bits (the threaded pass stores per-bond results and each particle sums its bonds in bond
// order, as the serial pass adds them). Breaks are only recorded during the pass; the
// simulation removes the broken bonds afterwards, in order (two-phase mutation).

#include <cstdint>
#include <vector>

#include "lab/core/bonds.hpp"

namespace rocklab {

template <int D>
struct BondPass {
  ParticleStore<D>& particles;
  BondStore<D>& bonds;
  double dt;
  bool threaded;
  int threads;
  bool breakable;  // false: no bond breaks, whatever its load

  // Out: the bonds that broke this step, by increasing index, with mode and stress.
  std::vector<std::uint32_t> broken;
  std::vector<BondBreakMode> modes;
  std::vector<double> stresses;

  bool lanes = true;  // 3D: four bonds per AVX register where the CPU has it (same bits)
  // The kinds, indexed by BondStore::kind, for their friction angles and moment factors
  // (nullptr: neither).
  const std::vector<BondKind>* kinds = nullptr;
};

// Whether 3D bonds can run four per AVX register here (BondPass::lanes asks for it).
bool bondLanesAvailable();

template <int D>
class BondForces {
 public:
  void compute(BondPass<D>& pass);
  // Call when bonds are added or removed or particles reordered.
  void invalidate() { adjacency_valid_ = false; }

 private:
  void buildAdjacency(std::size_t particles, const BondStore<D>& bonds);

  // Threaded pass: per-bond results and each particle's bonds as (bond << 1 | side).
  std::vector<std::uint8_t> active_;
  std::vector<Vec<D>> force_;
  std::vector<Ang<D>> torque_i_, torque_j_;
  std::vector<std::uint32_t> adjacency_row_, adjacency_;
  bool adjacency_valid_ = false;
  std::vector<std::vector<std::uint32_t>> block_broken_;
  std::vector<std::vector<std::pair<BondBreakMode, double>>> block_modes_;
  std::vector<double> tan_friction_, moment_factor_;  // per kind, this pass
};

}  // namespace rocklab
