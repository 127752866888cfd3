#pragma once
// Materials of particles and walls, and the per-pair overrides a scene may set.

#include <algorithm>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "lab/core/fields.hpp"

namespace rocklab {

// Parameters a contact law may read. Each law declares the ones of its own a protocol sets
// (contact_laws.hpp) and validates them before a run starts; the common ones are declared
// here. The defaults are quartz grains (Hertz) and the paper's linear contacts (a contact
// modulus of 4 GPa, section 1).
struct Material {
  std::string name = "default";
  double density = 2650.0;       // kg/m^3, for scene builders: particles carry their own
  double young = 70.0 * kGPa;    // Pa, Hertz-Mindlin
  double poisson = 0.25;         // -, Hertz-Mindlin
  double kn = 0.0;               // N/m, linear: the particle's normal spring, in series per contact
  double ks = 0.0;               // N/m, linear: shear spring, in series per contact
  double modulus = 4.0 * kGPa;   // Pa, linear: contact modulus E, kn = E A / L per contact; 0: none
  double stiffness_ratio = 1.0;  // -, linear with a modulus: kn / ks
  double friction = 0.5;         // -, Coulomb coefficient
  double damping_ratio = 0.0;    // -, critical damping ratio of the contact dashpots

  // The fields every law reads (the protocol's `material.*` keys beside the law's own).
  template <class F>
  void fields(F& f) {
    f(density, {"density_kg_per_m3", units::kg_per_m3, Range::closed(1, 1e5), "grain density"});
    f(friction, {"friction", units::none, Range::closed(0, 10),
                 "grain-grain Coulomb friction after formation"});
    f(damping_ratio, {"damping_ratio", units::none, Range::rightOpen(0, 1),
                      "critical damping ratio of contact dashpots"});
  }

  template <class Archive>
  void visit(Archive& ar) {
    ar("name", name), ar("density", density), ar("young", young), ar("poisson", poisson);
    ar("kn", kn), ar("ks", ks), ar("modulus", modulus), ar("stiffness_ratio", stiffness_ratio),
        ar("friction", friction), ar("damping_ratio", damping_ratio);
  }
};

struct PairOverride {
  std::optional<double> friction;
  std::optional<double> damping_ratio;
};

class MaterialTable {
 public:
  std::uint16_t add(Material m) {
    materials_.push_back(std::move(m));
    return static_cast<std::uint16_t>(materials_.size() - 1);
  }
  const Material& operator[](std::size_t i) const { return materials_.at(i); }
  Material& operator[](std::size_t i) { return materials_.at(i); }
  std::size_t size() const { return materials_.size(); }
  const std::vector<Material>& all() const { return materials_; }

  void setPair(std::uint16_t a, std::uint16_t b, PairOverride o) { overrides_[key(a, b)] = o; }
  PairOverride pair(std::uint16_t a, std::uint16_t b) const {
    auto it = overrides_.find(key(a, b));
    return it == overrides_.end() ? PairOverride{} : it->second;
  }

  // Coulomb friction of a pair: the override, else the smaller of the two (as PFC does).
  double friction(std::uint16_t a, std::uint16_t b) const;
  // Damping ratio of a pair: the override, else the mean of the two.
  double dampingRatio(std::uint16_t a, std::uint16_t b) const;

  const std::map<std::pair<std::uint16_t, std::uint16_t>, PairOverride>& overrides() const {
    return overrides_;
  }

 private:
  static std::pair<std::uint16_t, std::uint16_t> key(std::uint16_t a, std::uint16_t b) {
    return a < b ? std::pair{a, b} : std::pair{b, a};
  }
  std::vector<Material> materials_;
  std::map<std::pair<std::uint16_t, std::uint16_t>, PairOverride> overrides_;
};

inline double MaterialTable::friction(std::uint16_t a, std::uint16_t b) const {
  if (auto o = pair(a, b).friction) return *o;
  return std::min(materials_.at(a).friction, materials_.at(b).friction);
}

inline double MaterialTable::dampingRatio(std::uint16_t a, std::uint16_t b) const {
  if (auto o = pair(a, b).damping_ratio) return *o;
  return 0.5 * (materials_.at(a).damping_ratio + materials_.at(b).damping_ratio);
}

}  // namespace rocklab
