#include "lab/core/particles.hpp"

#include <algorithm>

namespace rocklab {

template <int D>
ParticleId ParticleStore<D>::add(const ParticleSpec<D>& spec) {
  if (!(spec.radius > 0.0) || !std::isfinite(spec.radius)) {
    throw std::invalid_argument("particle radius must be positive and finite, got " +
                                std::to_string(spec.radius) + " m");
  }
  if (!spec.fixed && !(spec.density > 0.0)) {
    throw std::invalid_argument("particle density must be positive, got " +
                                std::to_string(spec.density) + " kg/m^3");
  }
  if (!spec.position.allFinite() || !spec.velocity.allFinite()) {
    throw std::invalid_argument("particle position and velocity must be finite");
  }
  std::uint32_t slot;
  if (!free_slots_.empty()) {
    slot = free_slots_.back();
    free_slots_.pop_back();
  } else {
    slot = static_cast<std::uint32_t>(slot_index_.size());
    slot_index_.push_back(kNoIndex);
    slot_generation_.push_back(0);
  }
  const auto index = static_cast<std::uint32_t>(pos.size());
  slot_index_[slot] = index;

  const double mass = spec.density * particleVolume<D>(spec.radius, thickness);
  pos.push_back(spec.position);
  vel.push_back(spec.velocity);
  force.push_back(V::Zero());
  spin.push_back(spec.spin);
  torque.push_back(angZero<A>());
  inv_mass.push_back(spec.fixed ? 0.0 : 1.0 / mass);
  inv_inertia.push_back(spec.fixed ? 0.0 : 1.0 / particleInertia<D>(mass, spec.radius));
  physical_inv_mass.push_back(inv_mass.back());
  physical_inv_inertia.push_back(inv_inertia.back());
  radius.push_back(spec.radius);
  material.push_back(spec.material);
  groups.push_back(spec.groups);
  cluster.push_back(spec.cluster);
  body.push_back(kNoBody);
  slot_of.push_back(slot);
  return {slot, slot_generation_[slot]};
}

template <int D>
std::size_t ParticleStore<D>::index(ParticleId id) const {
  if (!valid(id)) {
    throw StaleParticleId("particle id (slot " + std::to_string(id.slot) + ", generation " +
                          std::to_string(id.generation) + ") does not name a live particle");
  }
  return slot_index_[id.slot];
}

template <int D>
void ParticleStore<D>::remove(ParticleId id) {
  const std::size_t i = index(id);
  const std::size_t last = size() - 1;
  auto move_last = [&](auto& v) {
    v[i] = v[last];
    v.pop_back();
  };
  if (i != last) slot_index_[slot_of[last]] = static_cast<std::uint32_t>(i);
  move_last(pos), move_last(vel), move_last(force), move_last(spin), move_last(torque);
  move_last(inv_mass), move_last(inv_inertia), move_last(radius), move_last(material);
  move_last(physical_inv_mass), move_last(physical_inv_inertia);
  move_last(groups), move_last(cluster), move_last(body), move_last(slot_of);
  slot_index_[id.slot] = kNoIndex;
  ++slot_generation_[id.slot];
  free_slots_.push_back(id.slot);
}

template <int D>
void ParticleStore<D>::permute(const std::vector<std::uint32_t>& order) {
  if (order.size() != size()) throw std::invalid_argument("permutation size mismatch");
  auto apply = [&](auto& v) {
    std::remove_reference_t<decltype(v)> out(v.size());
    for (std::size_t k = 0; k < order.size(); ++k) out[k] = v[order[k]];
    v.swap(out);
  };
  apply(pos), apply(vel), apply(force), apply(spin), apply(torque);
  apply(inv_mass), apply(inv_inertia), apply(radius), apply(material), apply(groups);
  apply(physical_inv_mass), apply(physical_inv_inertia);
  apply(cluster), apply(body), apply(slot_of);
  for (std::size_t k = 0; k < slot_of.size(); ++k) {
    slot_index_[slot_of[k]] = static_cast<std::uint32_t>(k);
  }
}

template class ParticleStore<2>;
template class ParticleStore<3>;

}  // namespace rocklab
