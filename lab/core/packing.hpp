#pragma once
// Packing generation: particle sizes from a distribution, random placement, and radius
// expansion in a fixed box to a target porosity (the PFC radius-expansion method).

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "lab/core/dim.hpp"
#include "lab/core/fields.hpp"
#include "lab/core/random.hpp"

namespace rocklab {

// Particle diameters. The defaults are a sand's: Gaussian in phi about 1 mm (phi 0, sd 0.5),
// truncated to [0.5, 2] mm.
struct SizeDistribution {
  enum class Kind { Uniform, Normal, PhiGaussian };
  Kind kind = Kind::PhiGaussian;
  double d_min = 0.5 * kmm;   // m; uniform: lower bound; normal and phi: draws below are redrawn
  double d_max = 2.0 * kmm;   // m; likewise the upper bound
  double d_mean = 1.0 * kmm;  // m, normal
  double d_std = 0.2 * kmm;   // m, normal
  double phi_mean = 0.0;      // phi units, phi-Gaussian: phi = -log2(d / 1 mm)
  double phi_std = 0.5;       // phi units

  static SizeDistribution uniform(double d_min, double d_max);
  static SizeDistribution normal(double mean, double std, double d_min, double d_max);
  static SizeDistribution phiGaussian(double phi_mean, double phi_std, double d_min, double d_max);

  // A diameter (m). Draws outside [d_min, d_max] are redrawn (truncated distributions).
  double sample(Rng& rng) const;
  std::string describe() const;

  template <class F>
  void fields(F& f) {
    static constexpr Choice<Kind> kKinds[] = {
        {"uniform", Kind::Uniform}, {"normal", Kind::Normal}, {"phi", Kind::PhiGaussian}};
    const Range size = Range::leftOpen(0, 1e4);
    f(kind,
      {"size_distribution",
       units::text,
       {},
       "diameters uniform in [d_min, d_max], normal(d_mean, d_std), or Gaussian in "
       "phi = -log2(d / 1 mm); normal and phi are truncated to [d_min, d_max]"},
      kKinds);
    f(d_min, {"d_min_mm", units::mm, size, "smallest diameter"});
    f(d_max, {"d_max_mm", units::mm, size, "largest diameter"});
    f(d_mean, {"d_mean_mm", units::mm, size, "mean diameter (normal)"});
    f(d_std,
      {"d_std_mm", units::mm, Range::closed(0, 1e4), "diameter standard deviation (normal)"});
    f(phi_mean, {"phi_mean", units::phi, Range::closed(-20, 20), "mean of phi (phi)"});
    f(phi_std, {"phi_std", units::phi, Range::closed(0, 10), "standard deviation of phi (phi)"});
  }
  // The bounds in order and the mean inside them (throws InvalidParameter); the ranges of
  // the fields are checked with them by checkFields.
  void validate() const;
};

// phi = -log2(d / 1 mm) and back (Krumbein's phi scale of grain size).
inline double phiOfDiameter(double d_m) {
  return -std::log2(d_m / 1e-3);
}
inline double diameterOfPhi(double phi) {
  return 1e-3 * std::exp2(-phi);
}

struct PackingSpec {
  std::size_t count = 1000;
  SizeDistribution sizes;
  double porosity = 0.4;                  // -, target: 1 - particle volume / box volume
  std::array<double, 3> aspect{1, 1, 1};  // box edge ratios
  double thickness = 1.0;                 // m, 2D disk thickness
  std::uint64_t seed = 1;
  double friction = 0.0;  // -, during expansion (0 gives the densest packing)
  int threads = 1;
  // Called now and then with the fraction done (at most 1); may throw to abandon the work.
  std::function<void(double)> progress;

  // The fields a protocol sets (its `sample.*` section; the box's aspect is the rig's).
  template <class F>
  void fields(F& f) {
    f(count, {"count", units::none, Range::closed(2, 5e7),
              "number of particles (grains for kind = grains); required unless the sample is "
              "read from a file (kind = file)"});
    f.section("", sizes);
    f(porosity, {"porosity_initial", units::none, Range::closed(0.05, 0.9),
                 "porosity the packing is generated at (radius expansion), before formation"});
    f(thickness, {"thickness_m", units::m, Range::leftOpen(0, 1e3), "disk thickness (2D)"});
  }
};

template <int D>
struct Packing {
  Vec<D> lo = Vec<D>::Zero(), hi = Vec<D>::Zero();  // inner faces of the box walls
  std::vector<Vec<D>> centers;
  std::vector<double> radii;
  double thickness = 1.0;

  double boxVolume() const;
  double solidVolume() const;
  // Nominal porosity: 1 - sum of particle volumes / box volume (overlaps not removed).
  double porosity() const { return 1.0 - solidVolume() / boxVolume(); }
};

struct PackingReport {
  std::uint64_t steps = 0;
  double max_overlap = 0.0;   // largest overlap / smaller radius at the end
  double coordination = 0.0;  // mean contacts per particle at the end
  double unbalanced = 0.0;    // unbalanced force ratio at the end
};

// Random sequential placement in the box [lo, hi]: each sphere (largest first) at the
// first of a few hundred random spots where it overlaps nothing placed before; if none is
// free it takes the least overlapping spot (an expansion then pushes the overlap apart).
template <int D>
std::vector<Vec<D>> placeRandomly(const std::vector<double>& r, const Vec<D>& lo, const Vec<D>& hi,
                                  Rng& rng);

template <int D>
Packing<D> generatePacking(const PackingSpec& spec, PackingReport* report = nullptr);

// The pieces of radius expansion, shared by the sphere and the grain generators.
template <int D>
class Simulation;
inline constexpr double kExpansionDensity = 2650.0;  // kg/m^3; the result is geometric
// A soft linear-spring scene in the box [lo, hi] of walls (no particles yet).
template <int D>
Simulation<D> expansionScene(double r_mean, double thickness, double friction, int threads,
                             const Vec<D>& lo, const Vec<D>& hi);
// Grows every radius (and clump) by 1 / s0, at most 2e-4 of it per step; calls
// `after_growth` (may be empty: e.g. to set the exact final radii); relaxes until the
// overlaps are gone or the packing is in equilibrium. Progress goes 0..1.
template <int D>
void growAndRelax(Simulation<D>& sim, double s0, const std::function<void(double)>& progress,
                  const std::function<void()>& after_growth);

}  // namespace rocklab
