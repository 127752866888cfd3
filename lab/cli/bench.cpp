#include "lab/cli/bench.hpp"

#include <chrono>
#include <cmath>
#include <iomanip>
#include <numbers>
#include <ostream>
#include <stdexcept>

#include <sys/resource.h>

#include <algorithm>

#include "lab/core/frame.hpp"
#include "lab/core/simulation.hpp"
#include "lab/flow/coupling.hpp"
#include "reports/snapshot.hpp"

namespace rocklab {

namespace {

// The scene of data/peers/README.md.
constexpr double kYoung = 70e9;  // Pa
constexpr double kPoisson = 0.25;
constexpr double kDensity = 2650.0;  // kg/m^3
constexpr double kFriction = 0.5;    // particle-particle; walls are frictionless
constexpr double kRestitution = 0.5;
constexpr double kTimeStep = 1.9e-7;  // s, 20% of the Rayleigh time of r = 0.9 mm
constexpr double kStrainRate = 1.0;   // 1/s, each wall moves in at edot * L / 2
// The bonded variant: PFC-like cement stiff enough to matter (E 10 GPa, lambda 1) and too
// strong to break in the timed phase, so it measures the bonds' force pass alone.
constexpr double kBondModulus = 10e9;   // Pa
constexpr double kBondStrength = 1e11;  // Pa

// The damping ratio that gives restitution e for a linear dashpot; with Tsuji's Hertz
// dashpot the peers use the same beta (LIGGGHTS and Yade).
double dampingRatio(double e) {
  const double l = std::log(e);
  return -l / std::sqrt(l * l + std::numbers::pi * std::numbers::pi);
}

Simulation<3> makeScene(const Packing<3>& p, double friction, const SimulationConfig& cfg) {
  Material sphere;
  sphere.name = "sphere";
  sphere.density = kDensity;
  sphere.young = kYoung;
  sphere.poisson = kPoisson;
  sphere.friction = friction;
  sphere.damping_ratio = dampingRatio(kRestitution);
  Material wall = sphere;
  wall.name = "wall";
  wall.friction = 0.0;
  MaterialTable mats;
  mats.add(sphere);
  const auto wall_material = mats.add(wall);
  Simulation<3> sim(mats, cfg);
  for (std::size_t i = 0; i < p.centers.size(); ++i) {
    ParticleSpec<3> s;
    s.position = p.centers[i];
    s.radius = p.radii[i];
    s.density = kDensity;
    sim.particles().add(s);
  }
  for (int d = 0; d < 3; ++d) {
    Wall<3> lo, hi;
    lo.name = std::string(1, "xyz"[d]) + "min";
    hi.name = std::string(1, "xyz"[d]) + "max";
    lo.normal = Eigen::Vector3d::Unit(d);
    lo.point = p.lo;
    hi.normal = -Eigen::Vector3d::Unit(d);
    hi.point = p.hi;
    lo.material = hi.material = wall_material;
    sim.addWall(lo);
    sim.addWall(hi);
  }
  return sim;
}

// Box extents from the six walls (xmin, xmax, ymin, ymax, zmin, zmax in that order).
Eigen::Vector3d boxExtent(const Simulation<3>& sim) {
  Eigen::Vector3d e;
  for (int d = 0; d < 3; ++d) e[d] = sim.wall(2 * d + 1).point[d] - sim.wall(2 * d).point[d];
  return e;
}

double faceArea(const Eigen::Vector3d& extent, int axis) {
  return extent[(axis + 1) % 3] * extent[(axis + 2) % 3];
}

double meanWallStress(const Simulation<3>& sim) {
  const Eigen::Vector3d e = boxExtent(sim);
  double s = 0.0;
  for (int w = 0; w < 6; ++w) s += sim.wall(w).normalStress(faceArea(e, w / 2));
  return s / 6.0;
}

}  // namespace

Packing<3> benchPacking(std::size_t n, std::uint64_t seed, int threads) {
  PackingSpec spec;
  spec.count = n;
  spec.sizes = SizeDistribution::uniform(1.8e-3, 2.2e-3);
  spec.porosity = 0.5;  // loose: no contact forces yet, whatever the box size
  spec.seed = seed;
  spec.threads = threads;
  const Packing<3> loose = generatePacking<3>(spec);

  // Servo all six walls to 1 MPa with friction 0.1 (the peers' preparation).
  SimulationConfig cfg;
  cfg.contact_law = "hertz";
  cfg.skin_ratio = 0.1;
  cfg.local_damping = 0.4;
  cfg.threads = threads;
  cfg.track_energy = false;
  Simulation<3> sim = makeScene(loose, 0.1, cfg);
  constexpr double kTarget = 1e6;
  const double max_speed = 1e-3 * 0.9e-3 / kTimeStep;
  for (int w = 0; w < 6; ++w) {
    ServoControl& s = sim.wall(w).servo;
    s.enabled = true;
    s.target_stress = kTarget;
    s.alpha = 0.3;
    s.max_speed = max_speed;
    s.area = faceArea(boxExtent(sim), w / 2);
  }
  bool settled = false;
  for (int k = 0; k < 200000 && !settled; ++k) {
    const Eigen::Vector3d e = boxExtent(sim);
    for (int w = 0; w < 6; ++w) sim.wall(w).servo.area = faceArea(e, w / 2);
    sim.step();
    if (k % 200 == 199) {
      settled = sim.unbalancedForceRatio() < 0.01;
      for (int w = 0; w < 6; ++w) {
        settled &= std::abs(sim.wall(w).normalStress(faceArea(e, w / 2)) / kTarget - 1.0) < 0.02;
      }
    }
  }
  if (!settled) {
    throw std::runtime_error(
        "the generated benchmark packing did not settle at 1 MPa in 200000 "
        "steps; pass a packing file with --packing");
  }
  Packing<3> dense;
  for (int d = 0; d < 3; ++d) {
    dense.lo[d] = sim.wall(2 * d).point[d];
    dense.hi[d] = sim.wall(2 * d + 1).point[d];
  }
  const auto& P = sim.particles();
  dense.centers.resize(P.size());
  dense.radii.resize(P.size());
  for (std::size_t i = 0; i < P.size(); ++i) {
    dense.centers[P.slot_of[i]] = P.pos[i];
    dense.radii[P.slot_of[i]] = P.radius[i];
  }
  return dense;
}

Packing<3> tilePacking(const Packing<3>& packing, const std::array<int, 3>& tile) {
  if (tile == std::array<int, 3>{1, 1, 1}) return packing;
  const Eigen::Vector3d size = packing.hi - packing.lo;
  Packing<3> out;
  out.lo = packing.lo;
  out.hi = packing.lo;
  for (int d = 0; d < 3; ++d) {
    if (tile[d] < 1) throw std::invalid_argument("--tile: every count must be at least 1");
    out.hi[d] += tile[d] * size[d];
  }
  const std::size_t copies = static_cast<std::size_t>(tile[0]) * tile[1] * tile[2];
  out.centers.reserve(copies * packing.centers.size());
  out.radii.reserve(copies * packing.radii.size());
  for (int z = 0; z < tile[2]; ++z) {
    for (int y = 0; y < tile[1]; ++y) {
      for (int x = 0; x < tile[0]; ++x) {
        const std::array<int, 3> k{x, y, z};
        for (std::size_t i = 0; i < packing.centers.size(); ++i) {
          Eigen::Vector3d c = packing.centers[i] - packing.lo;
          for (int d = 0; d < 3; ++d) {
            if (k[d] % 2 == 1) c[d] = size[d] - c[d];  // mirrored: see the header
            c[d] += packing.lo[d] + k[d] * size[d];
          }
          out.centers.push_back(c);
          out.radii.push_back(packing.radii[i]);
        }
      }
    }
  }
  return out;
}

double peakRssBytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return 1024.0 * static_cast<double>(u.ru_maxrss);  // Linux reports KiB
}

BenchResult runBench(const Packing<3>& packing, const BenchOptions& options, int threads) {
  SimulationConfig cfg;
  cfg.contact_law = "hertz";
  cfg.skin = options.skin;
  cfg.local_damping = 0.0;  // the peers' scene: contact dashpots only
  cfg.timestep.automatic = false;
  cfg.timestep.fixed_dt = kTimeStep;
  cfg.threads = threads;
  cfg.track_energy = options.energy;
  cfg.bond_lane_width = options.scalar_bonds ? 0 : 8;
  Simulation<3> sim = makeScene(packing, kFriction, cfg);
  BenchResult r;
  if (options.bonded) {
    // Cement the sample once its particles are in the cell grid's order (the first neighbour
    // build sorts them), as a protocol cements a formed sample: the bonds are installed
    // particle by particle, so the bond pass walks the particle arrays in order. Cemented
    // straight from the packing file's order, the bonds kept that random order after the
    // sort, and at 50,000 spheres the pass waited on the cache for a third of its time.
    sim.prepare();
    BondKind cement;
    cement.modulus = kBondModulus;
    cement.stiffness_ratio = 1.0;
    cement.tensile_mean = cement.shear_mean = kBondStrength;
    cement.tensile_std = cement.shear_std = 0.0;
    if (options.bond_model == "flat_joint") cement.model = BondModel::FlatJoint;
    r.flat_joints = cement.model == BondModel::FlatJoint;
    r.bonds = sim.cement(sim.addBondKind(cement), 0.0).installed;
    r.bond_lane_width = bondLaneWidth(cfg.bond_lane_width);
  }
  const Eigen::Vector3d extent = boxExtent(sim);
  for (int w = 0; w < 6; ++w) {
    sim.wall(w).velocity = kStrainRate * extent[w / 2] / 2.0 * sim.wall(w).normal;
  }
  sim.run(options.warmup);

  r.threads = threads;
  r.particles = sim.particles().size();
  r.steps = options.steps;
  r.coordination_start = sim.coordinationNumber();
  r.wall_stress_start = meanWallStress(sim);
  const std::uint64_t rebuilds = sim.contacts().rebuilds;
  const std::vector<StageTiming> before = sim.stageTimings();
  const auto t0 = std::chrono::steady_clock::now();
  sim.run(options.steps);
  const auto t1 = std::chrono::steady_clock::now();
  r.stages = sim.stageTimings();
  for (StageTiming& s : r.stages) {
    for (const StageTiming& b : before) {
      if (b.name != s.name) continue;
      s.seconds -= b.seconds;
      s.calls -= b.calls;
    }
  }
  r.seconds = std::chrono::duration<double>(t1 - t0).count();
  r.particle_steps_per_second =
      static_cast<double>(r.particles) * static_cast<double>(r.steps) / r.seconds;
  r.coordination_end = sim.coordinationNumber();
  r.wall_stress_end = meanWallStress(sim);
  r.rebuilds = sim.contacts().rebuilds - rebuilds;
  r.listed_pairs = sim.contacts().pairs.pairs();
  r.state_hash = sim.stateHash();
  r.peak_rss_bytes = peakRssBytes();
  return r;
}

namespace {

FlowCall flowCall(const flow::FlowReading& r) {
  FlowCall c;
  c.network_seconds = r.network_seconds;
  c.solve_seconds = r.solve.seconds;
  c.assembly_seconds = r.solve.assembly_seconds;
  c.analysis_seconds = r.solve.analysis_seconds;
  c.factorisation_seconds = r.solve.factorisation_seconds;
  c.iteration_seconds = r.solve.solve_seconds;
  c.path = flow::describe(r.solve.path);
  c.iterations = r.solve.iterations;
  c.permeability = r.permeability;
  return c;
}

}  // namespace

FlowBenchResult runFlowBench(const Packing<3>& packing, double strain) {
  SimulationConfig cfg;
  cfg.contact_law = "hertz";
  cfg.track_energy = false;
  const Simulation<3> sim = makeScene(packing, kFriction, cfg);
  flow::FlowSettings settings;
  settings.merge.small_pore_ratio = 0.0;  // as Yade's FlowEngine: every cell a pore
  flow::FlowCoupling<3> coupling{settings};
  const flow::FlowReading first = coupling.measure(sim);
  Packing<3> moved = packing;
  const double mid = 0.5 * (packing.lo[2] + packing.hi[2]);
  for (auto& x : moved.centers) x[2] = mid + (x[2] - mid) * (1.0 - strain);
  const flow::FlowReading repeat = coupling.measure(makeScene(moved, kFriction, cfg));
  FlowBenchResult r;
  r.particles = packing.centers.size();
  r.pores = first.pores;
  r.pipes = first.pipes;
  r.clusters = first.clusters;
  r.strain = strain;
  r.first = flowCall(first);
  r.repeat = flowCall(repeat);
  flow::ImplicitSettings fresh_settings = settings.implicit;
  fresh_settings.reuse_factor = false;
  const flow::SteadyFlow fresh =
      flow::solveImplicit(coupling.clusters(), settings.pressures, fresh_settings, {});
  r.fresh_solve_seconds = fresh.seconds;
  const double drop = settings.pressures.inlet - settings.pressures.outlet;
  for (std::size_t i = 0; i < fresh.pressure.size(); ++i) {
    r.repeat_max_difference = std::max(
        r.repeat_max_difference, std::abs(fresh.pressure[i] - repeat.solve.pressure[i]) / drop);
  }
  r.repeat_permeability_difference = std::abs(repeat.solve.inflow / fresh.inflow - 1.0);
  // Kozeny-Carman with the constant 180 (the peers' reference): k = d^2 n^3 / (180 (1-n)^2),
  // d the mean diameter, n the porosity of the box.
  double solid = 0.0, diameter = 0.0;
  for (double rad : packing.radii) {
    solid += 4.0 / 3.0 * std::numbers::pi * rad * rad * rad;
    diameter += 2.0 * rad;
  }
  diameter /= static_cast<double>(packing.radii.size());
  const Eigen::Vector3d e = packing.hi - packing.lo;
  const double n = 1.0 - solid / (e[0] * e[1] * e[2]);
  r.kozeny_carman = diameter * diameter * n * n * n / (180.0 * (1.0 - n) * (1.0 - n));
  r.peak_rss_bytes = peakRssBytes();
  return r;
}

RenderBenchResult runRenderBench(const Packing<3>& packing, const std::string& folder) {
  SimulationConfig cfg;
  cfg.contact_law = "hertz";
  cfg.track_energy = false;
  const Simulation<3> sim = makeScene(packing, kFriction, cfg);
  const Frame frame = captureFrame(sim);
  reports::FieldValues field;
  field.label = "height (mm)";
  field.lo = 1e3 * packing.lo[2];
  field.hi = 1e3 * packing.hi[2];
  for (const auto& x : frame.pos) field.values.push_back(1e3 * x[2]);
  RenderBenchResult r;
  r.particles = frame.size();
  const auto t0 = std::chrono::steady_clock::now();
  reports::renderView(frame, field, {}, "benchmark packing", folder + "/bench-view.png");
  const auto t1 = std::chrono::steady_clock::now();
  reports::renderSlice(frame, field, {}, "benchmark packing", folder + "/bench-slice.png");
  const auto t2 = std::chrono::steady_clock::now();
  r.view_seconds = std::chrono::duration<double>(t1 - t0).count();
  r.slice_seconds = std::chrono::duration<double>(t2 - t1).count();
  r.peak_rss_bytes = peakRssBytes();
  return r;
}

void printBench(std::ostream& out, const std::vector<BenchResult>& results,
                const std::vector<FlowBenchResult>& flow,
                const std::vector<RenderBenchResult>& render, bool json,
                const std::string& source) {
  if (json) {
    out << "{\n  \"scene\": \"peers standard (Hertz-Mindlin, 6 walls)\",\n  \"packing\": \""
        << source << "\",\n  \"time_step_s\": " << kTimeStep << ",\n  \"runs\": [\n";
    for (std::size_t k = 0; k < results.size(); ++k) {
      const BenchResult& r = results[k];
      out << "    {\"threads\": " << r.threads << ", \"particles\": " << r.particles
          << ", \"steps\": " << r.steps << ", \"seconds\": " << r.seconds
          << ", \"particle_steps_per_second\": " << r.particle_steps_per_second
          << ", \"coordination_start\": " << r.coordination_start
          << ", \"coordination_end\": " << r.coordination_end
          << ", \"wall_stress_start_Pa\": " << r.wall_stress_start
          << ", \"wall_stress_end_Pa\": " << r.wall_stress_end << ", \"rebuilds\": " << r.rebuilds
          << ", \"listed_pairs\": " << r.listed_pairs << ", \"bonds\": " << r.bonds
          << ", \"bond_lane_width\": " << r.bond_lane_width
          << ", \"flat_joints\": " << (r.flat_joints ? "true" : "false")
          << ", \"peak_rss_bytes\": " << r.peak_rss_bytes << ", \"stage_seconds\": {";
      for (std::size_t s = 0; s < r.stages.size(); ++s) {
        out << (s ? ", " : "") << "\"" << r.stages[s].name << "\": " << r.stages[s].seconds;
      }
      out << "}, \"state_hash\": \"" << std::hex << r.state_hash << std::dec << "\"}"
          << (k + 1 < results.size() ? "," : "") << "\n";
    }
    out << "  ]";
    auto call = [&](const FlowCall& c) {
      out << "{\"network_seconds\": " << c.network_seconds
          << ", \"solve_seconds\": " << c.solve_seconds
          << ", \"assembly_seconds\": " << c.assembly_seconds
          << ", \"analysis_seconds\": " << c.analysis_seconds
          << ", \"factorisation_seconds\": " << c.factorisation_seconds
          << ", \"iteration_seconds\": " << c.iteration_seconds << ", \"path\": \"" << c.path
          << "\", \"iterations\": " << c.iterations << ", \"permeability_m2\": " << c.permeability
          << "}";
    };
    for (const FlowBenchResult& f : flow) {
      out << ",\n  \"flow\": {\"particles\": " << f.particles << ", \"pores\": " << f.pores
          << ", \"pipes\": " << f.pipes << ", \"clusters\": " << f.clusters
          << ", \"strain\": " << f.strain << ", \"first\": ";
      call(f.first);
      out << ", \"repeat\": ";
      call(f.repeat);
      out << ", \"fresh_solve_seconds\": " << f.fresh_solve_seconds
          << ", \"repeat_max_difference\": " << f.repeat_max_difference
          << ", \"repeat_permeability_difference\": " << f.repeat_permeability_difference
          << ", \"kozeny_carman_m2\": " << f.kozeny_carman
          << ", \"peak_rss_bytes\": " << f.peak_rss_bytes << "}";
    }
    for (const RenderBenchResult& g : render) {
      out << ",\n  \"render\": {\"particles\": " << g.particles
          << ", \"view_seconds\": " << g.view_seconds << ", \"slice_seconds\": " << g.slice_seconds
          << ", \"peak_rss_bytes\": " << g.peak_rss_bytes << "}";
    }
    out << "\n}\n";
    return;
  }
  if (!results.empty()) {
    out << "rocklab bench: " << source << ", Hertz-Mindlin"
        << (results.front().bonds == 0    ? ""
            : results.front().flat_joints ? " + flat joints (2 rings of 3 elements)"
            : results.front().bond_lane_width > 0
                ? " + parallel bonds (" + std::to_string(results.front().bond_lane_width) +
                      " per vector register)"
                : std::string(" + parallel bonds (one at a time)"))
        << ", dt = " << kTimeStep << " s\n";
    out << std::left << std::setw(8) << "threads" << std::setw(10) << "N" << std::setw(8) << "steps"
        << std::setw(11) << "seconds" << std::setw(20) << "particle-steps/s" << std::setw(9)
        << "Z start" << std::setw(7) << "Z end" << std::setw(20) << "wall stress (MPa)"
        << std::setw(10) << "rebuilds" << std::setw(13) << "peak RSS/N"
        << "state hash\n";
  }
  for (const BenchResult& r : results) {
    std::ostringstream stress, rss;
    stress << std::fixed << std::setprecision(3) << r.wall_stress_start / 1e6 << " -> "
           << r.wall_stress_end / 1e6;
    rss << std::fixed << std::setprecision(0) << r.peak_rss_bytes / static_cast<double>(r.particles)
        << " B";
    out << std::left << std::setw(8) << r.threads << std::setw(10) << r.particles << std::setw(8)
        << r.steps << std::setw(11) << std::fixed << std::setprecision(3) << r.seconds
        << std::setw(20) << std::scientific << std::setprecision(3) << r.particle_steps_per_second
        << std::fixed << std::setprecision(3) << std::setw(9) << r.coordination_start
        << std::setw(7) << r.coordination_end << std::setw(20) << stress.str() << std::setw(10)
        << r.rebuilds << std::setw(13) << rss.str() << std::hex << r.state_hash << std::dec << "\n";
  }
  for (const BenchResult& r : results) {
    // The stages' wall time (what the steps spend outside them: the rebuild test, the loop).
    out << "  " << r.threads << (r.threads == 1 ? " thread" : " threads") << ", seconds per stage:";
    double staged = 0.0;
    for (const StageTiming& s : r.stages) {
      out << " " << s.name << " " << std::setprecision(3) << s.seconds;
      staged += s.seconds;
    }
    out << ", outside them " << r.seconds - staged << "\n";
  }
  auto call = [&](const char* name, const FlowCall& c) {
    out << "  " << name << ": network " << c.network_seconds << " s, solve " << c.solve_seconds
        << " s (" << c.path << ": assembly " << c.assembly_seconds << " s, analysis "
        << c.analysis_seconds << " s, factor " << c.factorisation_seconds << " s, "
        << (c.iterations > 0 ? std::to_string(c.iterations) + " iterations " : "solve ")
        << c.iteration_seconds << " s), total " << c.network_seconds + c.solve_seconds
        << " s, k = " << c.permeability << " m^2\n";
  };
  for (const FlowBenchResult& f : flow) {
    out << std::defaultfloat << std::setprecision(4) << "pore network on " << f.particles
        << " spheres: " << f.pores << " pores, " << f.pipes << " pipes, " << f.clusters
        << " clusters after merging\n";
    call("first call", f.first);
    out << "  then every centre moved by an axial strain of " << f.strain << "\n";
    call("repeat call", f.repeat);
    out << "  the moved network factorised anew instead: solve " << f.fresh_solve_seconds
        << " s; largest pressure difference " << f.repeat_max_difference << " of the drop, inflow "
        << f.repeat_permeability_difference << " relative\n  Kozeny-Carman (180) "
        << f.kozeny_carman << " m^2, k / KC " << f.first.permeability / f.kozeny_carman << "\n";
  }
  for (const RenderBenchResult& g : render) {
    out << std::defaultfloat << std::setprecision(4) << "snapshot of " << g.particles
        << " spheres: cutaway view " << g.view_seconds << " s, slice " << g.slice_seconds << " s\n";
  }
}

}  // namespace rocklab
