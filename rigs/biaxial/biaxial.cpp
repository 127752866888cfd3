#include "rigs/biaxial/biaxial.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>

#include "rigs/common/formation.hpp"
#include "rigs/common/localisation.hpp"
#include "rigs/common/measurements.hpp"

namespace rocklab::rigs::biaxial {

void LoadingTest::validate() const {
  if (stop_after_drop > 0.0 && axial_strain_max <= std::max(1e-3, stop_after_drop_min_strain)) {
    throw InvalidParameter("", "axial_strain_max",
                           "is too small to pass the peak that loading.stop_after_drop waits for "
                           "(more than 0.001 and than loading.stop_after_drop_min_strain)");
  }
}

// The volumetric strain a sample must have lost since its peak to count as dilating at a
// drop. Its load falling 30% unloads it elastically: at a burst of crushing at 18 MPa (500
// grains, seed 5 of triaxial-envelope-quick) the compacting sample swelled by 0.0004 as q fell;
// the dilatant tests of that sweep (0-4 MPa, seeds 1-8) had lost 0.0013 to 0.017 at their drop.
constexpr double kDilationAtDrop = 1e-3;

bool LoadingTest::ends(double strain, double load, double volumetric, double peak,
                       double peak_strain, double peak_volumetric) const {
  if (strain >= axial_strain_max) return true;
  const bool dropped = stop_after_drop > 0.0 && peak > 0.0 &&
                       load < (1.0 - stop_after_drop) * peak && strain > peak_strain &&
                       strain >= stop_after_drop_min_strain;
  return dropped && (!stop_after_drop_dilating || volumetric < peak_volumetric - kDilationAtDrop);
}

namespace {

// The names one test records under: its prefix (a test of a sweep: "test2."), its stages,
// and how its messages name it ("test2: ").
struct TestNames {
  std::string prefix, confinement, stage, who;
  explicit TestNames(const std::string& branch)
      : prefix(branch.empty() ? "" : branch + "."),
        confinement(prefix + "confinement"),
        stage(prefix + "loading"),
        who(branch.empty() ? "" : branch + ": ") {}
};

template <int D>
double lateralStress(const LoadingFrame<D>& f) {
  double sum = 0.0;
  for (int a = 0; a < D - 1; ++a) sum += f.stress(a);
  return sum / (D - 1);
}

// The deviatoric stress of the contents (LoadingFrame::interiorStress): the walls' reading
// less the grains' inertia and damping. Recorded beside the walls' q, from which the results
// come, to show how far the sample is from balance.
template <int D>
double interiorDeviatoricStress(const LoadingFrame<D>& f) {
  const Vec<D> sigma = f.interiorStress();
  double lateral = 0.0;
  for (int a = 0; a < D - 1; ++a) lateral += sigma[a];
  return sigma[Specimen<D>::kAxial] - lateral / (D - 1);
}

// The positions of the particles in slot order (stable through re-sorting), z = 0 in 2D.
template <int D>
std::vector<std::array<double, 3>> slotPositions(const Simulation<D>& sim) {
  const auto& P = sim.particles();
  std::vector<std::array<double, 3>> out(P.size(), {0.0, 0.0, 0.0});
  for (std::size_t s = 0; s < P.size(); ++s) {
    const auto& x = P.pos[P.indexOfSlot(static_cast<std::uint32_t>(s))];
    for (int d = 0; d < D; ++d) out[s][d] = x[d];
  }
  return out;
}

// What the loading loop keeps of the test: the peak, the curve, the bond breaks' log index
// at each record, the particles' positions at every twentieth of the strain range (the
// starts of the incremental strain fields), and how well the loading was controlled.
struct LoadingHistory {
  struct State {
    double strain = 0.0;
    std::uint64_t step = 0;
    double time = 0.0;
    std::vector<std::array<double, 3>> positions;
    template <class Archive>
    void visit(Archive& ar) {
      ar("strain", strain), ar("step", step), ar("time", time), ar("positions", positions);
    }
  };
  std::uint64_t start_step = 0;
  std::size_t bond_breaks_before = 0, clumps_broken_before = 0;  // the logs' lengths at the start
  double peak = -INFINITY, peak_strain = 0.0, peak_volumetric = 0.0, peak_axial = 0.0;
  double confining_error = 0.0, unbalanced_sum = 0.0, inertial_max = 0.0;
  LoadingCurve curve;
  std::vector<std::size_t> breaks_at;
  std::vector<State> states;
  AdaptiveRate rate;
  double meanUnbalanced() const {
    return unbalanced_sum / static_cast<double>(std::max<std::size_t>(1, curve.q.size()));
  }
  // The loop's state in a checkpoint (rigs/common/journal.hpp).
  template <class Archive>
  void visit(Archive& ar) {
    ar("start_step", start_step), ar("bond_breaks_before", bond_breaks_before);
    ar("clumps_broken_before", clumps_broken_before), ar("peak", peak);
    ar("peak_strain", peak_strain), ar("peak_volumetric", peak_volumetric);
    ar("peak_axial", peak_axial), ar("confining_error", confining_error);
    ar("unbalanced_sum", unbalanced_sum), ar("inertial_max", inertial_max);
    ar("curve", curve), ar("breaks_at", breaks_at), ar("states", states), ar("rate", rate);
  }
};

// Servos the formed specimen to the confinement (plus the seating stress axially). The
// ramp strains the sample far faster than the loading will (4 MPa at 2e4 MPa/s: about 20
// times the loading's 0.3125 /s), and a sample let go while still straining carries that
// motion into the loading: under density scaling 4 a shear band test began 0.45 MPa above
// its seating stress, and stayed there (measured). loading.rest_speed_ratio holds the
// confinement until the grains have come to rest against the loading's own pace.
template <int D>
void confine(Specimen<D>& sp, const LoadingTest& test, double sigma3, const TestNames& n,
             Recorder& rec, RunControl& control) {
  constexpr int ax = Specimen<D>::kAxial;
  const double platen_speed = 0.5 * test.axial_strain_rate * sp.frame->length(ax);
  servoTo(sp, sigma3 + test.seating_stress, sigma3, test.confining_rate, n.confinement, rec,
          control, test.rest_speed_ratio * platen_speed);
  if (sp.grain_kind) {
    rec.result(n.prefix + "crushed_grains_before_loading", static_cast<double>(sp.crushedGrains()),
               "");
  }
  recordBreaks(sp, rec, n.confinement);  // breaks up to here belong to the confinement
}

// Drives the axial platens at the strain rate until the strain limit (or the drop after the
// peak), recording the state and keeping the test's history.
template <int D>
LoadingHistory loadAxially(Specimen<D>& sp, const LoadingTest& test, double sigma3,
                           const TestNames& n, Recorder& rec, RunControl& control) {
  using Axis = typename LoadingFrame<D>::Axis;
  using Mode = typename LoadingFrame<D>::Mode;
  constexpr int ax = Specimen<D>::kAxial;
  auto& sim = *sp.sim;
  auto& frame = *sp.frame;
  const double rate = test.axial_strain_rate, strain_max = test.axial_strain_max;
  const auto record_every = static_cast<std::uint64_t>(sp.settings.output.record_every_steps);
  const auto snapshot_every = static_cast<std::uint64_t>(sp.settings.output.snapshot_every_steps);
  LoadingHistory h;
  h.rate = AdaptiveRate(test.boost);
  Journal::Unit unit = control.unit(n.stage);
  if (unit.done(h, sp)) return h;
  h.bond_breaks_before = sim.bondBreaks().size();
  h.clumps_broken_before = sim.clumpBreaks().size();
  frame.set(ax, Axis{Mode::StrainRate, rate});
  frame.resetReference();
  sp.resetBrokenCount();
  h.start_step = sim.steps();
  h.states.push_back({0.0, sim.steps(), sim.time(), slotPositions(sim)});
  // A confinement below 1 MPa is judged against 1 MPa: at zero the walls just keep clear.
  const double error_scale = std::max(sigma3, 1e6);
  unit.resume(h, sp);
  for (bool done = false; !done;) {
    unit.tick(h, sp);  // before the step: the loop goes on from a checkpoint's state
    frame.step();
    const std::uint64_t steps = sim.steps() - h.start_step;
    const double strain = frame.strain(ax);
    const double q = frame.stress(ax) - lateralStress(frame);
    if (q > h.peak) {
      h.peak = q;
      h.peak_strain = strain;
      h.peak_volumetric = frame.volumetricStrain();
      h.peak_axial = frame.stress(ax);
    }
    done = test.ends(strain, q, frame.volumetricStrain(), h.peak, h.peak_strain, h.peak_volumetric);
    const double rate_now = rate * h.rate.factor();
    if (steps % record_every == 0 || done) {
      recordState(sp, rec, n.prefix, n.stage, rate_now);
      rec.series(n.prefix + "axial_strain_rate_per_s", sim.steps(), sim.time(), rate_now);
      rec.series(n.prefix + "deviatoric_stress_MPa", sim.steps(), sim.time(), q / 1e6);
      rec.series(n.prefix + "interior_deviatoric_stress_MPa", sim.steps(), sim.time(),
                 interiorDeviatoricStress(frame) / 1e6);
      h.curve.axial_strain.push_back(strain);
      h.curve.q.push_back(q);
      h.curve.volumetric_strain.push_back(frame.volumetricStrain());
      h.breaks_at.push_back(sim.bondBreaks().size());
      if (strain >= h.states.back().strain + strain_max / 20.0) {
        h.states.push_back({strain, sim.steps(), sim.time(), slotPositions(sim)});
      }
      for (int a = 0; a < D - 1; ++a) {
        h.confining_error =
            std::max(h.confining_error, std::abs(frame.stress(a) - sigma3) / error_scale);
      }
      h.unbalanced_sum += sim.unbalancedForceRatio();
      h.inertial_max = std::max(h.inertial_max, inertialNumber(sp, rate_now));
    }
    if (h.rate.window(steps, sim)) frame.set(ax, Axis{Mode::StrainRate, rate * h.rate.factor()});
    if (snapshot_every > 0 && steps % snapshot_every == 0) {
      snapshot(sp, rec, n.stage, "step " + std::to_string(steps));
    }
    if (steps % 200 == 0) {
      control.tick(n.stage, sim.steps(), strain / strain_max,
                   "q " + fmt(q / 1e6) + " MPa at axial strain " + fmt(strain));
    }
  }
  snapshot(sp, rec, n.stage, "final");
  h.states.push_back({frame.strain(ax), sim.steps(), sim.time(), slotPositions(sim)});
  unit.finish(h, sp);
  return h;
}

// The test's peak, strains, breaks and control as results.
template <int D>
void recordTestResults(const Specimen<D>& sp, const LoadingHistory& h, double sigma3,
                       const TestNames& n, Recorder& rec) {
  constexpr int ax = Specimen<D>::kAxial;
  const auto& sim = *sp.sim;
  auto put = [&](const std::string& name, double v, const std::string& unit) {
    rec.result(n.prefix + name, v, unit);
  };
  put("peak_deviatoric_stress_MPa", h.peak / 1e6, "MPa");
  put("axial_stress_at_peak_MPa", h.peak_axial / 1e6, "MPa");
  put("axial_strain_at_peak", h.peak_strain, "");
  put("volumetric_strain_at_peak", h.peak_volumetric, "");
  if (sigma3 == 0.0) put("ucs_MPa", h.peak_axial / 1e6, "MPa");
  put("confining_stress_MPa", sigma3 / 1e6, "MPa");
  put("confining_stress_error_max", h.confining_error, "");
  put("axial_strain_final", sp.frame->strain(ax), "");
  put("volumetric_strain_final", sp.frame->volumetricStrain(), "");
  put("broken_bonds_tensile", static_cast<double>(sp.broken(BondBreakMode::Tensile)), "");
  put("broken_bonds_shear", static_cast<double>(sp.broken(BondBreakMode::Shear)), "");
  put("broken_bonds_total",
      static_cast<double>(sp.broken(BondBreakMode::Tensile) + sp.broken(BondBreakMode::Shear)), "");
  if (sp.grain_kind) {
    put("broken_grain_bonds_tensile",
        static_cast<double>(sp.brokenInGrains(BondBreakMode::Tensile)), "");
    put("broken_grain_bonds_shear", static_cast<double>(sp.brokenInGrains(BondBreakMode::Shear)),
        "");
    put("crushed_grains", static_cast<double>(sp.crushedGrains()), "");
  }
  if (sim.clumps().size() > 0) {  // a rigid grain crushes whole, into its pebbles
    put("crushed_grains", static_cast<double>(sim.clumpBreaks().size() - h.clumps_broken_before),
        "");
  }
  put("loading_steps", static_cast<double>(sim.steps() - h.start_step), "");
  put("mean_unbalanced_force_ratio", h.meanUnbalanced(), "");
  put("max_inertial_number", h.inertial_max, "");
}

// The critical point (rigs/common/envelope.hpp) as results, or a note that there is none.
template <int D>
CriticalPoint recordCriticalPoint(const Specimen<D>& sp, const LoadingHistory& h, double sigma3,
                                  const TestNames& n, Recorder& rec) {
  const CriticalPoint c = criticalPoint(h.curve);
  const auto& sim = *sp.sim;
  if (!c.found) {
    rec.message(sim.steps(), sim.time(), "info",
                n.who +
                    "no critical point: the sample neither turned to dilate nor left its "
                    "elastic compaction trend; load further (loading.axial_strain_max)");
    return c;
  }
  rec.result(n.prefix + "critical_is_compaction", c.compactive ? 1.0 : 0.0, "");
  rec.result(n.prefix + "critical_deviatoric_stress_MPa", c.q / 1e6, "MPa");
  // p = (sigma_1 + sigma_2 [+ sigma_3]) / D with the lateral stresses at sigma_3.
  rec.result(n.prefix + "critical_mean_stress_MPa", (sigma3 + c.q / D) / 1e6, "MPa");
  rec.result(n.prefix + "critical_axial_strain", c.axial_strain, "");
  return c;
}

// A band (rigs/common/localisation.hpp) to the notebook as `prefix + name + "_..."`; `what`
// says in which points it was found.
template <int D>
void reportBand(const Specimen<D>& sp, const Band& b, const TestNames& n, const std::string& name,
                const std::string& what, Recorder& rec) {
  const auto& sim = *sp.sim;
  const std::string p = n.prefix + name;
  rec.result(p + "_angle_deg", b.angle_to_axial_deg, "deg");
  rec.result(p + "_is_compaction", b.is_compaction() ? 1.0 : 0.0, "");
  rec.result(p + "_thickness_mm", b.thickness * 1e3, "mm");
  rec.result(p + "_contrast", b.contrast, "");
  rec.result(p + "_points", static_cast<double>(b.points), "");
  rec.message(sim.steps(), sim.time(), "info",
              n.who + "in the " + what + ": " + (b.is_compaction() ? "compaction" : "shear") +
                  " band at " + fmt(b.angle_to_axial_deg) + " deg to sigma_1, " +
                  fmt(b.thickness * 1e3) + " mm thick, " + fmt(b.contrast) +
                  " times the mean density");
}

template <int D>
void noBand(const Specimen<D>& sp, const TestNames& n, const std::string& what, Recorder& rec) {
  rec.message(sp.sim->steps(), sp.sim->time(), "info",
              n.who + "fewer than 10 " + what + ": no band to find in them");
}

// The band: in the strain field after the critical point, and in the breaks from it on.
// A dilatant test localises shear, a compactive one compaction: the band is sought in that
// part of the strain (a compaction band is a zone of localised compaction). A shear band,
// once formed, slips in place: its field is the whole post-critical range. A compaction
// band migrates along the sample (Olsson 1999; Baud et al. 2004), sharp in its own strain
// window and smeared over the whole range: its field is, of the whole range and each
// twentieth of the strain range after the critical point, the one with the most contrasted
// band.
template <int D>
void findBands(const Specimen<D>& sp, const BandAnalysis& analysis, const LoadingHistory& h,
               const CriticalPoint& critical, const TestNames& n, Recorder& rec) {
  constexpr int ax = Specimen<D>::kAxial;
  const bool compactive = critical.found && critical.compactive;
  const StrainPart part = compactive ? StrainPart::Compaction : StrainPart::Shear;
  const double width = analysis.band_width_radii * sp.mean_radius;
  const double field_from = critical.found ? critical.axial_strain : 0.0;
  const auto& states = h.states;  // the last is the end of the test
  std::size_t from = 0;
  while (from + 2 < states.size() && states[from + 1].strain <= field_from) ++from;
  struct Window {
    double from = 0.0, to = 0.0;
    Band band;
  };
  std::optional<Window> best;
  auto consider = [&](std::size_t a, std::size_t b) -> std::optional<Band> {
    const auto pts = strainedParticles(states[a].positions, states[b].positions, D,
                                       4.0 * sp.mean_radius, analysis.strained_fraction, part);
    if (pts.size() < 10) return std::nullopt;
    const Band band = findBand(pts, D, ax, width);
    if (!best || band.contrast > best->band.contrast) {
      best = Window{states[a].strain, states[b].strain, band};
    }
    return band;
  };
  const std::size_t last = states.size() - 1;
  if (const auto range = consider(from, last)) {
    rec.result(n.prefix + "band_range_contrast", range->contrast, "");
  }
  if (compactive) {
    // Each window's band, at the window's end: how the band moves and turns as the
    // compaction proceeds.
    for (std::size_t k = from; k + 1 < last; ++k) {
      if (const auto band = consider(k, k + 1)) {
        rec.series(n.prefix + "band_window_angle_deg", states[k + 1].step, states[k + 1].time,
                   band->angle_to_axial_deg);
        rec.series(n.prefix + "band_window_contrast", states[k + 1].step, states[k + 1].time,
                   band->contrast);
      }
    }
  }
  rec.result(n.prefix + "band_in_compaction_field", compactive ? 1.0 : 0.0, "");
  const std::string field = compactive ? "most compacted particles" : "most sheared particles";
  if (best) {
    rec.result(n.prefix + "band_strain_from", best->from, "");
    rec.result(n.prefix + "band_strain_to", best->to, "");
    reportBand(sp, best->band, n, "band", field, rec);
  } else {
    noBand(sp, n, field, rec);
  }
  // The bond breaks since the critical point, from the simulation's log.
  const auto& log = sp.sim->bondBreaks();
  const std::size_t first = critical.found ? h.breaks_at[critical.index] : h.bond_breaks_before;
  std::vector<std::array<double, 3>> breaks;
  for (std::size_t k = first; k < log.size(); ++k) {
    std::array<double, 3> x{0.0, 0.0, 0.0};
    for (int d = 0; d < D; ++d) x[d] = log[k].position[d];
    breaks.push_back(x);
  }
  const std::string from_critical = "bond breaks from the critical point on";
  if (breaks.size() >= 10) {
    reportBand(sp, findBand(breaks, D, ax, width), n, "break_band", from_critical, rec);
  } else {
    noBand(sp, n, from_critical, rec);
  }
}

template <int D>
void runDimension(const Settings& s, Recorder& rec, RunControl& control) {
  Specimen<D> sp = buildSpecimen<D>(s.specimen, control);
  recordSample(sp, rec);
  formAndCement(sp, rec, control);
  confineAndLoad(sp, s.test, s.analysis, s.confining_stress, "", rec, control);
  recordTimings<D>(rec, {sp.sim.get()});
}

}  // namespace

template <int D>
void recordSample(const Specimen<D>& sp, Recorder& rec) {
  rec.result("particles", static_cast<double>(sp.sim->particles().size()), "");
  const auto& ar = sp.grain_aspect_ratios;
  if (ar.empty()) return;
  rec.result("grains", static_cast<double>(ar.size()), "");
  rec.result("grain_aspect_ratio_mean",
             std::accumulate(ar.begin(), ar.end(), 0.0) / static_cast<double>(ar.size()), "");
  rec.result("grain_aspect_ratio_max", *std::max_element(ar.begin(), ar.end()), "");
  if (sp.grain_kind) {
    rec.result("grain_bonds_installed", static_cast<double>(sp.grain_bonds.installed), "");
  }
}

template <int D>
TestOutcome confineAndLoad(Specimen<D>& sp, const LoadingTest& test, const BandAnalysis& analysis,
                           double sigma3, const std::string& branch, Recorder& rec,
                           RunControl& control) {
  const TestNames n(branch);
  confine(sp, test, sigma3, n, rec, control);
  const LoadingHistory h = loadAxially(sp, test, sigma3, n, rec, control);
  recordTestResults(sp, h, sigma3, n, rec);
  TestOutcome out;
  out.sigma3 = sigma3;
  out.critical = recordCriticalPoint(sp, h, sigma3, n, rec);
  if (h.confining_error > 0.01) {
    rec.message(sp.sim->steps(), sp.sim->time(), "warning",
                n.who + "the confining stress strayed " + fmt(100 * h.confining_error) +
                    "% from its target during loading; raise numerics.servo_speed_radii_per_step "
                    "or lower the loading rate");
  }
  warnIfNotQuasiStatic(sp, rec, n.stage, h.meanUnbalanced(), h.inertial_max);
  findBands(sp, analysis, h, out.critical, n, rec);
  return out;
}

void run(const Settings& s, Recorder& rec, RunControl& control) {
  byDimension(s.specimen.protocol.dimension,
              [&](auto dim) { runDimension<dim.value>(s, rec, control); });
}

template void recordSample<2>(const Specimen<2>&, Recorder&);
template void recordSample<3>(const Specimen<3>&, Recorder&);
template TestOutcome confineAndLoad<2>(Specimen<2>&, const LoadingTest&, const BandAnalysis&,
                                       double, const std::string&, Recorder&, RunControl&);
template TestOutcome confineAndLoad<3>(Specimen<3>&, const LoadingTest&, const BandAnalysis&,
                                       double, const std::string&, Recorder&, RunControl&);

}  // namespace rocklab::rigs::biaxial
