#include "rigs/common/formation.hpp"

#include <sstream>

#include "rigs/common/formed_samples.hpp"
#include "rigs/common/measurements.hpp"

namespace rocklab::rigs {

namespace {

// When a densification may end before the unbalanced force ratio settles: the
// frictionless grains creep into a denser packing for long after they are dense, and the
// ratio then dips below its tolerance at a step that varies from seed to seed. A porosity
// that no longer falls may end it instead (off in the protocols: ending sooner changes the
// material, rigs/README.md).
struct Stall {
  std::uint64_t window = 1;    // steps
  double porosity_change = 0;  // -, the fall over a window below which it is dense; 0: never
};

// A settling's loop state (what a checkpoint inside it keeps).
struct Settling {
  std::uint64_t start = 0;
  double porosity = 1.0;  // at the last stall window's start
  template <class Archive>
  void visit(Archive& ar) {
    ar("start", start), ar("porosity", porosity);
  }
};

// Runs the frame until the stresses hold and the sample is in equilibrium (or, with a
// stall window, its porosity has stopped falling); returns the steps it took. Balance alone
// does not see a sample that moves as a whole: one strained by a fast servo ramp keeps
// straining after it, with small unbalanced forces. With `rest_speed` above 0 the grains'
// mean speed must also have fallen below it.
template <int D>
std::uint64_t settle(Specimen<D>& sp, const std::string& stage, Recorder& rec, RunControl& control,
                     const Stall& stall = {}, double rest_speed = 0.0) {
  Journal::Unit unit = control.unit("settle " + stage);
  Settling st{sp.sim->steps(), sp.frame->porosity()};
  std::uint64_t done = 0;
  if (unit.done(done, sp)) return done;
  unit.resume(st, sp);
  auto& sim = *sp.sim;
  const FormationSettings& f = sp.settings.formation;
  const auto record_every = static_cast<std::uint64_t>(sp.settings.output.record_every_steps);
  const auto max_steps = static_cast<std::uint64_t>(f.max_steps);
  for (;; unit.tick(st, sp)) {
    sp.frame->step();
    done = sim.steps() - st.start;
    if (done % record_every == 0) recordState(sp, rec, stage + ".", stage, 0.0);
    if (done % 100 != 0) continue;
    const double err = sp.frame->stressError(), u = sim.unbalancedForceRatio();
    control.tick(stage, sim.steps(), -1.0,
                 "stress error " + fmt(err) + ", unbalanced force ratio " + fmt(u));
    const bool held = err < f.stress_tolerance;
    if (held && u < f.unbalanced_force_ratio &&
        (rest_speed <= 0.0 || sim.meanSpeed() < rest_speed)) {
      unit.finish(done, sp);
      return done;
    }
    if (stall.porosity_change > 0.0 && done % stall.window == 0) {
      const double porosity = sp.frame->porosity(), fall = st.porosity - porosity;
      st.porosity = porosity;
      if (held && fall < stall.porosity_change) {
        rec.message(sim.steps(), sim.time(), "info",
                    stage + " ended by its porosity: it fell by " + fmt(fall) + " over the last " +
                        std::to_string(stall.window) +
                        " steps (formation.densified_porosity_change " +
                        fmt(stall.porosity_change) + "), the unbalanced force ratio is " + fmt(u));
        unit.finish(done, sp);
        return done;
      }
    }
    if (done >= max_steps) {
      std::ostringstream why;
      why << stage << " did not settle in " << done << " steps: the wall stresses miss their "
          << "targets by " << fmt(err) << " (formation.stress_tolerance " << f.stress_tolerance
          << "), the unbalanced force ratio is " << fmt(u) << " (formation.unbalanced_force_ratio "
          << f.unbalanced_force_ratio << ")";
      if (rest_speed > 0.0) {
        why << ", the grains' mean speed is " << fmt(sim.meanSpeed()) << " m/s (at rest below "
            << fmt(rest_speed) << " m/s: loading.rest_speed_ratio of the platens' speed)";
      }
      why << "; raise formation.max_steps or loosen the tolerances";
      throw std::runtime_error(why.str());
    }
  }
}

// Installs the cement on every contact and near contact, unloaded, and records what it did.
template <int D>
void cement(Specimen<D>& sp, Recorder& rec) {
  auto& sim = *sp.sim;
  const CementSettings& c = sp.settings.cement;
  sp.cement_kind = sim.addBondKind(c.kind);
  sp.cement = sim.cement(*sp.cement_kind, c.gap_ratio);
  rec.result("bonds_installed", static_cast<double>(sp.cement.installed), "");
  rec.result("bonds_skipped_nonpositive", static_cast<double>(sp.cement.skipped_nonpositive), "");
  rec.result("bonds_redrawn", static_cast<double>(sp.cement.redrawn), "");
  rec.result("cement_candidates", static_cast<double>(sp.cement.candidates), "");
  rec.message(sim.steps(), sim.time(), "info",
              "cemented " + std::to_string(sp.cement.installed) + " of " +
                  std::to_string(sp.cement.candidates) + " contacts; " +
                  std::to_string(sp.cement.skipped_nonpositive) +
                  " strength draws <= 0 left uncemented (bonds.negative_strength = " +
                  (c.kind.negative == NegativeStrength::Resample ? "resample" : "skip") + ")");
}

}  // namespace

template <int D>
void formAndCement(Specimen<D>& sp, Recorder& rec, RunControl& control) {
  using Axis = typename LoadingFrame<D>::Axis;
  using Mode = typename LoadingFrame<D>::Mode;
  const FormationSettings& f = sp.settings.formation;
  auto& sim = *sp.sim;
  auto ownFriction = [&] {
    MaterialTable own;
    for (const Material& m : sim.materials().all()) own.add(m);
    own[0].friction = sp.settings.material.grain.friction;
    sim.replaceMaterials(std::move(own));
  };
  std::uint64_t steps = 0;
  if (sp.formed_from) {
    // Formed by an earlier run of the lab (formed_samples.hpp): its records stand for the
    // formation, which would have gone the very same way.
    const FormedOrigin& o = *sp.formed_from;
    o.records.replay(rec);
    steps = o.densification_steps + o.formation_steps;
    rec.message(sim.steps(), sim.time(), "info",
                "formation.reuse: the sample formed by an earlier run with the same formation "
                "(" +
                    o.file + "), every grain bond stronger than it was loaded while forming; " +
                    std::to_string(steps) + " steps not run again");
  } else if (f.enabled) {
    if (!sp.formed_note.empty()) {
      rec.message(sim.steps(), sim.time(), "info", "formation.reuse: " + sp.formed_note);
    }
    // Kept for reuse only when formed here from its start (not resumed inside it), every
    // record captured and each grain bond's peak stresses tracked throughout.
    const FormedSamples* store = control.formedSamples();
    const bool keep = store && !control.replaying();
    if (keep) sim.trackBondPeaks(true);
    FormationCapture capture(rec);
    Recorder& forming = keep ? static_cast<Recorder&>(capture) : rec;
    // Densify isotropically at the lateral stress with the formation friction (a dense
    // packing), then with the grains' own friction take the formation state: a deviatoric
    // stress the low friction could not hold.
    for (int a = 0; a < D; ++a) sp.frame->set(a, Axis{Mode::Stress, 0.0, f.lateral_stress, 0.0});
    sim.setLocalDamping(f.local_damping);
    const Stall stall{static_cast<std::uint64_t>(f.densified_window_steps),
                      f.densified_porosity_change};
    const std::uint64_t densification = settle(sp, "densification", forming, control, stall);
    sim.setLocalDamping(sp.settings.simulation.local_damping);
    ownFriction();
    for (int a = 0; a < D; ++a) {
      const double target = a == Specimen<D>::kAxial ? f.axial_stress : f.lateral_stress;
      sp.frame->set(a, Axis{Mode::Stress, 0.0, target, 0.0});
    }
    const std::uint64_t formation = settle(sp, "formation", forming, control);
    steps = densification + formation;
    if (keep) {
      const std::string why = keepFormed(*store, sp, densification, formation, capture);
      if (!why.empty()) {
        rec.message(sim.steps(), sim.time(), "info",
                    "formation.reuse: the formed sample is not kept: " + why);
      }
      sim.trackBondPeaks(false);
    }
  }
  if (f.enabled) {
    // The sample was formed at formation.density_scaling (buildSpecimen); the rest runs at
    // numerics.density_scaling, the servo's cap still a move per step at the new step.
    const double loading_scaling = sp.settings.simulation.timestep.density_scaling;
    if (loading_scaling != f.density_scaling) {
      sim.setDensityScaling(loading_scaling);
      if (!(sim.dt() > 0.0)) sim.prepare();  // read back from a checkpoint: its step comes here
      sp.setServo();
    }
  } else {
    // The sample as it came (a file's): the walls stay at its box, the contacts as they are.
    ownFriction();
    rec.message(sim.steps(), sim.time(), "info",
                "formation.enabled = false: the sample is used as it is, walls at its box");
  }
  rec.result("formation_steps", static_cast<double>(steps), "");
  rec.result("porosity_after_formation", sp.frame->porosity(), "");
  rec.result("coordination_after_formation", sim.coordinationNumber(), "");
  rec.result("axial_stress_after_formation_MPa", sp.frame->stress(Specimen<D>::kAxial) / 1e6,
             "MPa");
  if (sp.settings.cement.enabled) cement(sp, rec);
  sim.restartEnergyLedger();
  sp.frame->resetReference();
  sp.resetBrokenCount();
  recordBreaks(sp, rec, "formation");  // the formation's, before any branch of the sample
  snapshot(sp, rec, "formation", "formed");
}

// A servo ramp's course: where it started, where it goes, in how long (the loop state a
// checkpoint inside the ramp keeps).
template <int D>
struct Ramp {
  std::array<double, D> from{}, to{};
  double duration = 0.0, t0 = 0.0;
  template <class Archive>
  void visit(Archive& ar) {
    ar("from", from), ar("to", to), ar("duration", duration), ar("t0", t0);
  }
};

template <int D>
void servoTo(Specimen<D>& sp, double axial, double lateral, double rate, const std::string& stage,
             Recorder& rec, RunControl& control, double rest_speed) {
  using Axis = typename LoadingFrame<D>::Axis;
  using Mode = typename LoadingFrame<D>::Mode;
  constexpr int ax = Specimen<D>::kAxial;
  const auto record_every = static_cast<std::uint64_t>(sp.settings.output.record_every_steps);
  Journal::Unit unit = control.unit("ramp " + stage);
  Ramp<D> r;
  if (!unit.done(r, sp)) {
    double span = 0.0;
    for (int a = 0; a < D; ++a) {
      r.from[a] = sp.frame->stress(a);
      r.to[a] = a == ax ? axial : lateral;
      span = std::max(span, std::abs(r.to[a] - r.from[a]));
    }
    r.duration = span / rate;
    for (int a = 0; a < D; ++a) {
      sp.frame->set(a, Axis{Mode::Stress, 0.0, r.from[a], (r.to[a] - r.from[a]) / r.duration});
    }
    r.t0 = sp.sim->time();
    unit.resume(r, sp);
    auto& sim = *sp.sim;
    for (; sim.time() - r.t0 < r.duration; unit.tick(r, sp)) {
      sp.frame->step();
      if (sim.steps() % record_every == 0) recordState(sp, rec, stage + ".", stage, 0.0);
      if (sim.steps() % 100 == 0) {
        control.tick(stage, sim.steps(), (sim.time() - r.t0) / r.duration,
                     "axial " + fmt(sp.frame->stress(ax) / 1e6) + " MPa");
      }
    }
    for (int a = 0; a < D; ++a) sp.frame->set(a, Axis{Mode::Stress, 0.0, r.to[a], 0.0});
    unit.finish(r, sp);
  }
  settle(sp, stage, rec, control, {}, rest_speed);
}

template void formAndCement<2>(Specimen<2>&, Recorder&, RunControl&);
template void formAndCement<3>(Specimen<3>&, Recorder&, RunControl&);
template void servoTo<2>(Specimen<2>&, double, double, double, const std::string&, Recorder&,
                         RunControl&, double);
template void servoTo<3>(Specimen<3>&, double, double, double, const std::string&, Recorder&,
                         RunControl&, double);

}  // namespace rocklab::rigs
