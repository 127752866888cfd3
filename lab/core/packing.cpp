#include "lab/core/packing.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "lab/core/errors.hpp"
#include "lab/core/simulation.hpp"

namespace rocklab {

SizeDistribution SizeDistribution::uniform(double d_min, double d_max) {
  SizeDistribution s;
  s.kind = Kind::Uniform;
  s.d_min = d_min;
  s.d_max = d_max;
  return s;
}

SizeDistribution SizeDistribution::normal(double mean, double std, double d_min, double d_max) {
  SizeDistribution s;
  s.kind = Kind::Normal;
  s.d_mean = mean;
  s.d_std = std;
  s.d_min = d_min;
  s.d_max = d_max;
  return s;
}

SizeDistribution SizeDistribution::phiGaussian(double phi_mean, double phi_std, double d_min,
                                               double d_max) {
  SizeDistribution s;
  s.kind = Kind::PhiGaussian;
  s.phi_mean = phi_mean;
  s.phi_std = phi_std;
  s.d_min = d_min;
  s.d_max = d_max;
  return s;
}

void SizeDistribution::validate() const {
  auto mm = [](double d) { return Range::formatNumber(d / kmm); };
  if (d_max < d_min) {
    throw InvalidParameter("", "d_max_mm", d_max / kmm, "[d_min_mm = " + mm(d_min) + ", 10000]",
                           "mm");
  }
  const std::string bounds = "[" + mm(d_min) + ", " + mm(d_max) + "]";
  if (kind == Kind::Normal && (d_mean < d_min || d_mean > d_max)) {
    throw InvalidParameter("", "d_mean_mm", d_mean / kmm, bounds + " (d_min_mm, d_max_mm)", "mm");
  }
  const double phi_lo = phiOfDiameter(d_max), phi_hi = phiOfDiameter(d_min);
  if (kind == Kind::PhiGaussian && (phi_mean < phi_lo || phi_mean > phi_hi)) {
    // The mean diameter 2^-phi_mean mm must lie within the bounds.
    throw InvalidParameter("", "phi_mean", phi_mean,
                           "[" + Range::formatNumber(phi_lo) + ", " + Range::formatNumber(phi_hi) +
                               "] (the phi of d_max_mm and d_min_mm)",
                           "phi");
  }
}

double SizeDistribution::sample(Rng& rng) const {
  if (kind == Kind::Uniform) return rng.uniform(d_min, d_max);
  // Truncation by redrawing; the validated mean lies inside the bounds, so at least a
  // good fraction of draws is accepted.
  for (int tries = 0; tries < 100000; ++tries) {
    const double d = kind == Kind::Normal ? rng.normal(d_mean, d_std)
                                          : diameterOfPhi(rng.normal(phi_mean, phi_std));
    if (d >= d_min && d <= d_max) return d;
  }
  throw std::runtime_error("size distribution: no draw fell inside [d_min, d_max]");
}

std::string SizeDistribution::describe() const {
  std::ostringstream s;
  switch (kind) {
    case Kind::Uniform:
      s << "uniform d in [" << d_min << ", " << d_max << "] m";
      break;
    case Kind::Normal:
      s << "normal d: mean " << d_mean << " m, std " << d_std << " m, truncated to [" << d_min
        << ", " << d_max << "] m";
      break;
    case Kind::PhiGaussian:
      s << "Gaussian in phi: mean " << phi_mean << ", std " << phi_std << " (d = 2^-phi mm), "
        << "truncated to [" << d_min << ", " << d_max << "] m";
      break;
  }
  return s.str();
}

template <int D>
double Packing<D>::boxVolume() const {
  double v = (hi - lo).prod();
  return D == 2 ? v * thickness : v;
}

template <int D>
double Packing<D>::solidVolume() const {
  double v = 0.0;
  for (double r : radii) v += particleVolume<D>(r, thickness);
  return v;
}

template <int D>
std::vector<Vec<D>> placeRandomly(const std::vector<double>& r, const Vec<D>& lo, const Vec<D>& hi,
                                  Rng& rng) {
  const double rmax = *std::max_element(r.begin(), r.end());
  double cell = 2.0 * rmax;
  std::array<int, D> dims;
  std::size_t cells = 1;
  for (;;) {
    cells = 1;
    for (int d = 0; d < D; ++d) {
      dims[d] = std::max(1, static_cast<int>((hi[d] - lo[d]) / cell));
      cells *= static_cast<std::size_t>(dims[d]);
    }
    if (cells <= 4 * r.size() + 64) break;
    cell *= 1.26;
  }
  auto cellOf = [&](const Vec<D>& x) {
    std::array<int, D> c;
    for (int d = 0; d < D; ++d) {
      c[d] = std::clamp(static_cast<int>((x[d] - lo[d]) / cell), 0, dims[d] - 1);
    }
    return c;
  };
  auto linear = [&](const std::array<int, D>& c) {
    std::size_t k = static_cast<std::size_t>(c[D - 1]);
    for (int d = D - 2; d >= 0; --d) k = k * static_cast<std::size_t>(dims[d]) + c[d];
    return k;
  };
  std::vector<std::vector<std::uint32_t>> grid(cells);
  std::vector<Vec<D>> x(r.size());
  for (std::size_t i = 0; i < r.size(); ++i) {
    Vec<D> best = Vec<D>::Zero();
    double best_overlap = INFINITY;
    for (int attempt = 0; attempt < 300 && best_overlap > 0.0; ++attempt) {
      Vec<D> p;
      for (int d = 0; d < D; ++d) {
        const double a = lo[d] + r[i], b = hi[d] - r[i];
        p[d] = a < b ? rng.uniform(a, b) : 0.5 * (lo[d] + hi[d]);
      }
      // The deepest overlap with what is placed (<= 0: free).
      double worst = -INFINITY;
      const auto c0 = cellOf(p - Vec<D>::Constant(r[i] + rmax));
      const auto c1 = cellOf(p + Vec<D>::Constant(r[i] + rmax));
      std::array<int, D> k = c0;
      for (;;) {
        for (std::uint32_t j : grid[linear(k)]) {
          worst = std::max(worst, r[i] + r[j] - (x[j] - p).norm());
        }
        int d = 0;
        while (d < D && ++k[d] > c1[d]) k[d] = c0[d], ++d;
        if (d == D) break;
      }
      if (worst < best_overlap) best = p, best_overlap = worst;
    }
    x[i] = best;
    grid[linear(cellOf(best))].push_back(static_cast<std::uint32_t>(i));
  }
  return x;
}

template <int D>
Simulation<D> expansionScene(double r_mean, double thickness, double friction, int threads,
                             const Vec<D>& lo, const Vec<D>& hi) {
  // A soft linear-spring scene: the result is geometric, and a soft spring gives a long
  // time step. Overlap per growth step relative to the radius is set by the growth rate,
  // not by the stiffness.
  Material m;
  m.name = "expansion";
  m.modulus = 0.0;  // springs only
  m.kn = 1e8 * (D == 3 ? r_mean : thickness);
  m.ks = 0.5 * m.kn;
  m.friction = friction;
  m.damping_ratio = 0.2;
  m.density = kExpansionDensity;
  MaterialTable mats;
  mats.add(m);
  SimulationConfig cfg;
  cfg.contact_law = "linear";
  cfg.skin_ratio = 0.1;
  cfg.local_damping = 0.7;
  cfg.threads = threads;
  cfg.track_energy = false;
  cfg.guard.overlap_limit = 0.95;    // random placement may start with deep overlaps
  cfg.guard.energy_runaway = false;  // growth pumps in energy that no ledger sees
  Simulation<D> sim(mats, cfg);
  sim.particles().thickness = thickness;
  for (int d = 0; d < D; ++d) {
    Wall<D> lo_wall, hi_wall;
    lo_wall.name = std::string(1, "xyz"[d]) + "min";
    hi_wall.name = std::string(1, "xyz"[d]) + "max";
    lo_wall.normal = Vec<D>::Unit(d);
    lo_wall.point = lo;
    hi_wall.normal = -Vec<D>::Unit(d);
    hi_wall.point = hi;
    sim.addWall(lo_wall);
    sim.addWall(hi_wall);
  }
  return sim;
}

template <int D>
void growAndRelax(Simulation<D>& sim, double s0, const std::function<void(double)>& progress,
                  const std::function<void()>& after_growth) {
  // Grow by at most 2e-4 of the radius per step.
  const double growth = std::log(1.0 / s0);
  const auto grow_steps = static_cast<std::uint64_t>(std::max(500.0, std::ceil(growth / 2e-4)));
  const double factor = std::exp(growth / static_cast<double>(grow_steps));
  for (std::uint64_t k = 0; k < grow_steps; ++k) {
    sim.scaleRadii(factor);
    sim.step();
    if (progress && k % 100 == 0) progress(0.5 * static_cast<double>(k) / grow_steps);
  }
  if (after_growth) {
    after_growth();
    sim.invalidateNeighbors();
  }
  // Relax until the overlaps left by growth are gone (a loose target) or the packing is
  // in equilibrium (a target beyond jamming, where overlaps must stay).
  const std::uint64_t relax_max = 40000;
  for (std::uint64_t k = 0; k < relax_max; k += 100) {
    sim.run(100);
    if (progress) progress(0.5 + 0.5 * static_cast<double>(k) / relax_max);
    if (sim.maxOverlapRatio() < 1e-3 || sim.unbalancedForceRatio() < 1e-3) break;
  }
}

template <int D>
Packing<D> generatePacking(const PackingSpec& spec, PackingReport* report) {
  const std::string where = "packing";
  checkFields(spec, where);
  requireRange(where, "friction", spec.friction, 0.0, false, INFINITY, true, "-");
  for (int d = 0; d < D; ++d) {
    requireRange(where, "aspect", spec.aspect[d], 0.0, true, INFINITY, true, "-");
  }

  Rng rng(spec.seed);
  Packing<D> out;
  out.thickness = spec.thickness;
  out.radii.resize(spec.count);
  for (double& r : out.radii) r = 0.5 * spec.sizes.sample(rng);
  std::sort(out.radii.begin(), out.radii.end(), std::greater<>());

  // The box holding the particles at the target porosity.
  const double box_volume = out.solidVolume() / (1.0 - spec.porosity);
  const double extent = D == 2 ? box_volume / spec.thickness : box_volume;
  double aspect_prod = 1.0;
  for (int d = 0; d < D; ++d) aspect_prod *= spec.aspect[d];
  const double s = std::pow(extent / aspect_prod, 1.0 / D);
  for (int d = 0; d < D; ++d) out.hi[d] = spec.aspect[d] * s;

  // Place at a reduced size where random placement succeeds easily (solid fraction 0.25 in
  // 3D, 0.4 in 2D, well below the random sequential limits of 0.38 and 0.55), counted in
  // the region centres can reach: in a small box the walls keep centres a radius away.
  const double solid = 1.0 - spec.porosity;
  const double start_fraction = D == 3 ? 0.25 : 0.40;
  const double r_mean =
      std::accumulate(out.radii.begin(), out.radii.end(), 0.0) / static_cast<double>(spec.count);
  double s0 = std::min(1.0, std::pow(start_fraction / solid, 1.0 / D));
  for (;;) {
    double reachable = 1.0;
    for (int d = 0; d < D; ++d) reachable *= std::max(0.0, 1.0 - 2.0 * s0 * r_mean / out.hi[d]);
    if (s0 < 0.2 || solid * std::pow(s0, D) <= start_fraction * reachable) break;
    s0 *= 0.98;
  }
  std::vector<double> r0(out.radii);
  for (double& r : r0) r *= s0;
  const std::vector<Vec<D>> x0 = placeRandomly<D>(r0, out.lo, out.hi, rng);

  Simulation<D> sim =
      expansionScene<D>(r_mean, spec.thickness, spec.friction, spec.threads, out.lo, out.hi);
  for (std::size_t i = 0; i < spec.count; ++i) {
    ParticleSpec<D> p;
    p.position = x0[i];
    p.radius = r0[i];
    p.density = kExpansionDensity;
    sim.particles().add(p);
  }
  auto& P = sim.particles();
  growAndRelax<D>(sim, s0, spec.progress, [&] {
    for (std::size_t i = 0; i < P.size(); ++i) P.radius[i] = out.radii[P.slot_of[i]];
  });

  out.centers.resize(spec.count);
  for (std::size_t i = 0; i < P.size(); ++i) out.centers[P.slot_of[i]] = P.pos[i];
  if (report) {
    report->steps = sim.steps();
    report->max_overlap = sim.maxOverlapRatio();
    report->coordination = sim.coordinationNumber();
    report->unbalanced = sim.unbalancedForceRatio();
  }
  return out;
}

template struct Packing<2>;
template struct Packing<3>;
template std::vector<Vec<2>> placeRandomly<2>(const std::vector<double>&, const Vec<2>&,
                                              const Vec<2>&, Rng&);
template std::vector<Vec<3>> placeRandomly<3>(const std::vector<double>&, const Vec<3>&,
                                              const Vec<3>&, Rng&);
template Simulation<2> expansionScene<2>(double, double, double, int, const Vec<2>&, const Vec<2>&);
template Simulation<3> expansionScene<3>(double, double, double, int, const Vec<3>&, const Vec<3>&);
template void growAndRelax<2>(Simulation<2>&, double, const std::function<void(double)>&,
                              const std::function<void()>&);
template void growAndRelax<3>(Simulation<3>&, double, const std::function<void(double)>&,
                              const std::function<void()>&);
template Packing<2> generatePacking<2>(const PackingSpec&, PackingReport*);
template Packing<3> generatePacking<3>(const PackingSpec&, PackingReport*);

}  // namespace rocklab
