#include "lab/core/neighbors.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace rocklab {

namespace {

template <int D>
struct Box {
  Vec<D> lo, hi;
};

template <int D>
Box<D> boundingBox(const std::vector<Vec<D>>& pos) {
  Box<D> b{pos.front(), pos.front()};
  for (const auto& x : pos) {
    b.lo = b.lo.cwiseMin(x);
    b.hi = b.hi.cwiseMax(x);
  }
  return b;
}

template <int D>
std::array<int, D> cellOf(const Vec<D>& x, const Vec<D>& lo, double cell,
                          const std::array<int, D>& dims) {
  std::array<int, D> c;
  for (int d = 0; d < D; ++d) {
    const double f = std::floor((x[d] - lo[d]) / cell);
    c[d] = static_cast<int>(std::clamp(f, 0.0, static_cast<double>(dims[d] - 1)));
  }
  return c;
}

template <int D>
std::size_t linearIndex(const std::array<int, D>& c, const std::array<int, D>& dims) {
  std::size_t k = static_cast<std::size_t>(c[D - 1]);
  for (int d = D - 2; d >= 0; --d) k = k * static_cast<std::size_t>(dims[d]) + c[d];
  return k;
}

// Grid dimensions for a cell width, with the width grown until the grid has at most
// `max_cells` cells so a sparse level over a wide domain does not allocate a huge grid.
template <int D>
std::array<int, D> gridDims(const Vec<D>& extent, double& cell, std::size_t max_cells) {
  for (;;) {
    std::array<int, D> dims;
    double cells = 1.0;
    for (int d = 0; d < D; ++d) {
      dims[d] = static_cast<int>(std::floor(extent[d] / cell)) + 1;
      cells *= dims[d];
    }
    if (cells <= static_cast<double>(max_cells)) return dims;
    cell *= 1.26;  // about 2^(1/3): halves the cell count in 3D
  }
}

}  // namespace

template <int D>
void NeighborGrid<D>::build(const std::vector<Vec<D>>& pos, const std::vector<double>& radius,
                            double skin, PairRows& out) {
  const std::size_t n = pos.size();
  out.row.assign(n + 1, 0);
  out.col.clear();
  found_.clear();
  if (n < 2) return;

  const Box<D> box = boundingBox<D>(pos);
  const Vec<D> extent = box.hi - box.lo;
  const auto [rmin_it, rmax_it] = std::minmax_element(radius.begin(), radius.end());
  const double rmin = *rmin_it, rmax = *rmax_it;

  // Level widths: the finest fits the smallest particle's reach; each next one doubles.
  // A narrow size range (widest reach within twice the finest) stays one plain grid.
  std::vector<double> widths;
  const double w0 = 2.0 * rmin + skin, wmax = 2.0 * rmax + skin;
  if (wmax <= 2.0 * w0) {
    widths.push_back(wmax);
  } else {
    for (double w = w0;; w *= 2.0) {
      widths.push_back(std::min(w, wmax));
      if (w >= wmax) break;
    }
  }
  levels_.assign(widths.size(), Level{});
  level_of_.resize(n);
  std::vector<std::size_t> count(widths.size(), 0);
  for (std::size_t i = 0; i < n; ++i) {
    const double need = 2.0 * radius[i] + skin;
    std::size_t l = 0;
    while (widths[l] < need) ++l;
    level_of_[i] = static_cast<std::uint8_t>(l);
    levels_[l].rmax = std::max(levels_[l].rmax, radius[i]);
    ++count[l];
  }

  std::vector<std::uint32_t> cell_of(n);
  for (std::size_t l = 0; l < levels_.size(); ++l) {
    Level& L = levels_[l];
    L.cell = widths[l];
    L.dims = gridDims<D>(extent, L.cell, std::max<std::size_t>(8 * count[l], 64));
    std::size_t cells = 1;
    for (int d = 0; d < D; ++d) cells *= static_cast<std::size_t>(L.dims[d]);
    L.start.assign(cells + 1, 0);
    L.items.resize(count[l]);
  }
  for (std::size_t i = 0; i < n; ++i) {
    Level& L = levels_[level_of_[i]];
    cell_of[i] = static_cast<std::uint32_t>(
        linearIndex<D>(cellOf<D>(pos[i], box.lo, L.cell, L.dims), L.dims));
    ++L.start[cell_of[i] + 1];
  }
  for (Level& L : levels_) std::partial_sum(L.start.begin(), L.start.end(), L.start.begin());
  {
    std::vector<std::vector<std::uint32_t>> fill(levels_.size());
    for (std::size_t l = 0; l < levels_.size(); ++l) {
      fill[l].assign(levels_[l].start.begin(), levels_[l].start.end() - 1);
    }
    for (std::size_t i = 0; i < n; ++i) {
      const auto l = level_of_[i];
      levels_[l].items[fill[l][cell_of[i]]++] = static_cast<std::uint32_t>(i);
    }
  }

  auto test = [&](std::uint32_t p, std::uint32_t q) {
    const double reach = radius[p] + radius[q] + skin;
    if ((pos[p] - pos[q]).squaredNorm() < reach * reach) {
      const std::uint64_t a = std::min(p, q), b = std::max(p, q);
      found_.push_back(a << 32 | b);
    }
  };

  for (std::uint32_t p = 0; p < n; ++p) {
    const std::size_t lp = level_of_[p];
    // Same level: the 3^D stencil around p's cell; each pair once, from its lower index.
    {
      const Level& L = levels_[lp];
      const auto c = cellOf<D>(pos[p], box.lo, L.cell, L.dims);
      std::array<int, D> lo, hi;
      for (int d = 0; d < D; ++d) {
        lo[d] = std::max(c[d] - 1, 0);
        hi[d] = std::min(c[d] + 1, L.dims[d] - 1);
      }
      std::array<int, D> k = lo;
      for (;;) {
        const std::size_t cell = linearIndex<D>(k, L.dims);
        for (std::uint32_t t = L.start[cell]; t < L.start[cell + 1]; ++t) {
          const std::uint32_t q = L.items[t];
          if (q > p) test(p, q);
        }
        int d = 0;
        while (d < D && ++k[d] > hi[d]) k[d] = lo[d], ++d;
        if (d == D) break;
      }
    }
    // Finer levels: the cells the reach of p overlaps.
    for (std::size_t lq = 0; lq < lp; ++lq) {
      const Level& L = levels_[lq];
      if (L.items.empty()) continue;
      const double reach = radius[p] + L.rmax + skin;
      const Vec<D> a = pos[p] - Vec<D>::Constant(reach), b = pos[p] + Vec<D>::Constant(reach);
      const auto lo = cellOf<D>(a, box.lo, L.cell, L.dims);
      const auto hi = cellOf<D>(b, box.lo, L.cell, L.dims);
      std::array<int, D> k = lo;
      for (;;) {
        const std::size_t cell = linearIndex<D>(k, L.dims);
        for (std::uint32_t t = L.start[cell]; t < L.start[cell + 1]; ++t) test(p, L.items[t]);
        int d = 0;
        while (d < D && ++k[d] > hi[d]) k[d] = lo[d], ++d;
        if (d == D) break;
      }
    }
  }

  // Bucket by the lower index, partners ascending: a deterministic layout whatever the
  // traversal, and the order the threaded force gather relies on (see simulation.cpp).
  std::sort(found_.begin(), found_.end());
  out.col.resize(found_.size());
  for (std::size_t k = 0; k < found_.size(); ++k) {
    ++out.row[(found_[k] >> 32) + 1];
    out.col[k] = static_cast<std::uint32_t>(found_[k] & 0xffffffffu);
  }
  std::partial_sum(out.row.begin(), out.row.end(), out.row.begin());
}

template <int D>
std::vector<std::uint32_t> NeighborGrid<D>::spatialOrder(const std::vector<Vec<D>>& pos,
                                                         const std::vector<double>& radius) {
  const std::size_t n = pos.size();
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  if (n < 2) return order;
  const Box<D> box = boundingBox<D>(pos);
  double rsum = 0.0;
  for (double r : radius) rsum += r;
  double cell = 4.0 * rsum / static_cast<double>(n);
  const auto dims = gridDims<D>(box.hi - box.lo, cell, std::max<std::size_t>(n, 64));
  std::vector<std::uint64_t> key(n);
  for (std::size_t i = 0; i < n; ++i) {
    key[i] = linearIndex<D>(cellOf<D>(pos[i], box.lo, cell, dims), dims);
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return key[a] < key[b]; });
  return order;
}

template class NeighborGrid<2>;
template class NeighborGrid<3>;

}  // namespace rocklab
