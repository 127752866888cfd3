#pragma once
// The particle store: hot per-particle state in structure-of-arrays form, cold metadata
// apart, and generation-checked handles that survive reordering and detect stale ids.

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "lab/core/dim.hpp"

namespace rocklab {

// A stable handle to a particle. `slot` names the particle for its whole life (contact
// history and bonds are keyed by slots); `generation` changes when a slot is reused, so a
// handle to a removed particle is detected instead of silently naming its successor.
struct ParticleId {
  std::uint32_t slot = 0;
  std::uint32_t generation = 0;
  friend bool operator==(const ParticleId&, const ParticleId&) = default;
};

// No rigid body (clump) or grain (cluster): the particle is on its own.
inline constexpr std::uint32_t kNoBody = 0xffffffffu;
inline constexpr std::uint32_t kNoCluster = 0xffffffffu;

class StaleParticleId : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

template <int D>
struct ParticleSpec {
  Vec<D> position = Vec<D>::Zero();
  Vec<D> velocity = Vec<D>::Zero();
  Ang<D> spin = angZero<Ang<D>>();
  double radius = 0.0;
  double density = 0.0;  // kg/m^3
  bool fixed = false;    // infinite mass and inertia: moves only if its velocity is prescribed
  std::uint16_t material = 0;
  std::uint32_t groups = 0;  // bit mask of user group tags
  // The breakable grain (cluster) the particle belongs to: intragranular bonds join
  // particles of one cluster, intergranular bonds particles of different ones.
  std::uint32_t cluster = kNoCluster;
};

template <int D>
class ParticleStore {
 public:
  using V = Vec<D>;
  using A = Ang<D>;

  // Hot state: what the force and integration loops touch, contiguous per quantity.
  std::vector<V> pos, vel, force;
  std::vector<A> spin, torque;
  // The inertial masses, what the forces accelerate: the physical ones below, or heavier under
  // density scaling (Simulation::setDensityScaling); 0 for fixed and driven particles.
  std::vector<double> inv_mass, inv_inertia, radius;
  std::vector<std::uint16_t> material;  // read in the contact loop to mix pair parameters

  // The physical masses (density times volume; a clump pebble's, its body's): what gravity
  // pulls and what density scaling scales from. 0 for fixed particles.
  std::vector<double> physical_inv_mass, physical_inv_inertia;

  // Cold metadata.
  std::vector<std::uint32_t> groups;
  std::vector<std::uint32_t> cluster;  // grain id or kNoCluster
  // The clump (rigid body) the particle is a pebble of, or kNoBody. Set by the simulation;
  // a pebble moves with its body and is skipped by the particle integration.
  std::vector<std::uint32_t> body;
  std::vector<std::uint32_t> slot_of;  // index -> slot

  // 2D particles are disks extruded to this thickness (m); ignored in 3D.
  double thickness = 1.0;

  std::size_t size() const { return pos.size(); }

  ParticleId add(const ParticleSpec<D>& spec);
  void remove(ParticleId id);

  bool valid(ParticleId id) const {
    return id.slot < slot_generation_.size() && slot_generation_[id.slot] == id.generation &&
           slot_index_[id.slot] != kNoIndex;
  }
  // Current array index of a particle; throws StaleParticleId for a removed particle.
  std::size_t index(ParticleId id) const;
  ParticleId id(std::size_t index) const {
    const auto s = slot_of[index];
    return {s, slot_generation_[s]};
  }
  std::size_t indexOfSlot(std::uint32_t slot) const { return slot_index_[slot]; }
  bool occupied(std::uint32_t slot) const {
    return slot < slot_index_.size() && slot_index_[slot] != kNoIndex;
  }
  std::size_t slotCapacity() const { return slot_index_.size(); }

  double mass(std::size_t i) const { return inv_mass[i] > 0 ? 1.0 / inv_mass[i] : INFINITY; }
  // Sets a particle's physical and inertial mass and moment of inertia (unscaled).
  void setMass(std::size_t i, double mass, double inertia) {
    inv_mass[i] = physical_inv_mass[i] = 1.0 / mass;
    inv_inertia[i] = physical_inv_inertia[i] = 1.0 / inertia;
  }
  double volume(std::size_t i) const { return particleVolume<D>(radius[i], thickness); }

  // Reorders every array so that new index k holds the particle that was at order[k].
  void permute(const std::vector<std::uint32_t>& order);

  // The slot bookkeeping, for checkpoints (one serializer visits it; see archive.hpp).
  template <class Archive>
  void visit(Archive& ar) {
    ar("thickness", thickness);
    ar("pos", pos), ar("vel", vel), ar("force", force), ar("spin", spin), ar("torque", torque);
    ar("inv_mass", inv_mass), ar("inv_inertia", inv_inertia), ar("radius", radius);
    ar("physical_inv_mass", physical_inv_mass), ar("physical_inv_inertia", physical_inv_inertia);
    ar("material", material), ar("groups", groups), ar("cluster", cluster);
    ar("body", body), ar("slot_of", slot_of);
    ar("slot_index", slot_index_), ar("slot_generation", slot_generation_);
    ar("free_slots", free_slots_);
  }

 private:
  static constexpr std::uint32_t kNoIndex = 0xffffffffu;
  std::vector<std::uint32_t> slot_index_;       // slot -> index, kNoIndex when free
  std::vector<std::uint32_t> slot_generation_;  // slot -> generation
  std::vector<std::uint32_t> free_slots_;
};

}  // namespace rocklab
