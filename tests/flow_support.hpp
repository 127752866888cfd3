#pragma once
// Packs and networks shared by the flow tests.

#include <array>
#include <cmath>
#include <vector>

#include "lab/core/random.hpp"
#include "lab/flow/network.hpp"
#include "lab/flow/triangulation.hpp"

namespace rocklab::flow {

// A homogeneous pack on a lattice whose triangulation is unique (no four co-circular or
// five co-spherical centres): triangular in 2D (spacing 1), body-centred cubic in 3D (cube
// side 1), n[d] cells per axis; centres moved by up to +-jitter, radii within +-10%.
template <int D>
PackView<D> latticePack(const std::array<int, D>& n, double radius, double jitter,
                        std::uint64_t seed) {
  Rng rng(seed);
  PackView<D> p;
  auto add = [&](Vec<D> x) {
    for (int d = 0; d < D; ++d) x[d] += rng.uniform(-jitter, jitter);
    p.centre.push_back(x);
    p.radius.push_back(radius * rng.uniform(0.9, 1.1));
  };
  if constexpr (D == 2) {
    const double row = std::sqrt(3.0) / 2.0;
    for (int j = 0; j < n[1]; ++j) {
      for (int i = 0; i < n[0]; ++i) add({i + 0.5 * (j % 2), j * row});
    }
  } else {
    for (int k = 0; k < n[2]; ++k) {
      for (int j = 0; j < n[1]; ++j) {
        for (int i = 0; i < n[0]; ++i) {
          add({double(i), double(j), double(k)});
          if (i + 1 < n[0] && j + 1 < n[1] && k + 1 < n[2]) add({i + 0.5, j + 0.5, k + 0.5});
        }
      }
    }
  }
  return p;
}

// The network of a pack, its hull trimmed as the coupling does.
template <int D>
Network<D> networkOf(const PackView<D>& p) {
  auto t = triangulate<D>(p.centre, p.radius);
  trimHull<D>(t, p.centre, p.radius, 2.0);
  Network<D> net(std::move(t), 1.0);
  net.measure(p, {});
  return net;
}

template <int D>
std::vector<PoreBoundary> endLayers(const Network<D>& net, double lo, double hi) {
  std::vector<PoreBoundary> b(net.pores(), PoreBoundary::Free);
  for (std::size_t c = 0; c < net.pores(); ++c) {
    const double h = net.centroid()[c][D - 1];
    if (h >= hi) b[c] = PoreBoundary::Inlet;
    if (h <= lo) b[c] = PoreBoundary::Outlet;
  }
  return b;
}

}  // namespace rocklab::flow
