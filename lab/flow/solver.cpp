#include "lab/flow/solver.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

namespace rocklab::flow {

namespace {

std::string stepMessage(double dt, double critical) {
  std::ostringstream s;
  if (!(critical > 0.0)) {
    return "a pore has no volume, so the explicit flow step (equation 6: min over pores of "
           "v_pore / (K_f sum C)) is zero: merge the small pores into their neighbours, or use "
           "virtual pore volumes (equation 7)";
  }
  s << "the explicit flow step " << dt << " s exceeds the critical step " << critical
    << " s (equation 6: min over pores of v_pore / (K_f sum C)); the pressures would diverge. "
       "Use a step of at most the critical one (0 picks it), or virtual pore volumes "
       "(equation 7)";
  return s.str();
}

// The pressure scale of the residuals: the drop, or 1 Pa without one (no flow).
double referenceDrop(const Pressures& bc) {
  const double drop = std::abs(bc.inlet - bc.outlet);
  return drop > 0.0 ? drop : 1.0;
}

bool imposed(PoreBoundary b) {
  return b != PoreBoundary::Free;
}

double imposedPressure(PoreBoundary b, const Pressures& bc) {
  return b == PoreBoundary::Inlet ? bc.inlet : bc.outlet;
}

// Clusters a conducting path links to an imposed pressure.
std::vector<char> connected(const Clusters& c) {
  std::vector<std::vector<std::uint32_t>> adj(c.count);
  for (std::size_t k = 0; k < c.edge_a.size(); ++k) {
    if (c.edge_conductance[k] <= 0.0) continue;
    adj[c.edge_a[k]].push_back(c.edge_b[k]);
    adj[c.edge_b[k]].push_back(c.edge_a[k]);
  }
  std::vector<char> seen(c.count, 0);
  std::vector<std::uint32_t> todo;
  for (std::uint32_t i = 0; i < c.count; ++i) {
    if (imposed(c.boundary[i])) seen[i] = 1, todo.push_back(i);
  }
  while (!todo.empty()) {
    const auto i = todo.back();
    todo.pop_back();
    for (auto j : adj[i]) {
      if (!seen[j]) seen[j] = 1, todo.push_back(j);
    }
  }
  return seen;
}

std::vector<double> startingPressure(const Clusters& c, const Pressures& bc,
                                     const std::vector<double>& previous) {
  std::vector<double> p = previous.size() == c.count
                              ? previous
                              : std::vector<double>(c.count, 0.5 * (bc.inlet + bc.outlet));
  for (std::size_t i = 0; i < c.count; ++i) {
    if (imposed(c.boundary[i])) p[i] = imposedPressure(c.boundary[i], bc);
  }
  return p;
}

// Inflow and outflow through the boundary clusters, and the largest free-cluster imbalance
// relative to its total conductance and the drop.
void balance(const Clusters& c, const Pressures& bc, const std::vector<char>& live,
             SteadyFlow& out) {
  std::vector<double> net(c.count, 0.0), sum_c(c.count, 0.0);
  out.inflow = out.outflow = 0.0;
  for (std::size_t k = 0; k < c.edge_a.size(); ++k) {
    const auto a = c.edge_a[k], b = c.edge_b[k];
    const double q = c.edge_conductance[k] * (out.pressure[a] - out.pressure[b]);  // a -> b
    net[a] -= q, net[b] += q;
    sum_c[a] += c.edge_conductance[k], sum_c[b] += c.edge_conductance[k];
    if (c.boundary[a] == PoreBoundary::Inlet && c.boundary[b] != PoreBoundary::Inlet)
      out.inflow += q;
    if (c.boundary[b] == PoreBoundary::Inlet && c.boundary[a] != PoreBoundary::Inlet)
      out.inflow -= q;
    if (c.boundary[b] == PoreBoundary::Outlet && c.boundary[a] != PoreBoundary::Outlet)
      out.outflow += q;
    if (c.boundary[a] == PoreBoundary::Outlet && c.boundary[b] != PoreBoundary::Outlet)
      out.outflow -= q;
  }
  const double drop = referenceDrop(bc);
  out.residual = 0.0;
  for (std::size_t i = 0; i < c.count; ++i) {
    if (imposed(c.boundary[i]) || !live[i] || sum_c[i] <= 0.0) continue;
    out.residual = std::max(out.residual, std::abs(net[i]) / (sum_c[i] * drop));
  }
}

}  // namespace

FlowStepTooLarge::FlowStepTooLarge(double dt, double critical)
    : std::invalid_argument(stepMessage(dt, critical)), critical_(critical) {}

double criticalFlowStep(const Clusters& c, double fluid_modulus) {
  std::vector<double> sum_c(c.count, 0.0);
  for (std::size_t k = 0; k < c.edge_a.size(); ++k) {
    sum_c[c.edge_a[k]] += c.edge_conductance[k];
    sum_c[c.edge_b[k]] += c.edge_conductance[k];
  }
  double dt = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < c.count; ++i) {
    if (!imposed(c.boundary[i]) && sum_c[i] > 0.0) {
      dt = std::min(dt, c.volume[i] / (fluid_modulus * sum_c[i]));
    }
  }
  return dt;
}

SteadyFlow solveImplicit(const Clusters& c, const Pressures& bc, const ImplicitSettings& s,
                         const std::vector<double>& previous) {
  const auto t0 = std::chrono::steady_clock::now();
  SteadyFlow out;
  out.pressure = startingPressure(c, bc, previous);
  const auto live = connected(c);
  // Unknowns: the free clusters linked to a boundary.
  std::vector<std::int64_t> unknown(c.count, -1);
  std::int64_t n = 0;
  for (std::size_t i = 0; i < c.count; ++i) {
    if (!imposed(c.boundary[i]) && live[i]) unknown[i] = n++;
    if (!live[i]) ++out.isolated;
  }
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(4 * c.edge_a.size() + static_cast<std::size_t>(n));
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
  for (std::size_t k = 0; k < c.edge_a.size(); ++k) {
    const double g = c.edge_conductance[k];
    const auto a = c.edge_a[k], b = c.edge_b[k];
    const auto ia = unknown[a], ib = unknown[b];
    if (ia >= 0) entries.emplace_back(ia, ia, g);
    if (ib >= 0) entries.emplace_back(ib, ib, g);
    if (ia >= 0 && ib >= 0) {
      entries.emplace_back(ia, ib, -g);
      entries.emplace_back(ib, ia, -g);
    } else if (ia >= 0 && imposed(c.boundary[b])) {
      rhs[ia] += g * out.pressure[b];
    } else if (ib >= 0 && imposed(c.boundary[a])) {
      rhs[ib] += g * out.pressure[a];
    }
  }
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(entries.begin(), entries.end());
  Eigen::VectorXd x;
  if (s.method == ImplicitMethod::Cholesky) {
    // CHOLMOD's supernodal factorization with its own fill-reducing ordering (AMD or
    // METIS): what Yade's FlowEngine uses; Eigen's simplicial LDLT fills in badly on 3D
    // networks.
    Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>> solver(A);
    if (solver.info() != Eigen::Success) {
      throw std::runtime_error("flow: the pore network's system could not be factorized");
    }
    x = solver.solve(rhs);
    out.converged = true;
  } else {
    Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper,
                             Eigen::IncompleteCholesky<double>>
        solver;
    solver.setTolerance(s.tolerance);
    solver.compute(A);
    Eigen::VectorXd guess(n);
    for (std::size_t i = 0; i < c.count; ++i) {
      if (unknown[i] >= 0) guess[unknown[i]] = out.pressure[i];
    }
    x = solver.solveWithGuess(rhs, guess);
    out.iterations = static_cast<std::size_t>(solver.iterations());
    out.converged = solver.info() == Eigen::Success;
  }
  for (std::size_t i = 0; i < c.count; ++i) {
    if (unknown[i] >= 0) out.pressure[i] = x[unknown[i]];
  }
  balance(c, bc, live, out);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

SteadyFlow solveExplicit(const Clusters& c, const Pressures& bc, const ExplicitSettings& s,
                         const std::vector<double>& previous) {
  const auto t0 = std::chrono::steady_clock::now();
  const double critical = criticalFlowStep(c, s.fluid_modulus);
  SteadyFlow out;
  // With virtual volumes the step only names the fluid time: the pressures it gives do not
  // depend on it (K_f dt / v = 1 / sum C).
  const bool any_free = std::isfinite(critical);
  if (s.virtual_volume) {
    out.dt = s.dt > 0.0 ? s.dt : (any_free && critical > 0.0 ? critical : 1.0);
  } else {
    out.dt = s.dt > 0.0 ? s.dt : (any_free ? critical : 1.0);
    if (out.dt > critical || !(critical > 0.0)) throw FlowStepTooLarge(out.dt, critical);
  }
  out.pressure = startingPressure(c, bc, previous);
  const auto live = connected(c);
  std::vector<double> sum_c(c.count, 0.0);
  for (std::size_t k = 0; k < c.edge_a.size(); ++k) {
    sum_c[c.edge_a[k]] += c.edge_conductance[k];
    sum_c[c.edge_b[k]] += c.edge_conductance[k];
  }
  // Pressure gain per unit of fluid taken in: K_f / v (equation 5), with v from equation 7
  // when virtual: then K_f / v = 1 / (dt sum C) and every pore answers alike.
  std::vector<double> gain(c.count, 0.0);
  for (std::size_t i = 0; i < c.count; ++i) {
    if (imposed(c.boundary[i]) || !live[i] || sum_c[i] <= 0.0) continue;
    const double v = s.virtual_volume ? s.fluid_modulus * out.dt * sum_c[i] : c.volume[i];
    gain[i] = s.fluid_modulus / v;
  }
  for (std::size_t i = 0; i < c.count; ++i) out.isolated += live[i] ? 0 : 1;
  const double drop = referenceDrop(bc);
  std::vector<double> taken(c.count);
  auto& p = out.pressure;
  for (out.iterations = 0; out.iterations < s.max_steps; ++out.iterations) {
    std::fill(taken.begin(), taken.end(), 0.0);
    for (std::size_t k = 0; k < c.edge_a.size(); ++k) {
      const auto a = c.edge_a[k], b = c.edge_b[k];
      const double dv = c.edge_conductance[k] * (p[a] - p[b]) * out.dt;  // equation 4
      taken[a] -= dv, taken[b] += dv;
    }
    double worst = 0.0;
    for (std::size_t i = 0; i < c.count; ++i) {
      if (gain[i] == 0.0) continue;
      worst = std::max(worst, std::abs(taken[i]) / (out.dt * sum_c[i] * drop));
      p[i] += gain[i] * taken[i];  // equation 5
    }
    if (!std::isfinite(worst)) {
      throw std::runtime_error("flow: the explicit pore pressures diverged (non-finite) at step " +
                               std::to_string(out.iterations));
    }
    if (worst < s.tolerance) {
      out.converged = true;
      break;
    }
  }
  balance(c, bc, live, out);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace rocklab::flow
