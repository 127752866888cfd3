#pragma once
// The bond stage: one force pass over all parallel bonds, serial or threaded with the same
// bits. Bonds are kept sorted by their particles (i, then j), so they form rows like the
// contact pairs and the threaded pass splits them as the contact pass does
// (contact_model_impl.hpp): each thread owns a run of rows and adds in bond order. Breaks
// are only recorded during the pass; the simulation removes the broken bonds afterwards, in
// order (two-phase mutation).

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
};

template <int D>
class BondForces {
 public:
  void compute(BondPass<D>& pass);
  // Call when bonds are added or removed or particles reordered.
  void invalidate() { rows_valid_ = false; }

 private:
  // One bond's result, kept for the thread that applies it in bond order.
  struct Kept {
    Vec<D> force;
    Ang<D> torque_i, torque_j;  // subtracted from i, added to j
    bool broken = false;
    BondBreakMode mode = BondBreakMode::Tensile;
    double stress = 0.0;
  };
  struct Break {
    std::uint32_t bond;
    BondBreakMode mode;
    double stress;
  };

  void buildRows(std::size_t particles, BondStore<D>& bonds);
  Kept evaluate(const BondPass<D>& pass, std::uint32_t b) const;
  void serialPass(BondPass<D>& pass);
  void threadedPass(BondPass<D>& pass);

  // Bonds by particle: row_[i]..row_[i+1] are i's bonds (to larger j, ascending);
  // partner_row_/partner_ list the bonds whose j is a particle, ascending.
  std::vector<std::uint32_t> row_, partner_row_, partner_;
  bool rows_valid_ = false;
  std::vector<std::size_t> range_;  // rows of each thread
  std::vector<std::vector<std::uint32_t>> own_cross_;
  std::vector<std::uint32_t> cross_;  // bonds reaching past their thread's rows, ascending
  std::vector<std::size_t> cross_start_;
  std::vector<Kept> cross_kept_;
  std::vector<std::vector<Break>> thread_breaks_;
};

}  // namespace rocklab
