#pragma once
// Steady flow through the pore clusters with the inlet and outlet pressures imposed and no
// flow through the sides (Li & Holt section 3.4, 3.5.2). Two solvers:
// - explicit (the paper's): each step moves C dp dt through every pipe (equation 4) and
//   raises each pore's pressure by K_f dV / v (equation 5), at a step no larger than the
//   critical one, min over pores of v / (K_f sum C) (equation 6 with the fluid modulus it
//   needs), with real or virtual (equation 7) pore volumes, until the pores balance;
// - implicit: the balance of every free pore, sum C (p_j - p_i) = 0, solved at once as a
//   sparse symmetric positive definite system (Eigen: Cholesky LDL^T, or conjugate
//   gradients with an incomplete Cholesky preconditioner).
// A cluster no conducting path links to an imposed pressure keeps the pressure it had.

#include <cstddef>
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
  template <class Archive>
  void visit(Archive& ar) {
    ar("pressure", pressure), ar("inflow", inflow), ar("outflow", outflow);
    ar("iterations", iterations), ar("residual", residual), ar("converged", converged);
    ar("seconds", seconds), ar("isolated", isolated), ar("dt", dt);
  }
};

// The critical explicit step (s) over the free clusters: min v / (K_f sum C).
double criticalFlowStep(const Clusters& c, double fluid_modulus);

enum class ImplicitMethod { Cholesky, ConjugateGradient };

struct ImplicitSettings {
  ImplicitMethod method = ImplicitMethod::Cholesky;
  double tolerance = 1e-12;  // relative residual for conjugate gradients

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
                  "conjugate gradients' relative residual"});
  }
};

SteadyFlow solveImplicit(const Clusters& c, const Pressures& bc, const ImplicitSettings& s,
                         const std::vector<double>& previous);

struct ExplicitSettings {
  double fluid_modulus = 2.2e9;  // Pa, K_f (water)
  double dt = 0.0;               // s; 0: the critical step
  bool virtual_volume = true;    // equation 7: v = K_f dt sum C instead of the real volume
  double tolerance = 1e-12;      // stop when every pore's imbalance is below this
  std::size_t max_steps = 1000000;

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
