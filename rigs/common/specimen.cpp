#include "rigs/common/specimen.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <sstream>

#include "lab/core/grains.hpp"
#include "lab/core/packing.hpp"

namespace rocklab::rigs {

using protocol::range;

void declareCommon(protocol::Schema& s, const std::vector<std::string>& rig_names) {
  s.text("protocol.name", std::nullopt, "name of the protocol, as it appears in the notebook");
  s.choice("protocol.rig", rig_names, std::nullopt, "the rig that runs the protocol");
  s.text("protocol.description", std::string(), "what the protocol is for");
  range(s.integer("protocol.dimension", 3, "2 (disks) or 3 (spheres)"), 2, false, 3, false);
  range(s.integer("protocol.seed", 1, "seed of the packing and the bond strengths"), 0, false, 9e15,
        false);
  s.textList("protocol.key_results", std::vector<std::string>{},
             "the protocol's key results, from its rig's list (`rocklab keys RIG`): what "
             "reports headline, accuracy studies compare and regression references guard");

  s.choice("sample.kind", {"spheres", "grains", "clumps"}, "spheres",
           "spheres: one disk or sphere per grain; grains: breakable superparticles, pebbles "
           "joined by intragranular bonds (grains.*, grain_bonds.*; Li & Holt section 2.2); "
           "clumps: the same shapes as rigid bodies (grains.*, clumps.*)");
  range(s.real("clumps.break_stress_MPa", "MPa", 1e6, 0.0,
               "a clump breaks into its pebbles when F / d^2 of its largest pebble contact "
               "force F reaches this (d: its equivalent diameter; McDowell & Bolton 1998); "
               "0: unbreakable"),
        0, false, 1e5, false);
  range(s.integer("sample.count", std::nullopt, "number of particles (grains for kind = grains)"),
        2, false, 5e7, false);
  range(s.integer("grains.pebbles_across", 4, "pebbles along a grain's long axis"), 2, false, 20,
        false);
  range(s.real("grains.max_aspect_ratio", "-", 1, 1.5,
               "longest over shortest caliper of every grain, exclusive"),
        1, true, 10, false);
  range(s.real("grains.roughness", "-", 1, 0.15, "relative amplitude of the outline's bumps"), 0,
        false, 0.5, false);
  range(s.real("grain_bonds.modulus_GPa", "GPa", 1e9, 8.0,
               "intragranular bond modulus, kn = E / L as for cement"),
        0, true, 1e4, false);
  range(s.real("grain_bonds.stiffness_ratio", "-", 1, 1.0, "kn / ks of intragranular bonds"), 0,
        true, 100, false);
  range(s.real("grain_bonds.radius_multiplier", "-", 1, 1.0,
               "intragranular bond radius over the pebble radius"),
        0, true, 10, false);
  range(s.real("grain_bonds.tensile_strength_mean_MPa", "MPa", 1e6, 40.0,
               "mean tensile strength of intragranular bonds"),
        0, true, 1e5, false);
  range(s.real("grain_bonds.tensile_strength_std_MPa", "MPa", 1e6, 0.0, "its std"), 0, false, 1e5,
        false);
  range(s.real("grain_bonds.shear_strength_mean_MPa", "MPa", 1e6, 40.0,
               "mean shear strength of intragranular bonds"),
        0, true, 1e5, false);
  range(s.real("grain_bonds.shear_strength_std_MPa", "MPa", 1e6, 0.0, "its std"), 0, false, 1e5,
        false);
  range(s.real("grain_bonds.friction_angle_deg", "deg", 1, 0.0,
               "intragranular bond friction angle (as bonds.friction_angle_deg)"),
        0, false, 85, false);
  range(s.real("grain_bonds.moment_factor", "-", 1, 1.0,
               "intragranular bond moment factor (as bonds.moment_factor)"),
        0, false, 1, false);
  s.choice("sample.size_distribution", {"uniform", "normal", "phi"}, "phi",
           "diameters uniform in [d_min, d_max], normal(d_mean, d_std), or Gaussian in "
           "phi = -log2(d / 1 mm); normal and phi are truncated to [d_min, d_max]");
  range(s.real("sample.d_min_mm", "mm", 1e-3, 0.5, "smallest diameter"), 0, true, 1e4, false);
  range(s.real("sample.d_max_mm", "mm", 1e-3, 2.0, "largest diameter"), 0, true, 1e4, false);
  range(s.real("sample.d_mean_mm", "mm", 1e-3, 1.0, "mean diameter (normal)"), 0, true, 1e4, false);
  range(s.real("sample.d_std_mm", "mm", 1e-3, 0.2, "diameter standard deviation (normal)"), 0,
        false, 1e4, false);
  range(s.real("sample.phi_mean", "phi", 1, 0.0, "mean of phi (phi)"), -20, false, 20, false);
  range(s.real("sample.phi_std", "phi", 1, 0.5, "standard deviation of phi (phi)"), 0, false, 10,
        false);
  range(s.real("sample.porosity_initial", "-", 1, 0.4,
               "porosity the packing is generated at (radius expansion), before formation"),
        0.05, false, 0.9, false);
  range(s.real("sample.aspect_axial", "-", 1, 1.0,
               "axial length over lateral length of the generated box"),
        0.1, false, 10, false);
  range(s.real("sample.thickness_m", "m", 1, 1.0, "disk thickness (2D)"), 0, true, 1e3, false);

  s.choice("material.contact_law", {"linear", "hertz"}, "linear", "contact law between grains");
  range(s.real("material.density_kg_per_m3", "kg/m^3", 1, 2650, "grain density"), 1, false, 1e5,
        false);
  range(s.real("material.contact_modulus_GPa", "GPa", 1e9, 4.0,
               "linear: contact modulus E, kn = E A / L per contact (PFC 5 deformability)"),
        0, true, 1e4, false);
  range(s.real("material.stiffness_ratio", "-", 1, 1.0, "linear: kn / ks of the contacts"), 0, true,
        100, false);
  range(s.real("material.young_GPa", "GPa", 1e9, 70.0, "hertz: Young's modulus of the grains"), 0,
        true, 1e4, false);
  range(s.real("material.poisson", "-", 1, 0.25, "hertz: Poisson's ratio of the grains"), -1, true,
        0.5, false);
  range(s.real("material.friction", "-", 1, 0.5, "grain-grain Coulomb friction after formation"), 0,
        false, 10, false);
  range(s.real("material.damping_ratio", "-", 1, 0.0, "critical damping ratio of contact dashpots"),
        0, false, 1, true);
  range(s.real("material.wall_friction", "-", 1, 0.0, "grain-wall friction"), 0, false, 10, false);

  s.flag("bonds.enabled", true, "cement the sample after formation (parallel bonds)");
  range(s.real("bonds.modulus_GPa", "GPa", 1e9, 4.0,
               "bond modulus E, normal stiffness per area kn = E / L (L = r1 + r2)"),
        0, true, 1e4, false);
  range(s.real("bonds.stiffness_ratio", "-", 1, 0.5, "kn / ks of the bonds"), 0, true, 100, false);
  range(s.real("bonds.radius_multiplier", "-", 1, 1.0, "bond radius over the smaller grain radius"),
        0, true, 10, false);
  range(s.real("bonds.tensile_strength_mean_MPa", "MPa", 1e6, 8.0, "mean tensile strength"), -1e4,
        false, 1e4, false);
  range(s.real("bonds.tensile_strength_std_MPa", "MPa", 1e6, 8.0, "tensile strength std"), 0, false,
        1e4, false);
  range(s.real("bonds.shear_strength_mean_MPa", "MPa", 1e6, 8.0, "mean shear strength"), -1e4,
        false, 1e4, false);
  range(s.real("bonds.shear_strength_std_MPa", "MPa", 1e6, 8.0, "shear strength std"), 0, false,
        1e4, false);
  range(s.real("bonds.friction_angle_deg", "deg", 1, 0.0,
               "bond friction angle: under a compressive normal stress sigma_n the shear strength "
               "is the drawn one plus sigma_n tan(angle) (PFC 5 pb_fa); 0: independent of load"),
        0, false, 85, false);
  range(s.real("bonds.moment_factor", "-", 1, 1.0,
               "share of the bending and twisting moments in the bond's peak stresses (PFC 5 "
               "pb_mcf); 1: the full beam stresses"),
        0, false, 1, false);
  s.choice("bonds.negative_strength", {"skip", "resample"}, "skip",
           "a strength drawn <= 0: skip (no bond: it would break unloaded) or resample");
  range(s.real("bonds.gap_ratio", "-", 1, 0.01,
               "pairs closer than this times the smaller radius are cemented too"),
        0, false, 1, false);

  range(s.real("formation.axial_stress_MPa", "MPa", 1e6, 30.0, "axial stress of formation"), 0,
        true, 1e4, false);
  range(s.real("formation.lateral_stress_MPa", "MPa", 1e6, 15.0, "lateral stress of formation"), 0,
        true, 1e4, false);
  range(s.real("formation.friction", "-", 1, 0.0,
               "grain friction while the sample is densified (isotropically, at the lateral "
               "formation stress); low friction packs densely"),
        0, false, 10, false);
  range(s.real("formation.stress_tolerance", "-", 1, 0.01,
               "settled when every wall is within this fraction of its target"),
        1e-6, false, 0.5, false);
  range(s.real("formation.unbalanced_force_ratio", "-", 1, 0.01,
               "and the mean unbalanced force is below this fraction of the mean contact force"),
        1e-7, false, 1, false);
  range(s.integer("formation.max_steps", 2000000, "give up settling after this many steps"), 100,
        false, 1e10, false);

  range(s.real("numerics.timestep_safety", "-", 1, 0.5, "time step over the critical estimate"), 0,
        true, 1, false);
  range(s.real("numerics.local_damping", "-", 1, 0.7, "PFC local damping coefficient"), 0, false, 1,
        true);
  range(s.integer("numerics.threads", 1, "OpenMP threads; results do not depend on it"), 1, false,
        1024, false);
  range(s.real("numerics.skin_ratio", "-", 1, 0.2, "Verlet skin over the mean radius"), 0, true, 10,
        false);
  range(s.real("numerics.overlap_limit", "-", 1, 0.25,
               "the run stops when an overlap exceeds this fraction of the smaller radius"),
        0, true, 1, false);
  range(s.real("numerics.servo_alpha", "-", 1, 0.5,
               "servo: fraction of the stress error closed "
               "per step"),
        0, true, 1, false);
  range(s.real("numerics.servo_speed_radii_per_step", "-", 1, 1e-3,
               "servo: largest wall move per step, in mean radii"),
        0, true, 1, false);
  range(s.real("numerics.quasi_static_unbalanced", "-", 1, 0.02,
               "warn when the mean unbalanced force ratio of a loading stage exceeds this"),
        0, true, 10, false);
  range(s.real("numerics.quasi_static_inertial", "-", 1, 1e-3,
               "warn when the inertial number of a loading stage exceeds this"),
        0, true, 10, false);

  range(s.integer("output.record_every_steps", 500, "steps between recorded measurements"), 1,
        false, 1e9, false);
  s.flag("output.snapshots", true,
         "save frames of the state (particles, contacts, bonds, walls) when the sample is "
         "formed and at the end of each loading stage, for reports and ParaView");
  range(s.integer("output.snapshot_every_steps", 0,
                  "also save a frame every this many loading steps (0: none)"),
        0, false, 1e12, false);
}

void validateCommon(const Settings& s) {
  if (s.real("sample.d_max_mm") < s.real("sample.d_min_mm")) {
    protocol::fail(s, "sample.d_max_mm", "must not be below sample.d_min_mm");
  }
  const std::string dist = s.text("sample.size_distribution");
  const double dmin = s.real("sample.d_min_mm"), dmax = s.real("sample.d_max_mm");
  if (dist == "normal" &&
      (s.real("sample.d_mean_mm") < dmin || s.real("sample.d_mean_mm") > dmax)) {
    protocol::fail(s, "sample.d_mean_mm", "must lie in [d_min_mm, d_max_mm]");
  }
  if (dist == "phi") {
    const double d = std::exp2(-s.real("sample.phi_mean"));
    if (d < dmin || d > dmax) {
      protocol::fail(s, "sample.phi_mean",
                     "the mean diameter 2^-phi_mean mm must lie in [d_min_mm, d_max_mm]");
    }
  }
  if (s.text("bonds.negative_strength") == "resample" &&
      (s.real("bonds.tensile_strength_mean_MPa") <= 0 ||
       s.real("bonds.shear_strength_mean_MPa") <= 0)) {
    protocol::fail(s, "bonds.negative_strength",
                   "resample needs positive mean strengths (it draws until positive)");
  }
}

std::string fmt(double v, int precision) {
  std::ostringstream o;
  o.precision(precision);
  o << v;
  return o.str();
}

namespace {

SizeDistribution sizes(const Settings& s) {
  const std::string d = s.text("sample.size_distribution");
  const double lo = s.si("sample.d_min_mm"), hi = s.si("sample.d_max_mm");
  if (d == "uniform") return SizeDistribution::uniform(lo, hi);
  if (d == "normal") {
    return SizeDistribution::normal(s.si("sample.d_mean_mm"), s.si("sample.d_std_mm"), lo, hi);
  }
  return SizeDistribution::phiGaussian(s.real("sample.phi_mean"), s.real("sample.phi_std"), lo, hi);
}

Material grainMaterial(const Settings& s, double friction) {
  Material m;
  m.name = "grain";
  m.density = s.real("material.density_kg_per_m3");
  m.modulus = s.si("material.contact_modulus_GPa");
  m.stiffness_ratio = s.real("material.stiffness_ratio");
  m.young = s.si("material.young_GPa");
  m.poisson = s.real("material.poisson");
  m.friction = friction;
  m.damping_ratio = s.real("material.damping_ratio");
  return m;
}

MaterialTable materials(const Settings& s, double friction) {
  MaterialTable t;
  t.add(grainMaterial(s, friction));
  Material wall = grainMaterial(s, s.real("material.wall_friction"));
  wall.name = "wall";
  t.add(wall);
  return t;
}

// Runs the frame until the stresses hold and the sample is in equilibrium.
template <int D>
std::uint64_t settle(Specimen<D>& sp, const Settings& s, const std::string& stage, Recorder& rec,
                     RunControl& control) {
  auto& sim = *sp.sim;
  const double tol = s.real("formation.stress_tolerance");
  const double ub = s.real("formation.unbalanced_force_ratio");
  const auto max_steps = static_cast<std::uint64_t>(s.integer("formation.max_steps"));
  const std::uint64_t start = sim.steps();
  for (;;) {
    sp.frame->step();
    const std::uint64_t done = sim.steps() - start;
    if (done % sp.record_every == 0) recordState(sp, rec, stage + ".", stage, 0.0);
    if (done % 100 != 0) continue;
    const double err = sp.frame->stressError(), u = sim.unbalancedForceRatio();
    control.tick(stage, sim.steps(), -1.0,
                 "stress error " + fmt(err) + ", unbalanced force ratio " + fmt(u));
    if (err < tol && u < ub) return done;
    if (done >= max_steps) {
      std::ostringstream why;
      why << stage << " did not settle in " << done << " steps: the wall stresses miss their "
          << "targets by " << fmt(err) << " (formation.stress_tolerance " << tol
          << "), the unbalanced force ratio is " << fmt(u) << " (formation.unbalanced_force_ratio "
          << ub << "); raise formation.max_steps or loosen the tolerances";
      throw std::runtime_error(why.str());
    }
  }
}

}  // namespace

template <int D>
Specimen<D> Specimen<D>::branch() const {
  Specimen<D> b;
  b.sim = std::make_unique<Simulation<D>>(sim->clone());
  b.frame = std::make_unique<LoadingFrame<D>>(*frame);
  b.frame->attach(*b.sim);
  b.mean_radius = mean_radius;
  b.density = density;
  b.cement_kind = cement_kind;
  b.cement = cement;
  b.cement_classes = cement_classes;
  b.grain_kind = grain_kind;
  b.grain_bonds = grain_bonds;
  b.grain_aspect_ratios = grain_aspect_ratios;
  b.clump_breaks = clump_breaks;
  b.fragments_reference = fragments_reference;
  b.record_every = record_every;
  b.snapshot_every = snapshot_every;
  std::copy(std::begin(broken_offset), std::end(broken_offset), std::begin(b.broken_offset));
  return b;
}

template <int D>
std::uint64_t Specimen<D>::broken(BondBreakMode mode) const {
  if (!cement_kind) return 0;
  return sim->brokenBonds(*cement_kind, mode) - broken_offset[mode == BondBreakMode::Shear];
}

template <int D>
std::uint64_t Specimen<D>::brokenInGrains(BondBreakMode mode) const {
  if (!grain_kind) return 0;
  return sim->brokenBonds(*grain_kind, mode) - broken_offset[2 + (mode == BondBreakMode::Shear)];
}

template <int D>
std::size_t Specimen<D>::crushedGrains() const {
  if (!grain_kind) return 0;
  return rocklab::crushedGrains(
      fragments_reference, grainFragments<D>(sim->particles(), sim->bonds(), sim->bondKinds()));
}

template <int D>
BondOrientations bondOrientations(const Simulation<D>& sim, std::uint8_t kind, int axis) {
  return countClasses(bondClasses(sim, kind, axis));
}

BondOrientations countClasses(const BondClasses& classes) {
  BondOrientations n;
  for (const auto& [key, k] : classes) {
    n.axial += k == 0 ? 1 : 0;
    n.inclined += k == 1 ? 1 : 0;
    n.lateral += k == 2 ? 1 : 0;
  }
  return n;
}

namespace {

// A bond's key: its particles' slots, the lower first.
template <int D>
std::uint64_t bondKey(const ParticleStore<D>& P, std::uint32_t i, std::uint32_t j) {
  const std::uint64_t a = P.slot_of[i], b = P.slot_of[j];
  return std::min(a, b) << 32 | std::max(a, b);
}

}  // namespace

template <int D>
BondClasses bondClasses(const Simulation<D>& sim, std::uint8_t kind, int axis) {
  // |cos| of the angle to the axis: above cos 30 deg axial, below cos 60 deg lateral.
  const double axial_cos = std::cos(std::numbers::pi / 6), lateral_cos = 0.5;
  const auto& P = sim.particles();
  const auto& B = sim.bonds();
  BondClasses classes;
  for (std::size_t b = 0; b < B.size(); ++b) {
    if (B.kind[b] != kind) continue;
    const Vec<D> d = P.pos[B.j[b]] - P.pos[B.i[b]];
    const double c = std::abs(d[axis]) / d.norm();
    const std::uint8_t k = c >= axial_cos ? 0 : c <= lateral_cos ? 2 : 1;
    classes.emplace(bondKey(P, B.i[b], B.j[b]), k);
  }
  return classes;
}

template <int D>
BondOrientations intactByClass(const Simulation<D>& sim, std::uint8_t kind,
                               const BondClasses& reference) {
  const auto& P = sim.particles();
  const auto& B = sim.bonds();
  BondOrientations n;
  for (std::size_t b = 0; b < B.size(); ++b) {
    if (B.kind[b] != kind) continue;
    const auto it = reference.find(bondKey(P, B.i[b], B.j[b]));
    if (it == reference.end()) continue;  // installed since (none are, in the rigs)
    n.axial += it->second == 0 ? 1 : 0;
    n.inclined += it->second == 1 ? 1 : 0;
    n.lateral += it->second == 2 ? 1 : 0;
  }
  return n;
}

template <int D>
void Specimen<D>::resetBrokenCount() {
  for (int m = 0; m < 2; ++m) {
    const auto mode = m == 0 ? BondBreakMode::Tensile : BondBreakMode::Shear;
    if (cement_kind) broken_offset[m] = sim->brokenBonds(*cement_kind, mode);
    if (grain_kind) broken_offset[2 + m] = sim->brokenBonds(*grain_kind, mode);
  }
  if (cement_kind) cement_classes = bondClasses(*sim, *cement_kind, kAxial);
  if (grain_kind) {
    fragments_reference = grainFragments<D>(sim->particles(), sim->bonds(), sim->bondKinds());
  }
}

namespace {

// The packing of the protocol: spheres by radius expansion, or grains grown as rigid
// bodies (then `grain` holds each pebble's grain).
template <int D>
Packing<D> makePacking(const Settings& s, RunControl& control, std::vector<std::uint32_t>& grain,
                       std::vector<double>& aspect_ratios) {
  const auto count = static_cast<std::size_t>(s.integer("sample.count"));
  std::array<double, 3> aspect{1.0, 1.0, 1.0};
  aspect[D - 1] = s.real("sample.aspect_axial");
  const auto seed = static_cast<std::uint64_t>(s.integer("protocol.seed"));
  const int threads = static_cast<int>(s.integer("numerics.threads"));
  auto progress = [&](double f) { control.tick("packing", 0, f, "growth to the porosity"); };
  if (s.text("sample.kind") != "spheres") {
    GrainPackingSpec g;
    g.grains = count;
    g.sizes = sizes(s);
    g.shape.pebbles_across = static_cast<int>(s.integer("grains.pebbles_across"));
    g.shape.max_aspect_ratio = s.real("grains.max_aspect_ratio");
    g.shape.roughness = s.real("grains.roughness");
    g.porosity = s.real("sample.porosity_initial");
    g.aspect = aspect;
    g.thickness = s.real("sample.thickness_m");
    g.seed = seed;
    g.threads = threads;
    g.progress = progress;
    PackingReport report;
    GrainPacking<D> out = generateGrainPacking<D>(g, &report);
    // Rigid grains jam looser than spheres (in 3D near 0.5 porosity before formation): a
    // target below that ends the growth with overlaps the first step would refuse.
    if (report.max_overlap > 0.5 * s.real("numerics.overlap_limit")) {
      protocol::fail(s, "sample.porosity_initial",
                     "is denser than these grains pack to by growth: it ended with overlaps of " +
                         std::to_string(report.max_overlap) +
                         " of a pebble radius; raise it (formation densifies the sample "
                         "afterwards; 3D grains pack to about 0.5)");
    }
    grain = std::move(out.grain);
    aspect_ratios = std::move(out.grain_aspect_ratio);
    return std::move(out.pebbles);
  }
  PackingSpec spec;
  spec.count = count;
  spec.sizes = sizes(s);
  spec.porosity = s.real("sample.porosity_initial");
  spec.aspect = aspect;
  spec.thickness = s.real("sample.thickness_m");
  spec.seed = seed;
  spec.threads = threads;
  spec.progress = progress;
  return generatePacking<D>(spec);
}

}  // namespace

template <int D>
Specimen<D> buildSpecimen(const Settings& s, RunControl& control) {
  control.tick("packing", 0, -1.0, "random placement and growth");
  std::vector<std::uint32_t> grain;
  std::vector<double> aspect_ratios;
  const Packing<D> p = makePacking<D>(s, control, grain, aspect_ratios);
  PackingSpec spec;
  spec.thickness = s.real("sample.thickness_m");
  spec.seed = static_cast<std::uint64_t>(s.integer("protocol.seed"));
  spec.threads = static_cast<int>(s.integer("numerics.threads"));

  Specimen<D> sp;
  sp.mean_radius =
      std::accumulate(p.radii.begin(), p.radii.end(), 0.0) / static_cast<double>(p.radii.size());
  sp.density = s.real("material.density_kg_per_m3");
  sp.record_every = static_cast<std::uint64_t>(s.integer("output.record_every_steps"));
  sp.snapshot_every = static_cast<std::uint64_t>(s.integer("output.snapshot_every_steps"));
  SimulationConfig cfg;
  cfg.contact_law = s.text("material.contact_law");
  cfg.skin = s.real("numerics.skin_ratio") * sp.mean_radius;
  cfg.local_damping = s.real("numerics.local_damping");
  cfg.timestep.safety = s.real("numerics.timestep_safety");
  cfg.guard.overlap_limit = s.real("numerics.overlap_limit");
  cfg.threads = spec.threads;
  cfg.track_energy = true;
  sp.sim = std::make_unique<Simulation<D>>(materials(s, s.real("formation.friction")), cfg);
  sp.sim->particles().thickness = spec.thickness;
  sp.sim->rng().reseed(spec.seed ^ 0x5eedb0d5ull);  // the bond strengths' own stream
  std::vector<ParticleId> ids;
  for (std::size_t i = 0; i < p.centers.size(); ++i) {
    ParticleSpec<D> ps;
    ps.position = p.centers[i];
    ps.radius = p.radii[i];
    ps.density = sp.density;
    if (!grain.empty()) ps.cluster = grain[i];
    ids.push_back(sp.sim->particles().add(ps));
  }
  if (s.text("sample.kind") == "clumps") {
    // Rigid grains: each grain's pebbles (consecutive in the packing) one clump.
    const double strength = s.si("clumps.break_stress_MPa");
    std::vector<ParticleId> pebbles;
    for (std::size_t i = 0; i < grain.size(); ++i) {
      pebbles.push_back(ids[i]);
      if (i + 1 == grain.size() || grain[i + 1] != grain[i]) {
        sp.sim->addClump(pebbles, strength);
        pebbles.clear();
      }
    }
    sp.grain_aspect_ratios = std::move(aspect_ratios);
  } else if (!grain.empty()) {
    // The grains are whole from the start: their intragranular bonds go in now, unloaded.
    BondKind k;
    k.name = "grain";
    k.intragranular = true;
    k.modulus = s.si("grain_bonds.modulus_GPa");
    k.stiffness_ratio = s.real("grain_bonds.stiffness_ratio");
    k.radius_multiplier = s.real("grain_bonds.radius_multiplier");
    k.tensile_mean = s.si("grain_bonds.tensile_strength_mean_MPa");
    k.tensile_std = s.si("grain_bonds.tensile_strength_std_MPa");
    k.shear_mean = s.si("grain_bonds.shear_strength_mean_MPa");
    k.shear_std = s.si("grain_bonds.shear_strength_std_MPa");
    k.friction_angle = s.real("grain_bonds.friction_angle_deg") * std::numbers::pi / 180.0;
    k.moment_factor = s.real("grain_bonds.moment_factor");
    k.negative = NegativeStrength::Resample;  // a grain is never born cracked
    sp.grain_kind = sp.sim->addBondKind(k);
    sp.grain_bonds = sp.sim->cement(*sp.grain_kind, 1e-3);
    sp.grain_aspect_ratios = std::move(aspect_ratios);
  }
  sp.frame = std::make_unique<LoadingFrame<D>>(*sp.sim, p.lo, p.hi, 1);
  sp.sim->prepare();
  sp.frame->setServo(s.real("numerics.servo_alpha"),
                     s.real("numerics.servo_speed_radii_per_step") * sp.mean_radius / sp.sim->dt());
  return sp;
}

template <int D>
void formAndCement(Specimen<D>& sp, const Settings& s, Recorder& rec, RunControl& control) {
  using Axis = typename LoadingFrame<D>::Axis;
  using Mode = typename LoadingFrame<D>::Mode;
  const double axial = s.si("formation.axial_stress_MPa");
  const double lateral = s.si("formation.lateral_stress_MPa");
  auto& sim = *sp.sim;
  // Densify isotropically at the lateral stress with the formation friction (a dense
  // packing), then with the grains' own friction take the formation state: a deviatoric
  // stress the low friction could not hold.
  for (int a = 0; a < D; ++a) sp.frame->set(a, Axis{Mode::Stress, 0.0, lateral, 0.0});
  std::uint64_t steps = settle(sp, s, "densification", rec, control);
  sim.replaceMaterials(materials(s, s.real("material.friction")));
  for (int a = 0; a < D; ++a) {
    sp.frame->set(a, Axis{Mode::Stress, 0.0, a == Specimen<D>::kAxial ? axial : lateral, 0.0});
  }
  steps += settle(sp, s, "formation", rec, control);
  rec.result("formation_steps", static_cast<double>(steps), "");
  rec.result("porosity_after_formation", sp.frame->porosity(), "");
  rec.result("coordination_after_formation", sim.coordinationNumber(), "");
  rec.result("axial_stress_after_formation_MPa", sp.frame->stress(Specimen<D>::kAxial) / 1e6,
             "MPa");

  if (s.flag("bonds.enabled")) {
    BondKind k;
    k.name = "cement";
    k.modulus = s.si("bonds.modulus_GPa");
    k.stiffness_ratio = s.real("bonds.stiffness_ratio");
    k.radius_multiplier = s.real("bonds.radius_multiplier");
    k.tensile_mean = s.si("bonds.tensile_strength_mean_MPa");
    k.tensile_std = s.si("bonds.tensile_strength_std_MPa");
    k.shear_mean = s.si("bonds.shear_strength_mean_MPa");
    k.shear_std = s.si("bonds.shear_strength_std_MPa");
    k.friction_angle = s.real("bonds.friction_angle_deg") * std::numbers::pi / 180.0;
    k.moment_factor = s.real("bonds.moment_factor");
    k.negative = s.text("bonds.negative_strength") == "resample" ? NegativeStrength::Resample
                                                                 : NegativeStrength::Skip;
    sp.cement_kind = sim.addBondKind(k);
    sp.cement = sim.cement(*sp.cement_kind, s.real("bonds.gap_ratio"));
    rec.result("bonds_installed", static_cast<double>(sp.cement.installed), "");
    rec.result("bonds_skipped_nonpositive", static_cast<double>(sp.cement.skipped_nonpositive), "");
    rec.result("bonds_redrawn", static_cast<double>(sp.cement.redrawn), "");
    rec.result("cement_candidates", static_cast<double>(sp.cement.candidates), "");
    rec.message(sim.steps(), sim.time(), "info",
                "cemented " + std::to_string(sp.cement.installed) + " of " +
                    std::to_string(sp.cement.candidates) + " contacts; " +
                    std::to_string(sp.cement.skipped_nonpositive) +
                    " strength draws <= 0 left uncemented (bonds.negative_strength = " +
                    s.text("bonds.negative_strength") + ")");
  }
  sim.restartEnergyLedger();
  sp.frame->resetReference();
  sp.resetBrokenCount();
  snapshot(sp, s, rec, "formation", "formed");
}

template <int D>
void snapshot(Specimen<D>& sp, const Settings& s, Recorder& rec, const std::string& stage,
              const std::string& label) {
  if (!s.flag("output.snapshots")) return;
  recordBreaks(sp, rec, stage);  // the breaks up to the frame are in the notebook with it
  rec.snapshot(stage, label, captureFrame(*sp.sim));
}

template <int D>
void servoTo(Specimen<D>& sp, const Settings& s, double axial, double lateral, double rate,
             const std::string& stage, Recorder& rec, RunControl& control) {
  using Axis = typename LoadingFrame<D>::Axis;
  using Mode = typename LoadingFrame<D>::Mode;
  auto& sim = *sp.sim;
  constexpr int ax = Specimen<D>::kAxial;
  std::array<double, D> from, to;
  double span = 0.0;
  for (int a = 0; a < D; ++a) {
    from[a] = sp.frame->stress(a);
    to[a] = a == ax ? axial : lateral;
    span = std::max(span, std::abs(to[a] - from[a]));
  }
  const double duration = span / rate;
  for (int a = 0; a < D; ++a) {
    sp.frame->set(a, Axis{Mode::Stress, 0.0, from[a], (to[a] - from[a]) / duration});
  }
  const double t0 = sim.time();
  while (sim.time() - t0 < duration) {
    sp.frame->step();
    if (sim.steps() % sp.record_every == 0) recordState(sp, rec, stage + ".", stage, 0.0);
    if (sim.steps() % 100 == 0) {
      control.tick(stage, sim.steps(), (sim.time() - t0) / duration,
                   "axial " + fmt(sp.frame->stress(ax) / 1e6) + " MPa");
    }
  }
  for (int a = 0; a < D; ++a) sp.frame->set(a, Axis{Mode::Stress, 0.0, to[a], 0.0});
  settle(sp, s, stage, rec, control);
}

template <int D>
void recordTimings(Recorder& rec, const std::vector<const Simulation<D>*>& sims) {
  std::vector<StageTiming> total;
  for (const auto* sim : sims) {
    for (const StageTiming& t : sim->stageTimings()) {
      auto it = std::find_if(total.begin(), total.end(),
                             [&](const StageTiming& x) { return x.name == t.name; });
      if (it == total.end()) {
        total.push_back(t);
      } else {
        it->seconds += t.seconds;
        it->calls += t.calls;
      }
    }
  }
  for (const StageTiming& t : total) rec.stageTiming(t.name, t.seconds, t.calls);
}

template <int D>
void warnIfNotQuasiStatic(const Simulation<D>& sim, const Settings& s, Recorder& rec,
                          const std::string& stage, double mean_unbalanced, double inertial_max) {
  const double ub_limit = s.real("numerics.quasi_static_unbalanced");
  const double i_limit = s.real("numerics.quasi_static_inertial");
  if (mean_unbalanced > ub_limit) {
    rec.message(sim.steps(), sim.time(), "warning",
                stage + " was not quasi-static: mean unbalanced force ratio " +
                    fmt(mean_unbalanced) + " > " + fmt(ub_limit) +
                    " (numerics.quasi_static_unbalanced); lower the loading rate");
  }
  if (inertial_max > i_limit) {
    rec.message(sim.steps(), sim.time(), "warning",
                stage + " was not quasi-static: inertial number up to " + fmt(inertial_max) +
                    " > " + fmt(i_limit) +
                    " (numerics.quasi_static_inertial); lower "
                    "loading.axial_strain_rate_per_s");
  }
}

template <int D>
double inertialNumber(const Specimen<D>& sp, double strain_rate) {
  const double p = std::abs(sp.frame->meanStress());
  if (!(p > 0.0)) return INFINITY;
  return std::abs(strain_rate) * 2.0 * sp.mean_radius * std::sqrt(sp.density / p);
}

namespace {

// The fields every break event has: when, where, in which stage.
template <int D>
EventRecord breakEvent(std::uint64_t step, double time, const Vec<D>& position,
                       const std::string& stage, const char* kind) {
  EventRecord e;
  e.step = step;
  e.time = time;
  e.stage = stage;
  e.kind = kind;
  e.x = position[0];
  e.y = position[1];
  if constexpr (D == 3) e.z = position[2];
  return e;
}

}  // namespace

template <int D>
void recordBreaks(Specimen<D>& sp, Recorder& rec, const std::string& stage) {
  const auto& kinds = sp.sim->bondKinds();
  for (const BondBreak<D>& b : sp.sim->takeBondBreaks()) {
    EventRecord e = breakEvent<D>(b.step, b.time, b.position, stage, "bond_break");
    e.mode = b.mode == BondBreakMode::Tensile ? "tensile" : "shear";
    e.granular = kinds[b.kind].intragranular ? "intra" : "inter";
    if (sp.keep_break_positions) sp.break_positions.push_back({e.x, e.y, e.z});
    e.particle_a = b.a.slot;
    e.particle_b = b.b.slot;
    e.value = b.stress;
    rec.event(e);
  }
  for (const ClumpBreak<D>& b : sp.sim->takeClumpBreaks()) {
    EventRecord e = breakEvent<D>(b.step, b.time, b.position, stage, "clump_break");
    e.mode = "crushing";
    e.granular = "intra";
    e.particle_a = b.clump;
    e.value = b.stress;
    rec.event(e);
    ++sp.clump_breaks;
  }
}

template <int D>
void recordState(Specimen<D>& sp, Recorder& rec, const std::string& prefix,
                 const std::string& stage, double strain_rate) {
  auto& sim = *sp.sim;
  auto& f = *sp.frame;
  constexpr int ax = Specimen<D>::kAxial;
  const std::uint64_t step = sim.steps();
  const double t = sim.time();
  auto put = [&](const std::string& name, double v) { rec.series(prefix + name, step, t, v); };
  double lateral = 0.0;
  for (int a = 0; a < D; ++a) {
    if (a != ax) lateral += f.stress(a) / (D - 1);
  }
  put("axial_stress_MPa", f.stress(ax) / 1e6);
  put("lateral_stress_MPa", lateral / 1e6);
  if constexpr (D == 3) {
    put("lateral_stress_x_MPa", f.stress(0) / 1e6);
    put("lateral_stress_y_MPa", f.stress(1) / 1e6);
  }
  put("axial_strain", f.strain(ax));
  put("volumetric_strain", f.volumetricStrain());
  put("porosity", f.porosity());
  put("coordination_number", sim.coordinationNumber());
  const double tensile = static_cast<double>(sp.broken(BondBreakMode::Tensile));
  const double shear = static_cast<double>(sp.broken(BondBreakMode::Shear));
  put("broken_bonds_tensile", tensile);
  put("broken_bonds_shear", shear);
  put("broken_bonds_total", tensile + shear);
  if (sp.cement_kind) {
    // Which cement broke, by orientation (BondOrientations): the fraction of each class
    // intact at the stage's start that has broken since.
    const BondOrientations now = intactByClass(sim, *sp.cement_kind, sp.cement_classes);
    const BondOrientations ref = countClasses(sp.cement_classes);
    auto broken = [](std::size_t intact, std::size_t reference) {
      return 1.0 - static_cast<double>(intact) / static_cast<double>(reference);
    };
    if (ref.axial > 0) put("broken_fraction_axial_bonds", broken(now.axial, ref.axial));
    if (ref.lateral > 0) put("broken_fraction_lateral_bonds", broken(now.lateral, ref.lateral));
    if (ref.inclined > 0) {
      put("broken_fraction_inclined_bonds", broken(now.inclined, ref.inclined));
    }
  }
  if (sp.grain_kind) {
    put("broken_grain_bonds_tensile",
        static_cast<double>(sp.brokenInGrains(BondBreakMode::Tensile)));
    put("broken_grain_bonds_shear", static_cast<double>(sp.brokenInGrains(BondBreakMode::Shear)));
    // Fragments: connected components of intact intragranular bonds, over all grains.
    const auto fragments = grainFragments<D>(sim.particles(), sim.bonds(), sim.bondKinds());
    put("crushed_grains", static_cast<double>(crushedGrains(sp.fragments_reference, fragments)));
    put("grain_fragments",
        static_cast<double>(std::accumulate(fragments.begin(), fragments.end(), std::size_t{0})));
  }
  put("unbalanced_force_ratio", sim.unbalancedForceRatio());
  if (strain_rate != 0.0) put("inertial_number", inertialNumber(sp, strain_rate));
  recordBreaks(sp, rec, stage);
}

template struct Specimen<2>;
template struct Specimen<3>;
template Specimen<2> buildSpecimen<2>(const Settings&, RunControl&);
template Specimen<3> buildSpecimen<3>(const Settings&, RunControl&);
template void formAndCement<2>(Specimen<2>&, const Settings&, Recorder&, RunControl&);
template void formAndCement<3>(Specimen<3>&, const Settings&, Recorder&, RunControl&);
template void servoTo<2>(Specimen<2>&, const Settings&, double, double, double, const std::string&,
                         Recorder&, RunControl&);
template void servoTo<3>(Specimen<3>&, const Settings&, double, double, double, const std::string&,
                         Recorder&, RunControl&);
template void recordState<2>(Specimen<2>&, Recorder&, const std::string&, const std::string&,
                             double);
template void recordState<3>(Specimen<3>&, Recorder&, const std::string&, const std::string&,
                             double);
template void recordBreaks<2>(Specimen<2>&, Recorder&, const std::string&);
template BondOrientations bondOrientations<2>(const Simulation<2>&, std::uint8_t, int);
template BondOrientations bondOrientations<3>(const Simulation<3>&, std::uint8_t, int);
template BondClasses bondClasses<2>(const Simulation<2>&, std::uint8_t, int);
template BondClasses bondClasses<3>(const Simulation<3>&, std::uint8_t, int);
template BondOrientations intactByClass<2>(const Simulation<2>&, std::uint8_t, const BondClasses&);
template BondOrientations intactByClass<3>(const Simulation<3>&, std::uint8_t, const BondClasses&);
template void snapshot<2>(Specimen<2>&, const Settings&, Recorder&, const std::string&,
                          const std::string&);
template void snapshot<3>(Specimen<3>&, const Settings&, Recorder&, const std::string&,
                          const std::string&);
template void recordBreaks<3>(Specimen<3>&, Recorder&, const std::string&);
template double inertialNumber<2>(const Specimen<2>&, double);
template void warnIfNotQuasiStatic<2>(const Simulation<2>&, const Settings&, Recorder&,
                                      const std::string&, double, double);
template void warnIfNotQuasiStatic<3>(const Simulation<3>&, const Settings&, Recorder&,
                                      const std::string&, double, double);
template void recordTimings<2>(Recorder&, const std::vector<const Simulation<2>*>&);
template void recordTimings<3>(Recorder&, const std::vector<const Simulation<3>*>&);
template double inertialNumber<3>(const Specimen<3>&, double);

}  // namespace rocklab::rigs
