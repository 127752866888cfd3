#pragma once
// The standard benchmark scene shared with LIGGGHTS and Yade (../shared/peers/README.md):
// a dense packing of spheres in a box of six frictionless walls moving inward, Hertz-
// Mindlin contacts, a fixed time step, 100 untimed and 2000 timed steps.

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "lab/core/packing.hpp"

namespace rocklab {

struct BenchOptions {
  std::string packing;  // a packing file; empty: generate one of n spheres
  std::size_t n = 10000;
  std::uint64_t steps = 2000;  // timed steps
  std::uint64_t warmup = 100;  // untimed steps first
  std::vector<int> threads{1};
  double skin = 0.2e-3;      // m, the Verlet skin LIGGGHTS ran with
  std::uint64_t seed = 1;    // for a generated packing
  bool energy = false;       // track contact dissipation (LIGGGHTS does not)
  std::string save_packing;  // write the generated packing here
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
  std::uint64_t rebuilds = 0;  // neighbour list rebuilds in the timed phase
  std::uint64_t state_hash = 0;
};

// The generated stand-in for the peers' packings: radii uniform in [0.9, 1.1] mm, grown to
// a loose state, then compressed by servo walls to 1 MPa with friction 0.1, as the peers'
// packings were prepared.
Packing<3> benchPacking(std::size_t n, std::uint64_t seed, int threads);

BenchResult runBench(const Packing<3>& packing, const BenchOptions& options, int threads);

void printBench(std::ostream& out, const std::vector<BenchResult>& results, bool json,
                const std::string& source);

}  // namespace rocklab
