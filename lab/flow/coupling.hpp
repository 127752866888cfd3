#pragma once
// The fluid in a scene that asks for it (Li & Holt section 3): a pore network on the
// simulation's particles, solved to steady state between an inlet and an outlet pressure
// along one axis, its pressures applied to the particles, the sample's Darcy permeability.
//
// The paper's quasi-steady scheme (section 3.5.2): every n particle steps the rig calls
// update(); the network's geometry follows the particles (section 3.3) and is triangulated
// anew only when the particles have moved too far or a cell turned inside out.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "lab/core/simulation.hpp"
#include "lab/flow/network.hpp"
#include "lab/flow/solver.hpp"

namespace rocklab::flow {

enum class FlowSolver { Implicit, Explicit };

struct FlowSettings {
  ConductanceLaw law;
  int axis = -1;  // the flow direction (0 x, 1 y, 2 z); -1: the last (y in 2D, z in 3D)
  Pressures pressures{1.0e4, 0.0};  // Pa, inlet (high end of the axis) and outlet
  // Pores whose centroid lies within this of the pack's extreme centres along the axis
  // take the inlet or outlet pressure (m; 0: one mean particle diameter).
  double boundary_layer = 0.0;
  MergeRule merge;
  FlowSolver solver = FlowSolver::Implicit;
  ImplicitSettings implicit;
  ExplicitSettings explicit_scheme;
  // Triangulate anew when a particle has moved this many mean radii since the last
  // triangulation (or a cell has inverted).
  double retriangulate_displacement = 0.5;
  // Cells with an edge longer than this times its particles' radii sum fill the hull's
  // bumps, not pores (trimHull).
  double trim_edge_ratio = 2.0;
  bool apply_forces = true;  // the pressures act on the particles

  // The keys a protocol sets (its `flow.*` section; the axis is the rig's).
  template <class F>
  void fields(F& f) {
    static constexpr Choice<FlowSolver> kSolvers[] = {{"implicit", FlowSolver::Implicit},
                                                      {"explicit", FlowSolver::Explicit}};
    f(pressures.inlet, {"pressure_drop_kPa", units::kPa, Range::leftOpen(0, 1e6),
                        "inlet over outlet pressure (the outlet is the reference, 0)"});
    f.section("", law);
    f(solver,
      {"solver",
       units::text,
       {},
       "steady state by one sparse solve, or by the paper's explicit time stepping"},
      kSolvers);
    f.section("", implicit);
    f.section("", explicit_scheme);
    f.section("", merge);
    f(retriangulate_displacement,
      {"retriangulate_displacement_radii", units::none, Range::leftOpen(0, 100),
       "triangulate anew once a particle has moved this many mean radii"});
    f(apply_forces, {"apply_forces", units::text, {}, "the pore pressures act on the particles"});
  }
};

struct FlowReading {
  double permeability = 0.0;                    // m^2, Darcy: k = mu Q L / (A dp)
  double inflow = 0.0, outflow = 0.0;           // m^3/s
  double length = 0.0;                          // m, between the inlet and outlet layers
  double area = 0.0;                            // m^2, the cross-section (2D: width x slice)
  std::size_t pores = 0, pipes = 0;             // of the triangulation
  std::size_t clusters = 0, cluster_pipes = 0;  // after merging: what the solver sees
  std::size_t hidden = 0, isolated = 0;
  std::size_t triangulations = 0;  // so far (1 + rebuilds)
  double critical_step = 0.0;      // s, equation 6 on the clusters
  SteadyFlow solve;                // the last solve (pressures per cluster, cost)
  double network_seconds = 0.0;    // triangulation and measurement of this update
  template <class Archive>
  void visit(Archive& ar) {
    ar("permeability", permeability), ar("inflow", inflow), ar("outflow", outflow);
    ar("length", length), ar("area", area), ar("pores", pores), ar("pipes", pipes);
    ar("clusters", clusters), ar("cluster_pipes", cluster_pipes), ar("hidden", hidden);
    ar("isolated", isolated), ar("triangulations", triangulations);
    ar("critical_step", critical_step), ar("solve", solve);
    ar("network_seconds", network_seconds);
  }
};

template <int D>
class FlowCoupling {
 public:
  using V = Vec<D>;
  explicit FlowCoupling(FlowSettings settings) : settings_(std::move(settings)) {}

  // Measures the network on the particles' present state (triangulating when needed),
  // solves the steady flow and applies the pore pressures to the particles.
  FlowReading update(Simulation<D>& sim);

  // Same, without touching the simulation's forces (a measurement on the side).
  FlowReading measure(const Simulation<D>& sim);

  // The last measured network solved again by every solver: their cost and their largest
  // difference from the Cholesky solution, relative to the drop.
  struct SolverCost {
    std::string name;
    double seconds = 0.0;
    std::size_t iterations = 0;
    double max_difference = 0.0;
    bool converged = false;
    double predicted_iterations = 0.0;  // explicit, given up: the steps it needs at least
    std::string refused;                // why a solver could not run (the explicit step), or empty
  };
  std::vector<SolverCost> compareSolvers() const;

  const FlowSettings& settings() const { return settings_; }
  // Equation 3's factor, e.g. once calibrated against Kozeny-Carman (k is proportional to it).
  void setAlpha(double alpha) { settings_.law.alpha = alpha; }
  double lastPermeability() const { return last_permeability_; }
  const Network<D>& network() const { return *network_; }
  // The clusters and pipes of the last update, as the solver saw them.
  const Clusters& clusters() const { return clusters_; }
  // Pressure of each pore of the last update (Pa).
  const std::vector<double>& porePressure() const { return pore_pressure_; }
  const std::vector<PoreBoundary>& poreBoundary() const { return boundary_; }
  // Mean particle radius of the pack (m).
  double meanRadius() const { return mean_radius_; }

  // What the coupling carries from one update to the next, for checkpoints: the network
  // and where it was built, the last pressures (the next solve starts from them), a
  // calibrated alpha.
  template <class Archive>
  void visit(Archive& ar) {
    ar("alpha", settings_.law.alpha);
    bool has_network = network_.has_value();
    ar("has_network", has_network);
    if constexpr (Archive::kReading) {
      if (has_network) {
        network_.emplace();
      } else {
        network_.reset();
      }
    }
    if (has_network) ar("network", *network_);
    ar("slots", slots_), ar("built_at", built_at_), ar("pack", pack_);
    ar("boundary", boundary_), ar("pore_pressure", pore_pressure_), ar("clusters", clusters_);
    ar("implicit", implicit_);
    if constexpr (Archive::kReading) implicit_.restore(clusters_);
    ar("mean_radius", mean_radius_), ar("inlet_level", inlet_level_);
    ar("outlet_level", outlet_level_), ar("last_permeability", last_permeability_);
    ar("triangulations", triangulations_), ar("hidden", hidden_);
  }

 private:
  PackView<D> pack(const Simulation<D>& sim) const;
  bool needsTriangulation(const PackView<D>& now) const;
  void triangulateAnew(const PackView<D>& now);
  int axis() const { return settings_.axis < 0 ? D - 1 : settings_.axis; }
  double gradient(const Network<D>& net, int axis) const;  // Pa/m along the axis

  FlowSettings settings_;
  std::optional<Network<D>> network_;
  std::vector<std::uint32_t> slots_;  // pack index -> particle slot
  std::vector<V> built_at_;           // centres at the last triangulation
  PackView<D> pack_;                  // the particles as last measured
  std::vector<PoreBoundary> boundary_;
  std::vector<double> pore_pressure_;
  Clusters clusters_;
  ImplicitSolver implicit_;  // keeps the last factor from one update to the next
  double mean_radius_ = 0.0, inlet_level_ = 0.0, outlet_level_ = 0.0;
  double last_permeability_ = 0.0;
  std::size_t triangulations_ = 0, hidden_ = 0;
};

}  // namespace rocklab::flow
