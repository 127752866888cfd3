#include "rigs/permeameter/permeameter.hpp"

#include <chrono>
#include <cmath>

#include "rigs/common/formation.hpp"
#include "rigs/common/measurements.hpp"

namespace rocklab::rigs::permeameter {

void Settings::validate() const {
  if (measurement.direction == FlowDirection::Both && flow.apply_forces) {
    throw InvalidParameter("", "flow.apply_forces",
                           "must be false with flow.direction = \"both\": the pressures of two "
                           "flows cannot act on the particles at once (a permeability "
                           "measurement's drop is small against the stresses)");
  }
  const FormationSettings& f = specimen.formation;
  if (mode == LoadingMode::Hydrostatic &&
      (stress_max <= f.axial_stress || stress_max <= f.lateral_stress)) {
    throw InvalidParameter("", "loading.stress_max_MPa", "must exceed the formation stresses");
  }
}

namespace {

// Kozeny-Carman, equation 8: k = d^2 phi^3 / (36 gamma_T (1 - phi)^2).
double kozenyCarman(double d, double phi, double gamma_t) {
  return d * d * phi * phi * phi / (36.0 * gamma_t * (1.0 - phi) * (1.0 - phi));
}

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

template <int D>
FlowStage<D>::FlowStage(const flow::FlowSettings& settings, FlowDirection direction)
    : apply_forces_(settings.apply_forces) {
  auto add = [&](const std::string& name, int axis) {
    flow::FlowSettings f = settings;
    f.axis = axis;
    dirs_.push_back({name, std::make_unique<flow::FlowCoupling<D>>(f), 0.0, {}});
  };
  if (direction != FlowDirection::Normal) add("along", D - 1);
  if (direction != FlowDirection::Along) add("normal", 0);
}

template <int D>
flow::FlowReading FlowStage<D>::solve(Direction& d, Simulation<D>* apply_to,
                                      const Simulation<D>& sim) {
  try {
    d.reading = apply_to ? d.coupling->update(*apply_to) : d.coupling->measure(sim);
  } catch (const flow::FlowStepTooLarge& e) {
    throw InvalidParameter("permeameter", "flow.explicit_timestep_s", e.what());
  }
  network_seconds_ += d.reading.network_seconds;
  solve_seconds_ += d.reading.solve.seconds;
  ++solves_;
  switch (d.reading.solve.path) {
    case flow::ImplicitPath::Factorised:
      ++factorised_;
      break;
    case flow::ImplicitPath::Refactorised:
      ++refactorised_;
      break;
    case flow::ImplicitPath::Iterated:
      ++iterated_;
      break;
    default:
      break;
  }
  return d.reading;
}

template <int D>
flow::FlowReading FlowStage<D>::start(const Simulation<D>& sim) {
  return solve(dirs_.front(), nullptr, sim);
}

template <int D>
void FlowStage<D>::calibrate(double alpha, const Simulation<D>& sim) {
  for (auto& d : dirs_) d.coupling->setAlpha(alpha);
  solve(dirs_.front(), nullptr, sim);
}

template <int D>
void FlowStage<D>::takeInitialPermeability(const Simulation<D>& sim) {
  for (std::size_t k = 0; k < dirs_.size(); ++k) {
    dirs_[k].k0 =
        k == 0 ? dirs_[k].reading.permeability : solve(dirs_[k], nullptr, sim).permeability;
  }
}

template <int D>
bool FlowStage<D>::update(Simulation<D>& sim) {
  if (updated_ && sim.steps() == last_step_) return false;
  updated_ = true;
  last_step_ = sim.steps();
  const auto t0 = std::chrono::steady_clock::now();
  for (std::size_t k = 0; k < dirs_.size(); ++k) {
    const bool apply = k == 0 && apply_forces_;
    solve(dirs_[k], apply ? &sim : nullptr, sim);
  }
  triangulations_ = std::max(triangulations_, dirs_.front().reading.triangulations);
  update_seconds_ += secondsSince(t0);
  ++updates_;
  return true;
}

template <int D>
FlowRecorder<D>::FlowRecorder(const Specimen<D>& sp, const Measurement& m, Recorder& rec)
    : sp_(sp), m_(m), rec_(rec) {}

template <int D>
double FlowRecorder<D>::startKozenyCarman() {
  const auto& frame = *sp_.frame;
  volume0_ = frame.volume();
  porosity0_ = m_.kozeny_carman_porosity_initial > 0.0 ? m_.kozeny_carman_porosity_initial
                                                       : frame.porosity();
  diameter_ = 2.0 * sp_.mean_radius;
  kc0_ = kozenyCarman(diameter_, porosity0_, m_.kozeny_carman_gamma_t);
  return kc0_;
}

template <int D>
void FlowRecorder<D>::initial(const flow::FlowReading& r, double alpha) {
  rec_.result("conductance_alpha", alpha, "");
  rec_.result("porosity_initial", sp_.frame->porosity(), "");
  rec_.result("kozeny_carman_porosity_initial", porosity0_, "");
  rec_.result("kozeny_carman_initial_m2", kc0_, "m^2");
  rec_.result("permeability_initial_m2", r.permeability, "m^2");
  rec_.result("pores", static_cast<double>(r.pores), "");
  rec_.result("pipes", static_cast<double>(r.pipes), "");
  rec_.result("pores_merged", static_cast<double>(r.clusters), "");
  rec_.result("pipes_merged", static_cast<double>(r.cluster_pipes), "");
  rec_.result("hidden_particles", static_cast<double>(r.hidden), "");
  rec_.result("isolated_pores", static_cast<double>(r.isolated), "");
  rec_.result("hydraulic_length_mm", r.length * 1e3, "mm");
  rec_.result("flow_section_mm2", r.area * 1e6, "mm^2");
  rec_.result("explicit_critical_step_s", r.critical_step, "s");
  rec_.result("flow_balance_error", std::abs(r.outflow - r.inflow) / r.inflow, "");
}

template <int D>
void FlowRecorder<D>::initialByDirection(const FlowStage<D>& flow) {
  const auto& dirs = flow.directions();
  if (dirs.size() < 2) return;
  for (const auto& d : dirs) rec_.result("permeability_initial_" + d.name + "_m2", d.k0, "m^2");
}

template <int D>
void FlowRecorder<D>::state(const FlowStage<D>& flow) {
  const auto& sim = *sp_.sim;
  const auto& frame = *sp_.frame;
  const std::uint64_t step = sim.steps();
  const double t = sim.time();
  const auto& dirs = flow.directions();
  for (const auto& d : dirs) {
    const double ratio = d.reading.permeability / d.k0;
    if (&d == &flow.primary()) {
      rec_.series("k_over_k0", step, t, ratio);
      rec_.series("permeability_m2", step, t, d.reading.permeability);
    }
    if (dirs.size() > 1) rec_.series("k_over_k0_" + d.name, step, t, ratio);
  }
  const flow::FlowReading& last = dirs.back().reading;
  // Kozeny-Carman on the porosity that follows the sample's volume from its initial one.
  const double phi = 1.0 - (1.0 - porosity0_) * volume0_ / frame.volume();
  rec_.series("kozeny_carman_over_k0", step, t,
              kozenyCarman(diameter_, phi, m_.kozeny_carman_gamma_t) / kc0_);
  rec_.series("flow.porosity", step, t, phi);
  rec_.series("flow.mean_stress_MPa", step, t, frame.meanStress() / 1e6);
  rec_.series("flow.axial_stress_MPa", step, t, frame.stress(D - 1) / 1e6);
  rec_.series("flow.lateral_stress_MPa", step, t, frame.stress(0) / 1e6);
  rec_.series("flow.axial_strain", step, t, frame.strain(D - 1));
  rec_.series("flow.volumetric_strain", step, t, frame.volumetricStrain());
  rec_.series("flow.solve_seconds", step, t, last.solve.seconds);
  rec_.series("flow.solve_iterations", step, t, static_cast<double>(last.solve.iterations));
  rec_.series("flow.triangulations", step, t, static_cast<double>(last.triangulations));
}

template <int D>
void FlowRecorder<D>::pressureField(const FlowStage<D>& flow, const std::string& stage) {
  const auto& coupling = *flow.primary().coupling;
  const auto& net = coupling.network();
  const auto& p = coupling.porePressure();
  for (std::size_t c = 0; c < net.pores(); ++c) {
    EventRecord e;
    e.step = sp_.sim->steps();
    e.time = sp_.sim->time();
    e.stage = stage;
    e.kind = "pore_pressure";
    e.x = net.centroid()[c][0];
    e.y = net.centroid()[c][1];
    if constexpr (D == 3) e.z = net.centroid()[c][2];
    e.value = p[c];
    rec_.event(e);
  }
}

template <int D>
void FlowRecorder<D>::compareSolvers(const FlowStage<D>& flow) {
  const auto& sim = *sp_.sim;
  const auto t0 = std::chrono::steady_clock::now();
  const auto costs = flow.primary().coupling->compareSolvers();
  // Its own stage timing: the explicit schemes can take most of a run (the real-volume one
  // runs to flow.explicit_max_steps where the network has flat pores).
  rec_.stageTiming("flow_solver_comparison",
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1);
  for (const auto& c : costs) {
    if (!c.refused.empty()) {
      rec_.message(sim.steps(), sim.time(), "info", "solver " + c.name + " not run: " + c.refused);
      continue;
    }
    rec_.result("solver_" + c.name + "_seconds", c.seconds, "s");
    rec_.result("solver_" + c.name + "_iterations", static_cast<double>(c.iterations), "");
    rec_.result("solver_" + c.name + "_max_difference", c.max_difference, "");
    rec_.result("solver_" + c.name + "_converged", c.converged ? 1.0 : 0.0, "");
    if (c.predicted_iterations > 0.0) {
      rec_.result("solver_" + c.name + "_predicted_iterations", c.predicted_iterations, "");
    }
    if (!c.converged) {
      const std::string rate =
          c.predicted_iterations > 0.0
              ? ": given up, its rate so far needs at least " + fmt(c.predicted_iterations)
              : "";
      rec_.message(sim.steps(), sim.time(), "warning",
                   "solver " + c.name + " did not converge in " + fmt(double(c.iterations)) +
                       " iterations" + rate +
                       " (flow.explicit_max_steps, flow.explicit_tolerance)");
    }
  }
}

template <int D>
void FlowRecorder<D>::final(const FlowStage<D>& flow) {
  rec_.stageTiming("flow_network", flow.networkSeconds(), flow.solves());
  rec_.stageTiming("flow_solve", flow.solveSeconds(), flow.solves());
  const auto& dirs = flow.directions();
  for (const auto& d : dirs) {
    const std::string suffix = dirs.size() > 1 ? "_" + d.name : "";
    rec_.result("k_over_k0_final" + suffix, d.coupling->lastPermeability() / d.k0, "");
  }
  rec_.result("triangulations", static_cast<double>(flow.triangulations()), "");
  rec_.result("flow_solves_factorised", static_cast<double>(flow.factorised()), "");
  rec_.result("flow_solves_refactorised", static_cast<double>(flow.refactorised()), "");
  rec_.result("flow_solves_iterated", static_cast<double>(flow.iterated()), "");
  pressureField(flow, "final");
  rec_.stageTiming("flow", flow.updateSeconds(), flow.updates());
}

namespace {

// Measures the permeability before loading (calibrating alpha when asked), records it with
// the network, the pressure field and the solvers' cost, and applies the first pressures.
template <int D>
void startFlow(Specimen<D>& sp, const Settings& s, FlowStage<D>& flow, FlowRecorder<D>& record,
               RunControl& control) {
  const auto& sim = *sp.sim;
  const double kc0 = record.startKozenyCarman();
  control.tick("flow network", sim.steps(), -1, "triangulating");
  flow::FlowReading r = flow.start(sim);
  double alpha = s.flow.law.alpha;
  if (s.measurement.calibrate_alpha) {
    // k is proportional to alpha (every conductance is): one rescaling matches it.
    alpha *= kc0 / r.permeability;
    flow.calibrate(alpha, sim);
    r = flow.primary().reading;
  }
  record.initial(r, alpha);
  flow.takeInitialPermeability(sim);
  record.initialByDirection(flow);
  record.pressureField(flow, "initial");
  if (s.measurement.compare_solvers) record.compareSolvers(flow);
}

template <int D>
void runDimension(const Settings& s, Recorder& rec, RunControl& control) {
  Specimen<D> sp = buildSpecimen<D>(s.specimen, control);
  biaxial::recordSample(sp, rec);
  formAndCement(sp, rec, control);
  FlowStage<D> flow(s.flow, s.measurement.direction);
  FlowRecorder<D> record(sp, s.measurement, rec);
  startFlow(sp, s, flow, record, control);
  auto solveAndRecord = [&] {
    if (flow.update(*sp.sim)) record.state(flow);
  };
  solveAndRecord();
  // Section 3.5.2: the network is solved to steady state every n particle steps, its
  // pressures applied, the permeability recorded.
  sp.frame->couple(solveAndRecord, static_cast<std::uint64_t>(s.measurement.update_every_steps),
                   &flow);
  if (s.mode == LoadingMode::Hydrostatic) {
    servoTo(sp, s.stress_max, s.stress_max, s.stress_rate, "loading", rec, control);
    rec.result("mean_stress_peak_MPa", sp.frame->meanStress() / 1e6, "MPa");
    rec.result("volumetric_strain_at_peak", sp.frame->volumetricStrain(), "");
    rec.result("porosity_at_peak", sp.frame->porosity(), "");
    snapshot(sp, rec, "loading", "final");
  } else {
    biaxial::confineAndLoad(sp, s.test, s.analysis, s.confining_stress, "", rec, control);
  }
  sp.frame->couple(nullptr, 1);
  solveAndRecord();
  record.final(flow);
  recordTimings<D>(rec, {sp.sim.get()});
}

}  // namespace

void run(const Settings& s, Recorder& rec, RunControl& control) {
  byDimension(s.specimen.protocol.dimension,
              [&](auto dim) { runDimension<dim.value>(s, rec, control); });
}

template class FlowStage<2>;
template class FlowStage<3>;
template class FlowRecorder<2>;
template class FlowRecorder<3>;

}  // namespace rocklab::rigs::permeameter
