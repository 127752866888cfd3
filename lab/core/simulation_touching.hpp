#pragma once
// Simulation::forEachTouching, for the files of the class that visit the touching contacts
// (simulation_readouts.cpp, simulation_clumps.cpp).

#include "lab/core/simulation.hpp"

namespace rocklab {

template <int D>
template <class F>
void Simulation<D>::forEachTouching(F&& visit) const {
  const auto& P = particles_;
  const auto& C = contacts_;
  if (!C.valid || C.pairs.row.size() != P.size() + 1) return;
  Touching t;
  for (std::size_t i = 0; i < P.size(); ++i) {
    for (std::uint32_t p = C.pairs.row[i]; p < C.pairs.row[i + 1]; ++p) {
      const std::uint32_t j = C.pairs.col[p];
      const double reach = P.radius[i] + P.radius[j];
      t.overlap = reach - (P.pos[j] - P.pos[i]).norm();
      if (!(t.overlap > 0.0)) continue;
      const double imsum = P.inv_mass[i] + P.inv_mass[j];
      t.i = i, t.j = j, t.wall = nullptr;
      t.mi = P.material[i], t.mj = P.material[j];
      t.shape = pairShape<D>(P.radius[i], P.radius[j], P.thickness);
      t.mstar = imsum > 0.0 ? 1.0 / imsum : 0.0;
      t.li = P.radius[i] - 0.5 * t.overlap, t.lj = P.radius[j] - 0.5 * t.overlap;
      t.min_radius = std::min(P.radius[i], P.radius[j]);
      t.shear2 = C.shear[p].squaredNorm();
      visit(t);
    }
  }
  for (std::size_t c = 0; c < C.wall_particle.size(); ++c) {
    const std::uint32_t i = C.wall_particle[c];
    const Wall<D>& w = walls_[C.wall_index[c]];
    t.overlap = P.radius[i] - w.distance(P.pos[i]);
    if (!(t.overlap > 0.0)) continue;
    t.i = i, t.j = i, t.wall = &w;
    t.mi = P.material[i], t.mj = w.material;
    t.shape = wallShape<D>(P.radius[i], P.thickness);
    t.mstar = P.inv_mass[i] > 0.0 ? 1.0 / P.inv_mass[i] : 0.0;
    t.li = P.radius[i] - t.overlap, t.lj = 0.0;
    t.min_radius = P.radius[i];
    t.shear2 = C.wall_shear[c].squaredNorm();
    visit(t);
  }
}

}  // namespace rocklab
