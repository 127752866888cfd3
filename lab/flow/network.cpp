#include "lab/flow/network.hpp"

#include <algorithm>
#include <numeric>
#include <unordered_map>

#include "lab/flow/geometry.hpp"

namespace rocklab::flow {

namespace {

std::uint64_t pairKey(std::uint32_t i, std::uint32_t j) {
  if (i > j) std::swap(i, j);
  return (static_cast<std::uint64_t>(i) << 32) | j;
}

// The vertices of facet f of a cell (all but vertex f), in cyclic order.
template <int D>
std::array<std::uint32_t, D> facetVertices(const std::array<std::uint32_t, D + 1>& cell, int f) {
  std::array<std::uint32_t, D> v;
  for (int k = 1; k <= D; ++k) v[k - 1] = cell[(f + k) % (D + 1)];
  return v;
}

// Unit normal of facet f of a cell, pointing away from the cell (from its vertex f).
template <int D>
Vec<D> outwardNormal(const std::vector<Vec<D>>& x, const std::array<std::uint32_t, D + 1>& cell,
                     int f) {
  const auto v = facetVertices<D>(cell, f);
  Vec<D> n;
  if constexpr (D == 2) {
    const Vec<2> e = x[v[1]] - x[v[0]];
    n = Vec<2>(e.y(), -e.x());
  } else {
    n = (x[v[1]] - x[v[0]]).cross(x[v[2]] - x[v[0]]);
  }
  n.normalize();
  if (n.dot(x[v[0]] - x[cell[f]]) < 0.0) n = -n;
  return n;
}

// Signed size of a cell (area 2D, volume 3D) over the size of an equilateral cell of its
// mean edge: 1 for a regular cell, near 0 for a flat one, negative once inverted.
template <int D>
double cellQuality(const std::vector<Vec<D>>& x, const std::array<std::uint32_t, D + 1>& c) {
  double edges = 0.0;
  int n = 0;
  for (int a = 0; a <= D; ++a) {
    for (int b = a + 1; b <= D; ++b, ++n) edges += (x[c[a]] - x[c[b]]).norm();
  }
  const double l = edges / n;
  if constexpr (D == 2) {
    const double signed_area = 0.5 * cross(Vec<2>(x[c[1]] - x[c[0]]), Vec<2>(x[c[2]] - x[c[0]]));
    return signed_area / (std::sqrt(3.0) / 4.0 * l * l);
  } else {
    const double signed_volume =
        (x[c[1]] - x[c[0]]).dot((x[c[2]] - x[c[0]]).cross(x[c[3]] - x[c[0]])) / 6.0;
    return signed_volume / (l * l * l / (6.0 * std::sqrt(2.0)));
  }
}

// Fluid space of a cell: the cell minus each particle's sector in it.
template <int D>
double poreSpace(const PackView<D>& p, const std::array<std::uint32_t, D + 1>& c) {
  const auto& x = p.centre;
  const auto& r = p.radius;
  if constexpr (D == 2) {
    const auto th = triangleAngles(x[c[0]], x[c[1]], x[c[2]]);
    double solid = 0.0;
    for (int k = 0; k < 3; ++k) solid += 0.5 * r[c[k]] * r[c[k]] * th[k];
    return triangleArea(x[c[0]], x[c[1]], x[c[2]]) - solid;
  } else {
    const double cell =
        std::abs((x[c[1]] - x[c[0]]).dot((x[c[2]] - x[c[0]]).cross(x[c[3]] - x[c[0]]))) / 6.0;
    double solid = 0.0;
    for (int k = 0; k < 4; ++k) {
      const auto& o = x[c[k]];
      const Vec<3> a = x[c[(k + 1) % 4]] - o, b = x[c[(k + 2) % 4]] - o, d = x[c[(k + 3) % 4]] - o;
      solid += solidAngle(a, b, d) * r[c[k]] * r[c[k]] * r[c[k]] / 3.0;
    }
    return cell - solid;
  }
}

}  // namespace

template <int D>
Network<D>::Network(Triangulation<D> topology, double slice)
    : topology_(std::move(topology)), slice_(slice) {
  const auto& nb = topology_.neighbours;
  for (std::uint32_t a = 0; a < nb.size(); ++a) {
    for (int f = 0; f <= D; ++f) {
      const std::int32_t b = nb[a][f];
      if (b == kHull || static_cast<std::uint32_t>(b) < a) continue;  // each pipe once
      pipe_a_.push_back(a);
      pipe_b_.push_back(static_cast<std::uint32_t>(b));
      pipe_facet_.push_back(static_cast<std::uint8_t>(f));
    }
  }
}

template <int D>
void Network<D>::measure(const PackView<D>& pack, const ConductanceLaw& law) {
  const auto& x = pack.centre;
  const auto& r = pack.radius;
  const auto& cells = topology_.cells;
  volume_.resize(cells.size());
  centroid_.resize(cells.size());
  worst_quality_ = 1.0;
  for (std::size_t c = 0; c < cells.size(); ++c) {
    V m = V::Zero();
    for (auto v : cells[c]) m += x[v];
    centroid_[c] = m / (D + 1);
    // Overlapping particles can count a sliver of solid twice: a pore is never negative.
    volume_[c] = std::max(poreSpace<D>(pack, cells[c]), 0.0) * (D == 2 ? slice_ : 1.0);
    worst_quality_ = std::min(worst_quality_, cellQuality<D>(x, cells[c]));
  }
  std::unordered_map<std::uint64_t, double> cement;
  cement.reserve(pack.bond.size());
  for (std::size_t b = 0; b < pack.bond.size(); ++b) {
    cement[pairKey(pack.bond[b][0], pack.bond[b][1])] = pack.bond_radius[b];
  }
  auto cementBetween = [&](std::uint32_t i, std::uint32_t j) {
    const auto it = cement.find(pairKey(i, j));
    if (it == cement.end()) return 0.0;
    return cementArea(r[i], r[j], (x[i] - x[j]).norm() - r[i] - r[j], it->second);
  };
  throat_.resize(pipes());
  conductance_.resize(pipes());
  for (std::size_t k = 0; k < pipes(); ++k) {
    const auto v = facetVertices<D>(cells[pipe_a_[k]], pipe_facet_[k]);
    double open = 0.0, mean_radius = 0.0;
    if constexpr (D == 2) {
      const auto t = virtualThroat(r[v[0]], r[v[1]], (x[v[0]] - x[v[1]]).norm());
      open = t.triangle - t.fans - cementBetween(v[0], v[1]);
      mean_radius = 0.5 * (r[v[0]] + r[v[1]]);
    } else {
      const auto th = triangleAngles(x[v[0]], x[v[1]], x[v[2]]);
      open = triangleArea(x[v[0]], x[v[1]], x[v[2]]);
      for (int q = 0; q < 3; ++q) {
        open -= 0.5 * r[v[q]] * r[v[q]] * th[q] + cementBetween(v[q], v[(q + 1) % 3]);
        mean_radius += r[v[q]] / 3.0;
      }
    }
    throat_[k] = std::max(open, 0.0);
    conductance_[k] = pipeConductance(law.alpha, law.viscosity, throat_[k], mean_radius);
  }
}

template <int D>
double Network<D>::outerSection(const std::vector<PoreBoundary>& boundary, PoreBoundary which,
                                const PackView<D>& pack, int axis) const {
  const auto& x = pack.centre;
  double area = 0.0;
  for (std::size_t c = 0; c < pores(); ++c) {
    if (boundary[c] != which) continue;
    const auto& cell = topology_.cells[c];
    for (int f = 0; f <= D; ++f) {
      if (topology_.neighbours[c][f] != kHull) continue;
      const auto v = facetVertices<D>(cell, f);
      double size;
      if constexpr (D == 2) {
        size = (x[v[0]] - x[v[1]]).norm() * slice_;
      } else {
        size = triangleArea(x[v[0]], x[v[1]], x[v[2]]);
      }
      area += size * outwardNormal<D>(x, cell, f)[axis];
    }
  }
  return area;
}

template <int D>
std::vector<Vec<D>> Network<D>::particleForces(const std::vector<double>& p,
                                               const PackView<D>& pack, double thickness) const {
  const auto& x = pack.centre;
  const auto& r = pack.radius;
  std::vector<V> force(x.size(), V::Zero());
  for (std::size_t k = 0; k < pipes(); ++k) {
    const double dp = p[pipe_a_[k]] - p[pipe_b_[k]];
    if (dp == 0.0) continue;
    const auto& cell = topology_.cells[pipe_a_[k]];
    const auto v = facetVertices<D>(cell, pipe_facet_[k]);
    const V n = outwardNormal<D>(x, cell, pipe_facet_[k]);
    // Each particle's solid share of the facet, and the open rest shared equally.
    std::array<double, D> solid;
    double facet = 0.0;
    if constexpr (D == 2) {
      const double d = (x[v[0]] - x[v[1]]).norm();
      facet = d * thickness;
      const double squeeze = std::min(1.0, d / (r[v[0]] + r[v[1]]));  // overlapping disks
      for (int q = 0; q < 2; ++q) solid[q] = r[v[q]] * squeeze * thickness;
    } else {
      const auto th = triangleAngles(x[v[0]], x[v[1]], x[v[2]]);
      facet = triangleArea(x[v[0]], x[v[1]], x[v[2]]);
      double fans = 0.0;
      for (int q = 0; q < 3; ++q) fans += solid[q] = 0.5 * r[v[q]] * r[v[q]] * th[q];
      if (fans > facet) {
        for (auto& s : solid) s *= facet / fans;
      }
    }
    const double open_share =
        (facet - std::accumulate(solid.begin(), solid.end(), 0.0)) / static_cast<double>(D);
    for (int q = 0; q < D; ++q) force[v[q]] += dp * (solid[q] + open_share) * n;
  }
  return force;
}

namespace {

// Union-find over pores with the boundary kind of each set.
struct PoreSets {
  std::vector<std::uint32_t> parent;
  std::vector<PoreBoundary> kind;
  explicit PoreSets(const std::vector<PoreBoundary>& boundary)
      : parent(boundary.size()), kind(boundary) {
    std::iota(parent.begin(), parent.end(), 0u);
  }
  std::uint32_t find(std::uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  // Joins the sets of a and b unless that would connect the inlet to the outlet.
  void join(std::uint32_t a, std::uint32_t b) {
    a = find(a), b = find(b);
    if (a == b) return;
    const auto ka = kind[a], kb = kind[b];
    if (ka != PoreBoundary::Free && kb != PoreBoundary::Free && ka != kb) return;
    parent[b] = a;
    if (ka == PoreBoundary::Free) kind[a] = kb;
  }
};

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// Joins every free set whose critical step v / sum C (the fluid modulus is common to all
// and cancels) is below `ratio` times the median to the set it is best connected to, in
// passes until none is left: two flat cells may first join each other.
template <int D>
void mergeSmallPores(const Network<D>& net, double ratio, PoreSets& sets) {
  const std::size_t n = net.pores();
  const auto& C = net.conductance();
  double limit = -1.0;
  for (int pass = 0; pass < 32; ++pass) {
    std::vector<double> volume(n, 0.0), sum_c(n, 0.0), best_c(n, -1.0);
    std::vector<std::uint32_t> best_to(n, 0);
    for (std::uint32_t i = 0; i < n; ++i) volume[sets.find(i)] += net.volume()[i];
    for (std::size_t k = 0; k < net.pipes(); ++k) {
      const auto a = sets.find(net.pipeA(k)), b = sets.find(net.pipeB(k));
      if (a == b) continue;
      sum_c[a] += C[k], sum_c[b] += C[k];
      if (C[k] > best_c[a]) best_c[a] = C[k], best_to[a] = b;
      if (C[k] > best_c[b]) best_c[b] = C[k], best_to[b] = a;
    }
    std::vector<std::uint32_t> small;
    std::vector<double> step;
    for (std::uint32_t i = 0; i < n; ++i) {
      if (sets.find(i) != i || sum_c[i] <= 0.0) continue;
      step.push_back(volume[i] / sum_c[i]);
      if (sets.kind[i] == PoreBoundary::Free) small.push_back(i);
    }
    if (limit < 0.0) limit = ratio * median(step);
    bool joined = false;
    for (auto i : small) {
      if (volume[i] / sum_c[i] >= limit) continue;
      sets.join(best_to[i], i);
      joined = true;
    }
    if (!joined) return;
  }
}

}  // namespace

template <int D>
Clusters mergePores(const Network<D>& net, const std::vector<PoreBoundary>& boundary,
                    const MergeRule& rule) {
  PoreSets sets(boundary);
  const auto& C = net.conductance();
  if (rule.conductance_ratio > 0.0) {
    const double limit = rule.conductance_ratio * median(C);
    for (std::size_t k = 0; k < net.pipes(); ++k) {
      if (C[k] > limit) sets.join(net.pipeA(k), net.pipeB(k));
    }
  }
  if (rule.small_pore_ratio > 0.0) mergeSmallPores(net, rule.small_pore_ratio, sets);
  Clusters c;
  c.of_pore.resize(net.pores());
  std::vector<std::uint32_t> index(net.pores(), 0xffffffffu);
  for (std::uint32_t i = 0; i < net.pores(); ++i) {
    const auto root = sets.find(i);
    if (index[root] == 0xffffffffu) index[root] = static_cast<std::uint32_t>(c.count++);
    c.of_pore[i] = index[root];
  }
  c.volume.assign(c.count, 0.0);
  c.boundary.assign(c.count, PoreBoundary::Free);
  c.position.assign(c.count, {0.0, 0.0, 0.0});
  std::vector<double> pores(c.count, 0.0);
  for (std::size_t i = 0; i < net.pores(); ++i) {
    const auto k = c.of_pore[i];
    c.volume[k] += net.volume()[i];
    if (boundary[i] != PoreBoundary::Free) c.boundary[k] = boundary[i];
    for (int d = 0; d < D; ++d) c.position[k][d] += net.centroid()[i][d];
    pores[k] += 1.0;
  }
  for (std::size_t k = 0; k < c.count; ++k) {
    for (auto& x : c.position[k]) x /= pores[k];
  }
  for (std::size_t k = 0; k < net.pipes(); ++k) {
    const auto a = c.of_pore[net.pipeA(k)], b = c.of_pore[net.pipeB(k)];
    if (a == b) continue;
    c.edge_a.push_back(a);
    c.edge_b.push_back(b);
    c.edge_conductance.push_back(C[k]);
  }
  return c;
}

template class Network<2>;
template class Network<3>;
template Clusters mergePores<2>(const Network<2>&, const std::vector<PoreBoundary>&,
                                const MergeRule&);
template Clusters mergePores<3>(const Network<3>&, const std::vector<PoreBoundary>&,
                                const MergeRule&);

}  // namespace rocklab::flow
