// The fluid coupled to the particles: the seepage force balances the pressure drop over the
// sample's section, it moves the particles along the flow, the permeability scales with the
// square of the grain size (Darcy units), and the network follows the particles, built anew
// only when they have moved too far.

#include <gtest/gtest.h>

#include <cmath>

#include "lab/flow/coupling.hpp"
#include "tests/support.hpp"

namespace rocklab::flow {
namespace {

using testing::addParticle;
using testing::linearMaterial;
using testing::table;

// Separated particles on a body-centred cubic (3D) or triangular (2D) lattice of spacing
// `scale`, jittered: no contacts, so only the fluid acts.
template <int D>
Simulation<D> latticeScene(int n, int height, double scale, std::uint64_t seed) {
  SimulationConfig cfg = testing::undamped();
  cfg.timestep.automatic = false;
  cfg.timestep.fixed_dt = 1e-6;
  Simulation<D> sim(table(linearMaterial(1e6, 1e6, 0.5)), cfg);
  Rng rng(seed);
  auto add = [&](Vec<D> x) {
    for (int d = 0; d < D; ++d) x[d] = scale * (x[d] + rng.uniform(-0.05, 0.05));
    addParticle<D>(sim, x, scale * (D == 2 ? 0.4 : 0.36) * rng.uniform(0.9, 1.1), Vec<D>::Zero());
  };
  if constexpr (D == 2) {
    for (int j = 0; j < height; ++j) {
      for (int i = 0; i < n; ++i) add({i + 0.5 * (j % 2), j * std::sqrt(3.0) / 2.0});
    }
  } else {
    for (int k = 0; k < height; ++k) {
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          add({double(i), double(j), double(k)});
          if (i + 1 < n && j + 1 < n && k + 1 < height) add({i + 0.5, j + 0.5, k + 0.5});
        }
      }
    }
  }
  return sim;
}

// The extent normal to the flow of the pack's centres: width (2D) or area (3D).
template <int D>
double crossSection(const Simulation<D>& sim) {
  Vec<D> lo = Vec<D>::Constant(1e300), hi = Vec<D>::Constant(-1e300);
  for (const auto& x : sim.particles().pos) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  double a = 1.0;
  for (int d = 0; d < D - 1; ++d) a *= hi[d] - lo[d];
  return a;
}

// The pressure on the network's outer surface: -sum p A n over the hull facets (outward
// normals), and the part of it on the inlet pores projected along the flow. The particles
// were added in slot order and the network numbers them so.
template <int D>
struct Surface {
  Vec<D> load = Vec<D>::Zero();  // N
  double inlet_section = 0.0;    // m^2
};
template <int D>
Surface<D> outerSurface(const FlowCoupling<D>& flow, const Simulation<D>& sim) {
  const auto& T = flow.network().topology();
  const auto& P = sim.particles();
  auto x = [&](std::uint32_t k) { return P.pos[P.indexOfSlot(k)]; };
  Surface<D> s;
  for (std::size_t c = 0; c < T.cells.size(); ++c) {
    const auto& v = T.cells[c];
    for (int f = 0; f <= D; ++f) {
      if (T.neighbours[c][f] != kHull) continue;
      const Vec<D> a = x(v[(f + 1) % (D + 1)]), b = x(v[(f + 2) % (D + 1)]);
      Vec<D> n;  // area-weighted normal
      if constexpr (D == 2) {
        n = Vec<2>(b.y() - a.y(), a.x() - b.x()) * P.thickness;
      } else {
        n = 0.5 * (b - a).cross(Vec<3>(x(v[(f + 3) % 4]) - a));
      }
      if (n.dot(a - x(v[f])) < 0.0) n = -n;
      s.load -= flow.porePressure()[c] * n;
      if (flow.poreBoundary()[c] == PoreBoundary::Inlet) s.inlet_section += n[D - 1];
    }
  }
  return s;
}

template <int D>
void seepageForceBalancesTheDrop() {
  auto sim = latticeScene<D>(D == 2 ? 16 : 6, D == 2 ? 28 : 12, 1e-3, 4);
  FlowSettings fs;
  fs.merge.small_pore_ratio = 0.0;  // every cell its own pore
  fs.pressures = {3.0e4, 1.0e4};
  FlowCoupling<D> flow(fs);
  const double A = crossSection(sim);
  const FlowReading r = flow.update(sim);
  EXPECT_GT(r.permeability, 0.0);
  EXPECT_NEAR(r.outflow / r.inflow, 1.0, 1e-9);
  Vec<D> total = Vec<D>::Zero();
  for (const auto& f : sim.appliedForces()) total += f;
  // The drop across each pipe acts on its whole facet: summed, the particles carry the
  // pressure on the network's outer surface, exactly.
  const Surface<D> surface = outerSurface(flow, sim);
  for (int d = 0; d < D; ++d) EXPECT_NEAR(total[d], surface.load[d], 1e-9 * total.norm());
  // Down the flow (the inlet is at the top), about the drop times the section (2D: times the
  // disks' extrusion, 1 m); the sides' bumps take a few percent.
  EXPECT_NEAR(surface.inlet_section / A, 1.0, 0.1);  // less the trimmed bumps
  // Darcy's section, from both ends (2D: the width times the network's slice).
  const double slice = D == 2 ? flow.network().slice() / sim.particles().thickness : 1.0;
  EXPECT_NEAR(r.area / (surface.inlet_section * slice), 1.0, 0.05);
  const double drop = fs.pressures.inlet - fs.pressures.outlet;
  EXPECT_NEAR(total[D - 1] / (-drop * surface.inlet_section), 1.0, 0.05);
  for (int d = 0; d < D - 1; ++d) EXPECT_LT(std::abs(total[d]), 0.02 * std::abs(total[D - 1]));

  // The force moves the free particles down the flow: momentum gained = force x time.
  const double dt = sim.config().timestep.fixed_dt;
  sim.run(10);
  Vec<D> momentum = Vec<D>::Zero();
  const auto& P = sim.particles();
  for (std::size_t i = 0; i < P.size(); ++i) momentum += P.vel[i] / P.inv_mass[i];
  EXPECT_NEAR(momentum[D - 1] / (total[D - 1] * 10 * dt), 1.0, 1e-9);
  // Its work is in the ledger: the energy balance still closes.
  const auto e = sim.energy();
  EXPECT_NEAR(e.imbalance(), 0.0, 1e-6 * e.kinetic());
}

TEST(FlowCoupling, SeepageForceBalancesTheDropAndMovesTheParticles3D) {
  seepageForceBalancesTheDrop<3>();
}

TEST(FlowCoupling, SeepageForceBalancesTheDropAndMovesTheParticles2D) {
  seepageForceBalancesTheDrop<2>();
}

// Every length x10: conductance r^4 / r grows x1000, L / A shrinks x10, so k grows x100.
template <int D>
void permeabilityScalesWithTheSquareOfTheGrainSize() {
  FlowSettings fs;
  fs.merge.small_pore_ratio = 0.0;  // every cell its own pore
  fs.apply_forces = false;
  auto small = latticeScene<D>(5, 9, 1e-4, 7);
  auto large = latticeScene<D>(5, 9, 1e-3, 7);
  FlowCoupling<D> a(fs), b(fs);
  const double ka = a.measure(small).permeability;
  const double kb = b.measure(large).permeability;
  EXPECT_NEAR(kb / ka, 100.0, 1e-6);
  // The viscosity cancels: Q ~ 1/mu, k = mu Q L / (A dp).
  fs.law.viscosity *= 7.0;
  FlowCoupling<D> c(fs);
  EXPECT_NEAR(c.measure(large).permeability / kb, 1.0, 1e-9);
}

TEST(FlowCoupling, PermeabilityScalesWithTheSquareOfTheGrainSize) {
  permeabilityScalesWithTheSquareOfTheGrainSize<3>();
  permeabilityScalesWithTheSquareOfTheGrainSize<2>();
}

TEST(FlowCoupling, NetworkFollowsTheParticlesAndIsRebuiltOnlyWhenTheyMoveFar) {
  auto sim = latticeScene<3>(5, 8, 1e-3, 9);
  FlowSettings fs;
  fs.merge.small_pore_ratio = 0.0;  // every cell its own pore
  fs.apply_forces = false;
  FlowCoupling<3> flow(fs);
  const FlowReading r0 = flow.measure(sim);
  EXPECT_EQ(r0.triangulations, 1u);
  // A uniform 1% compaction along the flow: same network, measured again; narrower
  // throats and a shorter sample.
  auto& P = sim.particles();
  for (auto& x : P.pos) x[2] *= 0.99;
  const FlowReading r1 = flow.measure(sim);
  EXPECT_EQ(r1.triangulations, 1u);
  EXPECT_EQ(r1.pores, r0.pores);
  EXPECT_LT(r1.permeability, r0.permeability);
  // One particle moved by more than half a mean radius: triangulated anew.
  P.pos[P.size() / 2][0] += 0.6 * flow.meanRadius();
  const FlowReading r2 = flow.measure(sim);
  EXPECT_EQ(r2.triangulations, 2u);
}

}  // namespace
}  // namespace rocklab::flow
