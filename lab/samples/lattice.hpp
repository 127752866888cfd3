#pragma once
// Regular lattices of equal particles (`rocklab pack --lattice`): the textbook packings
// whose stiffness and strength have closed forms, for checking a rig against theory, and,
// perturbed, the ordered end of what a sample can be.

#include <array>
#include <cstdint>
#include <string>

#include "lab/core/packing.hpp"

namespace rocklab {

enum class LatticeKind { Hex, Square, Sc, Bcc, Fcc };

struct LatticeSpec {
  LatticeKind kind = LatticeKind::Sc;
  double spacing = 2e-3;               // m, nearest-neighbour centre distance
  double radius = 0.0;                 // m, 0: half the spacing (neighbours touch)
  std::array<int, 3> cells{1, 1, 1};   // unit cells along x, y, z (z unused in 2D)
  double position_perturbation = 0.0;  // each coordinate moved by up to this times the radius
  double radius_perturbation = 0.0;    // each radius scaled by 1 + up to +- this
  std::uint64_t seed = 1;
};

// "hex" ... "fcc" and back; throws std::invalid_argument for another name.
LatticeKind latticeKindOf(const std::string& name);
int latticeDimension(LatticeKind k);  // hex, square: 2; sc, bcc, fcc: 3
// Particles per unit cell.
int latticeSitesPerCell(LatticeKind k);

// The lattice in the box of its particles' extent (walls touching the outermost ones).
template <int D>
Packing<D> latticePacking(const LatticeSpec& spec);

}  // namespace rocklab
