#pragma once
// The regular (weighted Delaunay) triangulation of particle centres, weighted by the squared
// radii: triangles in 2D, tetrahedra in 3D. CGAL stays inside triangulation.cpp; this is
// the plain interface the pore network is built from.
//
// Why regular and not plain Delaunay: in a polydisperse pack the Delaunay cell of centres
// can put a facet through a large particle, so a throat would be measured across solid. The
// power (regular) triangulation puts its facets on the radical planes between particles,
// which separate every pair of touching spheres (Chareyre et al. 2012, "Pore-scale
// modelling of viscous flow and induced forces in dense sphere packings", Transport in
// Porous Media 94). For equal radii the two are the same. A small particle entirely inside
// the power cells of its neighbours can be hidden (no vertex); it is counted.

#include <array>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "lab/core/dim.hpp"

namespace rocklab::flow {

// A pore network cannot be built from this input (fewer than D + 1 points, or all of them
// on one line (2D) or plane (3D)).
class DegenerateNetwork : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline constexpr std::int32_t kHull = -1;  // no cell across this facet: the hull

template <int D>
struct Triangulation {
  // Vertices of each cell, as indices into the input; facet f is opposite vertex f.
  std::vector<std::array<std::uint32_t, D + 1>> cells;
  // The cell across facet f of each cell, or kHull.
  std::vector<std::array<std::int32_t, D + 1>> neighbours;
  std::size_t hidden = 0;   // input points that got no vertex (inside their neighbours)
  std::size_t trimmed = 0;  // cells removed by trimHull
  template <class Archive>
  void visit(Archive& ar) {
    ar("cells", cells), ar("neighbours", neighbours), ar("hidden", hidden), ar("trimmed", trimmed);
  }
};

// Throws DegenerateNetwork for input that spans less than D dimensions.
template <int D>
Triangulation<D> triangulate(const std::vector<Vec<D>>& centres, const std::vector<double>& radii);

// Removes the cells with an edge longer than `max_edge_ratio` times the sum of its two
// particles' radii, and makes their neighbours' facets hull facets. Such cells are not pores:
// they are the long flat cells that fill the convex hull of a pack's bumpy surface, whose
// wide facets would be throats of no real pore and short-circuit the sample along its sides.
// Inside a dense pack every edge joins near neighbours and is far below twice that sum.
template <int D>
void trimHull(Triangulation<D>& t, const std::vector<Vec<D>>& centres,
              const std::vector<double>& radii, double max_edge_ratio);

}  // namespace rocklab::flow
