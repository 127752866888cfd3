#pragma once
// Steady flow through the pore clusters with the inlet and outlet pressures imposed and no
// flow through the sides (Li & Holt section 3.4, 3.5.2). Two solvers:
// - explicit (the paper's): each step moves C dp dt through every pipe (equation 4) and
//   raises each pore's pressure by K_f dV / v (equation 5), at a step no larger than the
//   critical one, min over pores of v / (K_f sum C) (equation 6 with the fluid modulus it
//   needs), with real or virtual (equation 7) pore volumes, until the pores balance;
// - implicit: the balance of every free pore, sum C (p_j - p_i) = 0, solved at once as a
//   sparse symmetric positive definite system (CHOLMOD's supernodal Cholesky, or Eigen's
//   conjugate gradients with an incomplete Cholesky preconditioner). A coupled run solves
//   the same network again and again while the particles move a little: ImplicitSolver keeps
//   the system's pattern, its ordering and symbolic analysis and the last numeric factor, and
//   solves a moved network by conjugate gradients preconditioned with that factor, from the
//   last pressures, where that costs fewer flops than factorising again.
// A cluster no conducting path links to an imposed pressure keeps the pressure it had.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "lab/flow/network.hpp"

namespace rocklab::flow {

// An explicit step above the critical one: the scheme would diverge.
class FlowStepTooLarge : public std::invalid_argument {
 public:
  FlowStepTooLarge(double dt, double critical);
  double critical() const { return critical_; }

 private:
  double critical_;
};

struct Pressures {
  double inlet = 1.0, outlet = 0.0;  // Pa
};

// How an implicit solve was reached.
enum class ImplicitPath : std::uint8_t {
  Factorised,    // a new pattern: ordering, symbolic analysis, numeric factor, solve
  Refactorised,  // the pattern kept: numeric factor and solve
  Iterated,      // conjugate gradients preconditioned with the kept factor
  Incomplete,    // conjugate gradients with incomplete Cholesky (ImplicitMethod::ConjugateGradient)
  Explicit,      // not an implicit solve
};

// "factorised", "refactorised", ...
const char* describe(ImplicitPath path);

struct SteadyFlow {
  std::vector<double> pressure;  // Pa, per cluster
  double inflow = 0.0;           // m^3/s into the sample through the inlet clusters
  double outflow = 0.0;          // m^3/s out through the outlet clusters
  std::size_t iterations = 0;    // explicit steps, or conjugate-gradient iterations
  double residual = 0.0;         // largest pore imbalance over its sum C times the drop
  bool converged = false;
  double seconds = 0.0;      // wall time of the solve
  std::size_t isolated = 0;  // clusters with no conducting path to a boundary
  double dt = 0.0;           // s, the explicit step used (0 for implicit)
  ImplicitPath path = ImplicitPath::Explicit;
  // Explicit, given up early (ExplicitSettings::give_up_when_hopeless): the steps the
  // imbalance's decay so far says the tolerance needs at least; 0 otherwise.
  double predicted_iterations = 0.0;
  // Where an implicit solve's time went (s): the system's values and right-hand side, the
  // ordering and symbolic analysis, the numeric factor, the triangular solves or iterations.
  double assembly_seconds = 0.0, analysis_seconds = 0.0;
  double factorisation_seconds = 0.0, solve_seconds = 0.0;
  template <class Archive>
  void visit(Archive& ar) {
    ar("pressure", pressure), ar("inflow", inflow), ar("outflow", outflow);
    ar("iterations", iterations), ar("residual", residual), ar("converged", converged);
    ar("seconds", seconds), ar("isolated", isolated), ar("dt", dt), ar("path", path);
    ar("assembly_seconds", assembly_seconds), ar("analysis_seconds", analysis_seconds);
    ar("factorisation_seconds", factorisation_seconds), ar("solve_seconds", solve_seconds);
    ar("predicted_iterations", predicted_iterations);
  }
};

// The critical explicit step (s) over the free clusters: min v / (K_f sum C).
double criticalFlowStep(const Clusters& c, double fluid_modulus);

enum class ImplicitMethod { Cholesky, ConjugateGradient };

struct ImplicitSettings {
  ImplicitMethod method = ImplicitMethod::Cholesky;
  double tolerance = 1e-12;  // relative residual for conjugate gradients
  bool reuse_factor = true;  // Cholesky: keep the pattern and factor from call to call

  template <class F>
  void fields(F& f) {
    static constexpr Choice<ImplicitMethod> kMethods[] = {
        {"cholesky", ImplicitMethod::Cholesky}, {"cg", ImplicitMethod::ConjugateGradient}};
    f(method,
      {"implicit_method",
       units::text,
       {},
       "sparse LDL^T, or conjugate gradients with incomplete Cholesky"},
      kMethods);
    f(tolerance, {"implicit_tolerance", units::none, Range::leftOpen(0, 1e-2),
                  "conjugate gradients' relative residual (also the iterations on a kept "
                  "Cholesky factor)"});
    f(reuse_factor, {"implicit_reuse_factor",
                     units::text,
                     {},
                     "Cholesky: keep the ordering and the factor from one update to the next "
                     "and iterate on them while that is cheaper than factorising (off: "
                     "factorise anew every update)"});
  }
};

// The implicit solve of one network, called again and again as its particles move.
//
// With the Cholesky method and reuse_factor, it keeps what does not change while the
// clusters and their pipes stay the same: the matrix's pattern, the ordering and CHOLMOD's
// symbolic analysis, and the numeric factor of the conductances it last factorised. A
// network with the same pipes is then solved by conjugate gradients preconditioned with that
// factor, starting from `previous` (also when other clusters are held now: the rows keep
// their clusters' numbers): when the conductances moved little, the factor of the old
// system is nearly the inverse of the new one and a few iterations reach the tolerance. The
// iterations are capped where their flops would exceed a new factor's (CHOLMOD's count of
// the factorisation against two triangular solves and a product per iteration); past the
// cap the system is factorised anew (ordered and analysed anew if other clusters are held),
// and so are the next few. Every choice counts operations, never wall time, so a run takes
// the same path, and gives the same bits, on any machine and after a resume.
class ImplicitSolver {
 public:
  ImplicitSolver();
  ~ImplicitSolver();
  // A copy starts without the kept factor (it is derived state); so does a moved-from one.
  ImplicitSolver(const ImplicitSolver&);
  ImplicitSolver& operator=(const ImplicitSolver&);
  ImplicitSolver(ImplicitSolver&&) noexcept;
  ImplicitSolver& operator=(ImplicitSolver&&) noexcept;

  SteadyFlow solve(const Clusters& c, const Pressures& bc, const ImplicitSettings& s,
                   const std::vector<double>& previous);

  // For checkpoints: the kept factor's ordering, the conductances and held clusters it was
  // made of, and whether the next solve factorises anew. After reading, restore(clusters of
  // the last solve) rebuilds the same factor, so a resumed run takes the uninterrupted run's
  // path, to the same bits.
  template <class Archive>
  void visit(Archive& ar) {
    ar("ordering", ordering_), ar("factored_conductance", factored_conductance_);
    ar("factored_held", factored_held_), ar("direct_ahead", direct_ahead_);
    ar("backoff", backoff_);
  }
  void restore(const Clusters& last);

 private:
  struct Kept;
  std::unique_ptr<Kept> kept_;
  std::vector<int> ordering_;                 // of the kept pattern's rows
  std::vector<double> factored_conductance_;  // per cluster pipe, of the kept factor
  std::vector<char> factored_held_;           // per cluster: its pressure was held
  std::uint32_t direct_ahead_ = 0;            // solves to factorise before iterating again
  std::uint32_t backoff_ = 0;                 // the last such run's length
};

// One solve on a fresh ImplicitSolver.
SteadyFlow solveImplicit(const Clusters& c, const Pressures& bc, const ImplicitSettings& s,
                         const std::vector<double>& previous);

struct ExplicitSettings {
  double fluid_modulus = 2.2e9;  // Pa, K_f (water)
  double dt = 0.0;               // s; 0: the critical step
  bool virtual_volume = true;    // equation 7: v = K_f dt sum C instead of the real volume
  double tolerance = 1e-12;      // stop when every pore's imbalance is below this
  std::size_t max_steps = 1000000;
  // Not a key: stop once the decay of the largest imbalance over the last window says
  // max_steps will not reach the tolerance (the solver comparison, where the real-volume
  // scheme is expected to fall short and would spend all of max_steps saying so).
  bool give_up_when_hopeless = false;

  template <class F>
  void fields(F& f) {
    f(fluid_modulus, {"fluid_bulk_modulus_GPa", units::GPa, Range::leftOpen(0, 1e3),
                      "K_f of equation 5 (water: 2.2)"});
    f(dt, {"explicit_timestep_s", units::s, Range::closed(0, 1e6),
           "explicit step (0: the critical step of equation 6; larger is refused)"});
    f(virtual_volume, {"virtual_volume",
                       units::text,
                       {},
                       "explicit scheme with the virtual pore volumes of equation 7 (steady "
                       "state only)"});
    f(tolerance, {"explicit_tolerance", units::none, Range::leftOpen(0, 1e-2),
                  "the explicit scheme stops when every pore's imbalance is below this "
                  "(relative to its conductances times the drop)"});
    f(max_steps, {"explicit_max_steps", units::none, Range::closed(1, 1e10),
                  "explicit steps before giving up (the paper's scheme converges like Jacobi "
                  "iterations: slowly on long networks)"});
  }
};

// Starts from `previous` (per cluster; empty: the mean of the two boundary pressures).
// Throws FlowStepTooLarge for a step above the critical one with real volumes.
SteadyFlow solveExplicit(const Clusters& c, const Pressures& bc, const ExplicitSettings& s,
                         const std::vector<double>& previous);

}  // namespace rocklab::flow
