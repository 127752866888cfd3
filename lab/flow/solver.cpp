#include "lab/flow/solver.hpp"

#include <cholmod.h>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
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
  std::vector<std::uint32_t> start(c.count + 1, 0);
  for (std::size_t k = 0; k < c.edge_a.size(); ++k) {
    if (c.edge_conductance[k] > 0.0) ++start[c.edge_a[k] + 1], ++start[c.edge_b[k] + 1];
  }
  for (std::size_t i = 0; i < c.count; ++i) start[i + 1] += start[i];
  std::vector<std::uint32_t> adj(start.back()), fill(start.begin(), start.end() - 1);
  for (std::size_t k = 0; k < c.edge_a.size(); ++k) {
    if (c.edge_conductance[k] <= 0.0) continue;
    adj[fill[c.edge_a[k]]++] = c.edge_b[k], adj[fill[c.edge_b[k]]++] = c.edge_a[k];
  }
  std::vector<char> seen(c.count, 0);
  std::vector<std::uint32_t> todo;
  for (std::uint32_t i = 0; i < c.count; ++i) {
    if (imposed(c.boundary[i])) seen[i] = 1, todo.push_back(i);
  }
  while (!todo.empty()) {
    const auto i = todo.back();
    todo.pop_back();
    for (auto k = start[i]; k < start[i + 1]; ++k) {
      if (!seen[adj[k]]) seen[adj[k]] = 1, todo.push_back(adj[k]);
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

const char* describe(ImplicitPath path) {
  switch (path) {
    case ImplicitPath::Factorised:
      return "factorised";
    case ImplicitPath::Refactorised:
      return "refactorised";
    case ImplicitPath::Iterated:
      return "iterated on the kept factor";
    case ImplicitPath::Incomplete:
      return "incomplete Cholesky CG";
    case ImplicitPath::Explicit:
      return "explicit";
  }
  return "";
}

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

namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// A cluster whose pressure the system holds: imposed, or cut off from every boundary.
std::vector<char> heldOf(const Clusters& c, const std::vector<char>& live) {
  std::vector<char> held(c.count);
  for (std::size_t i = 0; i < c.count; ++i) held[i] = imposed(c.boundary[i]) || !live[i];
  return held;
}

// The system over every cluster. A free cluster's row is its balance, sum C (p_i - p_j) = 0;
// a held cluster's row is d_i p_i = d_i p_held, with d_i its pipes' total conductance (so
// every row has the same scale), and its couplings are moved to the right-hand side, so that
// the matrix stays symmetric and holds no entry between a held and a free cluster (they would
// only add fill). The rows keep their clusters' numbers: a factor made with other clusters
// held still preconditions the system when the end layers shift. Each pipe's entries are
// found once, so new conductances are written in place.
struct Pattern {
  std::size_t count = 0;
  std::vector<std::uint32_t> edge_a, edge_b;
  std::vector<char> held;
  SparseMatrix matrix;  // both triangles
  // Per pipe, where (a,a), (b,b), (a,b) and (b,a) sit in the values; -1: not in the matrix.
  std::vector<std::array<std::int64_t, 4>> slot;
  std::vector<std::int64_t> diagonal;  // of (i,i)

  bool samePipes(const Clusters& c) const {
    return count == c.count && edge_a == c.edge_a && edge_b == c.edge_b;
  }

  void fill(const std::vector<double>& conductance) {
    double* v = matrix.valuePtr();
    std::fill(v, v + matrix.nonZeros(), 0.0);
    std::vector<double> total(count, 0.0);
    for (std::size_t k = 0; k < slot.size(); ++k) {
      const double g = conductance[k];
      const auto& s = slot[k];
      total[edge_a[k]] += g, total[edge_b[k]] += g;
      if (s[0] >= 0) v[s[0]] += g;
      if (s[1] >= 0) v[s[1]] += g;
      if (s[2] >= 0) v[s[2]] -= g, v[s[3]] -= g;
    }
    double mean = 0.0;
    for (double t : total) mean += t;
    mean = count > 0 && mean > 0.0 ? mean / static_cast<double>(count) : 1.0;
    for (std::size_t i = 0; i < count; ++i) {
      if (held[i]) v[diagonal[i]] = total[i] > 0.0 ? total[i] : mean;
    }
  }

  // What the held pressures push into their free neighbours, and their own rows.
  Eigen::VectorXd rhs(const std::vector<double>& conductance, const std::vector<double>& p) const {
    Eigen::VectorXd b = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(count));
    const double* v = matrix.valuePtr();
    for (std::size_t k = 0; k < slot.size(); ++k) {
      const auto a = edge_a[k], c = edge_b[k];
      if (!held[a] && held[c]) b[a] += conductance[k] * p[c];
      if (held[a] && !held[c]) b[c] += conductance[k] * p[a];
    }
    for (std::size_t i = 0; i < count; ++i) {
      if (held[i]) b[static_cast<Eigen::Index>(i)] = v[diagonal[i]] * p[i];
    }
    return b;
  }
};

Pattern patternOf(const Clusters& c, const std::vector<char>& held) {
  Pattern p;
  p.count = c.count;
  p.edge_a = c.edge_a, p.edge_b = c.edge_b, p.held = held;
  auto coupled = [&](std::size_t k) { return !held[c.edge_a[k]] && !held[c.edge_b[k]]; };
  // Each column: the diagonal and the free cluster's free neighbours, sorted, parallel pipes
  // once.
  const auto n = static_cast<Eigen::Index>(c.count);
  std::vector<int> start(c.count + 1, 0);
  for (std::size_t i = 0; i < c.count; ++i) start[i + 1] = 1;
  for (std::size_t k = 0; k < c.edge_a.size(); ++k) {
    if (coupled(k)) ++start[c.edge_a[k] + 1], ++start[c.edge_b[k] + 1];
  }
  for (std::size_t i = 0; i < c.count; ++i) start[i + 1] += start[i];
  std::vector<int> rows(static_cast<std::size_t>(start.back())),
      fill(start.begin(), start.end() - 1);
  for (std::size_t i = 0; i < c.count; ++i) rows[fill[i]++] = static_cast<int>(i);
  for (std::size_t k = 0; k < c.edge_a.size(); ++k) {
    if (!coupled(k)) continue;
    const auto a = c.edge_a[k], b = c.edge_b[k];
    rows[fill[a]++] = static_cast<int>(b), rows[fill[b]++] = static_cast<int>(a);
  }
  std::vector<int> outer(c.count + 1, 0);
  std::size_t kept = 0;
  for (std::size_t i = 0; i < c.count; ++i) {
    auto first = rows.begin() + start[i], last = rows.begin() + start[i + 1];
    std::sort(first, last);
    last = std::unique(first, last);
    for (auto it = first; it != last; ++it) rows[kept++] = *it;
    outer[i + 1] = static_cast<int>(kept);
  }
  p.matrix.resize(n, n);
  p.matrix.resizeNonZeros(static_cast<Eigen::Index>(kept));
  std::copy(outer.begin(), outer.end(), p.matrix.outerIndexPtr());
  std::copy(rows.begin(), rows.begin() + static_cast<std::ptrdiff_t>(kept),
            p.matrix.innerIndexPtr());
  std::fill(p.matrix.valuePtr(), p.matrix.valuePtr() + kept, 0.0);
  auto at = [&](std::uint32_t i, std::uint32_t j) -> std::int64_t {
    const int* col = p.matrix.innerIndexPtr();
    return std::lower_bound(col + outer[j], col + outer[j + 1], static_cast<int>(i)) - col;
  };
  p.diagonal.resize(c.count);
  for (std::uint32_t i = 0; i < c.count; ++i) p.diagonal[i] = at(i, i);
  p.slot.resize(c.edge_a.size());
  for (std::size_t k = 0; k < c.edge_a.size(); ++k) {
    const auto a = c.edge_a[k], b = c.edge_b[k];
    const bool both = coupled(k);
    p.slot[k] = {held[a] ? -1 : p.diagonal[a], held[b] ? -1 : p.diagonal[b], both ? at(a, b) : -1,
                 both ? at(b, a) : -1};
  }
  return p;
}

// A fill-reducing ordering from the clusters' positions: geometric nested dissection
// (George 1973; Gilbert, Miller & Teng 1998). A pore network is a well-shaped mesh in space,
// so a plane cuts it along a small separator: the clusters are split at the median of one of
// their longer extents, the pipes the plane cuts are covered by a few clusters (greedily,
// those with the most cut pipes first), and that separator is ordered after the two sides,
// each ordered the same way down to a few clusters. Of the axes tried, the smallest separator
// wins. Measured on the 115,882 pores of the 20,000-sphere benchmark packing
// (`rocklab bench --flow`, one thread), with the imposed clusters still coupled in the
// pattern: this ordering took 0.08 s and gave a factor of 1.5e10 flops (1.25 s); METIS's
// nested dissection gave 1.1e10 flops but took 0.6-0.8 s, and so did CHOLMOD's default (AMD,
// then METIS); AMD alone took 0.12 s and gave a factor of 2.4 s.
class GeometricDissection {
 public:
  GeometricDissection(const SparseMatrix& A, const std::vector<std::array<double, 3>>& position)
      : A_(A),
        position_(position),
        upper_(position.size(), 0),
        cut_(position.size(), 0),
        in_separator_(position.size(), 0) {}

  // perm[k]: the cluster in position k (CHOLMOD's and METIS's convention).
  std::vector<int> order() {
    std::vector<std::uint32_t> all(position_.size());
    for (std::uint32_t i = 0; i < all.size(); ++i) all[i] = i;
    std::vector<int> perm;
    perm.reserve(all.size());
    dissect(all, perm);
    return perm;
  }

 private:
  static constexpr std::size_t kLeaf = 64;   // clusters left in their own order
  static constexpr double kAxisRatio = 0.5;  // cut along axes at least this times the longest

  void dissect(std::vector<std::uint32_t>& nodes, std::vector<int>& perm) {
    if (nodes.size() <= kLeaf) {
      perm.insert(perm.end(), nodes.begin(), nodes.end());
      return;
    }
    std::array<double, 3> lo = position_[nodes[0]], hi = lo;
    for (auto v : nodes) {
      for (int d = 0; d < 3; ++d) {
        lo[d] = std::min(lo[d], position_[v][d]), hi[d] = std::max(hi[d], position_[v][d]);
      }
    }
    double longest = 0.0;
    for (int d = 0; d < 3; ++d) longest = std::max(longest, hi[d] - lo[d]);
    std::vector<std::uint32_t> lower, upper, separator;
    bool found = false;
    for (int axis = 0; axis < 3; ++axis) {
      if (hi[axis] - lo[axis] < kAxisRatio * longest) continue;
      const auto mid = nodes.begin() + static_cast<std::ptrdiff_t>(nodes.size() / 2);
      std::nth_element(nodes.begin(), mid, nodes.end(), [&](std::uint32_t a, std::uint32_t b) {
        const double xa = position_[a][axis], xb = position_[b][axis];
        return xa < xb || (xa == xb && a < b);
      });
      std::vector<std::uint32_t> cover = coverOfCut(nodes, mid);
      if (found && cover.size() >= separator.size()) continue;
      found = true;
      lower.clear(), upper.clear();
      for (auto it = nodes.begin(); it != nodes.end(); ++it) {
        if (!in_separator_[*it]) (it < mid ? lower : upper).push_back(*it);
      }
      separator = std::move(cover);
    }
    std::vector<std::uint32_t>().swap(nodes);
    dissect(lower, perm);
    dissect(upper, perm);
    perm.insert(perm.end(), separator.begin(), separator.end());
  }

  // Clusters covering every pipe between [begin, mid) and [mid, end); marks them in
  // in_separator_.
  std::vector<std::uint32_t> coverOfCut(const std::vector<std::uint32_t>& nodes,
                                        std::vector<std::uint32_t>::const_iterator mid) {
    const int stamp = ++stamp_;
    for (auto it = mid; it != nodes.end(); ++it) upper_[*it] = stamp;
    for (auto v : nodes) cut_[v] = 0, in_separator_[v] = 0;
    std::uint32_t most = 0;
    for (auto it = nodes.cbegin(); it != mid; ++it) {
      for (SparseMatrix::InnerIterator e(A_, *it); e; ++e) {
        if (upper_[e.row()] == stamp) most = std::max({most, ++cut_[*it], ++cut_[e.row()]});
      }
    }
    std::vector<std::uint32_t> cover;
    for (std::uint32_t d = most; d >= 1; --d) {
      for (auto v : nodes) {
        if (cut_[v] != d) continue;
        const bool up = upper_[v] == stamp;
        bool uncovered = false;
        for (SparseMatrix::InnerIterator e(A_, v); e && !uncovered; ++e) {
          const auto w = static_cast<std::uint32_t>(e.row());
          uncovered = cut_[w] > 0 && (upper_[w] == stamp) != up && !in_separator_[w];
        }
        if (uncovered) in_separator_[v] = 1, cover.push_back(v);
      }
    }
    return cover;
  }

  const SparseMatrix& A_;
  const std::vector<std::array<double, 3>>& position_;
  std::vector<int> upper_;          // the stamp of the last upper half a cluster was in
  std::vector<std::uint32_t> cut_;  // a cluster's cut pipes, in the cut being tried
  std::vector<char> in_separator_;  // in the cover of the cut being tried
  int stamp_ = 0;
};

// CHOLMOD's supernodal Cholesky factor of a symmetric positive definite matrix (its lower
// triangle is read), on the ordering above: the factorisation Yade's FlowEngine uses
// (Eigen's simplicial LDL^T fills in badly on 3D networks).
class SupernodalFactor {
 public:
  SupernodalFactor() {
    cholmod_start(&common_);
    common_.supernodal = CHOLMOD_SUPERNODAL;
    common_.nmethods = 1;
    common_.method[0].ordering = CHOLMOD_GIVEN;
    common_.postorder = 1;
  }
  ~SupernodalFactor() {
    if (factor_) cholmod_free_factor(&factor_, &common_);
    cholmod_finish(&common_);
  }
  SupernodalFactor(const SupernodalFactor&) = delete;
  SupernodalFactor& operator=(const SupernodalFactor&) = delete;

  // Symbolic analysis on a fill-reducing ordering (perm[k]: the row in position k).
  void analyse(SparseMatrix& A, std::vector<int> perm) {
    if (factor_) cholmod_free_factor(&factor_, &common_);
    cholmod_sparse a = view(A);
    factor_ = cholmod_analyze_p(&a, perm.data(), nullptr, 0, &common_);
    if (!factor_ || common_.status != CHOLMOD_OK) {
      throw std::runtime_error("flow: the pore network's system could not be analysed");
    }
    flops_ = common_.fl;
    nonzeros_ = common_.lnz;
  }
  void factorise(SparseMatrix& A) {
    cholmod_sparse a = view(A);
    if (!cholmod_factorize(&a, factor_, &common_) || common_.status != CHOLMOD_OK ||
        factor_->minor < factor_->n) {
      throw std::runtime_error(
          "flow: the pore network's system is not positive definite and could not be "
          "factorized");
    }
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const {
    cholmod_dense rhs{};
    rhs.nrow = rhs.d = rhs.nzmax = static_cast<std::size_t>(b.size());
    rhs.ncol = 1;
    rhs.x = const_cast<double*>(b.data());
    rhs.xtype = CHOLMOD_REAL;
    rhs.dtype = CHOLMOD_DOUBLE;
    cholmod_dense* x = cholmod_solve(CHOLMOD_A, factor_, &rhs, &common_);
    if (!x) throw std::runtime_error("flow: the pore network's triangular solve failed");
    Eigen::VectorXd out = Eigen::Map<const Eigen::VectorXd>(static_cast<double*>(x->x), b.size());
    cholmod_free_dense(&x, &common_);
    return out;
  }
  double flops() const { return flops_; }        // of one numeric factorisation
  double nonzeros() const { return nonzeros_; }  // in the factor

 private:
  static cholmod_sparse view(SparseMatrix& A) {
    cholmod_sparse a{};
    a.nrow = a.ncol = static_cast<std::size_t>(A.rows());
    a.nzmax = static_cast<std::size_t>(A.nonZeros());
    a.p = A.outerIndexPtr();
    a.i = A.innerIndexPtr();
    a.x = A.valuePtr();
    a.stype = -1;  // symmetric, its lower triangle
    a.itype = CHOLMOD_INT;
    a.xtype = CHOLMOD_REAL;
    a.dtype = CHOLMOD_DOUBLE;
    a.sorted = 1;
    a.packed = 1;
    return a;
  }

  mutable cholmod_common common_;
  cholmod_factor* factor_ = nullptr;
  double flops_ = 0.0, nonzeros_ = 0.0;
};

// Per flop, CHOLMOD's supernodal factorisation (dense updates) runs several times faster than
// an iteration's memory-bound triangular solves and product. Measured on the 20,000-sphere
// benchmark packing (`rocklab bench --flow`, one thread): the factor's 1.2e10 flops take
// 1.1-1.2 s (about 10 Gflop/s), an iteration's 4 lnz + 2 nnz(A) = 6.5e7 flops take
// 0.03-0.04 s (about 2 Gflop/s). The cap on the iterations counts each of their flops at this
// weight.
constexpr double kIterationFlopWeight = 5.0;

// The most direct solves in a row before the iterations on a kept factor are tried again.
constexpr std::uint32_t kMostDirectAhead = 16;

struct Iterated {
  std::size_t iterations = 0;
  bool converged = false;
};

// Conjugate gradients on A x = b preconditioned with the Cholesky factor of a nearby matrix,
// from x, until |b - A x| <= goal or `cap` iterations. It gives up early once its rate of
// convergence so far says the cap will not do.
Iterated preconditionedCg(const SparseMatrix& A, const SupernodalFactor& M,
                          const Eigen::VectorXd& b, Eigen::VectorXd& x, double goal,
                          std::size_t cap) {
  Iterated out;
  Eigen::VectorXd r = b - A * x;
  const double r0 = r.norm();
  if (r0 <= goal) return out.converged = true, out;
  Eigen::VectorXd z = M.solve(r), p = z, q(x.size());
  double rz = r.dot(z);
  for (out.iterations = 1; out.iterations <= cap; ++out.iterations) {
    q.noalias() = A * p;
    const double step = rz / p.dot(q);
    x += step * p;
    r -= step * q;
    const double rn = r.norm();
    if (rn <= goal) return out.converged = true, out;
    if (out.iterations >= 3) {
      // Geometric convergence so far: the iterations it would take to reach the goal.
      const double rate = std::log(rn / r0) / static_cast<double>(out.iterations);
      if (!(rate < 0.0) || std::log(goal / r0) / rate > static_cast<double>(cap)) break;
    }
    z = M.solve(r);
    const double rz_next = r.dot(z);
    p = z + (rz_next / rz) * p;
    rz = rz_next;
  }
  return out;
}

// The residual the conjugate gradients aim at: the tolerance times the norm of the free
// clusters' right-hand side (the held rows' scale is arbitrary).
double residualGoal(const Eigen::VectorXd& b, const std::vector<char>& held, double tolerance) {
  double sum = 0.0;
  for (std::size_t i = 0; i < held.size(); ++i) {
    if (!held[i]) sum += b[static_cast<Eigen::Index>(i)] * b[static_cast<Eigen::Index>(i)];
  }
  return tolerance * std::sqrt(sum);
}

}  // namespace

struct ImplicitSolver::Kept {
  Pattern pattern;
  SupernodalFactor factor;

  // The iterations on this factor cost less than a new factor up to this many.
  std::size_t iterationCap() const {
    const double per_iteration = 4.0 * factor.nonzeros() + 2.0 * pattern.matrix.nonZeros();
    return static_cast<std::size_t>(factor.flops() / (kIterationFlopWeight * per_iteration));
  }
};

ImplicitSolver::ImplicitSolver() = default;
ImplicitSolver::~ImplicitSolver() = default;
ImplicitSolver::ImplicitSolver(const ImplicitSolver&) {}
ImplicitSolver& ImplicitSolver::operator=(const ImplicitSolver& o) {
  if (this != &o) {
    kept_.reset();
    factored_conductance_.clear(), factored_held_.clear(), ordering_.clear();
    direct_ahead_ = backoff_ = 0;
  }
  return *this;
}
ImplicitSolver::ImplicitSolver(ImplicitSolver&&) noexcept = default;
ImplicitSolver& ImplicitSolver::operator=(ImplicitSolver&&) noexcept = default;

void ImplicitSolver::restore(const Clusters& last) {
  kept_.reset();
  if (factored_conductance_.size() != last.edge_a.size() || ordering_.size() != last.count ||
      factored_held_.size() != last.count || last.count == 0) {
    return;
  }
  kept_ = std::make_unique<Kept>();
  kept_->pattern = patternOf(last, factored_held_);
  kept_->pattern.fill(factored_conductance_);
  kept_->factor.analyse(kept_->pattern.matrix, ordering_);
  kept_->factor.factorise(kept_->pattern.matrix);
}

SteadyFlow ImplicitSolver::solve(const Clusters& c, const Pressures& bc, const ImplicitSettings& s,
                                 const std::vector<double>& previous) {
  const auto t0 = std::chrono::steady_clock::now();
  SteadyFlow out;
  out.pressure = startingPressure(c, bc, previous);
  const auto live = connected(c);
  const auto held = heldOf(c, live);
  for (std::size_t i = 0; i < c.count; ++i) out.isolated += live[i] ? 0 : 1;
  const bool keep = s.method == ImplicitMethod::Cholesky && s.reuse_factor;
  if (!keep || !kept_ || !kept_->pattern.samePipes(c)) {
    kept_ = std::make_unique<Kept>();
    kept_->pattern = patternOf(c, held);
    factored_conductance_.clear(), factored_held_.clear(), ordering_.clear();
    direct_ahead_ = backoff_ = 0;
    out.path = ImplicitPath::Factorised;
  } else if (kept_->pattern.held != held) {
    kept_->pattern = patternOf(c, held);  // the kept factor still preconditions it
  }
  Pattern& pattern = kept_->pattern;
  pattern.fill(c.edge_conductance);
  const Eigen::VectorXd rhs = pattern.rhs(c.edge_conductance, out.pressure);
  Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(out.pressure.data(), rhs.size());
  const double goal = residualGoal(rhs, held, s.tolerance);
  const auto t1 = std::chrono::steady_clock::now();
  out.assembly_seconds = std::chrono::duration<double>(t1 - t0).count();

  if (s.method == ImplicitMethod::ConjugateGradient) {
    Eigen::ConjugateGradient<SparseMatrix, Eigen::Lower | Eigen::Upper,
                             Eigen::IncompleteCholesky<double>>
        cg;
    // Eigen's tolerance is relative to the whole right-hand side.
    cg.setTolerance(rhs.norm() > 0.0 ? goal / rhs.norm() : s.tolerance);
    cg.compute(pattern.matrix);
    out.factorisation_seconds = secondsSince(t1);
    const auto t2 = std::chrono::steady_clock::now();
    x = cg.solveWithGuess(rhs, x);
    out.solve_seconds = secondsSince(t2);
    out.iterations = static_cast<std::size_t>(cg.iterations());
    out.converged = cg.info() == Eigen::Success;
    out.path = ImplicitPath::Incomplete;
  } else {
    bool solved = false;
    if (out.path != ImplicitPath::Factorised && direct_ahead_ > 0) {
      --direct_ahead_;
    } else if (out.path != ImplicitPath::Factorised) {
      const auto t2 = std::chrono::steady_clock::now();
      const Iterated it =
          preconditionedCg(pattern.matrix, kept_->factor, rhs, x, goal, kept_->iterationCap());
      out.solve_seconds = secondsSince(t2);
      out.iterations = it.iterations;
      solved = it.converged;
      out.path = ImplicitPath::Iterated;
      // Past the cap the conductances moved too far for the kept factor, and the next updates
      // will likely move them as far from the new one again: they factorise at once, one
      // after the first miss, then two, four, ... up to kMostDirectAhead, before the
      // iterations are tried again.
      backoff_ =
          solved ? 0 : std::min<std::uint32_t>(backoff_ ? 2 * backoff_ : 1, kMostDirectAhead);
      direct_ahead_ = backoff_;
    }
    if (!solved) {
      // The kept analysis serves while the same clusters are held as when it was made.
      const auto t2 = std::chrono::steady_clock::now();
      if (out.path == ImplicitPath::Factorised || factored_held_ != held) {
        if (c.position.size() != c.count) {
          throw std::logic_error("flow: clusters without positions cannot be ordered");
        }
        ordering_ = GeometricDissection(pattern.matrix, c.position).order();
        kept_->factor.analyse(pattern.matrix, ordering_);
        out.path = ImplicitPath::Factorised;
      } else {
        out.path = ImplicitPath::Refactorised;
      }
      const auto t3 = std::chrono::steady_clock::now();
      out.analysis_seconds = std::chrono::duration<double>(t3 - t2).count();
      kept_->factor.factorise(pattern.matrix);
      if (keep) factored_conductance_ = c.edge_conductance, factored_held_ = held;
      const auto t4 = std::chrono::steady_clock::now();
      out.factorisation_seconds = std::chrono::duration<double>(t4 - t3).count();
      x = kept_->factor.solve(rhs);
      out.solve_seconds += secondsSince(t4);
    }
    out.converged = true;
  }
  for (std::size_t i = 0; i < c.count; ++i) {
    if (!held[i]) out.pressure[i] = x[static_cast<Eigen::Index>(i)];
  }
  if (!keep) kept_.reset();
  balance(c, bc, live, out);
  out.seconds = secondsSince(t0);
  return out;
}

SteadyFlow solveImplicit(const Clusters& c, const Pressures& bc, const ImplicitSettings& s,
                         const std::vector<double>& previous) {
  ImplicitSolver solver;
  return solver.solve(c, bc, s, previous);
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
  // The decay of the largest imbalance over windows of a hundredth of the budget. A
  // Jacobi-like scheme's decay only slows as its faster modes die out, so the steps the last
  // window's rate predicts are a lower bound: past the budget, the scheme cannot make it.
  const std::size_t window = std::max<std::size_t>(1000, s.max_steps / 100);
  double window_worst = 0.0;
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
    if (s.give_up_when_hopeless && (out.iterations + 1) % window == 0) {
      if (window_worst > 0.0) {
        const double rate = std::log(worst / window_worst) / static_cast<double>(window);
        const double needed = rate < 0.0 ? static_cast<double>(out.iterations + 1) +
                                               std::log(s.tolerance / worst) / rate
                                         : std::numeric_limits<double>::infinity();
        if (needed > static_cast<double>(s.max_steps)) {
          out.predicted_iterations = needed;
          ++out.iterations;
          break;
        }
      }
      window_worst = worst;
    }
  }
  balance(c, bc, live, out);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace rocklab::flow
