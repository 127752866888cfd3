#pragma once
// A specimen in a loading frame: the simulation, the frame of walls around it, the settings
// it was built from (rigs/common/settings.hpp) and what the rig keeps about it (its bond
// kinds, what has been recorded of it). Built from a protocol's shared sections by
// buildSpecimen; formed and cemented by formation.hpp; measured by measurements.hpp.

#include <memory>
#include <optional>
#include <type_traits>
#include <vector>

#include "rigs/common/bond_classes.hpp"
#include "rigs/common/experiment.hpp"
#include "rigs/common/formation_records.hpp"
#include "rigs/common/frame.hpp"
#include "rigs/common/settings.hpp"

namespace rocklab::rigs {

// Runs `body(std::integral_constant<int, D>{})` for the protocol's dimension: a rig's
// entry point picks its 2D or 3D instantiation in one line.
template <class Body>
void byDimension(int dimension, Body&& body) {
  if (dimension == 2) {
    body(std::integral_constant<int, 2>{});
  } else {
    body(std::integral_constant<int, 3>{});
  }
}

template <int D>
struct Specimen {
  SpecimenSettings settings;
  std::unique_ptr<Simulation<D>> sim;
  std::unique_ptr<LoadingFrame<D>> frame;
  double mean_radius = 0.0;                 // m
  std::optional<std::uint8_t> cement_kind;  // intergranular cement, once cemented
  CementReport cement;
  // Breakable grains (sample.kind = grains): their bond kind, what was installed, and each
  // grain's measured aspect ratio (also of rigid grains, sample.kind = clumps).
  std::optional<std::uint8_t> grain_kind;
  CementReport grain_bonds;
  std::vector<double> grain_aspect_ratios;
  // Bonds broken before the measured stage (formation, coring) are not counted in it:
  // cement tensile, shear, then grain tensile, shear; likewise the grains' fragments.
  std::uint64_t broken_offset[4] = {0, 0, 0, 0};
  std::vector<std::uint32_t> fragments_reference;
  BondClasses cement_classes;  // intact cement at the measured stage's start
  // How much of the simulation's break logs has been handed to the notebook: the recorder
  // reads on from here and never empties the logs (they are the run's, not the observer's).
  std::size_t bond_breaks_recorded = 0, clump_breaks_recorded = 0;
  // Formed by an earlier run of the lab (formation.reuse; formed_samples.hpp): formAndCement
  // records the formation as that run did instead of forming the sample again. `formed_note`
  // says why a sample was not taken from the lab or kept for it, for the notebook.
  std::optional<FormedOrigin> formed_from;
  std::string formed_note;

  static constexpr int kAxial = D - 1;  // z in 3D, y in 2D
  // A deep copy for a branch of the experiment (e.g. virgin and cored). The breaks before
  // the branch are the parent's to record: the branch records only its own.
  Specimen branch() const;
  std::uint64_t broken(BondBreakMode mode) const;          // cement
  std::uint64_t brokenInGrains(BondBreakMode mode) const;  // intragranular
  std::size_t crushedGrains() const;  // grains in more fragments than at the reference
  void resetBrokenCount();
  // The frame's servo gain and speed cap: numerics.servo_speed_radii_per_step mean radii per
  // step at the simulation's present step (set again when the step changes its meaning).
  void setServo();
  // The specimen's state for a run's checkpoints (rigs/common/journal.hpp): the
  // simulation, the frame and what the rig keeps; reading back rebuilds them.
  template <class Archive>
  void journal(Archive& ar);
};

// Generates the packing, builds the simulation with the protocol's material (friction
// from formation.friction) and the frame at the packing's box.
template <int D>
Specimen<D> buildSpecimen(const SpecimenSettings& s, RunControl& control);

// The seed of the scene's random stream the bonds' strengths are drawn from (buildSpecimen
// reseeds with it; a reused formed sample draws its grains' strengths again from it).
inline std::uint64_t bondStream(const SpecimenSettings& s) {
  return static_cast<std::uint64_t>(s.protocol.seed) ^ 0x5eedb0d5ull;
}

}  // namespace rocklab::rigs
