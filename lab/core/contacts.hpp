#pragma once
// Contact storage: the Verlet candidate pairs with their tangential history in flat arrays
// parallel to the pair list, and the particle-wall candidates likewise.

#include <cstdint>
#include <vector>

#include "lab/core/dim.hpp"
#include "lab/core/neighbors.hpp"

namespace rocklab {

template <int D>
struct ContactStore {
  // Particle pairs (row i, partner col > i) and each pair's tangential spring force on
  // its partner. On a rebuild the history follows the pair by particle slots; when the
  // pair's orientation swaps, the force changes sign (it is the force on the other one).
  PairRows pairs;
  std::vector<Vec<D>> shear;

  // For the threaded force gather: the pairs in which each particle is the partner, by
  // increasing pair index (transpose of `pairs`).
  std::vector<std::uint32_t> partner_row, partner_pair;

  // Particle-wall candidates, ordered by particle then wall; the shear force acts on the
  // wall.
  std::vector<std::uint32_t> wall_particle;
  std::vector<std::uint16_t> wall_index;
  std::vector<Vec<D>> wall_shear;

  // Particle ids (slot << 32 | generation) at the last rebuild: the pair indices above
  // refer to the order of then, and a removed particle's history must not pass to a new
  // one that reuses its slot.
  std::vector<std::uint64_t> ids_at_build;

  // Positions at the last rebuild and the motion bound since then (m), for the skin test.
  std::vector<Vec<D>> ref_pos;
  double particle_travel = 0.0;
  double wall_travel = 0.0;
  double radius_growth = 0.0;
  double skin = 0.0;
  std::uint64_t rebuilds = 0;
  bool valid = false;

  template <class Archive>
  void visit(Archive& ar) {
    ar("pairs.row", pairs.row), ar("pairs.col", pairs.col), ar("shear", shear);
    ar("partner_row", partner_row), ar("partner_pair", partner_pair);
    ar("wall_particle", wall_particle), ar("wall_index", wall_index);
    ar("wall_shear", wall_shear), ar("ids_at_build", ids_at_build), ar("ref_pos", ref_pos);
    ar("particle_travel", particle_travel), ar("wall_travel", wall_travel);
    ar("radius_growth", radius_growth);
    ar("skin", skin), ar("rebuilds", rebuilds), ar("valid", valid);
  }
};

}  // namespace rocklab
