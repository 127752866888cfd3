// Building a specimen from the shared settings: the packing (spheres, breakable grains or
// rigid clumps), the simulation with its material, and the loading frame around it.

#include <numeric>
#include <sstream>

#include "lab/core/grains.hpp"
#include "lab/core/packing.hpp"
#include "rigs/common/formed_samples.hpp"
#include "rigs/common/specimen.hpp"

namespace rocklab::rigs {

double metresPer(LengthUnit u) {
  switch (u) {
    case LengthUnit::M:
      return 1.0;
    case LengthUnit::Cm:
      return 1e-2;
    case LengthUnit::Mm:
      return 1e-3;
    case LengthUnit::Um:
      return 1e-6;
  }
  return 1.0;
}

namespace {

// The packing of a sample file, in the protocol's dimension.
template <int D>
Packing<D> filePacking(const SampleSettings& sample) {
  return samplePacking<D>(readSampleFile(sample.file, sample.format, metresPer(sample.file_unit)),
                          sample.file);
}

}  // namespace

void SpecimenSettings::validate() const {
  if (sample.kind != SampleKind::File) {
    if (sample.packing.count == 0) {
      throw InvalidParameter("sample", "sample.count",
                             "missing: the number of particles (grains for kind = grains) to "
                             "generate; only a sample read from a file (kind = file) has none");
    }
    return;
  }
  if (sample.file.empty()) {
    throw InvalidParameter("sample", "sample.kind",
                           "kind = file needs sample.file, the file of the particles");
  }
  // The file is read now, so that a bad one is refused before anything is written.
  try {
    if (protocol.dimension == 2) {
      filePacking<2>(sample);
    } else {
      filePacking<3>(sample);
    }
  } catch (const std::runtime_error& e) {
    throw InvalidParameter("sample", "sample.file", e.what());
  }
}

namespace {

// The grains' material with a given friction (formation uses its own), and the walls'.
MaterialTable materials(const MaterialSettings& m, double friction) {
  Material grain = m.grain;
  grain.name = "grain";
  grain.friction = friction;
  Material wall = grain;
  wall.name = "wall";
  wall.friction = m.wall_friction;
  MaterialTable t;
  t.add(grain);
  t.add(wall);
  return t;
}

// The packing of the protocol: spheres by radius expansion, or grains grown as rigid
// bodies (then `grain` holds each pebble's grain).
template <int D>
Packing<D> makePacking(const SpecimenSettings& s, RunControl& control,
                       std::vector<std::uint32_t>& grain, std::vector<double>& aspect_ratios) {
  const SampleSettings& sample = s.sample;
  std::array<double, 3> aspect{1.0, 1.0, 1.0};
  aspect[D - 1] = sample.aspect_axial;
  const auto seed = static_cast<std::uint64_t>(s.protocol.seed);
  auto progress = [&](double f) { control.tick("packing", 0, f, "growth to the porosity"); };
  if (sample.kind == SampleKind::File) return filePacking<D>(sample);
  if (sample.kind != SampleKind::Spheres) {
    GrainPackingSpec g;
    g.grains = sample.packing.count;
    g.sizes = sample.packing.sizes;
    g.shape = sample.grain_shape;
    g.porosity = sample.packing.porosity;
    g.aspect = aspect;
    g.thickness = sample.packing.thickness;
    g.seed = seed;
    g.threads = s.simulation.threads;
    g.progress = progress;
    PackingReport report;
    GrainPacking<D> out = generateGrainPacking<D>(g, &report);
    // Rigid grains jam looser than spheres (in 3D near 0.5 porosity before formation): a
    // target below that ends the growth with overlaps the first step would refuse.
    if (report.max_overlap > 0.5 * s.simulation.guard.overlap_limit) {
      std::ostringstream why;
      why << "is denser than these grains pack to by growth: it ended with overlaps of "
          << report.max_overlap
          << " of a pebble radius; raise it (formation densifies the sample afterwards; 3D "
             "grains pack to about 0.5)";
      throw InvalidParameter("sample", "sample.porosity_initial", why.str());
    }
    grain = std::move(out.grain);
    aspect_ratios = std::move(out.grain_aspect_ratio);
    return std::move(out.pebbles);
  }
  PackingSpec spec = sample.packing;
  spec.aspect = aspect;
  spec.seed = seed;
  spec.threads = s.simulation.threads;
  spec.progress = progress;
  return generatePacking<D>(spec);
}

// Each grain's pebbles (consecutive in the packing) made one rigid clump.
template <int D>
void makeClumps(Simulation<D>& sim, const std::vector<ParticleId>& ids,
                const std::vector<std::uint32_t>& grain, double strength) {
  std::vector<ParticleId> pebbles;
  for (std::size_t i = 0; i < grain.size(); ++i) {
    pebbles.push_back(ids[i]);
    if (i + 1 == grain.size() || grain[i + 1] != grain[i]) {
      sim.addClump(pebbles, strength);
      pebbles.clear();
    }
  }
}

}  // namespace

template <int D>
Specimen<D> buildSpecimen(const SpecimenSettings& s, RunControl& control) {
  Journal::Unit unit = control.unit("sample");
  {
    Specimen<D> restored;
    restored.settings = s;
    if (unit.done(restored)) return restored;
  }
  std::string formed_note;
  if (const FormedSamples* store = control.formedSamples()) {
    if (std::optional<Specimen<D>> formed = reuseFormed<D>(*store, s, formed_note)) {
      unit.finish(*formed);
      return std::move(*formed);
    }
  }
  control.tick("packing", 0, -1.0, "random placement and growth");
  std::vector<std::uint32_t> grain;
  std::vector<double> aspect_ratios;
  const Packing<D> p = makePacking<D>(s, control, grain, aspect_ratios);

  Specimen<D> sp;
  sp.settings = s;
  sp.mean_radius =
      std::accumulate(p.radii.begin(), p.radii.end(), 0.0) / static_cast<double>(p.radii.size());
  // The Verlet skin is the configuration's ratio of the mean radius (the core takes it).
  // Formed at the formation's density scaling (formation.density_scaling); formAndCement
  // hands the loading numerics.density_scaling.
  SimulationConfig config = s.simulation;
  if (s.formation.enabled) config.timestep.density_scaling = s.formation.density_scaling;
  sp.sim = std::make_unique<Simulation<D>>(materials(s.material, s.formation.friction), config);
  auto& sim = *sp.sim;
  sim.particles().thickness = s.sample.packing.thickness;
  sim.rng().reseed(bondStream(s));
  std::vector<ParticleId> ids;
  for (std::size_t i = 0; i < p.centers.size(); ++i) {
    ParticleSpec<D> ps;
    ps.position = p.centers[i];
    ps.radius = p.radii[i];
    ps.density = s.material.grain.density;
    if (!grain.empty()) ps.cluster = grain[i];
    ids.push_back(sim.particles().add(ps));
  }
  sp.grain_aspect_ratios = std::move(aspect_ratios);
  if (s.sample.kind == SampleKind::Clumps) {
    makeClumps(sim, ids, grain, s.sample.clump_break_stress);
  } else if (s.sample.kind == SampleKind::Grains) {
    // The grains are whole from the start: their intragranular bonds go in now, unloaded.
    BondKind k = s.grain_bonds;
    k.name = "grain";
    k.intragranular = true;
    sp.grain_kind = sim.addBondKind(k);
    sp.grain_bonds = sim.cement(*sp.grain_kind, 1e-3);
  }
  sp.frame = std::make_unique<LoadingFrame<D>>(sim, p.lo, p.hi, 1);
  sp.formed_note = std::move(formed_note);
  sim.prepare();
  sp.setServo();
  unit.finish(sp);
  return sp;
}

template Specimen<2> buildSpecimen<2>(const SpecimenSettings&, RunControl&);
template Specimen<3> buildSpecimen<3>(const SpecimenSettings&, RunControl&);

}  // namespace rocklab::rigs
