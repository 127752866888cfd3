#include "rigs/permeameter/permeameter.hpp"

#include <chrono>
#include <cmath>
#include <memory>
#include <sstream>

#include "lab/flow/coupling.hpp"
#include "rigs/biaxial/loading.hpp"
#include "rigs/common/specimen.hpp"

namespace rocklab::rigs::permeameter {

using protocol::range;
using protocol::Settings;

void declare(protocol::Schema& s) {
  s.choice("loading.mode", {"hydrostatic", "biaxial"}, "hydrostatic",
           "hydrostatic: every axis to one stress (2D: plane strain, equal in x and y); "
           "biaxial: confinement, then axial strain through failure (3D: triaxial)");
  range(s.real("loading.stress_max_MPa", "MPa", 1e6, 30.0, "hydrostatic: peak stress"), 0, true,
        1e5, false);
  range(s.real("loading.stress_rate_MPa_per_s", "MPa/s", 1e6, 2e4, "hydrostatic: stress rate"), 0,
        true, 1e12, false);
  range(s.real("loading.confining_stress_MPa", "MPa", 1e6, 2.0,
               "biaxial: lateral stress held by servo walls (sigma_3)"),
        0, false, 1e4, false);
  biaxial::declareLoading(s);

  s.choice("flow.direction", {"along", "normal", "both"}, "along",
           "flow along the loading axis (y 2D, z 3D: top to bottom, Figure 10), normal to it "
           "(x), or both, measured side by side on the same test (Figure 14)");
  range(s.real("flow.pressure_drop_kPa", "kPa", 1e3, 10.0,
               "inlet over outlet pressure (the outlet is the reference, 0)"),
        0, true, 1e6, false);
  range(s.real("flow.viscosity_mPa_s", "mPa s", 1e-3, 1.0, "fluid viscosity (water: 1)"), 0, true,
        1e9, false);
  range(s.real("flow.fluid_bulk_modulus_GPa", "GPa", 1e9, 2.2, "K_f of equation 5 (water: 2.2)"), 0,
        true, 1e3, false);
  range(s.real("flow.conductance_alpha", "-", 1, 1.0,
               "alpha of equation 3, C = alpha pi r_e^4 / (8 mu r_av) (1: Hagen-Poiseuille)"),
        0, true, 1e6, false);
  s.flag("flow.calibrate_alpha", false,
         "set alpha so that the permeability before loading equals Kozeny-Carman's "
         "(section 3.5.3; the paper found 0.82 in its units)");
  range(s.real("flow.kozeny_carman_gamma_T", "-", 1, 5.0,
               "pore shape factor times tortuosity of equation 8 (about 5)"),
        0, true, 1e3, false);
  range(s.real("flow.kozeny_carman_porosity_initial", "-", 1, 0.0,
               "porosity Kozeny-Carman starts from, then follows the volumetric strain (0: the "
               "sample's measured porosity; the paper's 2D comparison assumes 0.30)"),
        0, false, 1, true);
  s.choice("flow.solver", {"implicit", "explicit"}, "implicit",
           "steady state by one sparse solve, or by the paper's explicit time stepping");
  s.choice("flow.implicit_method", {"cholesky", "cg"}, "cholesky",
           "sparse LDL^T, or conjugate gradients with incomplete Cholesky");
  range(s.real("flow.tolerance", "-", 1, 1e-12,
               "conjugate gradients' relative residual; the explicit scheme stops when every "
               "pore's imbalance is below it (relative to its conductances times the drop)"),
        0, true, 1e-2, false);
  range(s.real("flow.explicit_timestep_s", "s", 1, 0.0,
               "explicit step (0: the critical step of equation 6; larger is refused)"),
        0, false, 1e6, false);
  s.flag("flow.virtual_volume", true,
         "explicit scheme with the virtual pore volumes of equation 7 (steady state only)");
  range(s.integer("flow.explicit_max_steps", 1000000,
                  "explicit steps before giving up (the paper's scheme converges like Jacobi "
                  "iterations: slowly on long networks)"),
        1, false, 1e10, false);
  range(s.real("flow.merge_conductance_ratio", "-", 1, 0.0,
               "merge the pores of a pipe whose conductance exceeds this times the median "
               "(Figure 7b; 0: off)"),
        0, false, 1e9, false);
  range(s.real("flow.merge_small_pore_ratio", "-", 1, 0.01,
               "merge a pore whose own explicit step is below this times the median into its "
               "best connected neighbour (flat cells; 0: off)"),
        0, false, 1, true);
  range(s.real("flow.retriangulate_displacement_radii", "-", 1, 0.5,
               "triangulate anew once a particle has moved this many mean radii"),
        0, true, 100, false);
  range(s.integer("flow.update_every_steps", 2000,
                  "particle steps between steady-state solves (section 3.5.2: every n)"),
        1, false, 1e9, false);
  s.flag("flow.apply_forces", true, "the pore pressures act on the particles");
  s.flag("flow.compare_solvers", true,
         "before loading, solve the network with every solver and record their cost");
}

void validate(const Settings& s) {
  biaxial::validateLoading(s);
  if (s.text("flow.direction") == "both" && s.flag("flow.apply_forces")) {
    protocol::fail(s, "flow.apply_forces",
                   "must be false with flow.direction = \"both\": the pressures of two flows "
                   "cannot act on the particles at once (a permeability measurement's drop is "
                   "small against the stresses)");
  }
  if (s.text("loading.mode") == "hydrostatic" &&
      (s.real("loading.stress_max_MPa") <= s.real("formation.axial_stress_MPa") ||
       s.real("loading.stress_max_MPa") <= s.real("formation.lateral_stress_MPa"))) {
    protocol::fail(s, "loading.stress_max_MPa", "must exceed the formation stresses");
  }
}

namespace {

using flow::FlowCoupling;
using flow::FlowReading;

// Kozeny-Carman, equation 8: k = d^2 phi^3 / (36 gamma_T (1 - phi)^2).
double kozenyCarman(double d, double phi, double gamma_t) {
  return d * d * phi * phi * phi / (36.0 * gamma_t * (1.0 - phi) * (1.0 - phi));
}

flow::FlowSettings flowSettings(const Settings& s, int axis) {
  flow::FlowSettings f;
  f.law.alpha = s.real("flow.conductance_alpha");
  f.law.viscosity = s.si("flow.viscosity_mPa_s");
  f.axis = axis;
  f.pressures = {s.si("flow.pressure_drop_kPa"), 0.0};
  f.merge.conductance_ratio = s.real("flow.merge_conductance_ratio");
  f.merge.small_pore_ratio = s.real("flow.merge_small_pore_ratio");
  f.solver =
      s.text("flow.solver") == "explicit" ? flow::FlowSolver::Explicit : flow::FlowSolver::Implicit;
  f.implicit.method = s.text("flow.implicit_method") == "cg"
                          ? flow::ImplicitMethod::ConjugateGradient
                          : flow::ImplicitMethod::Cholesky;
  f.implicit.tolerance = s.real("flow.tolerance");
  f.explicit_scheme.fluid_modulus = s.si("flow.fluid_bulk_modulus_GPa");
  f.explicit_scheme.dt = s.real("flow.explicit_timestep_s");
  f.explicit_scheme.virtual_volume = s.flag("flow.virtual_volume");
  f.explicit_scheme.tolerance = s.real("flow.tolerance");
  f.explicit_scheme.max_steps = static_cast<std::size_t>(s.integer("flow.explicit_max_steps"));
  f.retriangulate_displacement = s.real("flow.retriangulate_displacement_radii");
  f.apply_forces = s.flag("flow.apply_forces");
  return f;
}

// One measured flow direction: its coupling and its permeability before loading.
template <int D>
struct Direction {
  std::string name;  // "along" or "normal"
  std::unique_ptr<FlowCoupling<D>> flow;
  double k0 = 0.0;
};

template <int D>
class Permeameter {
 public:
  Permeameter(Specimen<D>& sp, const Settings& s, Recorder& rec)
      : sp_(sp), s_(s), rec_(rec), gamma_t_(s.real("flow.kozeny_carman_gamma_T")) {
    const std::string dir = s.text("flow.direction");
    if (dir != "normal") add("along", D - 1);
    if (dir != "along") add("normal", 0);
  }

  // Measures the permeability before loading (calibrating alpha when asked) and records
  // the network, the pressure field and the solvers' cost.
  void start(RunControl& control) {
    const auto& frame = *sp_.frame;
    volume0_ = frame.volume();
    const double given = s_.real("flow.kozeny_carman_porosity_initial");
    porosity0_ = given > 0.0 ? given : frame.porosity();
    diameter_ = 2.0 * sp_.mean_radius;
    kc0_ = kozenyCarman(diameter_, porosity0_, gamma_t_);
    control.tick("flow network", sp_.sim->steps(), -1, "triangulating");
    FlowReading r = measure(primary(), false);
    double alpha = s_.real("flow.conductance_alpha");
    if (s_.flag("flow.calibrate_alpha")) {
      // k is proportional to alpha (every conductance is): one rescaling matches it.
      alpha *= kc0_ / r.permeability;
      for (auto& d : dirs_) d.flow->setAlpha(alpha);
      r = measure(primary(), false);
    }
    rec_.result("conductance_alpha", alpha, "");
    rec_.result("porosity_initial", frame.porosity(), "");
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
    for (auto& d : dirs_) {
      d.k0 = d.name == primary().name ? r.permeability : measure(d, false).permeability;
      if (dirs_.size() > 1) rec_.result("permeability_initial_" + d.name + "_m2", d.k0, "m^2");
    }
    pressureField("initial");
    if (s_.flag("flow.compare_solvers")) compareSolvers();
    record();
  }

  // Every n steps of the loading: solve, apply, record (once per step).
  void record() {
    const auto& sim = *sp_.sim;
    const std::uint64_t step = sim.steps();
    if (recorded_ && step == last_step_) return;
    recorded_ = true;
    last_step_ = step;
    const auto t0 = std::chrono::steady_clock::now();
    const auto& frame = *sp_.frame;
    const double t = sim.time();
    FlowReading last;
    for (auto& d : dirs_) {
      last = measure(d, d.name == primary().name && s_.flag("flow.apply_forces"));
      const double ratio = last.permeability / d.k0;
      if (d.name == primary().name) {
        rec_.series("k_over_k0", step, t, ratio);
        rec_.series("permeability_m2", step, t, last.permeability);
        triangulations_ = std::max(triangulations_, last.triangulations);
      }
      if (dirs_.size() > 1) rec_.series("k_over_k0_" + d.name, step, t, ratio);
    }
    // Kozeny-Carman on the porosity that follows the sample's volume from its initial one.
    const double phi = 1.0 - (1.0 - porosity0_) * volume0_ / frame.volume();
    rec_.series("kozeny_carman_over_k0", step, t, kozenyCarman(diameter_, phi, gamma_t_) / kc0_);
    rec_.series("flow.porosity", step, t, phi);
    rec_.series("flow.mean_stress_MPa", step, t, frame.meanStress() / 1e6);
    rec_.series("flow.axial_stress_MPa", step, t, frame.stress(D - 1) / 1e6);
    rec_.series("flow.lateral_stress_MPa", step, t, frame.stress(0) / 1e6);
    rec_.series("flow.axial_strain", step, t, frame.strain(D - 1));
    rec_.series("flow.volumetric_strain", step, t, frame.volumetricStrain());
    rec_.series("flow.solve_seconds", step, t, last.solve.seconds);
    rec_.series("flow.triangulations", step, t, static_cast<double>(last.triangulations));
    seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ++calls_;
  }

  void finish() {
    record();
    rec_.stageTiming("flow_network", network_seconds_, solves_);
    rec_.stageTiming("flow_solve", solve_seconds_, solves_);
    for (auto& d : dirs_) {
      const std::string suffix = dirs_.size() > 1 ? "_" + d.name : "";
      rec_.result("k_over_k0_final" + suffix, d.flow->lastPermeability() / d.k0, "");
    }
    rec_.result("triangulations", static_cast<double>(triangulations_), "");
    pressureField("final");
    rec_.stageTiming("flow", seconds_, calls_);
  }

 private:
  void add(const std::string& name, int axis) {
    dirs_.push_back({name, std::make_unique<FlowCoupling<D>>(flowSettings(s_, axis)), 0.0});
  }
  Direction<D>& primary() { return dirs_.front(); }

  FlowReading measure(Direction<D>& d, bool apply) {
    try {
      FlowReading r = apply ? d.flow->update(*sp_.sim) : d.flow->measure(*sp_.sim);
      network_seconds_ += r.network_seconds;
      solve_seconds_ += r.solve.seconds;
      ++solves_;
      return r;
    } catch (const flow::FlowStepTooLarge& e) {
      protocol::fail(s_, "flow.explicit_timestep_s", e.what());
    }
  }

  // The steady pressure of every pore of the primary direction (Figure 11), as events.
  void pressureField(const std::string& stage) {
    const auto& net = primary().flow->network();
    const auto& p = primary().flow->porePressure();
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

  void compareSolvers() {
    for (const auto& c : primary().flow->compareSolvers()) {
      if (!c.refused.empty()) {
        rec_.message(sp_.sim->steps(), sp_.sim->time(), "info",
                     "solver " + c.name + " not run: " + c.refused);
        continue;
      }
      rec_.result("solver_" + c.name + "_seconds", c.seconds, "s");
      rec_.result("solver_" + c.name + "_iterations", static_cast<double>(c.iterations), "");
      rec_.result("solver_" + c.name + "_max_difference", c.max_difference, "");
      rec_.result("solver_" + c.name + "_converged", c.converged ? 1.0 : 0.0, "");
      if (!c.converged) {
        rec_.message(sp_.sim->steps(), sp_.sim->time(), "warning",
                     "solver " + c.name + " did not converge in " + fmt(double(c.iterations)) +
                         " iterations (flow.explicit_max_steps, flow.tolerance)");
      }
    }
  }

  Specimen<D>& sp_;
  const Settings& s_;
  Recorder& rec_;
  std::vector<Direction<D>> dirs_;
  double gamma_t_;
  double volume0_ = 0.0, porosity0_ = 0.0, diameter_ = 0.0, kc0_ = 0.0;
  std::size_t triangulations_ = 0;
  // The fluid's cost for the notebook's stage timings (every direction's measurements).
  double network_seconds_ = 0.0, solve_seconds_ = 0.0;
  std::uint64_t solves_ = 0;
  bool recorded_ = false;
  std::uint64_t last_step_ = 0;
  double seconds_ = 0.0;
  std::uint64_t calls_ = 0;
};

template <int D>
void runDimension(const Settings& s, Recorder& rec, RunControl& control) {
  Specimen<D> sp = buildSpecimen<D>(s, control);
  biaxial::recordSample(sp, rec);
  formAndCement(sp, s, rec, control);
  Permeameter<D> lab(sp, s, rec);
  lab.start(control);
  // Section 3.5.2: the network is solved to steady state every n particle steps, its
  // pressures applied, the permeability recorded.
  sp.frame->couple([&] { lab.record(); },
                   static_cast<std::uint64_t>(s.integer("flow.update_every_steps")));
  if (s.text("loading.mode") == "hydrostatic") {
    const double peak = s.si("loading.stress_max_MPa");
    servoTo(sp, s, peak, peak, s.si("loading.stress_rate_MPa_per_s"), "loading", rec, control);
    rec.result("mean_stress_peak_MPa", sp.frame->meanStress() / 1e6, "MPa");
    rec.result("volumetric_strain_at_peak", sp.frame->volumetricStrain(), "");
    rec.result("porosity_at_peak", sp.frame->porosity(), "");
    snapshot(sp, s, rec, "loading", "final");
  } else {
    biaxial::confineAndLoad(sp, s, s.si("loading.confining_stress_MPa"), "", rec, control);
  }
  sp.frame->couple(nullptr, 1);
  lab.finish();
  recordTimings<D>(rec, {sp.sim.get()});
}

}  // namespace

void run(const Settings& s, Recorder& rec, RunControl& control) {
  byDimension(s, [&](auto dim) { runDimension<dim.value>(s, rec, control); });
}

}  // namespace rocklab::rigs::permeameter
