#include "rigs/common/specimen.hpp"

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

template struct Specimen<2>;
template struct Specimen<3>;

}  // namespace rocklab::rigs
