#include "rigs/common/specimen.hpp"

#include <algorithm>
#include <optional>

#include "lab/core/grains.hpp"

namespace rocklab::rigs {

template <int D>
Specimen<D> Specimen<D>::branch() const {
  Specimen<D> b;
  b.settings = settings;
  b.sim = std::make_unique<Simulation<D>>(sim->clone());
  b.frame = std::make_unique<LoadingFrame<D>>(*frame);
  b.frame->attach(*b.sim);
  b.mean_radius = mean_radius;
  b.cement_kind = cement_kind;
  b.cement = cement;
  b.cement_classes = cement_classes;
  b.grain_kind = grain_kind;
  b.grain_bonds = grain_bonds;
  b.grain_aspect_ratios = grain_aspect_ratios;
  b.fragments_reference = fragments_reference;
  std::copy(std::begin(broken_offset), std::end(broken_offset), std::begin(b.broken_offset));
  b.bond_breaks_recorded = sim->bondBreaks().size();
  b.clump_breaks_recorded = sim->clumpBreaks().size();
  return b;
}

template <int D>
std::uint64_t Specimen<D>::broken(BondBreakMode mode) const {
  if (!cement_kind) return 0;
  return sim->brokenBonds(*cement_kind, mode) - broken_offset[mode == BondBreakMode::Shear];
}

template <int D>
std::uint64_t Specimen<D>::brokenInGrains(BondBreakMode mode) const {
  if (!grain_kind) return 0;
  return sim->brokenBonds(*grain_kind, mode) - broken_offset[2 + (mode == BondBreakMode::Shear)];
}

template <int D>
std::size_t Specimen<D>::crushedGrains() const {
  if (!grain_kind) return 0;
  return rocklab::crushedGrains(
      fragments_reference, grainFragments<D>(sim->particles(), sim->bonds(), sim->bondKinds()));
}

template <int D>
void Specimen<D>::setServo() {
  frame->setServo(settings.servo.alpha,
                  settings.servo.speed_radii_per_step * mean_radius / sim->dt());
}

template <int D>
void Specimen<D>::resetBrokenCount() {
  for (int m = 0; m < 2; ++m) {
    const auto mode = m == 0 ? BondBreakMode::Tensile : BondBreakMode::Shear;
    if (cement_kind) broken_offset[m] = sim->brokenBonds(*cement_kind, mode);
    if (grain_kind) broken_offset[2 + m] = sim->brokenBonds(*grain_kind, mode);
  }
  if (cement_kind) cement_classes = bondClasses(*sim, *cement_kind, kAxial);
  if (grain_kind) {
    fragments_reference = grainFragments<D>(sim->particles(), sim->bonds(), sim->bondKinds());
  }
}

template <int D>
template <class Archive>
void Specimen<D>::journal(Archive& ar) {
  if constexpr (Archive::kReading) {
    // Into the objects the rig holds (it keeps references to them across units), or new
    // ones for a specimen still to be made.
    std::string bytes;
    ar("sim", bytes);
    if (sim) {
      *sim = Simulation<D>::fromStateBytes(bytes);
    } else {
      sim = std::make_unique<Simulation<D>>(Simulation<D>::fromStateBytes(bytes));
    }
    if (!frame) {
      frame = std::make_unique<LoadingFrame<D>>(*sim, typename LoadingFrame<D>::Restored{});
    }
  } else {
    ar("sim", sim->stateBytes());
  }
  ar("frame", *frame);
  ar("mean_radius", mean_radius);
  // Optional kinds as a flag and a value; the bond classes as sorted pairs.
  auto optional = [&](const char* name, std::optional<std::uint8_t>& kind) {
    bool has = kind.has_value();
    std::uint8_t value = kind.value_or(0);
    ar((std::string(name) + ".has").c_str(), has);
    ar(name, value);
    if constexpr (Archive::kReading) kind = has ? std::optional<std::uint8_t>(value) : std::nullopt;
  };
  optional("cement_kind", cement_kind);
  optional("grain_kind", grain_kind);
  ar("cement", cement);
  ar("grain_bonds", grain_bonds);
  ar("grain_aspect_ratios", grain_aspect_ratios);
  for (int k = 0; k < 4; ++k) ar("broken_offset", broken_offset[k]);
  ar("fragments_reference", fragments_reference);
  std::vector<std::uint64_t> keys;
  std::vector<std::uint8_t> classes;
  if constexpr (!Archive::kReading) {
    for (const auto& [key, c] : cement_classes) keys.push_back(key);
    std::sort(keys.begin(), keys.end());
    for (std::uint64_t key : keys) classes.push_back(cement_classes.at(key));
  }
  ar("cement_classes.keys", keys);
  ar("cement_classes.values", classes);
  if constexpr (Archive::kReading) {
    cement_classes.clear();
    for (std::size_t k = 0; k < keys.size(); ++k) cement_classes[keys[k]] = classes[k];
  }
  ar("bond_breaks_recorded", bond_breaks_recorded);
  ar("clump_breaks_recorded", clump_breaks_recorded);
  bool formed = formed_from.has_value();
  ar("formed_from.has", formed);
  if constexpr (Archive::kReading)
    formed_from = formed ? std::optional<FormedOrigin>(FormedOrigin{}) : std::nullopt;
  if (formed) ar("formed_from", *formed_from);
  ar("formed_note", formed_note);
}

template struct Specimen<2>;
template struct Specimen<3>;
template void Specimen<2>::journal(ArchiveWriter&);
template void Specimen<2>::journal(ArchiveReader&);
template void Specimen<3>::journal(ArchiveWriter&);
template void Specimen<3>::journal(ArchiveReader&);

}  // namespace rocklab::rigs
