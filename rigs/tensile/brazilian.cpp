#include "rigs/tensile/brazilian.hpp"

#include <cmath>
#include <numbers>

#include "lab/core/errors.hpp"
#include "rigs/common/measurements.hpp"
#include "rigs/common/release.hpp"
#include "rigs/tensile/crack.hpp"

namespace rocklab::rigs::brazilian {

void Settings::validate() const {
  unconfined::validate(specimen, release, loading);
}

namespace {

// The disk: its centre and diameter in the loading plane (x and the axial axis), its
// thickness (2D: the disks'; 3D: the cylinder's length along y).
template <int D>
struct Disk {
  Vec<D> centre = Vec<D>::Zero();
  double diameter = 0.0, thickness = 0.0;
  template <class Archive>
  void visit(Archive& ar) {
    ar("centre", centre), ar("diameter", diameter), ar("thickness", thickness);
  }
};

// The in-plane distance of x from the disk's axis.
template <int D>
double planeDistance(const Vec<D>& x, const Vec<D>& centre) {
  constexpr int ax = Specimen<D>::kAxial;
  return std::hypot(x[0] - centre[0], x[ax] - centre[ax]);
}

// Brings the platens to touch the disk's top and bottom, unloaded.
template <int D>
void seatPlatens(Specimen<D>& sp) {
  constexpr int ax = Specimen<D>::kAxial;
  const auto& P = sp.sim->particles();
  double lo = INFINITY, hi = -INFINITY;
  for (std::size_t i = 0; i < P.size(); ++i) {
    lo = std::min(lo, P.pos[i][ax] - P.radius[i]);
    hi = std::max(hi, P.pos[i][ax] + P.radius[i]);
  }
  sp.frame->place(ax, lo, hi);
}

// Cuts the disk out of the unloaded sample: the particles whose centres lie outside it go
// with their bonds (the cut frees the stress the bonds locked in); the side walls are taken
// a box length away, the platens brought to touch its top and bottom.
template <int D>
Disk<D> cutDisk(Specimen<D>& sp, const Settings& s, Recorder& rec) {
  constexpr int ax = Specimen<D>::kAxial;
  auto& sim = *sp.sim;
  auto& frame = *sp.frame;
  Disk<D> disk;
  for (int a = 0; a < D; ++a) {
    disk.centre[a] = 0.5 * (sim.wall(2 * a).point[a] + sim.wall(2 * a + 1).point[a]);
  }
  disk.diameter = s.diameter_ratio * std::min(frame.length(0), frame.length(ax));
  disk.thickness = D == 2 ? sim.particles().thickness : frame.length(1);
  if (disk.diameter < 20.0 * sp.mean_radius) {
    throw InvalidParameter("", "cut.diameter_ratio",
                           "leaves a disk of " + fmt(disk.diameter / (2 * sp.mean_radius)) +
                               " mean particle diameters across: at least 10 are needed (a "
                               "larger sample or ratio)");
  }
  const auto& P = sim.particles();
  std::vector<ParticleId> outside;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (planeDistance<D>(P.pos[i], disk.centre) > 0.5 * disk.diameter) outside.push_back(P.id(i));
  }
  const std::size_t before = P.size();
  sim.removeParticles(outside);
  unconfined::clearSides(sp);
  // The platens touch the disk while it relaxes: a free disk would drift away from them with
  // whatever momentum the cut left it (local damping does not damp a rigid motion).
  seatPlatens(sp);
  rec.result("disk_particles", static_cast<double>(P.size()), "");
  rec.result("particles_cut_away", static_cast<double>(before - P.size()), "");
  rec.result("disk_diameter_mm", disk.diameter * 1e3, "mm");
  rec.result("disk_thickness_mm", disk.thickness * 1e3, "mm");
  rec.result("bonds_in_disk", static_cast<double>(sim.bonds().size()), "");
  rec.message(sim.steps(), sim.time(), "info",
              "cut a disk of " + fmt(disk.diameter * 1e3) + " mm (" + std::to_string(P.size()) +
                  " particles) from the sample");
  return disk;
}

// What the loading keeps: its start, the peak and how quasi-static it was.
struct LoadingHistory {
  std::uint64_t start_step = 0;
  unconfined::PeakWatch watch;  // the peak force and the closure at it
  double inertial_at_peak = 0.0;
  template <class Archive>
  void visit(Archive& ar) {
    ar("start_step", start_step), ar("watch", watch), ar("inertial_at_peak", inertial_at_peak);
  }
};

// Closes the platens at the rate until the force has dropped past the peak (or the closure
// limit), recording the force, the closure, the nominal stress 2F / (pi D t) and the breaks.
template <int D>
LoadingHistory load(Specimen<D>& sp, const Settings& s, const Disk<D>& disk, Recorder& rec,
                    RunControl& control) {
  using Axis = typename LoadingFrame<D>::Axis;
  using Mode = typename LoadingFrame<D>::Mode;
  constexpr int ax = Specimen<D>::kAxial;
  const std::string stage = "loading";
  auto& sim = *sp.sim;
  auto& frame = *sp.frame;
  const auto record_every = static_cast<std::uint64_t>(sp.settings.output.record_every_steps);
  const auto snapshot_every = static_cast<std::uint64_t>(sp.settings.output.snapshot_every_steps);
  LoadingHistory h;
  Journal::Unit unit = control.unit(stage);
  if (unit.done(h, sp)) return h;
  seatPlatens(sp);  // at the relaxed disk: what it pushed on them while relaxing is let go
  frame.set(ax, Axis{Mode::StrainRate, s.loading.axial_strain_rate});
  frame.resetReference();
  sp.resetBrokenCount();
  h.start_step = sim.steps();
  h.watch.breaks_at_peak = sim.bondBreaks().size();
  unit.resume(h, sp);
  const double to_stress = 2.0 / (std::numbers::pi * disk.diameter * disk.thickness);
  for (bool done = false; !done;) {
    unit.tick(h, sp);
    frame.step();
    const std::uint64_t steps = sim.steps() - h.start_step;
    const double force = frame.force(ax), closure = frame.strain(ax);
    const bool new_peak = h.watch.see(sp, force, closure);
    if (new_peak) {
      // At the peak, the disk's own stress scale: its nominal stress 2F / (pi D t).
      h.inertial_at_peak = inertialNumber(sp, s.loading.axial_strain_rate, force * to_stress);
    }
    done = h.watch.ends(force, closure, sim.bondBreaks().size(), s.loading);
    if (h.watch.recordDue(steps, sim.steps(), record_every, new_peak, done)) {
      auto put = [&](const std::string& name, double v) {
        rec.series(name, sim.steps(), sim.time(), v);
      };
      put("platen_force_N", force);
      put("platen_closure_mm", closure * frame.length(ax) / (1.0 - closure) * 1e3);
      put("diametral_strain", closure);
      put("tensile_stress_MPa", force * to_stress / 1e6);
      h.watch.record(sp, rec, stage);
    }
    if (snapshot_every > 0 && steps % snapshot_every == 0) {
      snapshot(sp, rec, stage, "step " + std::to_string(steps));
    }
    if (steps % 200 == 0) {
      control.tick(stage, sim.steps(), closure / s.loading.axial_strain_max,
                   "F " + fmt(force) + " N at diametral strain " + fmt(closure));
    }
  }
  snapshot(sp, rec, stage, "final");
  unit.finish(h, sp);
  return h;
}

template <int D>
void recordResults(const Specimen<D>& sp, const Disk<D>& disk, const LoadingHistory& h,
                   Recorder& rec) {
  const auto& sim = *sp.sim;
  const unconfined::PeakWatch& w = h.watch;
  const double sigma_t = 2.0 * w.peak / (std::numbers::pi * disk.diameter * disk.thickness);
  rec.result("tensile_strength_MPa", sigma_t / 1e6, "MPa");
  rec.result("peak_force_N", w.peak, "N");
  rec.result("diametral_strain_at_peak", w.peak_strain, "");
  unconfined::recordLoadingResults(sp, w, h.start_step, h.inertial_at_peak, rec);
  // The fracture: the breaks from the peak to the end, where the macroscopic crack runs.
  constexpr int ax = Specimen<D>::kAxial;
  const auto& log = sim.bondBreaks();
  std::vector<CrackPoint> points;
  for (std::size_t k = w.breaks_at_peak; k < log.size(); ++k) {
    points.push_back({log[k].position[0] - disk.centre[0], log[k].position[ax] - disk.centre[ax]});
  }
  const Crack c = crackOf(points, disk.diameter);
  if (c.points < 10) {
    rec.message(sim.steps(), sim.time(), "info",
                "fewer than 10 bonds broke after the peak: no fracture to locate");
    return;
  }
  rec.result("fracture_breaks", static_cast<double>(c.points), "");
  rec.result("fracture_angle_to_loading_deg", c.angle_to_axis_deg, "deg");
  rec.result("fracture_offset_ratio", c.offset_ratio, "");
  rec.result("fracture_elongation", c.elongation, "");
  rec.result("fracture_through_centre", c.throughCentre() ? 1.0 : 0.0, "");
  rec.message(sim.steps(), sim.time(), "info",
              std::string("the fracture ") +
                  (c.throughCentre() ? "runs through the centre along the loading diameter"
                                     : "misses the centre or the loading diameter") +
                  ": " + fmt(c.angle_to_axis_deg) + " deg to it, its breaks' centroid " +
                  fmt(c.offset_ratio) + " diameters from the centre");
}

template <int D>
void runDimension(const Settings& s, Recorder& rec, RunControl& control) {
  Specimen<D> sp = unconfined::formAndUnload<D>(s.specimen, s.release, rec, control);
  const Disk<D> disk = cutDisk(sp, s, rec);
  snapshot(sp, rec, "cut", "disk");
  unconfined::relax(sp, s.release.relax_steps_max, rec, control);
  const LoadingHistory h = load(sp, s, disk, rec, control);
  recordResults(sp, disk, h, rec);
  recordTimings<D>(rec, {sp.sim.get()});
}

}  // namespace

void run(const Settings& s, Recorder& rec, RunControl& control) {
  byDimension(s.specimen.protocol.dimension,
              [&](auto dim) { runDimension<dim.value>(s, rec, control); });
}

}  // namespace rocklab::rigs::brazilian
