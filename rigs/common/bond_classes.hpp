#pragma once
// Which cement broke, by orientation. Intact bonds of one kind by their orientation to the
// sigma_1 axis: within 30 degrees of it ("axial" bonds: their breaks open cracks across the
// axis) and within 30 degrees of the plane normal to it ("lateral" bonds: cracks along the
// axis, which slow the waves that cross it; Li & Holt section 4.2 explain Figure 18b's
// anisotropy by which of them fail), and the rest, 30-60 degrees from the axis ("inclined":
// they carry most of the shear stiffness in the planes through the axis, which the S wave
// along the axis, szx, sees).

#include <cstdint>
#include <unordered_map>

#include "lab/core/simulation.hpp"

namespace rocklab::rigs {

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

}  // namespace rocklab::rigs
