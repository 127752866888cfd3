#include "rigs/ucs/ucs.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "lab/core/errors.hpp"
#include "rigs/common/measurements.hpp"
#include "rigs/ucs/curve.hpp"

namespace rocklab::rigs::ucs {

void Settings::validate() const {
  unconfined::validate(specimen, release, loading);
  if (shape == Shape::Cylinder && specimen.protocol.dimension != 3) {
    throw InvalidParameter("", "cut.shape",
                           "a cylinder needs dimension = 3: in 2D the specimen is the prism");
  }
}

namespace {

// The specimen between the platens: its cross-section (the box's at the release, or the
// cylinder's), its width across the axis (the prism's smaller side, the cylinder's
// diameter) and its height.
struct Section {
  double area = 0.0, width = 0.0, height = 0.0;  // m^2 (2D: width x thickness), m, m
};

// The distance of x from the specimen's axis (through `centre`, along the axial axis).
template <int D>
double axisDistance(const Vec<D>& x, const Vec<D>& centre) {
  double r2 = 0.0;
  for (int a = 0; a < D - 1; ++a) r2 += (x[a] - centre[a]) * (x[a] - centre[a]);
  return std::sqrt(r2);
}

// Takes the unloaded sample out of its box: the side walls a box length away, the platens
// where they are; a cylinder is cut from it first (the particles whose centres lie farther
// than D / 2 from the box's axis go with their bonds, a cut and not a break).
template <int D>
Section takeOut(Specimen<D>& sp, const Settings& s, Recorder& rec) {
  constexpr int ax = Specimen<D>::kAxial;
  auto& sim = *sp.sim;
  auto& frame = *sp.frame;
  Section sec;
  sec.area = frame.faceArea(ax);
  sec.height = frame.length(ax);
  sec.width = frame.length(0);
  for (int a = 1; a < D - 1; ++a) sec.width = std::min(sec.width, frame.length(a));
  if (s.shape == Shape::Cylinder) {
    Vec<D> centre;
    for (int a = 0; a < D; ++a) {
      centre[a] = 0.5 * (sim.wall(2 * a).point[a] + sim.wall(2 * a + 1).point[a]);
    }
    sec.width *= s.diameter_ratio;
    sec.area = 0.25 * std::numbers::pi * sec.width * sec.width;
    if (sec.width < 20.0 * sp.mean_radius) {
      throw InvalidParameter("", "cut.diameter_ratio",
                             "leaves a cylinder of " + fmt(sec.width / (2 * sp.mean_radius)) +
                                 " mean particle diameters across: at least 10 are needed (a "
                                 "larger sample or ratio)");
    }
    const auto& P = sim.particles();
    std::vector<ParticleId> outside;
    for (std::size_t i = 0; i < P.size(); ++i) {
      if (axisDistance<D>(P.pos[i], centre) > 0.5 * sec.width) outside.push_back(P.id(i));
    }
    sim.removeParticles(outside);
    rec.result("particles_cut_away", static_cast<double>(outside.size()), "");
  }
  unconfined::clearSides(sp);
  rec.result("specimen_particles", static_cast<double>(sim.particles().size()), "");
  rec.result("specimen_width_mm", sec.width * 1e3, "mm");
  rec.result("specimen_height_mm", sec.height * 1e3, "mm");
  rec.result("cross_section_mm2", sec.area * 1e6, "mm^2");
  return sec;
}

// The gauge section: the particles (slots) whose centres lie within the middle
// `gauge.height_ratio` of the specimen's height at the start of the loading, and their
// positions then.
template <int D>
struct Gauge {
  std::vector<std::uint32_t> slots;
  std::vector<Vec<D>> start;
  template <class Archive>
  void visit(Archive& ar) {
    ar("slots", slots), ar("start", start);
  }
};

template <int D>
Gauge<D> chooseGauge(const Simulation<D>& sim, double ratio) {
  constexpr int ax = Specimen<D>::kAxial;
  const auto& P = sim.particles();
  double lo = INFINITY, hi = -INFINITY;
  for (std::size_t i = 0; i < P.size(); ++i) {
    lo = std::min(lo, P.pos[i][ax]), hi = std::max(hi, P.pos[i][ax]);
  }
  const double mid = 0.5 * (lo + hi), half = 0.5 * ratio * (hi - lo);
  Gauge<D> g;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (std::abs(P.pos[i][ax] - mid) <= half) {
      g.slots.push_back(P.slot_of[i]);
      g.start.push_back(P.pos[i]);
    }
  }
  return g;
}

// The gauge's strains now (curve.hpp's affine fit of its particles' displacements).
template <int D>
GaugeStrains gaugeStrains(const Simulation<D>& sim, const Gauge<D>& g) {
  const auto& P = sim.particles();
  std::vector<Vec<D>> now;
  now.reserve(g.slots.size());
  for (std::uint32_t slot : g.slots) now.push_back(P.pos[P.indexOfSlot(slot)]);
  return affineStrains<D>(g.start, now, Specimen<D>::kAxial);
}

// What the loading keeps: its start, the gauge, the peak, the records and how quasi-static
// it was.
template <int D>
struct LoadingHistory {
  std::uint64_t start_step = 0;
  Gauge<D> gauge;
  unconfined::PeakWatch watch;  // the peak stress and the platens' strain at it
  std::size_t peak_record = 0;
  double inertial_at_peak = 0.0;
  CompressionCurve curve;
  template <class Archive>
  void visit(Archive& ar) {
    ar("start_step", start_step), ar("gauge", gauge), ar("watch", watch);
    ar("peak_record", peak_record), ar("inertial_at_peak", inertial_at_peak);
    ar("curve", curve);
  }
};

// The platens' own friction for the loading (`loading.platen_friction`): the walls'
// material, which only the platens now touch.
template <int D>
void setPlatenFriction(Simulation<D>& sim, double friction) {
  MaterialTable own;
  for (const Material& m : sim.materials().all()) own.add(m);
  own[1].friction = friction;
  sim.replaceMaterials(std::move(own));
}

// Closes the platens at the strain rate until the stress has dropped past its peak or the
// strain limit, recording the stress and the strains of the platens and of the gauge.
template <int D>
LoadingHistory<D> load(Specimen<D>& sp, const Settings& s, const Section& sec, Recorder& rec,
                       RunControl& control) {
  using Axis = typename LoadingFrame<D>::Axis;
  using Mode = typename LoadingFrame<D>::Mode;
  constexpr int ax = Specimen<D>::kAxial;
  const std::string stage = "loading";
  auto& sim = *sp.sim;
  auto& frame = *sp.frame;
  const auto record_every = static_cast<std::uint64_t>(sp.settings.output.record_every_steps);
  const auto snapshot_every = static_cast<std::uint64_t>(sp.settings.output.snapshot_every_steps);
  LoadingHistory<D> h;
  Journal::Unit unit = control.unit(stage);
  if (unit.done(h, sp)) return h;
  frame.set(ax, Axis{Mode::StrainRate, s.loading.axial_strain_rate});
  frame.resetReference();
  sp.resetBrokenCount();
  h.start_step = sim.steps();
  h.gauge = chooseGauge(sim, s.gauge_height);
  h.watch.breaks_at_peak = sim.bondBreaks().size();
  rec.result("gauge_particles", static_cast<double>(h.gauge.slots.size()), "");
  unit.resume(h, sp);
  setPlatenFriction(sim, s.platen_friction);
  for (bool done = false; !done;) {
    unit.tick(h, sp);
    frame.step();
    const std::uint64_t steps = sim.steps() - h.start_step;
    const double strain = frame.strain(ax);
    const double stress = frame.force(ax) / sec.area;
    const bool new_peak = h.watch.see(sp, stress, strain);
    if (new_peak) h.inertial_at_peak = inertialNumber(sp, s.loading.axial_strain_rate, stress);
    done = h.watch.ends(stress, strain, sim.bondBreaks().size(), s.loading);
    if (h.watch.recordDue(steps, sim.steps(), record_every, new_peak, done)) {
      const GaugeStrains e = gaugeStrains(sim, h.gauge);
      const double volumetric = e.axial + (D - 1) * e.lateral;
      if (new_peak) h.peak_record = h.curve.size();
      h.curve.push(stress, strain, e.axial, e.lateral, volumetric);
      auto put = [&](const std::string& name, double v) {
        rec.series(name, sim.steps(), sim.time(), v);
      };
      put("axial_stress_MPa", stress / 1e6);
      put("axial_strain", strain);
      put("gauge_axial_strain", e.axial);
      put("lateral_strain", e.lateral);
      put("volumetric_strain", volumetric);
      h.watch.record(sp, rec, stage);
    }
    if (snapshot_every > 0 && steps % snapshot_every == 0) {
      snapshot(sp, rec, stage, "step " + std::to_string(steps));
    }
    if (steps % 200 == 0) {
      control.tick(stage, sim.steps(), strain / s.loading.axial_strain_max,
                   "sigma " + fmt(stress / 1e6) + " MPa at axial strain " + fmt(strain));
    }
  }
  snapshot(sp, rec, stage, "final");
  unit.finish(h, sp);
  return h;
}

template <int D>
void recordResults(const Specimen<D>& sp, const Section& sec, const LoadingHistory<D>& h,
                   Recorder& rec) {
  const unconfined::PeakWatch& w = h.watch;
  const CompressionCurve& c = h.curve;
  rec.result("ucs_MPa", w.peak / 1e6, "MPa");
  rec.result("peak_force_N", w.peak * sec.area, "N");
  rec.result("axial_strain_at_peak", w.peak_strain, "");
  const HalfPeakModuli m = halfPeakModuli(c, h.peak_record);
  rec.result("young_modulus_secant_50_MPa", m.young_secant / 1e6, "MPa");
  rec.result("young_modulus_tangent_50_MPa", m.young_tangent / 1e6, "MPa");
  rec.result("poisson_ratio_secant_50", m.poisson_secant, "");
  rec.result("poisson_ratio_tangent_50", m.poisson_tangent, "");
  const CrackDamage cd = crackDamage(c, h.peak_record);
  rec.result("crack_damage_stress_MPa", cd.stress / 1e6, "MPa");
  rec.result("crack_damage_ratio", cd.stress / w.peak, "");
  rec.result("volumetric_strain_at_crack_damage", cd.volumetric, "");
  if (h.peak_record < c.size()) {
    rec.result("volumetric_strain_at_peak", c.volumetric[h.peak_record], "");
    rec.result("lateral_strain_at_peak", c.lateral[h.peak_record], "");
  }
  unconfined::recordLoadingResults(sp, w, h.start_step, h.inertial_at_peak, rec);
  const auto& sim = *sp.sim;
  if (std::isnan(m.young_tangent)) {
    rec.message(sim.steps(), sim.time(), "warning",
                "fewer than 3 records between 40% and 60% of the peak: no tangent moduli "
                "(lower output.record_every_steps)");
  }
}

template <int D>
void runDimension(const Settings& s, Recorder& rec, RunControl& control) {
  Specimen<D> sp = unconfined::formAndUnload<D>(s.specimen, s.release, rec, control);
  const Section sec = takeOut(sp, s, rec);
  snapshot(sp, rec, "cut", "specimen");
  unconfined::relax(sp, s.release.relax_steps_max, rec, control);
  const LoadingHistory<D> h = load(sp, s, sec, rec, control);
  recordResults(sp, sec, h, rec);
  recordTimings<D>(rec, {sp.sim.get()});
}

}  // namespace

void run(const Settings& s, Recorder& rec, RunControl& control) {
  byDimension(s.specimen.protocol.dimension,
              [&](auto dim) { runDimension<dim.value>(s, rec, control); });
}

}  // namespace rocklab::rigs::ucs
