#include "rigs/common/measurements.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numeric>
#include <sstream>

#include "lab/core/grains.hpp"

namespace rocklab::rigs {

std::string fmt(double v, int precision) {
  std::ostringstream o;
  o.precision(precision);
  o << v;
  return o.str();
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

// Which cement broke, by orientation (bond_classes.hpp): the fraction of each class intact
// at the stage's start that has broken since.
template <int D>
void recordBrokenByOrientation(const Specimen<D>& sp, std::uint8_t kind,
                               const std::function<void(const std::string&, double)>& put) {
  const BondOrientations now = intactByClass(*sp.sim, kind, sp.cement_classes);
  const BondOrientations ref = countClasses(sp.cement_classes);
  auto broken = [](std::size_t intact, std::size_t reference) {
    return 1.0 - static_cast<double>(intact) / static_cast<double>(reference);
  };
  if (ref.axial > 0) put("broken_fraction_axial_bonds", broken(now.axial, ref.axial));
  if (ref.lateral > 0) put("broken_fraction_lateral_bonds", broken(now.lateral, ref.lateral));
  if (ref.inclined > 0) put("broken_fraction_inclined_bonds", broken(now.inclined, ref.inclined));
}

}  // namespace

template <int D>
void recordBreaks(Specimen<D>& sp, Recorder& rec, const std::string& stage) {
  const auto& sim = *sp.sim;
  const auto& kinds = sim.bondKinds();
  const auto& bonds = sim.bondBreaks();
  for (; sp.bond_breaks_recorded < bonds.size(); ++sp.bond_breaks_recorded) {
    const BondBreak<D>& b = bonds[sp.bond_breaks_recorded];
    EventRecord e = breakEvent<D>(b.step, b.time, b.position, stage, "bond_break");
    e.mode = b.mode == BondBreakMode::Tensile ? "tensile" : "shear";
    e.granular = kinds[b.kind].intragranular ? "intra" : "inter";
    e.particle_a = b.a.slot;
    e.particle_b = b.b.slot;
    e.value = b.stress;
    rec.event(e);
  }
  const auto& clumps = sim.clumpBreaks();
  for (; sp.clump_breaks_recorded < clumps.size(); ++sp.clump_breaks_recorded) {
    const ClumpBreak<D>& b = clumps[sp.clump_breaks_recorded];
    EventRecord e = breakEvent<D>(b.step, b.time, b.position, stage, "clump_break");
    e.mode = "crushing";
    e.granular = "intra";
    e.particle_a = b.clump;
    e.value = b.stress;
    rec.event(e);
  }
}

template <int D>
void recordState(Specimen<D>& sp, Recorder& rec, const std::string& prefix,
                 const std::string& stage, double strain_rate) {
  const auto& sim = *sp.sim;
  const auto& f = *sp.frame;
  constexpr int ax = Specimen<D>::kAxial;
  const std::uint64_t step = sim.steps();
  const double t = sim.time();
  const std::function<void(const std::string&, double)> put =
      [&](const std::string& name, double v) { rec.series(prefix + name, step, t, v); };
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
  if (sp.cement_kind) recordBrokenByOrientation(sp, *sp.cement_kind, put);
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

template <int D>
void snapshot(Specimen<D>& sp, Recorder& rec, const std::string& stage, const std::string& label) {
  if (!sp.settings.output.snapshots) return;
  recordBreaks(sp, rec, stage);  // the breaks up to the frame are in the notebook with it
  rec.snapshot(stage, label, captureFrame(*sp.sim));
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
  // The end states bit for bit: a resumed or rerun run is the same run when these agree.
  for (const auto* sim : sims) {
    char hash[17];
    std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(sim->stateHash()));
    rec.message(
        sim->steps(), sim->time(), "info",
        "final state hash " + std::string(hash) + " at step " + std::to_string(sim->steps()));
  }
}

template <int D>
void warnIfNotQuasiStatic(const Specimen<D>& sp, Recorder& rec, const std::string& stage,
                          double mean_unbalanced, double inertial_max) {
  const auto& sim = *sp.sim;
  const QuasiStaticLimits& limit = sp.settings.quasi_static;
  if (mean_unbalanced > limit.unbalanced) {
    rec.message(sim.steps(), sim.time(), "warning",
                stage + " was not quasi-static: mean unbalanced force ratio " +
                    fmt(mean_unbalanced) + " > " + fmt(limit.unbalanced) +
                    " (numerics.quasi_static_unbalanced); lower the loading rate");
  }
  if (inertial_max > limit.inertial) {
    rec.message(sim.steps(), sim.time(), "warning",
                stage + " was not quasi-static: inertial number up to " + fmt(inertial_max) +
                    " > " + fmt(limit.inertial) +
                    " (numerics.quasi_static_inertial); lower "
                    "loading.axial_strain_rate_per_s");
  }
}

template <int D>
double inertialNumber(const Specimen<D>& sp, double strain_rate) {
  return inertialNumber(sp, strain_rate, std::abs(sp.frame->meanStress()));
}

template <int D>
double inertialNumber(const Specimen<D>& sp, double strain_rate, double p) {
  if (!(p > 0.0)) return INFINITY;
  // The density the forces accelerate: heavier under density scaling.
  const double density = sp.settings.material.grain.density * sp.sim->inertialMassRatio();
  return std::abs(strain_rate) * 2.0 * sp.mean_radius * std::sqrt(density / p);
}

#define ROCKLAB_MEASUREMENTS(D)                                                                    \
  template void recordState<D>(Specimen<D>&, Recorder&, const std::string&, const std::string&,    \
                               double);                                                            \
  template void recordBreaks<D>(Specimen<D>&, Recorder&, const std::string&);                      \
  template void snapshot<D>(Specimen<D>&, Recorder&, const std::string&, const std::string&);      \
  template void recordTimings<D>(Recorder&, const std::vector<const Simulation<D>*>&);             \
  template void warnIfNotQuasiStatic<D>(const Specimen<D>&, Recorder&, const std::string&, double, \
                                        double);                                                   \
  template double inertialNumber<D>(const Specimen<D>&, double);                                   \
  template double inertialNumber<D>(const Specimen<D>&, double, double);
ROCKLAB_MEASUREMENTS(2)
ROCKLAB_MEASUREMENTS(3)
#undef ROCKLAB_MEASUREMENTS

}  // namespace rocklab::rigs
