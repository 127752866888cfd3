#pragma once
// The standard benchmark scene shared with LIGGGHTS and Yade (data/peers/README.md):
// a dense packing of spheres in a box of six frictionless walls moving inward, Hertz-
// Mindlin contacts, a fixed time step, 100 untimed and 2000 timed steps.

#include <array>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "lab/core/packing.hpp"
#include "lab/core/stage_clock.hpp"

namespace rocklab {

struct BenchOptions {
  std::string packing;  // a packing file; empty: generate one of n spheres
  std::size_t n = 10000;
  std::uint64_t steps = 2000;  // timed steps
  std::uint64_t warmup = 100;  // untimed steps first
  std::vector<int> threads{1};
  double skin = 0.2e-3;              // m, the Verlet skin LIGGGHTS ran with
  std::uint64_t seed = 1;            // for a generated packing
  bool energy = false;               // track contact dissipation (LIGGGHTS does not)
  std::string save_packing;          // write the generated packing here
  std::array<int, 3> tile{1, 1, 1};  // copies of the packing along x, y, z (a larger scene)
  bool scalar_bonds = false;         // bonds one at a time, not four per AVX register (same bits)
  bool bonded = false;               // a bond on every initial contact (cemented rock)
  bool flow = false;                 // also time the pore network and a steady solve on the packing
  double flow_strain = 1e-4;         // axial strain of the packing before the repeat flow call
  bool render = false;               // also time an off-screen snapshot of the packing
  std::string render_dir = ".";      // where the snapshot's PNGs go
  // The bonds' model when bonded: "parallel" or "flat_joint".
  std::string bond_model = "parallel";
};

struct BenchResult {
  int threads = 1;
  std::size_t particles = 0;
  std::uint64_t steps = 0;
  double seconds = 0.0;
  double particle_steps_per_second = 0.0;
  double coordination_start = 0.0;
  double coordination_end = 0.0;
  double wall_stress_start = 0.0;  // Pa, mean of the six walls
  double wall_stress_end = 0.0;
  std::uint64_t rebuilds = 0;      // neighbour list rebuilds in the timed phase
  std::uint64_t listed_pairs = 0;  // pairs in the neighbour list at the end
  std::uint64_t bonds = 0;         // bonded variant: bonds installed (none break: see bench.cpp)
  int bond_lane_width = 0;         // the bonds ran this many per vector register (0: one at a time)
  bool flat_joints = false;        // the bonds were flat joints (one at a time, beside the lanes)
  std::uint64_t state_hash = 0;
  double peak_rss_bytes = 0.0;  // of the process so far (getrusage)
  // Wall time of each stage of the step in the timed phase (those the scene calls): where a
  // second thread's time goes, stage by stage.
  std::vector<StageTiming> stages;
};

// One call of the pore network: measured (and triangulated on the first call), then solved.
struct FlowCall {
  double network_seconds = 0.0;  // triangulation (first call) and the network's measurement
  double solve_seconds = 0.0;    // the whole solve, of which:
  double assembly_seconds = 0.0, analysis_seconds = 0.0;
  double factorisation_seconds = 0.0, iteration_seconds = 0.0;
  std::string path;  // how the solve was reached (flow::describe)
  std::size_t iterations = 0;
  double permeability = 0.0;  // m^2
};

// The pore network on the packing (as Yade's FlowEngine builds it): the first call
// triangulates, measures the network and solves; the repeat call, after every centre moved
// by an axial strain along the flow (z) about the mid-height, measures the network on the
// moved particles (no new triangulation) and solves it, keeping what the first solve left.
// The repeat's pressures are held against a fresh factorisation of the same moved network.
struct FlowBenchResult {
  std::size_t particles = 0, pores = 0, pipes = 0, clusters = 0;
  double strain = 0.0;
  FlowCall first, repeat;
  double fresh_solve_seconds = 0.0;             // the moved network factorised anew instead
  double repeat_max_difference = 0.0;           // largest pore pressure difference from it / drop
  double repeat_permeability_difference = 0.0;  // relative
  double kozeny_carman = 0.0;  // m^2, for the same porosity and mean diameter (constant 180)
  double peak_rss_bytes = 0.0;
};

// An off-screen snapshot of the packing (the cutaway view and the slice of a report).
struct RenderBenchResult {
  std::size_t particles = 0;
  double view_seconds = 0.0, slice_seconds = 0.0;
  double peak_rss_bytes = 0.0;
};

// The generated stand-in for the peers' packings: radii uniform in [0.9, 1.1] mm, grown to
// a loose state, then compressed by servo walls to 1 MPa with friction 0.1, as the peers'
// packings were prepared.
Packing<3> benchPacking(std::size_t n, std::uint64_t seed, int threads);

// The packing repeated tile[0] x tile[1] x tile[2] times in a box as many times larger: a
// scene of any size with the same local structure. Every other copy is mirrored along each
// axis, so two copies meet face to face with the same layer of particles that touched the
// wall there (plain copies would meet misaligned: fewer contacts, and a jolt).
Packing<3> tilePacking(const Packing<3>& packing, const std::array<int, 3>& tile);

BenchResult runBench(const Packing<3>& packing, const BenchOptions& options, int threads);
FlowBenchResult runFlowBench(const Packing<3>& packing, double strain);
RenderBenchResult runRenderBench(const Packing<3>& packing, const std::string& folder);

// Peak resident memory of this process so far (bytes).
double peakRssBytes();

void printBench(std::ostream& out, const std::vector<BenchResult>& results,
                const std::vector<FlowBenchResult>& flow,
                const std::vector<RenderBenchResult>& render, bool json, const std::string& source);

}  // namespace rocklab
