// CGAL's regular triangulations behind the plain interface of triangulation.hpp. The kernel
// has exact predicates (the orientation and power tests decide the topology and must not
// be fooled by rounding on nearly co-spherical points) and inexact constructions (the
// network only reads the input coordinates back).
#include "lab/flow/triangulation.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_2.h>
#include <CGAL/Regular_triangulation_3.h>
#include <CGAL/Regular_triangulation_cell_base_3.h>
#include <CGAL/Regular_triangulation_face_base_2.h>
#include <CGAL/Regular_triangulation_vertex_base_2.h>
#include <CGAL/Regular_triangulation_vertex_base_3.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_data_structure_2.h>
#include <CGAL/Triangulation_data_structure_3.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <string>
#include <utility>

namespace rocklab::flow {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;

struct Cgal2 {
  using Vb =
      CGAL::Triangulation_vertex_base_with_info_2<std::uint32_t, K,
                                                  CGAL::Regular_triangulation_vertex_base_2<K>>;
  using Fb = CGAL::Triangulation_face_base_with_info_2<std::int32_t, K,
                                                       CGAL::Regular_triangulation_face_base_2<K>>;
  using Tds = CGAL::Triangulation_data_structure_2<Vb, Fb>;
  using RT = CGAL::Regular_triangulation_2<K, Tds>;
  using Point = K::Weighted_point_2;
  static Point point(const Vec<2>& c, double r) { return Point(K::Point_2(c.x(), c.y()), r * r); }
};

struct Cgal3 {
  using Vb =
      CGAL::Triangulation_vertex_base_with_info_3<std::uint32_t, K,
                                                  CGAL::Regular_triangulation_vertex_base_3<K>>;
  using Cb = CGAL::Triangulation_cell_base_with_info_3<std::int32_t, K,
                                                       CGAL::Regular_triangulation_cell_base_3<K>>;
  using Tds = CGAL::Triangulation_data_structure_3<Vb, Cb>;
  using RT = CGAL::Regular_triangulation_3<K, Tds>;
  using Point = K::Weighted_point_3;
  static Point point(const Vec<3>& c, double r) {
    return Point(K::Point_3(c.x(), c.y(), c.z()), r * r);
  }
};

template <int D>
using Cgal = std::conditional_t<D == 2, Cgal2, Cgal3>;

// Finite cells (faces in 2D) of either triangulation.
template <int D, class RT>
auto finiteCells(RT& rt) {
  if constexpr (D == 2) {
    return rt.finite_face_handles();
  } else {
    return rt.finite_cell_handles();
  }
}

}  // namespace

template <int D>
Triangulation<D> triangulate(const std::vector<Vec<D>>& centres, const std::vector<double>& radii) {
  using C = Cgal<D>;
  const char* span = D == 2 ? "on one line" : "on one plane";
  if (centres.size() < D + 1) {
    throw DegenerateNetwork("a pore network needs at least " + std::to_string(D + 1) +
                            " particles; the sample has " + std::to_string(centres.size()));
  }
  std::vector<std::pair<typename C::Point, std::uint32_t>> points;
  points.reserve(centres.size());
  for (std::size_t i = 0; i < centres.size(); ++i) {
    points.emplace_back(C::point(centres[i], radii[i]), static_cast<std::uint32_t>(i));
  }
  typename C::RT rt(points.begin(), points.end());
  if (rt.dimension() < D) {
    throw DegenerateNetwork(std::string("the particle centres lie ") + span +
                            ": they enclose no pore");
  }
  Triangulation<D> t;
  std::int32_t next = 0;
  for (auto c : finiteCells<D>(rt)) c->info() = next++;
  t.cells.reserve(next);
  t.neighbours.reserve(next);
  std::vector<char> used(centres.size(), 0);
  for (auto c : finiteCells<D>(rt)) {
    std::array<std::uint32_t, D + 1> v;
    std::array<std::int32_t, D + 1> n;
    for (int k = 0; k <= D; ++k) {
      v[k] = c->vertex(k)->info();
      used[v[k]] = 1;
      const auto across = c->neighbor(k);
      n[k] = rt.is_infinite(across) ? kHull : across->info();
    }
    t.cells.push_back(v);
    t.neighbours.push_back(n);
  }
  for (char u : used) t.hidden += u ? 0 : 1;
  return t;
}

template <int D>
void trimHull(Triangulation<D>& t, const std::vector<Vec<D>>& centres,
              const std::vector<double>& radii, double max_edge_ratio) {
  const std::size_t n = t.cells.size();
  std::vector<std::int32_t> index(n, kHull);
  std::int32_t kept = 0;
  for (std::size_t c = 0; c < n; ++c) {
    const auto& v = t.cells[c];
    bool pore = true;
    for (int a = 0; a <= D && pore; ++a) {
      for (int b = a + 1; b <= D && pore; ++b) {
        const double limit = max_edge_ratio * (radii[v[a]] + radii[v[b]]);
        pore = (centres[v[a]] - centres[v[b]]).squaredNorm() <= limit * limit;
      }
    }
    if (pore) index[c] = kept++;
  }
  std::size_t w = 0;
  for (std::size_t c = 0; c < n; ++c) {
    if (index[c] == kHull) continue;
    t.cells[w] = t.cells[c];
    for (int f = 0; f <= D; ++f) {
      const auto nb = t.neighbours[c][f];
      t.neighbours[w][f] = nb == kHull ? kHull : index[nb];
    }
    ++w;
  }
  t.trimmed += n - w;
  t.cells.resize(w);
  t.neighbours.resize(w);
}

template Triangulation<2> triangulate<2>(const std::vector<Vec<2>>&, const std::vector<double>&);
template Triangulation<3> triangulate<3>(const std::vector<Vec<3>>&, const std::vector<double>&);

template void trimHull<2>(Triangulation<2>&, const std::vector<Vec<2>>&, const std::vector<double>&,
                          double);
template void trimHull<3>(Triangulation<3>&, const std::vector<Vec<3>>&, const std::vector<double>&,
                          double);

}  // namespace rocklab::flow
