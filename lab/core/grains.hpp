#pragma once
// Breakable superparticles (Li & Holt 2002, section 2.2, Figure 3): irregular grains made
// of pebbles on a close-packed lattice cut by a perturbed ellipse (2D) or ellipsoid (3D),
// with their aspect ratio (longest over shortest caliper) kept below a limit, sizes from a
// distribution (Gaussian in phi), packed as rigid bodies to a target porosity. The rig
// then joins the pebbles of each grain with intragranular bonds (a cluster: deformable,
// crushable) and the grains with intergranular cement. Crushing is tracked as fragments:
// the connected components of a grain's intact intragranular bonds.

#include <cstdint>
#include <functional>
#include <vector>

#include "lab/core/bonds.hpp"
#include "lab/core/clumps.hpp"
#include "lab/core/packing.hpp"
#include "lab/core/particles.hpp"

namespace rocklab {

struct GrainShapeSpec {
  int pebbles_across = 4;         // pebbles along a grain's long axis
  double max_aspect_ratio = 1.5;  // -, longest over shortest caliper, exclusive (Li & Holt 2.2)
  double roughness = 0.15;        // -, relative amplitude of the outline's perturbation

  template <class F>
  void fields(F& f) {
    f(pebbles_across,
      {"pebbles_across", units::none, Range::closed(2, 20), "pebbles along a grain's long axis"});
    f(max_aspect_ratio, {"max_aspect_ratio", units::none, Range::leftOpen(1, 10),
                         "longest over shortest caliper of every grain, exclusive"});
    f(roughness, {"roughness", units::none, Range::closed(0, 0.5),
                  "relative amplitude of the outline's bumps"});
  }
};

// Longest over shortest caliper (Feret) diameter of the union of the pebbles, over 180
// directions (2D) or 2000 (3D, a Fibonacci lattice on the sphere; the longest caliper
// comes out short by at most about 0.1%).
template <int D>
double feretAspectRatio(const ClumpShape<D>& shape);

// One irregular grain of length `length` (no two of its pebbles' surfaces are farther
// apart), equal touching pebbles centred on their centroid. Throws InvalidParameter when no grain
// within the aspect limit is found in 500 tries (a limit too close to 1 for the pebble count).
template <int D>
ClumpShape<D> makeGrainShape(double length, const GrainShapeSpec& spec, Rng& rng);

struct GrainPackingSpec {
  std::size_t grains = 200;
  SizeDistribution sizes;  // grain lengths
  GrainShapeSpec shape;
  double porosity = 0.25;  // -, 1 - pebble volume / box volume (pores inside grains count)
  std::array<double, 3> aspect{1, 1, 1};
  double thickness = 1.0;  // m, 2D
  std::uint64_t seed = 1;
  int threads = 1;
  std::function<void(double)> progress;
};

template <int D>
struct GrainPacking {
  Packing<D> pebbles;
  std::vector<std::uint32_t> grain;        // per pebble: its grain
  std::vector<double> grain_length;        // m, per grain: the drawn size
  std::vector<double> grain_aspect_ratio;  // -, per grain: measured on the generated grain
  std::size_t grains() const { return grain_length.size(); }
};

// Grains placed at a reduced size and grown as rigid clumps (frictionless) in a fixed box
// until the pebbles fill 1 - porosity of it; beyond jamming the overlaps left show in the
// report. Seedable: one seed gives one packing.
template <int D>
GrainPacking<D> generateGrainPacking(const GrainPackingSpec& spec, PackingReport* report = nullptr);

// Fragments of each grain: connected components of its pebbles under the intact bonds of
// intragranular kinds. Indexed by cluster id (ids without pebbles count 0).
template <int D>
std::vector<std::uint32_t> grainFragments(const ParticleStore<D>& particles,
                                          const BondStore<D>& bonds,
                                          const std::vector<BondKind>& kinds);

// Grains with more fragments now than at the reference (crushed, at least partly).
std::size_t crushedGrains(const std::vector<std::uint32_t>& reference,
                          const std::vector<std::uint32_t>& now);

}  // namespace rocklab
