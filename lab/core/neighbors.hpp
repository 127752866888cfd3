#pragma once
// Neighbour search: a multi-level cell grid feeding a Verlet list with a skin.
//
// Particles are sorted into levels by size; the cells of level l are twice as wide as
// those of level l-1 (Ogarko & Luding 2012, "A fast multilevel algorithm for contact
// detection of arbitrarily polydisperse objects"). A pair in one level is found from the
// 3^D stencil; a pair across levels is found once, by the larger particle scanning the
// finer level's cells that its reach overlaps. With a narrow size range there is a single
// level, the plain cell grid. The cost stays linear in N for size ratios of 10:1 and more,
// where a single grid sized for the largest particle would put hundreds of fines per cell.

#include <array>
#include <cstdint>
#include <vector>

#include "lab/core/dim.hpp"

namespace rocklab {

// Candidate pairs in compressed-row form: the partners of particle i are
// col[row[i] .. row[i+1]), every partner index greater than i, in increasing order.
struct PairRows {
  std::vector<std::uint32_t> row;
  std::vector<std::uint32_t> col;
  std::size_t pairs() const { return col.size(); }
};

template <int D>
class NeighborGrid {
 public:
  // Every pair whose surfaces are closer than `skin`.
  void build(const std::vector<Vec<D>>& pos, const std::vector<double>& radius, double skin,
             PairRows& out);

  // An order of the particles along the cells of a grid of about two diameters: sorting
  // the particle arrays by it keeps neighbours close in memory.
  static std::vector<std::uint32_t> spatialOrder(const std::vector<Vec<D>>& pos,
                                                 const std::vector<double>& radius);

  int levels() const { return static_cast<int>(levels_.size()); }

 private:
  struct Level {
    double cell = 0.0;
    double rmax = 0.0;
    std::array<int, D> dims{};
    std::vector<std::uint32_t> start;  // cell -> first item
    std::vector<std::uint32_t> items;  // particle indices sorted by cell
  };
  std::vector<Level> levels_;
  std::vector<std::uint8_t> level_of_;
  std::vector<std::uint64_t> found_;  // (min << 32 | max) candidate pairs before bucketing
};

}  // namespace rocklab
