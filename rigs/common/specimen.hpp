#pragma once
// A specimen in a loading frame, built from a protocol: the packing, the material, the
// frame; formation under stress and cementing; and the measurements every rig records.
// The protocol sections shared by the rigs (protocol, sample, material, bonds,
// formation, numerics, output) are declared here once.

#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <unordered_map>

#include "lab/protocol/params.hpp"
#include "rigs/common/experiment.hpp"
#include "rigs/common/frame.hpp"

namespace rocklab::rigs {

using protocol::Settings;

// Declares the shared sections. `rig_names` are the allowed values of protocol.rig.
void declareCommon(protocol::Schema& s, const std::vector<std::string>& rig_names);
// Checks across keys of the shared sections (throws protocol::ProtocolError).
void validateCommon(const Settings& s);

// A number for a message: `precision` significant digits.
std::string fmt(double v, int precision = 3);

// Runs `body(std::integral_constant<int, D>{})` for the protocol's dimension: a rig's
// entry point picks its 2D or 3D instantiation in one line.
template <class Body>
void byDimension(const Settings& s, Body&& body) {
  if (s.integer("protocol.dimension") == 2) {
    body(std::integral_constant<int, 2>{});
  } else {
    body(std::integral_constant<int, 3>{});
  }
}

// Intact bonds of one kind by their orientation to the sigma_1 axis: within 30 degrees of
// it ("axial" bonds: their breaks open cracks across the axis) and within 30 degrees of the
// plane normal to it ("lateral" bonds: cracks along the axis, which slow the waves that
// cross it; Li & Holt section 4.2 explain Figure 18b's anisotropy by which of them fail),
// and the rest, 30-60 degrees from the axis ("inclined": they carry most of the shear
// stiffness in the planes through the axis, which the S wave along the axis, szx, sees).
struct BondOrientations {
  std::size_t axial = 0, lateral = 0, inclined = 0;
};
template <int D>
BondOrientations bondOrientations(const Simulation<D>& sim, std::uint8_t kind, int axis);

// Each bond of one kind, keyed by its two particles' slots (which outlive the particles'
// sorting and the removal of broken bonds), with its orientation class at this instant:
// 0 axial, 1 inclined, 2 lateral.
using BondClasses = std::unordered_map<std::uint64_t, std::uint8_t>;
template <int D>
BondClasses bondClasses(const Simulation<D>& sim, std::uint8_t kind, int axis);
// The bonds of `kind` intact now, each counted in the class it had in `reference`: a bond
// that turns across a class boundary under load stays in its class, so a class's broken
// fraction cannot fall below zero (counted by the present orientation, it did, by 0.001).
template <int D>
BondOrientations intactByClass(const Simulation<D>& sim, std::uint8_t kind,
                               const BondClasses& reference);
// The bonds of each class in `classes`.
BondOrientations countClasses(const BondClasses& classes);

template <int D>
struct Specimen {
  std::unique_ptr<Simulation<D>> sim;
  std::unique_ptr<LoadingFrame<D>> frame;
  double mean_radius = 0.0;                 // m
  double density = 0.0;                     // kg/m^3
  std::optional<std::uint8_t> cement_kind;  // intergranular cement, once cemented
  CementReport cement;
  // Breakable grains (sample.kind = grains): their bond kind, what was installed, and each
  // grain's measured aspect ratio.
  std::optional<std::uint8_t> grain_kind;
  CementReport grain_bonds;
  std::vector<double> grain_aspect_ratios;
  // Rigid grains (sample.kind = clumps) broken into their pebbles so far.
  std::uint64_t clump_breaks = 0;
  std::uint64_t record_every = 500;
  std::uint64_t snapshot_every = 0;  // 0: only at the ends of stages
  // Bonds broken before the measured stage (formation, coring) are not counted in it:
  // cement tensile, shear, then grain tensile, shear; likewise the grains' fragments.
  std::uint64_t broken_offset[4] = {0, 0, 0, 0};
  std::vector<std::uint32_t> fragments_reference;
  BondClasses cement_classes;  // intact cement at the measured stage's start
  // Positions of the breaks handed to the notebook while this is on (localisation).
  bool keep_break_positions = false;
  std::vector<std::array<double, 3>> break_positions;

  static constexpr int kAxial = D - 1;  // z in 3D, y in 2D
  // A deep copy for a branch of the experiment (e.g. virgin and cored).
  Specimen branch() const;
  std::uint64_t broken(BondBreakMode mode) const;          // cement
  std::uint64_t brokenInGrains(BondBreakMode mode) const;  // intragranular
  std::size_t crushedGrains() const;  // grains in more fragments than at the reference
  void resetBrokenCount();
};

// Generates the packing, builds the simulation with the protocol's material (friction
// from formation.friction) and the frame at the packing's box.
template <int D>
Specimen<D> buildSpecimen(const Settings& s, RunControl& control);

// Servo-controls the frame to the formation state (axial and lateral stress), settles it to
// equilibrium, then sets the material's own friction and, when bonds are enabled, cements
// every contact with zero initial load (the sample is "formed under stress").
template <int D>
void formAndCement(Specimen<D>& sp, const Settings& s, Recorder& rec, RunControl& control);

// Moves the frame by servo from its present stresses to (axial, lateral) targets at a
// stress rate, and holds there until settled. Used by coring and reloading.
template <int D>
void servoTo(Specimen<D>& sp, const Settings& s, double axial, double lateral, double rate,
             const std::string& stage, Recorder& rec, RunControl& control);

// Records the standard measurements as series `prefix + name` and hands over bond breaks
// as events of `stage`.
template <int D>
void recordState(Specimen<D>& sp, Recorder& rec, const std::string& prefix,
                 const std::string& stage, double strain_rate);
template <int D>
void recordBreaks(Specimen<D>& sp, Recorder& rec, const std::string& stage);

// A frame of the state, when the protocol asks for snapshots (output.snapshots).
template <int D>
void snapshot(Specimen<D>& sp, const Settings& s, Recorder& rec, const std::string& stage,
              const std::string& label);

// The stage timings of the simulations an experiment ran (branches summed), to the recorder.
template <int D>
void recordTimings(Recorder& rec, const std::vector<const Simulation<D>*>& sims);

// Quasi-static control is measured, not assumed: warns (a notebook message) when a
// loading stage's mean unbalanced force ratio or largest inertial number (0: not measured)
// passed the protocol's limits.
template <int D>
void warnIfNotQuasiStatic(const Simulation<D>& sim, const Settings& s, Recorder& rec,
                          const std::string& stage, double mean_unbalanced, double inertial_max);

// The inertial number I = edot d sqrt(rho / p) of the present loading: below about 1e-3 a
// granular test is quasi-static (GDR MiDi 2004; da Cruz et al. 2005).
template <int D>
double inertialNumber(const Specimen<D>& sp, double strain_rate);

}  // namespace rocklab::rigs
