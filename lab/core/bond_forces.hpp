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

  // Out: the breaks this step, by increasing bond index, with mode and stress. A parallel
  // bond breaks whole (`removes`); a flat joint breaks element by element and stays, its
  // element's centroid at `offsets` from the bond's centre and the elastic energy it gave up
  // in `energies` (a parallel bond's is its load's, which it keeps).
  std::vector<std::uint32_t> broken;
  std::vector<BondBreakMode> modes;
  std::vector<double> stresses;
  std::vector<std::uint8_t> removes;
  std::vector<Vec<D>> offsets;
  std::vector<double> energies;
  // Out: flat joints every element of which is broken and apart, to remove without a break;
  // the energy the broken elements' friction dissipated (J).
  std::vector<std::uint32_t> released;
  double slip_energy = 0.0;

  // Bonds up to this many per vector register (8, 4; 0: one at a time) where the CPU has the
  // width: the same bits at any width.
  int lane_width = 8;
  // The kinds, indexed by BondStore::kind, for their friction angles and moment factors
  // (nullptr: neither).
  const std::vector<BondKind>* kinds = nullptr;
};

// Whether 3D bonds can run four per AVX register here (BondPass::lanes asks for it).
// The lanes the bond pass runs in for a requested width: 8 (AVX-512), 4 (AVX) or 0.
int bondLaneWidth(int requested);

template <int D>
class BondForces {
 public:
  void compute(BondPass<D>& pass);
  // Call when bonds are added or removed or particles reordered.
  void invalidate() { adjacency_valid_ = false; }
  // From now on each parallel bond's highest peripheral stresses are kept: the tensile
  // stress and the shear stress less its frictional part (the cohesion it needed). A bond
  // holds for as long as its strengths exceed both, so another draw of strengths above them
  // takes the same path (formed samples reused: rigs/common/formed_samples.hpp). Off with
  // false; the peaks are lost when a bond is added or removed (peaks() is then null).
  void trackPeaks(bool on) {
    tracking_ = on, peaks_lost_ = false;
    peaks_.tensile.clear(), peaks_.cohesion.clear();
  }
  struct Peaks {
    std::vector<double> tensile, cohesion;  // Pa, per bond in store order
  };
  const Peaks* peaks(std::size_t bonds) const {
    return tracking_ && peaks_.tensile.size() == bonds && !peaks_lost_ ? &peaks_ : nullptr;
  }

 private:
  void buildAdjacency(std::size_t particles, const BondStore<D>& bonds);

  // Threaded pass: per-bond results and each particle's bonds as (bond << 1 | side).
  std::vector<std::uint8_t> active_;
  std::vector<Vec<D>> force_;
  std::vector<Ang<D>> torque_i_, torque_j_;
  std::vector<std::uint32_t> adjacency_row_, adjacency_;
  bool adjacency_valid_ = false;
  // A break found in a block of bonds, and the block's flat joints released.
  struct Break {
    std::uint32_t bond;
    BondBreakMode mode;
    double stress, energy;
    Vec<D> offset;
    bool removes;
  };
  struct BlockOut {
    std::vector<Break> breaks;
    std::vector<std::uint32_t> released;
    double slip_energy = 0.0;
  };
  std::vector<BlockOut> block_;
  std::vector<double> tan_friction_, moment_factor_, joint_friction_;  // per kind, this pass
  std::vector<FaceLayout> layouts_;                                    // per kind (flat joints)
  bool tracking_ = false, peaks_lost_ = false;
  Peaks peaks_;
};

}  // namespace rocklab
