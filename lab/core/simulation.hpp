#pragma once
// A DEM simulation: particles, walls and contacts advanced by velocity Verlet, with only
// the stages the scene calls for, per-stage timing, energy bookkeeping, an instability
// guard and checkpoints.
//
// Who may change what: scene set-up code (generators, rigs between steps) edits particles
// and walls through the mutable accessors; rigs during a run only set wall velocities and
// servo targets; observers (logging, rendering) use the const accessors and can never
// change the run.

#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "lab/core/bond_forces.hpp"
#include "lab/core/bonds.hpp"
#include "lab/core/clumps.hpp"
#include "lab/core/contact_laws.hpp"
#include "lab/core/contact_model.hpp"
#include "lab/core/contacts.hpp"
#include "lab/core/fields.hpp"
#include "lab/core/material.hpp"
#include "lab/core/neighbors.hpp"
#include "lab/core/particles.hpp"
#include "lab/core/random.hpp"
#include "lab/core/stage_clock.hpp"
#include "lab/core/walls.hpp"

namespace rocklab {

struct TimeStepConfig {
  bool automatic = true;      // estimate the critical step and follow it
  double fixed_dt = 0.0;      // s, the step when not automatic
  double safety = 0.5;        // -, automatic step = safety * critical estimate
  int update_interval = 100;  // steps between critical-step estimates
  // -, density scaling (PFC's practice for quasi-static runs): the automatic step is this
  // times the critical estimate, and every free particle whose own critical step is shorter
  // gets an inertial mass and moment heavier by (target / own)^2, so that none is less
  // stable than at 1 (off). Equilibrium states do not depend on inertia; the path to them
  // does, so it is for quasi-static stages only, its inertial number checked by the rig.
  double density_scaling = 1.0;
};

struct GuardConfig {
  double overlap_limit = 0.25;  // -, largest overlap / smaller radius before the run stops
  double energy_growth = 2.0;   // -, kinetic energy above this times (initial + input) stops it
  // Off only for scenes that add energy no ledger sees (radius expansion in packing).
  bool energy_runaway = true;
};

// The defaults are PFC's for quasi-static loading (local damping 0.7) and a Verlet skin of a
// fifth of the mean radius; scenes that need otherwise (a collision, a wave) say so.
struct SimulationConfig {
  std::string contact_law = "linear";
  double skin = 0.0;           // m, Verlet skin; 0: skin_ratio times the mean radius
  double skin_ratio = 0.2;     // -, the skin over the mean radius
  double local_damping = 0.7;  // -, PFC local damping coefficient, 0 (off) to < 1
  TimeStepConfig timestep;
  GuardConfig guard;
  int threads = 1;           // OpenMP threads; results do not depend on it
  bool track_energy = true;  // friction and viscous dissipation, per contact
  bool spatial_sort = true;  // reorder particles along the cell grid on rebuilds
  std::array<double, 3> gravity{0.0, 0.0, 0.0};  // m/s^2, only the first D components used
  // false: bonds carry any load unbroken (an ultrasonic window: microseconds in which the
  // lab sample breaks nothing, while a DEM sample loaded fast keeps breaking for long).
  bool bond_breakage = true;
  // Bonds up to this many per vector register (bond_lanes.hpp, 2D and 3D: 8 with AVX-512, 4
  // with AVX), or one at a time (0): the same bits at any width, so this only changes the
  // speed; the tests compare them.
  int bond_lane_width = 8;
  // Touching pairs up to this many per vector register (contact_lanes.hpp: 8 with AVX-512, 4
  // with AVX), or one at a time (0): the same bits at any width, as for bonds.
  int contact_lane_width = 8;

  // The fields a protocol sets, with their keys (the contact law in the material section).
  template <class F>
  void fields(F& f) {
    f(contact_law, {"material.contact_law", units::text, {}, "contact law between grains"},
      contactLawChoices());
    f(timestep.safety, {"numerics.timestep_safety", units::none, Range::leftOpen(0, 1),
                        "time step over the critical estimate"});
    f(timestep.density_scaling,
      {"numerics.density_scaling", units::none, Range::closed(1, 16),
       "quasi-static stages after the formation (formation.density_scaling is its own): the "
       "critical step over the lightest particles' own, reached by heavier inertial masses "
       "where needed (1: off; never in wave windows)"});
    f(local_damping, {"numerics.local_damping", units::none, Range::rightOpen(0, 1),
                      "PFC local damping coefficient"});
    f(threads, {"numerics.threads", units::none, Range::closed(1, 1024),
                "OpenMP threads; results do not depend on it"});
    f(skin_ratio, {"numerics.skin_ratio", units::none, Range::leftOpen(0, 10),
                   "Verlet skin over the mean radius"});
    f(guard.overlap_limit,
      {"numerics.overlap_limit", units::none, Range::leftOpen(0, 1),
       "the run stops when an overlap exceeds this fraction of the smaller radius"});
  }
};

// Energy exchanged since the ledger started (J).
struct EnergyLedger {
  double initial = 0.0;        // kinetic + strain energy when the ledger started
  double boundary_work = 0.0;  // work of walls and driven (fixed) particles on the others
  double body_work = 0.0;      // work of gravity and applied (fluid) forces
  double friction = 0.0;       // dissipated by Coulomb sliding
  double viscous = 0.0;        // dissipated by contact dashpots
  double local_damping = 0.0;  // dissipated by local (non-viscous) damping
  double bond_breakage = 0.0;  // elastic energy bonds held when they broke
  // Kinetic energy lost when clumps broke into pebbles (each pebble keeps its velocity in
  // the body, but the pebbles' own masses differ from their share of the body's).
  double clump_release = 0.0;
  // Kinetic energy the density scaling added (or took) when it changed inertial masses at
  // unchanged velocities.
  double mass_scaling = 0.0;
  double positive_input = 0.0;  // energy put in (for the runaway guard)
  bool started = false;
};

struct EnergyReport {
  double kinetic_translation = 0.0;
  double kinetic_rotation = 0.0;
  double strain = 0.0;
  EnergyLedger ledger;
  double kinetic() const { return kinetic_translation + kinetic_rotation; }
  // Energy now held or dissipated, minus the energy that came in: zero for an exact scheme.
  double imbalance() const {
    return kinetic() + strain + ledger.friction + ledger.viscous + ledger.local_damping +
           ledger.bond_breakage + ledger.clump_release -
           (ledger.initial + ledger.boundary_work + ledger.body_work + ledger.mass_scaling);
  }
};

class SimulationUnstable : public std::runtime_error {
 public:
  enum class Cause { NonFinite, Overlap, EnergyRunaway };
  SimulationUnstable(Cause cause, std::uint64_t step, const std::string& diagnosis)
      : std::runtime_error(diagnosis), cause_(cause), step_(step) {}
  Cause cause() const { return cause_; }
  std::uint64_t step() const { return step_; }

 private:
  Cause cause_;
  std::uint64_t step_;
};

// A clump that broke into its pebbles.
template <int D>
struct ClumpBreak {
  std::uint64_t step = 0;
  double time = 0.0;
  Vec<D> position = Vec<D>::Zero();  // centroid
  std::uint32_t clump = 0;
  std::uint32_t pebbles = 0;
  double stress = 0.0;  // Pa, characteristic stress that broke it

  template <class Archive>
  void visit(Archive& ar) {
    ar("step", step), ar("time", time), ar("position", position), ar("clump", clump);
    ar("pebbles", pebbles), ar("stress", stress);
  }
};

template <int D>
class Simulation {
 public:
  using V = Vec<D>;
  using A = Ang<D>;

  Simulation(MaterialTable materials, SimulationConfig config);
  ~Simulation();
  Simulation(Simulation&&) noexcept;
  Simulation& operator=(Simulation&&) noexcept;

  // --- scene set-up ---
  ParticleStore<D>& particles() { return particles_; }
  const ParticleStore<D>& particles() const { return particles_; }
  std::size_t addWall(Wall<D> w);
  Wall<D>& wall(std::size_t i) { return walls_.at(i); }
  // Moves a wall to a new point at once (a rig placing its platens); the contacts are found
  // anew before the next step. No work is booked: place a wall only where it presses on
  // nothing, as a platen brought to touch a specimen.
  void placeWall(std::size_t i, const V& point);
  const Wall<D>& wall(std::size_t i) const { return walls_.at(i); }
  const std::vector<Wall<D>>& walls() const { return walls_; }
  const MaterialTable& materials() const { return materials_; }
  const SimulationConfig& config() const { return config_; }
  // Call after moving particles by hand, adding or removing them, or changing radii.
  void invalidateNeighbors() {
    contacts_.valid = false;
    forces_valid_ = false;
  }
  // Scales every radius by `factor` (radius expansion); masses stay. Growth counts against
  // the neighbour skin like motion, so the list is rebuilt only when needed.
  void scaleRadii(double factor);
  void setLocalDamping(double alpha) { config_.local_damping = alpha; }
  void setThreads(int threads) { config_.threads = threads; }  // the results do not change
  void setBondBreakage(bool on) { config_.bond_breakage = on; }
  void setFixedTimeStep(double dt);
  // Density scaling from now on (TimeStepConfig::density_scaling; 1: the physical masses
  // back, as a wave window needs). Takes effect at once when the simulation is prepared.
  void setDensityScaling(double factor);
  // Replaces the materials (e.g. the friction after forming a sample); contact history and
  // bonds stay. The table must keep the indices particles and walls use. The step stays until
  // its next estimate: the rigs change the friction alone, and a resumed run changes it again
  // after its checkpoint, where an estimate would part it from the run never stopped.
  void replaceMaterials(MaterialTable materials);
  // A deep copy through the checkpoint serializer (a branch of an experiment, a wave
  // measurement on a copy of a loaded sample); stage timings start anew.
  Simulation clone() const;
  // The whole state as bytes of the checkpoint serializer, and a simulation made from them
  // that continues bit for bit (a rig's checkpoint holds them beside the rig's own state).
  std::string stateBytes() const;
  static Simulation fromStateBytes(const std::string& bytes);
  // Starts the energy ledger anew from the present state.
  void restartEnergyLedger();
  Rng& rng() { return rng_; }

  // --- cement ---
  std::uint8_t addBondKind(BondKind kind);
  const std::vector<BondKind>& bondKinds() const { return bond_kinds_; }
  // Installs a bond of `kind` with zero load on every particle pair that touches or whose
  // gap is below gap_ratio times the smaller radius (the sample is "formed under stress":
  // the bonds take only what comes after). Strengths are drawn per bond from the scene's
  // random stream. Pairs already bonded are left as they are. An intragranular kind joins
  // only particles of one cluster (grain), any other kind only particles of different
  // clusters (or of none); pebbles of one clump are never bonded.
  CementReport cement(std::uint8_t kind, double gap_ratio);
  // Removes particles and the bonds that hold them (a cut, not a break: nothing is logged
  // as broken), as a rig cuts a specimen from a formed sample. The others keep their state,
  // their bonds and contact history; the energy ledger restarts, since what the removed
  // particles held leaves with them. A pebble of an unbroken clump cannot be removed alone.
  void removeParticles(const std::vector<ParticleId>& ids);
  const BondStore<D>& bonds() const { return bonds_; }
  // Draws the strengths of every bond of kind `kind_index` again, from the scene's random
  // stream in bond order as cement() drew them, for `kind`, which replaces the kind and
  // differs from it in its strengths only. Returns the draws <= 0 drawn again, or nullopt,
  // changing nothing, when a draw is <= 0 and the kind skips such bonds (cement() would not
  // have installed that bond). Parallel bonds only (a flat joint's slits draw as well).
  std::optional<std::size_t> redrawStrengths(std::uint8_t kind_index, const BondKind& kind);
  // Keeps each bond's peak stresses from now on (BondForces::trackPeaks); bondPeaks() is
  // null when they are not kept or were lost to a bond added or removed.
  void trackBondPeaks(bool on) { bond_forces_.trackPeaks(on); }
  const typename BondForces<D>::Peaks* bondPeaks() const {
    return bond_forces_.peaks(bonds_.size());
  }
  // Bonds broken so far of a kind and mode.
  std::uint64_t brokenBonds(std::uint8_t kind, BondBreakMode mode) const;
  // Every bond break since the scene began, oldest first. Observers read on from where they
  // stopped (their own cursor into it); reading changes nothing.
  const std::vector<BondBreak<D>>& bondBreaks() const { return bond_breaks_; }

  // --- clumps (rigid bodies of pebbles) ---
  // Makes the given particles, all of one density, a rigid clump with their momentum and
  // their angular momentum about its centroid; contacts between them are never formed
  // again. `strength` (Pa, 0: never)
  // breaks it back into its pebbles when the largest normal contact force F on a pebble
  // gives a characteristic stress F / d^2 (d: the clump's equivalent diameter; McDowell &
  // Bolton 1998, "On the micromechanics of crushable aggregates") at or above it.
  std::uint32_t addClump(const std::vector<ParticleId>& pebbles, double strength = 0.0,
                         int resolution = 128);
  const ClumpStore<D>& clumps() const { return clumps_; }
  // Breaks a clump into its pebbles, which keep the velocity they had in the body.
  void releaseClump(std::uint32_t clump);
  // Every clump break since the scene began, oldest first (as bondBreaks()).
  const std::vector<ClumpBreak<D>>& clumpBreaks() const { return clump_breaks_; }

  // --- driven particles (a wave transmitter, rigs/ultrasonic/README.md) ---
  // Makes the particles at these slots driven: infinite mass and inertia, no spin, moving
  // with the velocity setDrivenVelocity gives them whatever the forces on them; their work
  // on the others is booked as boundary work. Clump pebbles cannot be driven.
  void drive(const std::vector<std::uint32_t>& slots);
  // The velocity of driven particles from this step on (the rig's source signal).
  void setDrivenVelocity(const std::vector<std::uint32_t>& slots, const V& velocity);

  // --- applied loads ---
  // Forces on particles besides contacts, bonds and gravity (the pore fluid's), indexed by
  // particle slot. They stay until replaced; an empty vector removes them. Their work is
  // booked with the body forces' (ledger.body_work).
  void setAppliedForces(std::vector<V> by_slot) { applied_ = std::move(by_slot); }
  const std::vector<V>& appliedForces() const { return applied_; }

  // --- running ---
  // Validates the settings, builds the contact model and the neighbour list, evaluates the
  // forces and sets the time step; step() does it on its first call.
  void prepare();
  void step();
  void run(std::uint64_t steps);

  // --- const read-outs ---
  double time() const { return time_; }
  double dt() const { return dt_; }
  std::uint64_t steps() const { return step_; }
  // The critical time step estimate (s) with the physical masses: min over particles of
  // sqrt(m / sum kn) and sqrt(I / sum ks l^2) with tangent stiffnesses, and of the
  // lone-particle bound.
  double criticalTimeStep() const;
  // Total inertial over total physical mass of the free particles: 1 without density scaling.
  double inertialMassRatio() const;
  EnergyReport energy() const;
  // Mean particle-particle contacts per particle, 2 C / N (overlap > 0; walls excluded).
  double coordinationNumber() const;
  std::size_t particleContacts() const;
  // Largest overlap over the smaller radius, particle pairs and walls.
  double maxOverlapRatio() const;
  // Touching particle pairs with their elastic normal force and tangential spring force.
  struct ContactForce {
    std::size_t i, j;
    double normal, tangential;  // N
  };
  std::vector<ContactForce> contactForces() const;
  // Mean unbalanced force over mean contact force (PFC's equilibrium measure).
  double unbalancedForceRatio() const;
  // Mean speed (m/s) of the free particles and clumps: whether the sample is at rest, which
  // the unbalanced forces do not tell of a sample straining as a whole.
  double meanSpeed() const;
  // The first moment of the unbalanced forces about `origin`, per axis a: the sum over the
  // free particles and clumps of (x - origin)_a F_a, F the contact, bond and wall forces on
  // each (its weight and applied load left out). A box of walls holding the sample: its wall
  // stress (compression positive, the mean of each axis's two walls about the box's centre)
  // plus this over its volume is the Love-Weber average stress of the contents, the sum of
  // branch vector times force over the contacts (Love 1927; Weber 1966). The two differ by
  // the bodies' inertia and damping, the walls' reading of a sample that is not balanced.
  V unbalancedForceMoment(const V& origin) const;
  const ContactStore<D>& contacts() const { return contacts_; }
  std::vector<StageTiming> stageTimings() const;
  // FNV-1a hash of the dynamic state, to compare runs bit for bit.
  std::uint64_t stateHash() const;

  // --- checkpoints ---
  void saveCheckpoint(const std::string& path) const;
  static Simulation loadCheckpoint(const std::string& path);
  // Version 3 added config.bond_breakage, 4 the bond kinds' friction_angle and moment_factor,
  // 5 config.skin_ratio, 6 the applied forces, 7 density scaling (the particles' physical
  // masses, config.timestep.density_scaling, ledger.mass_scaling), 8 flat joints (the bond
  // kinds' model and faces, the bonds' face states), 9 the flat joints' slit fraction, 10 the
  // flat joints' element forces and moments in the face's frame.
  static constexpr std::uint32_t kCheckpointVersion = 10;

 private:
  enum Stage { kIntegrate, kNeighbors, kBodyForces, kContacts, kBonds, kServo, kGuard, kStages };

  // Forces and torques at the present positions. With history_dt = 0 the contact history
  // does not advance (the set-up evaluation that velocity Verlet needs before its first
  // step); returns whether an overlap exceeded the guard's limit.
  bool computeForces(double history_dt);
  // Each particle's own critical step (s; infinite for fixed particles and pebbles) with its
  // physical mass, and the bound of the clumps (which are never scaled).
  struct StepLimits {
    std::vector<double> particle;
    double bodies = INFINITY;
  };
  StepLimits stepLimits() const;
  // The automatic step: safety times the critical estimate, or under density scaling times
  // its target, with the inertial masses set for it.
  double automaticStep();
  // After a change of stiffness or scaling: the automatic step and the inertial masses
  // estimated now when the simulation is prepared, else left to prepare() (the contact model
  // the estimate needs may be gone with the materials).
  void estimateStepAgain();
  void setInertialMasses(const std::vector<double>& limits, double target);
  void computeBondForces(double dt);
  void applyGravity(double dt);
  void applyForces(double dt);
  void integrateClumpsFirstHalf(double& max_speed);
  void integrateClumpsSecondHalf(double& kinetic, double& damping, double& body_work);
  void placePebbles(std::uint32_t c, bool positions);
  std::size_t drivenIndex(std::uint32_t slot) const;  // throws for a free slot
  void gatherClumpLoad(std::uint32_t c);
  void breakOverloadedClumps();
  bool hasClumps() const { return !clumps_.pos.empty(); }
  void initialIntegrate();
  void finalIntegrate();
  bool needsRebuild();
  void rebuild();
  void sortAlongGrid();
  void guard(bool overlap_exceeded);
  [[noreturn]] void fail(SimulationUnstable::Cause cause, const std::string& what) const;
  std::string diagnose() const;
  template <class Archive>
  void visit(Archive& ar);
  // A touching contact as observers see it; `wall` is null for a particle pair.
  struct Touching {
    std::size_t i = 0, j = 0;
    const Wall<D>* wall = nullptr;
    std::uint16_t mi = 0, mj = 0;
    ContactShape shape;
    double overlap = 0.0, mstar = 0.0, li = 0.0, lj = 0.0, min_radius = 0.0;
    double shear2 = 0.0;  // squared tangential spring force
  };
  // Visits every touching particle pair, then every touching particle-wall contact.
  template <class F>
  void forEachTouching(F&& visit) const;
  bool threaded() const { return config_.threads > 1; }
  // Threads of the per-particle passes (contacts, integration): config.threads, but one per
  // kParticlesPerThread particles at most (simulation.cpp says why).
  int particleThreads() const;

  MaterialTable materials_;
  SimulationConfig config_;
  ParticleStore<D> particles_;
  std::vector<Wall<D>> walls_;
  std::vector<V> wall_prev_force_;
  ContactStore<D> contacts_;
  NeighborGrid<D> grid_;
  std::unique_ptr<ContactModel<D>> model_;
  Rng rng_;
  EnergyLedger ledger_;
  std::vector<BondKind> bond_kinds_;
  BondStore<D> bonds_;
  BondForces<D> bond_forces_;
  std::vector<BondBreak<D>> bond_breaks_;
  std::vector<std::uint64_t> broken_counts_;  // 2 per kind: tensile, shear
  ClumpStore<D> clumps_;
  std::vector<ClumpBreak<D>> clump_breaks_;
  std::vector<V> applied_;  // by slot; empty in scenes without applied forces

  double time_ = 0.0;
  double dt_ = 0.0;
  std::uint64_t step_ = 0;
  double kinetic_ = 0.0;  // after the last step, for the guard
  bool prepared_ = false;
  bool forces_valid_ = false;
  // Local damping force and torque of the last step, kept apart so that `force` and
  // `torque` stay the physical unbalanced force; allocated only when damping is on.
  std::vector<V> damp_force_;
  std::vector<A> damp_torque_;
  std::array<StageTime, kStages> stages_{};
};

}  // namespace rocklab
