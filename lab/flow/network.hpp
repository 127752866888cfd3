#pragma once
// The pore network of a particle pack (Li & Holt section 3.2-3.4): pores are the cells of
// the regular triangulation of particle centres, pipes the facets two cells share. Built
// once per triangulation; its geometry (volumes, throats, conductances) is measured again
// from the moved particles without rebuilding (section 3.3). Pores joined by a highly
// conductive pipe are merged into clusters (Figure 7b); the solvers work on the clusters.

#include <array>
#include <cstdint>
#include <vector>

#include "lab/core/dim.hpp"
#include "lab/core/fields.hpp"
#include "lab/flow/triangulation.hpp"

namespace rocklab::flow {

// The particles the network is measured on: centres, radii, and the intact bonds (as index
// pairs into the same arrays, with their radii) whose cement narrows the throats.
template <int D>
struct PackView {
  std::vector<Vec<D>> centre;
  std::vector<double> radius;
  std::vector<std::array<std::uint32_t, 2>> bond;
  std::vector<double> bond_radius;
  template <class Archive>
  void visit(Archive& ar) {
    ar("centre", centre), ar("radius", radius), ar("bond", bond), ar("bond_radius", bond_radius);
  }
};

// Which pores have their pressure imposed.
enum class PoreBoundary : std::uint8_t { Free = 0, Inlet = 1, Outlet = 2 };

struct ConductanceLaw {
  double alpha = 1.0;         // -, equation 3's factor (1: Hagen-Poiseuille)
  double viscosity = 1.0e-3;  // Pa s (water)

  template <class F>
  void fields(F& f) {
    f(viscosity,
      {"viscosity_mPa_s", units::mPa_s, Range::leftOpen(0, 1e9), "fluid viscosity (water: 1)"});
    f(alpha, {"conductance_alpha", units::none, Range::leftOpen(0, 1e6),
              "alpha of equation 3, C = alpha pi r_e^4 / (8 mu r_av) (1: Hagen-Poiseuille)"});
  }
};

template <int D>
class Network {
 public:
  using V = Vec<D>;
  // `slice` is the thickness (m) a 2D network stands for: the pore volumes are the pore
  // areas times it, and the permeability's cross-section is the width times it (a 2D pack
  // is one layer of grains, each pipe one throat of that layer; ignored in 3D).
  Network(Triangulation<D> topology, double slice);
  // An empty network for a checkpoint to be read into (visit).
  Network() : slice_(0.0) {}

  // Measures every pore and pipe on `pack` (the same particles, in the same order, as the
  // triangulation was built on).
  void measure(const PackView<D>& pack, const ConductanceLaw& law);

  std::size_t pores() const { return topology_.cells.size(); }
  std::size_t pipes() const { return pipe_a_.size(); }
  const Triangulation<D>& topology() const { return topology_; }
  double slice() const { return slice_; }

  // Per pore.
  const std::vector<double>& volume() const { return volume_; }  // m^3, fluid volume
  const std::vector<V>& centroid() const { return centroid_; }
  // Smallest signed cell size over its unsigned one; <= 0 once a cell has turned inside out.
  double worstCellQuality() const { return worst_quality_; }
  // Per pipe: the two pores, the throat's fluid area (m^2) and conductance (m^3/(Pa s)).
  std::uint32_t pipeA(std::size_t k) const { return pipe_a_[k]; }
  std::uint32_t pipeB(std::size_t k) const { return pipe_b_[k]; }
  const std::vector<double>& throat() const { return throat_; }
  const std::vector<double>& conductance() const { return conductance_; }

  // Force of the pore pressures on the particles (N, indexed like the pack): across each
  // pipe the pressure drop acts on the whole facet. On the particles' sections it is the
  // pore pressure on their surfaces (the sector of each particle in a cell is closed by the
  // cell's facets, so the pressure on its curved wall equals the pressure on its flat cuts);
  // on the fluid section it is the viscous drag the throat's particles take, shared equally
  // (Chareyre et al. 2012). A uniform pressure gives no force; a drop dp across a sample of
  // cross-section A gives dp A on the solid in total. `thickness` is the 2D disks' extrusion.
  // Projected area along `axis` of the hull facets of the pores marked `which`, signed by
  // their outward normals so that bumps cancel (m^2; 2D: length times the slice): the
  // section of the network at its inlet or outlet face.
  double outerSection(const std::vector<PoreBoundary>& boundary, PoreBoundary which,
                      const PackView<D>& pack, int axis) const;

  std::vector<V> particleForces(const std::vector<double>& pore_pressure, const PackView<D>& pack,
                                double thickness) const;

  // The network as built and last measured, for checkpoints (a resumed run goes on with the
  // same triangulation: triangulating anew would not be the uninterrupted run).
  template <class Archive>
  void visit(Archive& ar) {
    ar("topology", topology_), ar("slice", slice_), ar("pipe_a", pipe_a_), ar("pipe_b", pipe_b_);
    ar("pipe_facet", pipe_facet_), ar("volume", volume_), ar("throat", throat_);
    ar("conductance", conductance_), ar("centroid", centroid_);
    ar("worst_quality", worst_quality_);
  }

 private:
  Triangulation<D> topology_;
  double slice_;
  std::vector<std::uint32_t> pipe_a_, pipe_b_;
  std::vector<std::uint8_t> pipe_facet_;  // the facet of pore a the pipe goes through
  std::vector<double> volume_, throat_, conductance_;
  std::vector<V> centroid_;
  double worst_quality_ = 1.0;
};

// Pores grouped into clusters, and the network between the clusters that the solvers see.
struct Clusters {
  std::vector<std::uint32_t> of_pore;  // cluster of each pore
  std::size_t count = 0;
  // Pipes between different clusters: ends and conductance (parallel pipes stay apart).
  std::vector<std::uint32_t> edge_a, edge_b;
  std::vector<double> edge_conductance;
  std::vector<double> volume;                   // m^3 per cluster
  std::vector<PoreBoundary> boundary;           // per cluster: imposed if any of its pores is
  std::vector<std::array<double, 3>> position;  // m, its pores' mean centroid (2D: z 0)
  template <class Archive>
  void visit(Archive& ar) {
    ar("of_pore", of_pore), ar("count", count), ar("edge_a", edge_a), ar("edge_b", edge_b);
    ar("edge_conductance", edge_conductance), ar("volume", volume), ar("boundary", boundary);
    ar("position", position);
  }
};

struct MergeRule {
  // Merge the two pores of a pipe whose conductance exceeds this times the median (0: no
  // merging by conductance). Section 3.2: the widely open pores.
  double conductance_ratio = 0.0;
  // Merge a pore whose own critical step v / (K_f sum C) is below this times the median into
  // the neighbour it is best connected to (0: never). Flat cells have next to no volume and
  // would drive the explicit step to zero (equation 6).
  double small_pore_ratio = 0.01;

  template <class F>
  void fields(F& f) {
    f(conductance_ratio, {"merge_conductance_ratio", units::none, Range::closed(0, 1e9),
                          "merge the pores of a pipe whose conductance exceeds this times the "
                          "median (Figure 7b; 0: off)"});
    f(small_pore_ratio, {"merge_small_pore_ratio", units::none, Range::rightOpen(0, 1),
                         "merge a pore whose own explicit step is below this times the median "
                         "into its best connected neighbour (flat cells; 0: off)"});
  }
};

// Groups the pores; a cluster never joins an inlet pore to an outlet pore.
template <int D>
Clusters mergePores(const Network<D>& net, const std::vector<PoreBoundary>& boundary,
                    const MergeRule& rule);

}  // namespace rocklab::flow
