#include "lab/core/grains.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <string>

#include "lab/core/errors.hpp"
#include "lab/core/simulation.hpp"

namespace rocklab {

namespace {

// Directions for calipers: half a circle (2D); a Fibonacci lattice on the sphere (3D).
template <int D>
const std::vector<Vec<D>>& caliperDirections() {
  static const std::vector<Vec<D>> dirs = [] {
    std::vector<Vec<D>> out;
    if constexpr (D == 2) {
      for (int k = 0; k < 180; ++k) {
        const double a = std::numbers::pi * k / 180.0;
        out.push_back({std::cos(a), std::sin(a)});
      }
    } else {
      const int n = 2000;  // about 0.08 rad apart
      const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
      for (int k = 0; k < n; ++k) {
        const double z = 1.0 - (k + 0.5) / n * 2.0;
        const double r = std::sqrt(1.0 - z * z), a = golden * k;
        out.push_back({r * std::cos(a), r * std::sin(a), z});
      }
    }
    return out;
  }();
  return dirs;
}

template <int D>
Eigen::Matrix<double, D, D> randomRotation(Rng& rng) {
  if constexpr (D == 2) {
    return Eigen::Rotation2Dd(rng.uniform(0.0, 2.0 * std::numbers::pi)).toRotationMatrix();
  } else {
    // A uniformly random unit quaternion (normalised 4D Gaussian).
    Eigen::Quaterniond q(rng.normal(), rng.normal(), rng.normal(), rng.normal());
    q.normalize();
    return q.toRotationMatrix();
  }
}

// Lattice sites of a close packing of spheres of diameter s: hexagonal (2D), face-centred
// cubic (3D), shifted by a random fraction of a cell, within radius `reach`.
template <int D>
std::vector<Vec<D>> closePackedSites(double s, double reach, Rng& rng) {
  std::vector<Vec<D>> sites;
  if constexpr (D == 2) {
    const Eigen::Vector2d e1(s, 0.0), e2(0.5 * s, 0.5 * std::sqrt(3.0) * s);
    const Eigen::Vector2d shift = rng.uniform() * e1 + rng.uniform() * e2;
    const int n = static_cast<int>(std::ceil(reach / (0.5 * s))) + 2;
    for (int i = -n; i <= n; ++i) {
      for (int j = -n; j <= n; ++j) {
        const Eigen::Vector2d p = i * e1 + j * e2 + shift;
        if (p.norm() <= reach) sites.push_back(p);
      }
    }
  } else {
    const double a = s * std::sqrt(2.0);  // cube edge of the FCC cell
    const Eigen::Vector3d basis[4] = {
        {0, 0, 0}, {0.5 * a, 0.5 * a, 0}, {0.5 * a, 0, 0.5 * a}, {0, 0.5 * a, 0.5 * a}};
    const Eigen::Vector3d shift(rng.uniform() * a, rng.uniform() * a, rng.uniform() * a);
    const int n = static_cast<int>(std::ceil(reach / a)) + 1;
    for (int i = -n; i <= n; ++i) {
      for (int j = -n; j <= n; ++j) {
        for (int k = -n; k <= n; ++k) {
          for (const auto& b : basis) {
            const Eigen::Vector3d p = Eigen::Vector3d(i, j, k) * a + b + shift;
            if (p.norm() <= reach) sites.push_back(p);
          }
        }
      }
    }
  }
  return sites;
}

// Whether the pebbles form one chain of touching neighbours (spacing s).
template <int D>
bool connected(const std::vector<Vec<D>>& p, double s) {
  std::vector<std::uint8_t> seen(p.size(), 0);
  std::vector<std::size_t> stack{0};
  seen[0] = 1;
  std::size_t count = 1;
  while (!stack.empty()) {
    const std::size_t a = stack.back();
    stack.pop_back();
    for (std::size_t b = 0; b < p.size(); ++b) {
      if (!seen[b] && (p[a] - p[b]).norm() <= s * (1.0 + 1e-9)) {
        seen[b] = 1;
        ++count;
        stack.push_back(b);
      }
    }
  }
  return count == p.size();
}

}  // namespace

template <int D>
double feretAspectRatio(const ClumpShape<D>& shape) {
  double longest = 0.0, shortest = INFINITY;
  for (const Vec<D>& u : caliperDirections<D>()) {
    double lo = INFINITY, hi = -INFINITY;
    for (std::size_t k = 0; k < shape.centers.size(); ++k) {
      const double x = shape.centers[k].dot(u);
      lo = std::min(lo, x - shape.radii[k]);
      hi = std::max(hi, x + shape.radii[k]);
    }
    longest = std::max(longest, hi - lo);
    shortest = std::min(shortest, hi - lo);
  }
  return longest / shortest;
}

template <int D>
ClumpShape<D> makeGrainShape(double length, const GrainShapeSpec& spec, Rng& rng) {
  const std::string where = "grain shape";
  checkFields(spec, where);
  requireRange(where, "length", length, 0.0, true, INFINITY, true, "m");
  const double rp = length / (2.0 * spec.pebbles_across), s = 2.0 * rp;
  const double reach = 0.5 * length - rp;  // pebble centres within: calipers <= length
  const std::vector<Vec<D>> dirs = [&] {
    std::vector<Vec<D>> d;
    for (int m = 0; m < 4; ++m) {
      Vec<D> v;
      for (int k = 0; k < D; ++k) v[k] = rng.normal();
      d.push_back(v.normalized());
    }
    return d;
  }();
  for (int attempt = 0; attempt < 500; ++attempt) {
    // An ellipse (ellipsoid) of random elongation below the limit, with a smooth random
    // perturbation of its outline: harmonics 2-4 (2D) or four random quadrupoles (3D).
    const double ar = rng.uniform(1.0, spec.max_aspect_ratio);
    Vec<D> axes;
    axes[0] = reach + 0.5 * rp;  // half a pebble of slack keeps the end pebbles
    axes[1] = axes[0] / ar;
    if constexpr (D == 3) axes[2] = axes[0] / rng.uniform(1.0, ar);
    double amp[4], phase[4];
    for (int m = 0; m < 4; ++m) {
      amp[m] = spec.roughness * rng.normal() / 2.0;
      phase[m] = rng.uniform(0.0, 2.0 * std::numbers::pi);
    }
    auto inside = [&](const Vec<D>& p) {
      const Vec<D> u = p.cwiseQuotient(axes);
      const double rho = u.norm();
      if (rho == 0.0) return true;
      double noise = 0.0;
      if constexpr (D == 2) {
        const double theta = std::atan2(u.y(), u.x());
        for (int m = 0; m < 3; ++m) noise += amp[m] * std::cos((m + 2) * theta + phase[m]);
      } else {
        for (int m = 0; m < 4; ++m) {
          const double c = u.dot(dirs[m]) / rho;
          noise += amp[m] * (c * c - 1.0 / 3.0);
        }
      }
      return rho <= 1.0 + noise && p.norm() <= reach;
    };
    std::vector<Vec<D>> kept;
    for (const Vec<D>& p : closePackedSites<D>(s, reach, rng)) {
      if (inside(p)) kept.push_back(p);
    }
    if (kept.size() < 3 || !connected<D>(kept, s)) continue;
    const Eigen::Matrix<double, D, D> R = randomRotation<D>(rng);
    Vec<D> mean = Vec<D>::Zero();
    for (const auto& p : kept) mean += p;
    mean /= static_cast<double>(kept.size());
    ClumpShape<D> shape;
    for (const auto& p : kept) {
      shape.centers.push_back(R * (p - mean));
      shape.radii.push_back(rp);
    }
    if (feretAspectRatio<D>(shape) < spec.max_aspect_ratio) return shape;
  }
  // No shape fits: the lattice of so few pebbles cannot be that round.
  throw InvalidParameter(where, "max_aspect_ratio", spec.max_aspect_ratio,
                         "reachable with " + std::to_string(spec.pebbles_across) +
                             " pebbles across (no grain found in 500 tries; raise it)",
                         "-");
}

template <int D>
GrainPacking<D> generateGrainPacking(const GrainPackingSpec& spec, PackingReport* report) {
  const std::string where = "grain packing";
  checkFields(spec.sizes, "size distribution");
  requireRange(where, "grains", static_cast<double>(spec.grains), 1, false, 1e7, false, "grains");
  requireRange(where, "porosity", spec.porosity, 0.0, true, 1.0, true, "-");
  requireRange(where, "thickness", spec.thickness, 0.0, true, INFINITY, true, "m");
  for (int d = 0; d < D; ++d) {
    requireRange(where, "aspect", spec.aspect[d], 0.0, true, INFINITY, true, "-");
  }
  Rng rng(spec.seed);
  GrainPacking<D> out;
  out.pebbles.thickness = spec.thickness;
  std::vector<double> lengths(spec.grains);
  for (double& l : lengths) l = spec.sizes.sample(rng);
  std::sort(lengths.begin(), lengths.end(), std::greater<>());
  std::vector<ClumpShape<D>> shapes;
  std::vector<double> bound;  // radius of the sphere about the centroid holding the grain
  double solid = 0.0, r_mean = 0.0;
  std::size_t pebbles = 0;
  for (const double l : lengths) {
    shapes.push_back(makeGrainShape<D>(l, spec.shape, rng));
    const auto& g = shapes.back();
    double b = 0.0;
    for (std::size_t k = 0; k < g.centers.size(); ++k) {
      b = std::max(b, g.centers[k].norm() + g.radii[k]);
      solid += particleVolume<D>(g.radii[k], spec.thickness);  // pebbles do not overlap
      r_mean += g.radii[k];
    }
    pebbles += g.centers.size();
    bound.push_back(b);
    out.grain_length.push_back(l);
    out.grain_aspect_ratio.push_back(feretAspectRatio<D>(g));
  }
  r_mean /= static_cast<double>(pebbles);

  const double box_volume = solid / (1.0 - spec.porosity);
  const double extent = D == 2 ? box_volume / spec.thickness : box_volume;
  double aspect_prod = 1.0;
  for (int d = 0; d < D; ++d) aspect_prod *= spec.aspect[d];
  const double edge = std::pow(extent / aspect_prod, 1.0 / D);
  for (int d = 0; d < D; ++d) out.pebbles.hi[d] = spec.aspect[d] * edge;

  // Place the bounding spheres at a reduced size where random placement succeeds easily.
  double bound_volume = 0.0;
  for (double b : bound) bound_volume += particleVolume<D>(b, spec.thickness);
  const double start_fraction = D == 3 ? 0.25 : 0.40;
  const double s0 = std::min(1.0, std::pow(start_fraction * box_volume / bound_volume, 1.0 / D));
  std::vector<double> r0(bound);
  for (double& r : r0) r *= s0;
  const std::vector<Vec<D>> x0 = placeRandomly<D>(r0, out.pebbles.lo, out.pebbles.hi, rng);

  // Growth as in generatePacking, here of rigid clumps, so that the grains keep their shapes.
  Simulation<D> sim =
      expansionScene<D>(r_mean, spec.thickness, 0.0, spec.threads, out.pebbles.lo, out.pebbles.hi);
  for (std::size_t g = 0; g < shapes.size(); ++g) {
    std::vector<ParticleId> ids;
    for (std::size_t k = 0; k < shapes[g].centers.size(); ++k) {
      ParticleSpec<D> p;
      p.position = x0[g] + s0 * shapes[g].centers[k];
      p.radius = s0 * shapes[g].radii[k];
      p.density = kExpansionDensity;
      p.cluster = static_cast<std::uint32_t>(g);
      ids.push_back(sim.particles().add(p));
    }
    sim.addClump(ids, 0.0, 16);  // inertia only steers the packing: coarse is enough
  }
  growAndRelax<D>(sim, s0, spec.progress, {});

  // Pebbles in slot order (grain by grain), at their exact sizes.
  const auto& P = sim.particles();
  out.pebbles.centers.resize(P.size());
  out.pebbles.radii.resize(P.size());
  out.grain.resize(P.size());
  std::size_t slot = 0;
  for (std::size_t g = 0; g < shapes.size(); ++g) {
    for (std::size_t k = 0; k < shapes[g].centers.size(); ++k, ++slot) {
      const std::size_t i = P.indexOfSlot(static_cast<std::uint32_t>(slot));
      out.pebbles.centers[slot] = P.pos[i];
      out.pebbles.radii[slot] = shapes[g].radii[k];
      out.grain[slot] = static_cast<std::uint32_t>(g);
    }
  }
  if (report) {
    report->steps = sim.steps();
    report->max_overlap = sim.maxOverlapRatio();
    report->coordination = sim.coordinationNumber();
    report->unbalanced = sim.unbalancedForceRatio();
  }
  return out;
}

template <int D>
std::vector<std::uint32_t> grainFragments(const ParticleStore<D>& P, const BondStore<D>& bonds,
                                          const std::vector<BondKind>& kinds) {
  const std::size_t n = P.size();
  std::vector<std::uint32_t> parent(n);
  std::iota(parent.begin(), parent.end(), 0u);
  auto root = [&](std::uint32_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  for (std::size_t b = 0; b < bonds.size(); ++b) {
    if (!kinds.at(bonds.kind[b]).intragranular || !bonds.intact(b)) continue;
    const std::uint32_t a = root(bonds.i[b]), c = root(bonds.j[b]);
    if (a != c) parent[std::max(a, c)] = std::min(a, c);
  }
  std::uint32_t grains = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (P.cluster[i] != kNoCluster) grains = std::max(grains, P.cluster[i] + 1);
  }
  std::vector<std::uint32_t> fragments(grains, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (P.cluster[i] != kNoCluster && root(static_cast<std::uint32_t>(i)) == i) {
      ++fragments[P.cluster[i]];
    }
  }
  return fragments;
}

std::size_t crushedGrains(const std::vector<std::uint32_t>& reference,
                          const std::vector<std::uint32_t>& now) {
  std::size_t crushed = 0;
  for (std::size_t g = 0; g < std::min(reference.size(), now.size()); ++g) {
    crushed += now[g] > reference[g];
  }
  return crushed;
}

template double feretAspectRatio<2>(const ClumpShape<2>&);
template double feretAspectRatio<3>(const ClumpShape<3>&);
template ClumpShape<2> makeGrainShape<2>(double, const GrainShapeSpec&, Rng&);
template ClumpShape<3> makeGrainShape<3>(double, const GrainShapeSpec&, Rng&);
template GrainPacking<2> generateGrainPacking<2>(const GrainPackingSpec&, PackingReport*);
template GrainPacking<3> generateGrainPacking<3>(const GrainPackingSpec&, PackingReport*);
template std::vector<std::uint32_t> grainFragments<2>(const ParticleStore<2>&, const BondStore<2>&,
                                                      const std::vector<BondKind>&);
template std::vector<std::uint32_t> grainFragments<3>(const ParticleStore<3>&, const BondStore<3>&,
                                                      const std::vector<BondKind>&);

}  // namespace rocklab
