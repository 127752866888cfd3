// The pore network: geometry against hand computation, the solvers against each other and
// against Darcy's linear pressure, the explicit scheme's critical step and merging. The
// inputs no network can be built from are stability cases (tests/stability).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "lab/core/archive.hpp"
#include "lab/core/random.hpp"
#include "lab/flow/geometry.hpp"
#include "lab/flow/network.hpp"
#include "lab/flow/solver.hpp"
#include "lab/flow/triangulation.hpp"
#include "tests/flow_support.hpp"

namespace rocklab::flow {
namespace {

constexpr double kPi = std::numbers::pi;

// Hagen-Poiseuille conductance of a throat of fluid area S and mean radius r (alpha 1).
double handConductance(double S, double r, double mu) {
  const double re = std::sqrt(S / kPi);
  return kPi * std::pow(re, 4) / (8.0 * mu * r);
}

TEST(FlowGeometry, SolidAngleOfAnOctantIsHalfPi) {
  EXPECT_NEAR(solidAngle({1, 0, 0}, {0, 1, 0}, {0, 0, 1}), kPi / 2, 1e-14);
  // A face seen from its far side still subtends the same angle (orientation-free).
  EXPECT_NEAR(solidAngle({1, 0, 0}, {0, 0, 1}, {0, 1, 0}), kPi / 2, 1e-14);
}

TEST(FlowGeometry, PoreVolumeIsTheCellMinusTheSectors) {
  // The corner tetrahedron with a sphere of radius 0.3 at the right-angled corner only:
  // 1/6 minus an eighth of the sphere.
  Triangulation<3> t;
  t.cells = {{0, 1, 2, 3}};
  t.neighbours = {{kHull, kHull, kHull, kHull}};
  PackView<3> p;
  p.centre = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  p.radius = {0.3, 0.0, 0.0, 0.0};
  Network<3> net(t, 1.0);
  net.measure(p, {});
  EXPECT_NEAR(net.volume()[0], 1.0 / 6.0 - kPi * 0.027 / 6.0, 1e-14);
  // 2D: the right triangle minus a quarter disk, times the slice.
  Triangulation<2> t2;
  t2.cells = {{0, 1, 2}};
  t2.neighbours = {{kHull, kHull, kHull}};
  PackView<2> p2;
  p2.centre = {{0, 0}, {1, 0}, {0, 1}};
  p2.radius = {0.3, 0.0, 0.0};
  Network<2> net2(t2, 0.5);
  net2.measure(p2, {});
  EXPECT_NEAR(net2.volume()[0], 0.5 * (0.5 - kPi * 0.09 / 4.0), 1e-14);
}

// Two cells sharing one pipe whose throat is an equilateral triangle of side 1 between
// particles of radius r: its area less three 60-degree fans, Hagen-Poiseuille's conductance.
template <int D>
void expectOneEquilateralThroat(Network<D>& net, const PackView<D>& p, double r, double mu) {
  ASSERT_EQ(net.pores(), 2u);
  ASSERT_EQ(net.pipes(), 1u);
  net.measure(p, {1.0, mu});
  const double S = std::sqrt(3.0) / 4.0 - kPi * r * r / 2.0;
  EXPECT_NEAR(net.throat()[0], S, 1e-12);
  EXPECT_NEAR(net.conductance()[0] / handConductance(S, r, mu), 1.0, 1e-12);
}

// Two tetrahedra on an equilateral triangle of side 1 (apexes far enough that the shared
// face is Delaunay): one pipe, whose throat is the triangle minus three 60-degree fans.
TEST(FlowGeometry, ThreeDimensionalPipeConductanceByHand) {
  const double r = 0.3, mu = 1e-3, h = std::sqrt(3.0) / 6.0;
  PackView<3> p;
  p.centre = {{0, 0, 0}, {1, 0, 0}, {0.5, std::sqrt(3.0) / 2, 0}, {0.5, h, 1}, {0.5, h, -1}};
  p.radius.assign(5, r);
  Network<3> net(triangulate<3>(p.centre, p.radius), 1.0);
  expectOneEquilateralThroat(net, p, r, mu);
  // Equation 3's factor scales it.
  const double S = std::sqrt(3.0) / 4.0 - kPi * r * r / 2.0;
  net.measure(p, {0.82, mu});
  EXPECT_NEAR(net.conductance()[0] / handConductance(S, r, mu), 0.82, 1e-12);
}

// 2D: two triangles on a shared edge of length 1 between disks of radius r. With the
// virtual third particle of the pair's radius at the pair's gap (Figure 8), the throat
// triangle is equilateral of side 1, as in the 3D case.
TEST(FlowGeometry, TwoDimensionalPipeThroughTheVirtualThirdParticle) {
  const double r = 0.35, mu = 2e-3;
  PackView<2> p;
  p.centre = {{0, 0}, {1, 0}, {0.5, 0.9}, {0.5, -0.9}};
  p.radius.assign(4, r);
  Network<2> net(triangulate<2>(p.centre, p.radius), 2 * r);
  expectOneEquilateralThroat(net, p, r, mu);
}

TEST(FlowGeometry, CementNarrowsTheThroatAndBreakageOpensIt) {
  const double r = 0.3, R = 0.15;
  PackView<3> p;
  const double h = std::sqrt(3.0) / 6.0;
  p.centre = {{0, 0, 0}, {1, 0, 0}, {0.5, std::sqrt(3.0) / 2, 0}, {0.5, h, 1}, {0.5, h, -1}};
  p.radius.assign(5, r);
  Network<3> net = networkOf<3>(p);
  const double open = net.throat()[0];
  p.bond = {{0, 1}};
  p.bond_radius = {R};
  net.measure(p, {});
  // A strip R wide over the gap of 0.4 and the neck, on the throat's side of the bond.
  const double cement = R * 0.4 + R * R * R * (2.0 / r) / 6.0;
  EXPECT_NEAR(open - net.throat()[0], cement, 1e-12);
  p.bond.clear();
  p.bond_radius.clear();
  net.measure(p, {});
  EXPECT_DOUBLE_EQ(net.throat()[0], open);
}

TEST(FlowNetwork, UniformPressurePushesNoParticle) {
  const auto p = latticePack<3>({4, 4, 4}, 0.36, 0.05, 3);
  const Network<3> net = networkOf<3>(p);
  const auto f = net.particleForces(std::vector<double>(net.pores(), 5e5), p, 1.0);
  for (const auto& fi : f) EXPECT_LT(fi.norm(), 1e-9);
}

// The steady pressure of a homogeneous pack: both implicit methods and the explicit scheme
// agree to 1e-6 of the drop, inflow equals outflow, and the pressure falls linearly along
// the flow (Darcy; the paper's Figure 11).
template <int D>
void steadyFlowIsLinearAndTheSolversAgree(const std::array<int, D>& n) {
  const auto p = latticePack<D>(n, D == 2 ? 0.4 : 0.36, 0.05, 11);
  const Network<D> net = networkOf<D>(p);
  double top = 0.0;
  for (const auto& x : p.centre) top = std::max(top, x[D - 1]);
  const double lo = 1.0, hi = top - 1.0;  // layers one spacing thick at both ends
  const auto boundary = endLayers<D>(net, lo, hi);
  const Clusters c = mergePores<D>(net, boundary, {0.0, 0.0});
  const Pressures bc{2.0e4, 1.0e4};
  const auto chol = solveImplicit(c, bc, {ImplicitMethod::Cholesky, 0}, {});
  const auto cg = solveImplicit(c, bc, {ImplicitMethod::ConjugateGradient, 1e-12}, {});
  ExplicitSettings ex;
  ex.virtual_volume = true;
  ex.tolerance = 1e-11;
  const auto explicit_flow = solveExplicit(c, bc, ex, {});
  ASSERT_TRUE(chol.converged && cg.converged && explicit_flow.converged);
  const double drop = bc.inlet - bc.outlet;
  for (std::size_t i = 0; i < c.count; ++i) {
    EXPECT_NEAR(cg.pressure[i], chol.pressure[i], 1e-6 * drop);
    EXPECT_NEAR(explicit_flow.pressure[i], chol.pressure[i], 1e-6 * drop);
  }
  EXPECT_GT(chol.inflow, 0.0);
  EXPECT_NEAR(chol.outflow / chol.inflow, 1.0, 1e-9);
  EXPECT_NEAR(explicit_flow.inflow / chol.inflow, 1.0, 1e-6);
  // Darcy: the free pores' pressure is a straight line of the height. Fit it, and average
  // each pore's departure from it over slabs one spacing thick.
  std::vector<double> h, pr;
  for (std::size_t k = 0; k < net.pores(); ++k) {
    if (boundary[k] != PoreBoundary::Free) continue;
    h.push_back(net.centroid()[k][D - 1]);
    pr.push_back(chol.pressure[c.of_pore[k]]);
  }
  const double n_free = static_cast<double>(h.size());
  double mh = 0, mp = 0, shh = 0, shp = 0;
  for (std::size_t k = 0; k < h.size(); ++k) mh += h[k] / n_free, mp += pr[k] / n_free;
  for (std::size_t k = 0; k < h.size(); ++k) {
    shh += (h[k] - mh) * (h[k] - mh), shp += (h[k] - mh) * (pr[k] - mp);
  }
  const double slope = shp / shh;
  // The layers' pressures are imposed at their inner edges give or take half a spacing.
  EXPECT_NEAR(slope * (hi - lo) / drop, 1.0, 0.1);
  const int slabs = static_cast<int>(std::floor(hi - lo));
  std::vector<double> off(slabs, 0.0), count(slabs, 0.0);
  for (std::size_t k = 0; k < h.size(); ++k) {
    const int s = static_cast<int>((h[k] - lo) / (hi - lo) * slabs);
    if (s < 0 || s >= slabs) continue;
    off[s] += pr[k] - (mp + slope * (h[k] - mh));
    count[s] += 1.0;
  }
  for (int s = 0; s < slabs; ++s) {
    ASSERT_GT(count[s], 0.0);
    EXPECT_LT(std::abs(off[s] / count[s]), 0.02 * drop) << "slab " << s;
  }
}

TEST(FlowSolvers, SteadyPressureIsLinearAndSolversAgree3D) {
  steadyFlowIsLinearAndTheSolversAgree<3>({6, 6, 12});
}

TEST(FlowSolvers, SteadyPressureIsLinearAndSolversAgree2D) {
  steadyFlowIsLinearAndTheSolversAgree<2>({16, 28});
}

// A lattice pack's pore network with its ends one layer deep and its flat cells joined to
// their best neighbour (they would make the explicit scheme's step vanish), and the real
// volumes' explicit scheme on it: the setting whose step is bounded.
Clusters mergedLattice(const std::array<int, 3>& cells, double top, std::uint64_t seed) {
  const auto p = latticePack<3>(cells, 0.36, 0.05, seed);
  const Network<3> net = networkOf<3>(p);
  return mergePores<3>(net, endLayers<3>(net, 1.0, top), {0.0, 0.05});
}

ExplicitSettings realVolumes() {
  ExplicitSettings ex;
  ex.virtual_volume = false;
  return ex;
}

TEST(FlowSolvers, ExplicitSchemeIsStableAtItsCriticalStepAndRefusesALargerOne) {
  const Clusters c = mergedLattice({4, 4, 7}, 4.0, 5);
  const Pressures bc{1.0e4, 0.0};
  ExplicitSettings ex = realVolumes();
  ex.fluid_modulus = 2.2e9;
  ex.tolerance = 1e-8;
  const double critical = criticalFlowStep(c, ex.fluid_modulus);
  ASSERT_GT(critical, 0.0);
  ex.dt = critical;
  const auto at_critical = solveExplicit(c, bc, ex, {});
  EXPECT_TRUE(at_critical.converged);
  const auto exact = solveImplicit(c, bc, {}, {});
  for (std::size_t i = 0; i < c.count; ++i) {
    EXPECT_NEAR(at_critical.pressure[i], exact.pressure[i], 1e-6 * bc.inlet);
  }
  ex.dt = 1.01 * critical;
  try {
    solveExplicit(c, bc, ex, {});
    FAIL() << "a step above the critical one was accepted";
  } catch (const FlowStepTooLarge& e) {
    EXPECT_DOUBLE_EQ(e.critical(), critical);
    EXPECT_NE(std::string(e.what()).find("critical step"), std::string::npos) << e.what();
  }
}

// The solver comparison's explicit scheme gives up once its decay says the budget will not
// do, and says how many steps it would take at least: a lower bound of the steps the scheme
// takes when let run (its decay only slows as the faster modes die out; measured here 22,000
// against 72,000), above the budget. A scheme that can converge within its budget is never
// stopped, to the same bits.
TEST(FlowSolvers, AHopelessExplicitSchemeGivesUpEarlyAndSaysWhatItWouldNeed) {
  const Clusters c = mergedLattice({5, 5, 12}, 9.0, 9);
  const Pressures bc{1.0e4, 0.0};
  ExplicitSettings ex = realVolumes();
  ex.tolerance = 1e-10;
  ex.max_steps = 10000000;
  const SteadyFlow full = solveExplicit(c, bc, ex, {});
  ASSERT_TRUE(full.converged);
  ASSERT_GT(full.iterations, 20000u);
  ex.give_up_when_hopeless = true;
  const SteadyFlow watched = solveExplicit(c, bc, ex, {});
  EXPECT_TRUE(watched.converged);
  EXPECT_EQ(watched.iterations, full.iterations);
  EXPECT_EQ(watched.pressure, full.pressure);
  EXPECT_EQ(watched.predicted_iterations, 0.0);
  ex.max_steps = full.iterations / 4;
  const SteadyFlow hopeless = solveExplicit(c, bc, ex, {});
  EXPECT_FALSE(hopeless.converged);
  EXPECT_LT(hopeless.iterations, ex.max_steps);
  EXPECT_GT(hopeless.predicted_iterations, static_cast<double>(ex.max_steps));
  EXPECT_LT(hopeless.predicted_iterations, static_cast<double>(full.iterations));
}

// A network solved again and again, as a coupled run does: its clusters with the
// conductances of a pack, the end layers one spacing thick. About 25,000 clusters: on a
// network of a few thousand a new factor costs about as much as four iterations, and the
// solver rightly factorises.
struct RepeatedNetwork {
  Clusters clusters;
  Pressures bc{2.0e4, 1.0e4};
  RepeatedNetwork() {
    const auto p = latticePack<3>({12, 12, 16}, 0.36, 0.05, 23);
    const Network<3> net = networkOf<3>(p);
    double top = 0.0;
    for (const auto& x : p.centre) top = std::max(top, x[2]);
    clusters = mergePores<3>(net, endLayers<3>(net, 1.0, top - 1.0), {0.0, 0.0});
  }
  // Every conductance times a random factor in [1 - spread, 1 + spread].
  void move(double spread, std::uint64_t seed) {
    Rng rng(seed);
    for (double& g : clusters.edge_conductance) g *= rng.uniform(1.0 - spread, 1.0 + spread);
  }
  // One cluster of an end layer set free (the layers shift as a sample deforms).
  void freeOne(PoreBoundary layer) {
    const auto it = std::find(clusters.boundary.begin(), clusters.boundary.end(), layer);
    ASSERT_NE(it, clusters.boundary.end());
    *it = PoreBoundary::Free;
  }
  // The largest pressure difference from a fresh factorisation of the same system, over the
  // drop, and the inflows' relative difference.
  std::pair<double, double> offFresh(const SteadyFlow& f) const {
    ImplicitSettings fresh;
    fresh.reuse_factor = false;
    const SteadyFlow exact = solveImplicit(clusters, bc, fresh, {});
    double worst = 0.0;
    for (std::size_t i = 0; i < clusters.count; ++i) {
      worst = std::max(worst, std::abs(f.pressure[i] - exact.pressure[i]) / (bc.inlet - bc.outlet));
    }
    return {worst, std::abs(f.inflow / exact.inflow - 1.0)};
  }
};

// Conductances moved by 2% and a cluster of the inlet layer set free (the layers shift as a
// sample deforms): the kept factor preconditions a few conjugate-gradient iterations from the
// last pressures, and they reach the direct solve's answer to 1e-9 of the drop (the
// iterations stop at a residual of 1e-12 of the right-hand side; measured 1e-12 here).
TEST(FlowSolvers, AKeptFactorSolvesAMovedNetworkAsTheDirectSolveDoes) {
  RepeatedNetwork r;
  ImplicitSolver solver;
  const SteadyFlow first = solver.solve(r.clusters, r.bc, {}, {});
  EXPECT_EQ(first.path, ImplicitPath::Factorised);
  r.move(0.02, 1);
  r.freeOne(PoreBoundary::Inlet);
  const SteadyFlow moved = solver.solve(r.clusters, r.bc, {}, first.pressure);
  EXPECT_EQ(moved.path, ImplicitPath::Iterated);
  EXPECT_GT(moved.iterations, 0u);
  EXPECT_LT(moved.iterations, 20u);
  EXPECT_EQ(moved.factorisation_seconds, 0.0);
  const auto [worst, inflow] = r.offFresh(moved);
  EXPECT_LT(worst, 1e-9);
  EXPECT_LT(inflow, 1e-9);
  // The same conductances again: the warm start is the answer already.
  EXPECT_EQ(solver.solve(r.clusters, r.bc, {}, moved.pressure).iterations, 0u);
}

// Conductances scattered by a factor of up to 10 either way: iterating on the old factor
// would cost more than a new one, so the solver gives up on it within its cap and factorises
// anew; the next update factorises at once, and the one after iterates again on the fresh
// factor. Each answer is the direct one. A new pattern (a pipe fewer) is analysed anew.
TEST(FlowSolvers, AFactorTooFarOffIsReplacedAndANewPatternAnalysed) {
  RepeatedNetwork r;
  ImplicitSolver solver;
  const SteadyFlow first = solver.solve(r.clusters, r.bc, {}, {});
  Rng rng(3);
  for (double& g : r.clusters.edge_conductance) g *= std::pow(10.0, rng.uniform(-1.0, 1.0));
  const SteadyFlow far = solver.solve(r.clusters, r.bc, {}, first.pressure);
  EXPECT_EQ(far.path, ImplicitPath::Refactorised);
  EXPECT_GT(far.iterations, 0u);
  EXPECT_GT(far.factorisation_seconds, 0.0);
  EXPECT_LT(r.offFresh(far).first, 1e-12);
  r.move(0.5, 4);
  const SteadyFlow next = solver.solve(r.clusters, r.bc, {}, far.pressure);
  EXPECT_EQ(next.path, ImplicitPath::Refactorised);
  EXPECT_EQ(next.iterations, 0u);
  EXPECT_LT(r.offFresh(next).first, 1e-12);
  r.move(0.01, 8);
  const SteadyFlow gentle = solver.solve(r.clusters, r.bc, {}, next.pressure);
  EXPECT_EQ(gentle.path, ImplicitPath::Iterated);
  EXPECT_LT(r.offFresh(gentle).first, 1e-9);
  r.clusters.edge_a.pop_back(), r.clusters.edge_b.pop_back();
  r.clusters.edge_conductance.pop_back();
  const SteadyFlow fewer = solver.solve(r.clusters, r.bc, {}, gentle.pressure);
  EXPECT_EQ(fewer.path, ImplicitPath::Factorised);
  EXPECT_GT(fewer.analysis_seconds, 0.0);
  EXPECT_LT(r.offFresh(fewer).first, 1e-12);
}

// A checkpoint carries the kept factor's ordering, conductances and held clusters: the
// solver read back and restored takes the path the uninterrupted one takes, to the same
// bits, though the clusters moved and an end layer changed since that factor was made (a
// factor rebuilt from the last clusters would order and hold them differently).
TEST(FlowSolvers, ARestoredSolverTakesTheUninterruptedPath) {
  RepeatedNetwork r;
  ImplicitSolver solver;
  const SteadyFlow first = solver.solve(r.clusters, r.bc, {}, {});
  r.move(0.02, 5);
  Rng rng(7);
  for (auto& x : r.clusters.position) {
    for (double& xi : x) xi += rng.uniform(-0.3, 0.3);
  }
  r.freeOne(PoreBoundary::Outlet);
  const SteadyFlow second = solver.solve(r.clusters, r.bc, {}, first.pressure);
  ASSERT_EQ(second.path, ImplicitPath::Iterated);
  ArchiveWriter w;
  w("solver", solver);
  const Clusters last = r.clusters;
  r.move(0.02, 6);
  const SteadyFlow third = solver.solve(r.clusters, r.bc, {}, second.pressure);
  ASSERT_EQ(third.path, ImplicitPath::Iterated);

  ImplicitSolver resumed;
  ArchiveReader in(w.bytes().data(), w.bytes().size());
  in("solver", resumed);
  resumed.restore(last);
  const SteadyFlow again = resumed.solve(r.clusters, r.bc, {}, second.pressure);
  EXPECT_EQ(again.path, third.path);
  EXPECT_EQ(again.iterations, third.iterations);
  EXPECT_EQ(again.pressure, third.pressure);
}

TEST(FlowNetwork, MergingKeepsVolumeAndNeverJoinsInletToOutlet) {
  const auto p = latticePack<3>({5, 5, 8}, 0.36, 0.05, 9);
  const Network<3> net = networkOf<3>(p);
  const auto boundary = endLayers<3>(net, 1.0, 5.0);
  const Clusters all = mergePores<3>(net, boundary, {0.0, 0.0});
  EXPECT_EQ(all.count, net.pores());
  EXPECT_EQ(all.edge_a.size(), net.pipes());
  const Clusters merged = mergePores<3>(net, boundary, {5.0, 0.05});
  EXPECT_LT(merged.count, all.count);
  EXPECT_LT(merged.edge_a.size(), all.edge_a.size());
  double v_all = 0.0, v_merged = 0.0;
  for (double v : all.volume) v_all += v;
  for (double v : merged.volume) v_merged += v;
  EXPECT_NEAR(v_merged, v_all, 1e-12 * v_all);
  for (std::size_t k = 0; k < net.pores(); ++k) {
    const auto cb = merged.boundary[merged.of_pore[k]];
    if (boundary[k] != PoreBoundary::Free) {
      EXPECT_EQ(cb, boundary[k]);
    }
  }
  // Merging is an approximation (section 3.2): the flow stays within a few percent.
  const Pressures bc{1.0, 0.0};
  const double q_all = solveImplicit(all, bc, {}, {}).inflow;
  const double q_merged = solveImplicit(merged, bc, {}, {}).inflow;
  EXPECT_NEAR(q_merged / q_all, 1.0, 0.25);
  // The small-pore rule lifts the critical step.
  EXPECT_GT(criticalFlowStep(merged, 1.0), criticalFlowStep(all, 1.0));
}

}  // namespace
}  // namespace rocklab::flow
