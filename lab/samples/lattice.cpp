#include "lab/samples/lattice.hpp"

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

namespace rocklab {

LatticeKind latticeKindOf(const std::string& name) {
  if (name == "hex") return LatticeKind::Hex;
  if (name == "square") return LatticeKind::Square;
  if (name == "sc") return LatticeKind::Sc;
  if (name == "bcc") return LatticeKind::Bcc;
  if (name == "fcc") return LatticeKind::Fcc;
  throw std::invalid_argument("lattice '" + name + "': one of hex, square (2D), sc, bcc, fcc (3D)");
}

int latticeDimension(LatticeKind k) {
  return k == LatticeKind::Hex || k == LatticeKind::Square ? 2 : 3;
}

namespace {

struct Cell {
  std::array<double, 3> edge;                // in spacings
  std::vector<std::array<double, 3>> sites;  // in spacings, inside the cell
};

// The conventional unit cells, scaled so that nearest neighbours are one spacing apart:
// triangular (hex) a = 1 in a 1 x sqrt(3) cell of 2; bcc a = 2 / sqrt(3) (neighbours along
// the cube diagonal); fcc a = sqrt(2) (along the face diagonal).
Cell unitCell(LatticeKind k) {
  const double h = std::sqrt(3.0), b = 2.0 / std::sqrt(3.0), f = std::sqrt(2.0);
  switch (k) {
    case LatticeKind::Hex:
      return {{1.0, h, 1.0}, {{0.25, 0.25 * h, 0}, {0.75, 0.75 * h, 0}}};
    case LatticeKind::Square:
      return {{1.0, 1.0, 1.0}, {{0.5, 0.5, 0}}};
    case LatticeKind::Sc:
      return {{1.0, 1.0, 1.0}, {{0.5, 0.5, 0.5}}};
    case LatticeKind::Bcc:
      return {{b, b, b}, {{0.25 * b, 0.25 * b, 0.25 * b}, {0.75 * b, 0.75 * b, 0.75 * b}}};
    case LatticeKind::Fcc:
      return {{f, f, f},
              {{0.25 * f, 0.25 * f, 0.25 * f},
               {0.75 * f, 0.75 * f, 0.25 * f},
               {0.75 * f, 0.25 * f, 0.75 * f},
               {0.25 * f, 0.75 * f, 0.75 * f}}};
  }
  return {};
}

// Uniform on [-1, 1) from the generator's raw bits: the same numbers on every platform
// (std::uniform_real_distribution's algorithm is the library's choice).
double symmetric(std::mt19937_64& g) {
  return 2.0 * static_cast<double>(g() >> 11) * 0x1.0p-53 - 1.0;
}

}  // namespace

int latticeSitesPerCell(LatticeKind k) {
  return static_cast<int>(unitCell(k).sites.size());
}

template <int D>
Packing<D> latticePacking(const LatticeSpec& s) {
  if (latticeDimension(s.kind) != D) throw std::invalid_argument("lattice of the other dimension");
  if (!(s.spacing > 0.0)) throw std::invalid_argument("lattice spacing must be positive");
  for (int a = 0; a < D; ++a) {
    if (s.cells[a] < 1) throw std::invalid_argument("lattice cells per axis must be at least 1");
  }
  const Cell cell = unitCell(s.kind);
  const double r0 = s.radius > 0.0 ? s.radius : 0.5 * s.spacing;
  std::mt19937_64 rng(s.seed);
  Packing<D> p;
  std::array<int, 3> n{s.cells[0], s.cells[1], D == 3 ? s.cells[2] : 1};
  for (int k = 0; k < n[2]; ++k) {
    for (int j = 0; j < n[1]; ++j) {
      for (int i = 0; i < n[0]; ++i) {
        const std::array<int, 3> at{i, j, k};
        for (const auto& site : cell.sites) {
          Vec<D> x;
          for (int a = 0; a < D; ++a) {
            x[a] = (at[a] * cell.edge[a] + site[a]) * s.spacing +
                   s.position_perturbation * r0 * symmetric(rng);
          }
          p.centers.push_back(x);
          p.radii.push_back(r0 * (1.0 + s.radius_perturbation * symmetric(rng)));
        }
      }
    }
  }
  p.lo = Vec<D>::Constant(1e300), p.hi = Vec<D>::Constant(-1e300);
  for (std::size_t q = 0; q < p.centers.size(); ++q) {
    p.lo = p.lo.cwiseMin(p.centers[q] - Vec<D>::Constant(p.radii[q]));
    p.hi = p.hi.cwiseMax(p.centers[q] + Vec<D>::Constant(p.radii[q]));
  }
  return p;
}

template Packing<2> latticePacking<2>(const LatticeSpec&);
template Packing<3> latticePacking<3>(const LatticeSpec&);

}  // namespace rocklab
