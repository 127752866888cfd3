#include "rigs/common/bond_classes.hpp"

#include <cmath>
#include <numbers>

namespace rocklab::rigs {

template <int D>
BondOrientations bondOrientations(const Simulation<D>& sim, std::uint8_t kind, int axis) {
  return countClasses(bondClasses(sim, kind, axis));
}

BondOrientations countClasses(const BondClasses& classes) {
  BondOrientations n;
  for (const auto& [key, k] : classes) {
    n.axial += k == 0 ? 1 : 0;
    n.inclined += k == 1 ? 1 : 0;
    n.lateral += k == 2 ? 1 : 0;
  }
  return n;
}

namespace {

// A bond's key: its particles' slots, the lower first.
template <int D>
std::uint64_t bondKey(const ParticleStore<D>& P, std::uint32_t i, std::uint32_t j) {
  const std::uint64_t a = P.slot_of[i], b = P.slot_of[j];
  return std::min(a, b) << 32 | std::max(a, b);
}

}  // namespace

template <int D>
BondClasses bondClasses(const Simulation<D>& sim, std::uint8_t kind, int axis) {
  // |cos| of the angle to the axis: above cos 30 deg axial, below cos 60 deg lateral.
  const double axial_cos = std::cos(std::numbers::pi / 6), lateral_cos = 0.5;
  const auto& P = sim.particles();
  const auto& B = sim.bonds();
  BondClasses classes;
  for (std::size_t b = 0; b < B.size(); ++b) {
    if (B.kind[b] != kind || !B.intact(b)) continue;
    const Vec<D> d = P.pos[B.j[b]] - P.pos[B.i[b]];
    const double c = std::abs(d[axis]) / d.norm();
    const std::uint8_t k = c >= axial_cos ? 0 : c <= lateral_cos ? 2 : 1;
    classes.emplace(bondKey(P, B.i[b], B.j[b]), k);
  }
  return classes;
}

template <int D>
BondOrientations intactByClass(const Simulation<D>& sim, std::uint8_t kind,
                               const BondClasses& reference) {
  const auto& P = sim.particles();
  const auto& B = sim.bonds();
  BondOrientations n;
  for (std::size_t b = 0; b < B.size(); ++b) {
    if (B.kind[b] != kind || !B.intact(b)) continue;
    const auto it = reference.find(bondKey(P, B.i[b], B.j[b]));
    if (it == reference.end()) continue;  // installed since (none are, in the rigs)
    n.axial += it->second == 0 ? 1 : 0;
    n.inclined += it->second == 1 ? 1 : 0;
    n.lateral += it->second == 2 ? 1 : 0;
  }
  return n;
}

template BondOrientations bondOrientations<2>(const Simulation<2>&, std::uint8_t, int);
template BondOrientations bondOrientations<3>(const Simulation<3>&, std::uint8_t, int);
template BondClasses bondClasses<2>(const Simulation<2>&, std::uint8_t, int);
template BondClasses bondClasses<3>(const Simulation<3>&, std::uint8_t, int);
template BondOrientations intactByClass<2>(const Simulation<2>&, std::uint8_t, const BondClasses&);
template BondOrientations intactByClass<3>(const Simulation<3>&, std::uint8_t, const BondClasses&);

}  // namespace rocklab::rigs
