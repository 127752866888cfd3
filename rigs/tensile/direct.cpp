#include "rigs/tensile/direct.hpp"

#include <algorithm>
#include <cmath>

#include "lab/core/errors.hpp"
#include "rigs/common/analysis.hpp"
#include "rigs/common/measurements.hpp"
#include "rigs/tensile/crack.hpp"

namespace rocklab::rigs::direct_tension {

void Settings::validate() const {
  unconfined::validate(specimen, release, loading);
}

namespace {

// The glued end layers (particle slots), the gauge between them and the cross-section.
struct Grips {
  std::vector<std::uint32_t> bottom, top;
  double gauge = 0.0;         // m, between the layers' mean axial positions
  double area = 0.0;          // m^2, the box's cross-section at the release (2D: width x thickness)
  double lo = 0.0, hi = 0.0;  // m, the specimen's axial extent
  template <class Archive>
  void visit(Archive& ar) {
    ar("bottom", bottom), ar("top", top), ar("gauge", gauge), ar("area", area), ar("lo", lo);
    ar("hi", hi);
  }
};

// The mean axial position of a layer's particles.
template <int D>
double layerPosition(const Simulation<D>& sim, const std::vector<std::uint32_t>& slots) {
  constexpr int ax = Specimen<D>::kAxial;
  const auto& P = sim.particles();
  double sum = 0.0;
  for (std::uint32_t s : slots) sum += P.pos[P.indexOfSlot(s)][ax];
  return sum / static_cast<double>(slots.size());
}

// The force the specimen pulls a layer back with, along the axis (N, tension positive):
// the sum of the contact and bond forces on its particles.
template <int D>
double layerPull(const Simulation<D>& sim, const std::vector<std::uint32_t>& slots, double sign) {
  constexpr int ax = Specimen<D>::kAxial;
  const auto& P = sim.particles();
  double sum = 0.0;
  for (std::uint32_t s : slots) sum += P.force[P.indexOfSlot(s)][ax];
  return -sign * sum;
}

// Takes the unloaded sample out of its box (every wall a box length away) and glues its end
// layers: the particles within `layer_diameters` mean diameters of its bottom and top become
// driven, held still until the loading pulls them.
template <int D>
Grips glue(Specimen<D>& sp, const Settings& s, Recorder& rec) {
  constexpr int ax = Specimen<D>::kAxial;
  auto& sim = *sp.sim;
  auto& frame = *sp.frame;
  Grips g;
  g.area = frame.faceArea(ax);
  unconfined::clearSides(sp);
  const double away = frame.length(ax);
  frame.place(ax, sim.wall(2 * ax).point[ax] - away, sim.wall(2 * ax + 1).point[ax] + away);
  const auto& P = sim.particles();
  g.lo = INFINITY, g.hi = -INFINITY;
  for (std::size_t i = 0; i < P.size(); ++i) {
    g.lo = std::min(g.lo, P.pos[i][ax] - P.radius[i]);
    g.hi = std::max(g.hi, P.pos[i][ax] + P.radius[i]);
  }
  const double layer = s.layer_diameters * 2.0 * sp.mean_radius;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (P.pos[i][ax] - P.radius[i] < g.lo + layer) g.bottom.push_back(P.slot_of[i]);
    if (P.pos[i][ax] + P.radius[i] > g.hi - layer) g.top.push_back(P.slot_of[i]);
  }
  if (g.hi - g.lo < 4.0 * layer) {
    throw InvalidParameter("", "glue.layer_diameters",
                           "the glued layers would take more than half the specimen's length");
  }
  sim.drive(g.bottom);
  sim.drive(g.top);
  sim.setDrivenVelocity(g.bottom, Vec<D>::Zero());
  sim.setDrivenVelocity(g.top, Vec<D>::Zero());
  g.gauge = layerPosition(sim, g.top) - layerPosition(sim, g.bottom);
  rec.result("glued_particles_bottom", static_cast<double>(g.bottom.size()), "");
  rec.result("glued_particles_top", static_cast<double>(g.top.size()), "");
  rec.result("gauge_length_mm", g.gauge * 1e3, "mm");
  rec.result("cross_section_mm2", g.area * 1e6, "mm^2");
  return g;
}

// What the pull keeps: its start, the peak, the stress-strain records (for the modulus) and
// how quasi-static it was.
struct PullHistory {
  std::uint64_t start_step = 0;
  unconfined::PeakWatch watch;  // the peak stress and the strain at it
  double inertial_at_peak = 0.0;
  std::vector<double> strain, stress;
  template <class Archive>
  void visit(Archive& ar) {
    ar("start_step", start_step), ar("watch", watch), ar("inertial_at_peak", inertial_at_peak);
    ar("strain", strain), ar("stress", stress);
  }
};

// Pulls the glued layers apart at the strain rate (each at half the speed, opposite) until
// the stress has dropped past its peak or the strain limit.
template <int D>
PullHistory pull(Specimen<D>& sp, const Settings& s, const Grips& g, Recorder& rec,
                 RunControl& control) {
  constexpr int ax = Specimen<D>::kAxial;
  const std::string stage = "loading";
  auto& sim = *sp.sim;
  const auto record_every = static_cast<std::uint64_t>(sp.settings.output.record_every_steps);
  const auto snapshot_every = static_cast<std::uint64_t>(sp.settings.output.snapshot_every_steps);
  PullHistory h;
  Journal::Unit unit = control.unit(stage);
  if (unit.done(h, sp)) return h;
  const double speed = 0.5 * s.loading.axial_strain_rate * g.gauge;
  sim.setDrivenVelocity(g.bottom, -speed * Vec<D>::Unit(ax));
  sim.setDrivenVelocity(g.top, speed * Vec<D>::Unit(ax));
  sp.resetBrokenCount();
  h.start_step = sim.steps();
  h.watch.breaks_at_peak = sim.bondBreaks().size();
  unit.resume(h, sp);
  for (bool done = false; !done;) {
    unit.tick(h, sp);
    sp.frame->step();
    const std::uint64_t steps = sim.steps() - h.start_step;
    const double strain = (layerPosition(sim, g.top) - layerPosition(sim, g.bottom)) / g.gauge - 1;
    const double force = 0.5 * (layerPull(sim, g.top, 1.0) + layerPull(sim, g.bottom, -1.0));
    const double stress = force / g.area;
    const bool new_peak = h.watch.see(sp, stress, strain);
    if (new_peak) h.inertial_at_peak = inertialNumber(sp, s.loading.axial_strain_rate, stress);
    done = h.watch.ends(stress, strain, sim.bondBreaks().size(), s.loading);
    if (h.watch.recordDue(steps, sim.steps(), record_every, new_peak, done)) {
      auto put = [&](const std::string& name, double v) {
        rec.series(name, sim.steps(), sim.time(), v);
      };
      put("pull_force_N", force);
      put("axial_strain", strain);
      put("tensile_stress_MPa", stress / 1e6);
      h.watch.record(sp, rec, stage);
      h.strain.push_back(strain);
      h.stress.push_back(stress);
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

// The modulus in tension: the least-squares slope of stress against strain over the records
// from 10% to 50% of the peak before it (the elastic part, past the first seating).
double tensileModulus(const PullHistory& h) {
  const double peak = h.watch.peak;
  return slopeWhere(h.strain, h.stress, h.strain.size(), [&](std::size_t k) {
    return h.strain[k] <= h.watch.peak_strain && h.stress[k] >= 0.1 * peak &&
           h.stress[k] <= 0.5 * peak;
  });
}

template <int D>
void recordResults(const Specimen<D>& sp, const Grips& g, const PullHistory& h, Recorder& rec) {
  constexpr int ax = Specimen<D>::kAxial;
  const auto& sim = *sp.sim;
  const unconfined::PeakWatch& w = h.watch;
  rec.result("tensile_strength_MPa", w.peak / 1e6, "MPa");
  rec.result("peak_force_N", w.peak * g.area, "N");
  rec.result("axial_strain_at_peak", w.peak_strain, "");
  rec.result("tensile_modulus_MPa", tensileModulus(h) / 1e6, "MPa");
  unconfined::recordLoadingResults(sp, w, h.start_step, h.inertial_at_peak, rec);
  // The fracture: the breaks from the peak on. Its axis lies across the load; where it lies
  // along the gauge says whether the specimen broke in it or at a glued layer.
  const auto& log = sim.bondBreaks();
  std::vector<CrackPoint> points;
  double mean = 0.0;
  for (std::size_t k = w.breaks_at_peak; k < log.size(); ++k) {
    points.push_back({log[k].position[0], log[k].position[ax]});
    mean += log[k].position[ax];
  }
  if (points.size() < 10) {
    rec.message(sim.steps(), sim.time(), "info",
                "fewer than 10 bonds broke after the peak: no fracture to locate");
    return;
  }
  mean /= static_cast<double>(points.size());
  const Crack c = crackOf(points, g.hi - g.lo);
  const double height = (mean - g.lo) / (g.hi - g.lo);
  rec.result("fracture_breaks", static_cast<double>(c.points), "");
  rec.result("fracture_angle_to_loading_deg", c.angle_to_axis_deg, "deg");
  rec.result("fracture_height_ratio", height, "");
  const double layer = (layerPosition(sim, g.bottom) - g.lo) / (g.hi - g.lo);
  if (height < 2.0 * layer || height > 1.0 - 2.0 * layer) {
    rec.message(sim.steps(), sim.time(), "warning",
                "the specimen broke at a glued layer (its fracture at " + fmt(height) +
                    " of its length): the strength is the grip's, not the rock's");
  }
}

template <int D>
void runDimension(const Settings& s, Recorder& rec, RunControl& control) {
  Specimen<D> sp = unconfined::formAndUnload<D>(s.specimen, s.release, rec, control);
  const Grips g = glue(sp, s, rec);
  unconfined::relax(sp, s.release.relax_steps_max, rec, control);
  const PullHistory h = pull(sp, s, g, rec, control);
  recordResults(sp, g, h, rec);
  recordTimings<D>(rec, {sp.sim.get()});
}

}  // namespace

void run(const Settings& s, Recorder& rec, RunControl& control) {
  byDimension(s.specimen.protocol.dimension,
              [&](auto dim) { runDimension<dim.value>(s, rec, control); });
}

}  // namespace rocklab::rigs::direct_tension
