#include "lab/flow/coupling.hpp"

#include <algorithm>
#include <chrono>
#include <limits>
#include <unordered_map>

namespace rocklab::flow {

template <int D>
double FlowCoupling<D>::gradient(const Network<D>& net, int axis) const {
  // Least-squares slope of the free pores' pressure against their centroid's height.
  double n = 0.0, mh = 0.0, mp = 0.0;
  for (std::size_t c = 0; c < net.pores(); ++c) {
    if (boundary_[c] != PoreBoundary::Free) continue;
    n += 1.0, mh += net.centroid()[c][axis], mp += pore_pressure_[c];
  }
  if (n < 2.0)
    return (settings_.pressures.inlet - settings_.pressures.outlet) /
           (inlet_level_ - outlet_level_);
  mh /= n, mp /= n;
  double shh = 0.0, shp = 0.0;
  for (std::size_t c = 0; c < net.pores(); ++c) {
    if (boundary_[c] != PoreBoundary::Free) continue;
    const double dh = net.centroid()[c][axis] - mh;
    shh += dh * dh, shp += dh * (pore_pressure_[c] - mp);
  }
  return shp / shh;
}

template <int D>
std::vector<typename FlowCoupling<D>::SolverCost> FlowCoupling<D>::compareSolvers() const {
  const auto& bc = settings_.pressures;
  const double drop = std::abs(bc.inlet - bc.outlet);
  const SteadyFlow exact = solveImplicit(clusters_, bc, {ImplicitMethod::Cholesky, 0.0}, {});
  std::vector<SolverCost> out;
  auto add = [&](const std::string& name, auto&& solve) {
    SolverCost c;
    c.name = name;
    try {
      const SteadyFlow f = solve();
      c.seconds = f.seconds;
      c.iterations = f.iterations;
      c.converged = f.converged;
      c.predicted_iterations = f.predicted_iterations;
      for (std::size_t i = 0; i < f.pressure.size(); ++i) {
        c.max_difference =
            std::max(c.max_difference, std::abs(f.pressure[i] - exact.pressure[i]) / drop);
      }
    } catch (const FlowStepTooLarge& e) {
      c.refused = e.what();
    }
    out.push_back(c);
  };
  add("implicit_cholesky", [&] { return exact; });
  add("implicit_cg", [&] {
    return solveImplicit(clusters_, bc,
                         {ImplicitMethod::ConjugateGradient, settings_.implicit.tolerance}, {});
  });
  ExplicitSettings ex = settings_.explicit_scheme;
  ex.give_up_when_hopeless = true;  // a scheme that cannot converge says so early
  ex.virtual_volume = true;
  add("explicit_virtual_volume", [&] { return solveExplicit(clusters_, bc, ex, {}); });
  ex.virtual_volume = false;
  ex.dt = 0.0;
  add("explicit_real_volume", [&] { return solveExplicit(clusters_, bc, ex, {}); });
  return out;
}

template <int D>
PackView<D> FlowCoupling<D>::pack(const Simulation<D>& sim) const {
  const auto& P = sim.particles();
  PackView<D> v;
  v.centre.reserve(slots_.size());
  v.radius.reserve(slots_.size());
  std::unordered_map<std::uint32_t, std::uint32_t> index_of_slot;
  index_of_slot.reserve(slots_.size());
  for (std::uint32_t k = 0; k < slots_.size(); ++k) {
    const std::size_t i = P.indexOfSlot(slots_[k]);
    v.centre.push_back(P.pos[i]);
    v.radius.push_back(P.radius[i]);
    index_of_slot.emplace(slots_[k], k);
  }
  const auto& B = sim.bonds();
  for (std::size_t b = 0; b < B.size(); ++b) {
    if (!B.intact(b)) continue;  // a flat joint broken through: no cement left
    const auto a = index_of_slot.find(B.i[b]), c = index_of_slot.find(B.j[b]);
    if (a == index_of_slot.end() || c == index_of_slot.end()) continue;
    v.bond.push_back({a->second, c->second});
    v.bond_radius.push_back(B.radius[b]);
  }
  return v;
}

template <int D>
bool FlowCoupling<D>::needsTriangulation(const PackView<D>& now) const {
  if (!network_) return true;
  const double limit = settings_.retriangulate_displacement * mean_radius_;
  for (std::size_t k = 0; k < now.centre.size(); ++k) {
    if ((now.centre[k] - built_at_[k]).squaredNorm() > limit * limit) return true;
  }
  return network_->worstCellQuality() < 0.0;
}

template <int D>
void FlowCoupling<D>::triangulateAnew(const PackView<D>& now) {
  // A 2D pack stands for one layer of grains: its slice is one mean diameter thick.
  auto cells = triangulate<D>(now.centre, now.radius);
  trimHull<D>(cells, now.centre, now.radius, settings_.trim_edge_ratio);
  network_.emplace(std::move(cells), 2.0 * mean_radius_);
  hidden_ = network_->topology().hidden;
  built_at_ = now.centre;
  ++triangulations_;
}

template <int D>
FlowReading FlowCoupling<D>::measure(const Simulation<D>& sim) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto& P = sim.particles();
  if (slots_.size() != P.size() || !network_) {
    slots_.assign(P.slot_of.begin(), P.slot_of.end());
    std::sort(slots_.begin(), slots_.end());
    network_.reset();
  }
  pack_ = pack(sim);
  const PackView<D>& now = pack_;
  double radii = 0.0;
  for (double r : now.radius) radii += r;
  mean_radius_ = radii / static_cast<double>(std::max<std::size_t>(now.radius.size(), 1));
  if (needsTriangulation(now)) triangulateAnew(now);
  // The network is measured after a triangulation too: the quality check needs it.
  Network<D>& net = *network_;
  net.measure(now, settings_.law);

  // Inlet and outlet layers at the pack's two ends along the flow axis.
  const int ax = axis();
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto& x : now.centre) lo = std::min(lo, x[ax]), hi = std::max(hi, x[ax]);
  const double layer =
      settings_.boundary_layer > 0.0 ? settings_.boundary_layer : 2.0 * mean_radius_;
  inlet_level_ = hi - layer;
  outlet_level_ = lo + layer;
  boundary_.assign(net.pores(), PoreBoundary::Free);
  for (std::size_t c = 0; c < net.pores(); ++c) {
    const double h = net.centroid()[c][ax];
    if (h >= inlet_level_) boundary_[c] = PoreBoundary::Inlet;
    if (h <= outlet_level_) boundary_[c] = PoreBoundary::Outlet;
  }
  clusters_ = mergePores<D>(net, boundary_, settings_.merge);
  const Clusters& clusters = clusters_;
  const auto t1 = std::chrono::steady_clock::now();

  // Start from the last pressures where the pores are the same ones.
  std::vector<double> start;
  if (pore_pressure_.size() == net.pores()) {
    start.assign(clusters.count, 0.0);
    std::vector<double> n(clusters.count, 0.0);
    for (std::size_t c = 0; c < net.pores(); ++c) {
      start[clusters.of_pore[c]] += pore_pressure_[c];
      n[clusters.of_pore[c]] += 1.0;
    }
    for (std::size_t i = 0; i < clusters.count; ++i) start[i] /= n[i];
  }
  FlowReading r;
  r.solve = settings_.solver == FlowSolver::Implicit
                ? implicit_.solve(clusters, settings_.pressures, settings_.implicit, start)
                : solveExplicit(clusters, settings_.pressures, settings_.explicit_scheme, start);
  pore_pressure_.resize(net.pores());
  for (std::size_t c = 0; c < net.pores(); ++c) {
    pore_pressure_[c] = r.solve.pressure[clusters.of_pore[c]];
  }
  r.area = 0.5 * (std::abs(net.outerSection(boundary_, PoreBoundary::Inlet, now, ax)) +
                  std::abs(net.outerSection(boundary_, PoreBoundary::Outlet, now, ax)));
  r.inflow = r.solve.inflow;
  r.outflow = r.solve.outflow;
  const double drop = settings_.pressures.inlet - settings_.pressures.outlet;
  r.length = drop / std::abs(gradient(net, ax));
  r.permeability = settings_.law.viscosity * r.inflow * r.length / (r.area * drop);
  last_permeability_ = r.permeability;
  r.pores = net.pores();
  r.pipes = net.pipes();
  r.clusters = clusters.count;
  r.cluster_pipes = clusters.edge_a.size();
  r.hidden = hidden_;
  r.isolated = r.solve.isolated;
  r.triangulations = triangulations_;
  r.critical_step = criticalFlowStep(clusters, settings_.explicit_scheme.fluid_modulus);
  r.network_seconds = std::chrono::duration<double>(t1 - t0).count();
  return r;
}

template <int D>
FlowReading FlowCoupling<D>::update(Simulation<D>& sim) {
  FlowReading r = measure(sim);
  if (settings_.apply_forces) {
    const auto& P = sim.particles();
    const auto force = network_->particleForces(pore_pressure_, pack_, P.thickness);
    std::vector<V> by_slot(P.slotCapacity(), V::Zero());
    for (std::size_t k = 0; k < slots_.size(); ++k) by_slot[slots_[k]] = force[k];
    sim.setAppliedForces(std::move(by_slot));
  }
  return r;
}

template class FlowCoupling<2>;
template class FlowCoupling<3>;

}  // namespace rocklab::flow
