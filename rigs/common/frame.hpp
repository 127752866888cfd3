#pragma once
// The loading frame: a box of rigid walls (4 in 2D, 6 in 3D) around the sample. Each axis
// is fixed, strain-rate controlled, or servo-controlled to a stress (constant or ramp).
// Stresses come from wall forces over the current face areas, strains from wall
// positions, porosity from the box volume and the particle volumes. The frame only writes
// wall velocities and servo targets and reads wall forces: a rig never touches particles.

#include <array>
#include <functional>

#include "lab/core/archive.hpp"
#include "lab/core/simulation.hpp"

namespace rocklab::rigs {

// What a coupled effect keeps from one call to the next (a pore fluid's network and its
// pressures): checkpointed with the frame, so that a resumed run continues the effect as an
// uninterrupted one would.
class CoupledState {
 public:
  virtual ~CoupledState() = default;
  virtual void save(ArchiveWriter& ar) = 0;
  virtual void load(ArchiveReader& ar) = 0;
};

template <int D>
class LoadingFrame {
 public:
  enum class Mode { Fixed, StrainRate, Stress };
  struct Axis {
    Mode mode = Mode::Fixed;
    double strain_rate = 0.0;  // 1/s, compression positive (StrainRate)
    double stress = 0.0;       // Pa, compression positive, at the moment it is set (Stress)
    double stress_rate = 0.0;  // Pa/s (Stress: a ramp)
    template <class Archive>
    void visit(Archive& ar) {
      ar("mode", mode), ar("strain_rate", strain_rate), ar("stress", stress);
      ar("stress_rate", stress_rate);
    }
  };

  // Adds the walls on the faces of [lo, hi]; wall 2a bounds axis a from below, 2a + 1 from
  // above. `wall_material` is an index of the simulation's material table.
  LoadingFrame(Simulation<D>& sim, const Vec<D>& lo, const Vec<D>& hi, std::uint16_t wall_material);
  // Re-attaches to a copy of the simulation this frame drives (its walls at the same
  // indices), keeping the frame's settings but not its coupled effect (which acts on the
  // original).
  void attach(Simulation<D>& sim) {
    sim_ = &sim;
    effect_ = nullptr;
    coupled_state_ = nullptr;
  }
  // A frame read back from a checkpoint (visit) around a simulation read back with it: its
  // walls are already the simulation's.
  struct Restored {};
  LoadingFrame(Simulation<D>& sim, Restored) : sim_(&sim) {}
  // The frame's own state, for checkpoints (the walls are the simulation's; a coupled effect
  // is set again by the rig, its state read back into it).
  template <class Archive>
  void visit(Archive& ar) {
    ar("axes", axes_), ar("reference", reference_), ar("solid_volume", solid_volume_);
    ar("servo_alpha", servo_alpha_), ar("servo_max_speed", servo_max_speed_);
    ar("effect_interval", effect_interval_);
    bool coupled = coupled_state_ != nullptr;
    ar("coupled_state", coupled);
    if (!coupled) return;
    if constexpr (Archive::kReading) {
      if (!coupled_state_) {
        throw CheckpointError("the checkpoint holds a coupled effect's state the rig has not set");
      }
      coupled_state_->load(ar);
    } else {
      coupled_state_->save(ar);
    }
  }

  void set(int axis, const Axis& a);
  const Axis& axis(int a) const { return axes_[a]; }
  // Servo gain (relaxation factor, 0..1] and speed cap (m/s) for stress-controlled axes.
  void setServo(double alpha, double max_speed);

  // Keeps areas and strain-rate velocities current, runs the coupled effect when due, then
  // advances one step.
  void step();
  // An effect that acts before every step whose number is a multiple of `interval`: a
  // coupled pore fluid solved to steady state and applied to the particles (Li & Holt
  // section 3.5.2: every n particle steps). An empty function removes it. `state`, if the
  // effect keeps one, goes into the frame's checkpoints.
  void couple(std::function<void()> effect, std::uint64_t interval, CoupledState* state = nullptr) {
    effect_ = std::move(effect);
    effect_interval_ = std::max<std::uint64_t>(interval, 1);
    coupled_state_ = effect_ ? state : nullptr;
  }

  Simulation<D>& sim() { return *sim_; }
  const Simulation<D>& sim() const { return *sim_; }

  double length(int axis) const;
  double faceArea(int axis) const;
  double stress(int axis) const;  // Pa, compression positive, mean of the axis's two walls
  double force(int axis) const;   // N, compression positive, mean of the axis's two walls
  // Pa, compression positive: the Love-Weber average stress of the box's contents along each
  // axis, the wall stress less the inertia and damping the walls also carry
  // (Simulation::unbalancedForceMoment). Equal to stress() in equilibrium.
  Vec<D> interiorStress() const;
  // Moves the walls of an axis to lo (its lower wall) and hi (its upper), at once: platens
  // brought to touch a specimen cut from the sample, side walls taken away from it. They
  // must press on nothing there (Simulation::placeWall).
  void place(int axis, double lo, double hi);
  double meanStress() const;
  // Strain since the last resetReference(), compression positive.
  double strain(int axis) const;
  double volumetricStrain() const;
  void resetReference();
  double volume() const;    // m^3 (2D: area times thickness)
  double porosity() const;  // 1 - particle volume / box volume
  // Largest relative miss of the stress targets over the stress-controlled axes.
  double stressError() const;

 private:
  void apply();
  Simulation<D>* sim_;
  std::array<Axis, D> axes_{};
  std::array<double, D> reference_{};
  double solid_volume_ = 0.0;
  double servo_alpha_ = 0.5;
  double servo_max_speed_ = 0.0;
  std::function<void()> effect_;
  std::uint64_t effect_interval_ = 1;
  CoupledState* coupled_state_ = nullptr;
};

}  // namespace rocklab::rigs
