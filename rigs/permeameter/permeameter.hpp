#pragma once
// The permeameter (Li & Holt section 3.5, Figure 10): a sample in the loading frame with a
// pore fluid driven through it by fixed pressures at its two ends along the flow and no
// flow through its sides. The network is solved to steady state every n particle steps,
// its pressures act on the particles, and the Darcy permeability k is recorded against
// stress, strain and porosity, normalised by its value before loading, beside the
// Kozeny-Carman estimate (equation 8).
//
// Loading: hydrostatic (every axis to one stress; in 2D the paper's "plane strain, equal
// loading in x and y"), or biaxial / triaxial (confinement, then axial strain through
// failure). The flow goes along the loading axis, normal to it, or both ways at once: the
// permeability anisotropy of Figure 14 measured on one test.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "lab/flow/coupling.hpp"
#include "rigs/biaxial/loading.hpp"
#include "rigs/common/outputs.hpp"

namespace rocklab::rigs::permeameter {

enum class LoadingMode { Hydrostatic, Biaxial };
enum class FlowDirection { Along, Normal, Both };

// What the permeameter measures beside the fluid's own settings (flow::FlowSettings).
struct Measurement {
  FlowDirection direction = FlowDirection::Along;
  bool calibrate_alpha = false;
  double kozeny_carman_gamma_t = 5.0;
  double kozeny_carman_porosity_initial = 0.0;  // 0: the sample's measured porosity
  std::int64_t update_every_steps = 2000;
  bool compare_solvers = true;

  template <class F>
  void fields(F& f) {
    static constexpr Choice<FlowDirection> kDirections[] = {{"along", FlowDirection::Along},
                                                            {"normal", FlowDirection::Normal},
                                                            {"both", FlowDirection::Both}};
    f(direction,
      {"direction",
       units::text,
       {},
       "flow along the loading axis (y 2D, z 3D: top to bottom, Figure 10), normal to "
       "it (x), or both, measured side by side on the same test (Figure 14)"},
      kDirections);
    f(calibrate_alpha, {"calibrate_alpha",
                        units::text,
                        {},
                        "set alpha so that the permeability before loading equals Kozeny-"
                        "Carman's (section 3.5.3; the paper found 0.82 in its units)"});
    f(kozeny_carman_gamma_t, {"kozeny_carman_gamma_T", units::none, Range::leftOpen(0, 1e3),
                              "pore shape factor times tortuosity of equation 8 (about 5)"});
    f(kozeny_carman_porosity_initial,
      {"kozeny_carman_porosity_initial", units::none, Range::rightOpen(0, 1),
       "porosity Kozeny-Carman starts from, then follows the volumetric strain (0: the "
       "sample's measured porosity; the paper's 2D comparison assumes 0.30)"});
    f(update_every_steps, {"update_every_steps", units::none, Range::closed(1, 1e9),
                           "particle steps between steady-state solves (section 3.5.2: every n)"});
    f(compare_solvers, {"compare_solvers",
                        units::text,
                        {},
                        "before loading, solve the network with every solver and record their "
                        "cost"});
  }
};

struct Settings {
  SpecimenSettings specimen;
  LoadingMode mode = LoadingMode::Hydrostatic;
  double stress_max = 30.0 * kMPa;       // Pa, hydrostatic
  double stress_rate = 2e4 * kMPa;       // Pa/s, hydrostatic
  double confining_stress = 2.0 * kMPa;  // Pa, biaxial (Figure 14)
  biaxial::LoadingTest test;
  biaxial::BandAnalysis analysis;
  flow::FlowSettings flow;
  Measurement measurement;

  template <class F>
  void fields(F& f) {
    static constexpr Choice<LoadingMode> kModes[] = {{"hydrostatic", LoadingMode::Hydrostatic},
                                                     {"biaxial", LoadingMode::Biaxial}};
    f.section("", specimen);
    auto loading = f.at("loading.");
    loading(mode,
            {"mode",
             units::text,
             {},
             "hydrostatic: every axis to one stress (2D: plane strain, equal in x and y; "
             "loading.stress_*); biaxial: confinement, then axial strain through failure "
             "(3D: triaxial; loading.confining_stress_MPa and the test's keys)"},
            kModes);
    loading(stress_max, loading_keys::kStressMax);
    loading(stress_rate, loading_keys::kStressRate);
    loading(confining_stress, loading_keys::kConfiningStress);
    f.section("loading.", test);
    f.section("analysis.", analysis);
    f.section("flow.", measurement);
    f.section("flow.", flow);
  }
  void validate() const;
};

// The fluid in the run (a stage of it, not of its recording): one pore network per measured
// direction, each solved to steady state when update() is called (every n particle steps),
// the primary direction's pressures applied to the particles when flow.apply_forces. Its
// state goes into the run's checkpoints with the frame it is coupled to.
template <int D>
class FlowStage : public CoupledState {
 public:
  struct Direction {
    std::string name;  // "along" or "normal"
    std::unique_ptr<flow::FlowCoupling<D>> coupling;
    double k0 = 0.0;            // m^2, before loading
    flow::FlowReading reading;  // of the last update
  };
  FlowStage(const flow::FlowSettings& settings, FlowDirection direction);

  // Measures the primary direction before loading, without forces; returns its reading.
  flow::FlowReading start(const Simulation<D>& sim);
  // Sets equation 3's factor of every direction (a calibration) and measures again.
  void calibrate(double alpha, const Simulation<D>& sim);
  // Each direction's permeability before loading, k0: the primary's last reading, the
  // others measured now.
  void takeInitialPermeability(const Simulation<D>& sim);
  // Solves every direction on the present state and applies the primary's pressures;
  // returns whether it did (a second call at the same step does nothing).
  bool update(Simulation<D>& sim);

  const std::vector<Direction>& directions() const { return dirs_; }
  const Direction& primary() const { return dirs_.front(); }
  std::size_t triangulations() const { return triangulations_; }
  // The fluid's cost for the notebook's stage timings.
  double networkSeconds() const { return network_seconds_; }
  double solveSeconds() const { return solve_seconds_; }
  double updateSeconds() const { return update_seconds_; }
  std::uint64_t solves() const { return solves_; }
  std::uint64_t updates() const { return updates_; }
  // Implicit solves by how they were reached (flow::ImplicitPath): new factors, factors of a
  // kept ordering, iterations on a kept factor.
  std::uint64_t factorised() const { return factorised_; }
  std::uint64_t refactorised() const { return refactorised_; }
  std::uint64_t iterated() const { return iterated_; }

  void save(ArchiveWriter& ar) override { visit(ar); }
  void load(ArchiveReader& ar) override { visit(ar); }

 private:
  template <class Archive>
  void visit(Archive& ar) {
    for (auto& d : dirs_) {
      ar(d.name + ".coupling", *d.coupling), ar(d.name + ".k0", d.k0);
      ar(d.name + ".reading", d.reading);
    }
    ar("triangulations", triangulations_), ar("network_seconds", network_seconds_);
    ar("solve_seconds", solve_seconds_), ar("update_seconds", update_seconds_);
    ar("solves", solves_), ar("updates", updates_), ar("updated", updated_);
    ar("last_step", last_step_), ar("factorised", factorised_);
    ar("refactorised", refactorised_), ar("iterated", iterated_);
  }
  flow::FlowReading solve(Direction& d, Simulation<D>* apply_to, const Simulation<D>& sim);
  std::vector<Direction> dirs_;
  bool apply_forces_;
  std::size_t triangulations_ = 0;
  double network_seconds_ = 0.0, solve_seconds_ = 0.0, update_seconds_ = 0.0;
  std::uint64_t solves_ = 0, updates_ = 0;
  std::uint64_t factorised_ = 0, refactorised_ = 0, iterated_ = 0;
  bool updated_ = false;
  std::uint64_t last_step_ = 0;
};

// What the permeameter records of the fluid: the permeability before loading, every
// update's series, the pressure field and the solvers' cost. It only reads the stage.
template <int D>
class FlowRecorder {
 public:
  FlowRecorder(const Specimen<D>& sp, const Measurement& m, Recorder& rec);
  // The Kozeny-Carman reference before loading (equation 8), from the sample's porosity or
  // the one the protocol assumes; returns it (m^2).
  double startKozenyCarman();
  void initial(const flow::FlowReading& r, double alpha);
  void initialByDirection(const FlowStage<D>& flow);
  // An update's series: k / k0 per direction, Kozeny-Carman's, and the sample's state.
  void state(const FlowStage<D>& flow);
  // The steady pressure of every pore of the primary direction (Figure 11), as events.
  void pressureField(const FlowStage<D>& flow, const std::string& stage);
  // The primary network solved by every solver: their cost and agreement.
  void compareSolvers(const FlowStage<D>& flow);
  void final(const FlowStage<D>& flow);

 private:
  const Specimen<D>& sp_;
  const Measurement& m_;
  Recorder& rec_;
  double volume0_ = 0.0, porosity0_ = 0.0, diameter_ = 0.0, kc0_ = 0.0;
};

void run(const Settings& s, Recorder& rec, RunControl& control);

}  // namespace rocklab::rigs::permeameter
