#include "rigs/ultrasonic/ultrasonic.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <optional>

#include "lab/signal/signal.hpp"
#include "rigs/common/formation.hpp"
#include "rigs/common/measurements.hpp"
#include "rigs/ultrasonic/wave.hpp"

namespace rocklab::rigs::ultrasonic {

void Settings::validate() const {
  if (specimen.sample.kind == SampleKind::Clumps) {
    throw InvalidParameter("", "sample.kind", "must be spheres or grains on the ultrasonic bench");
  }
  const bool hydrostatic = mode == LoadingMode::Hydrostatic;
  const std::vector<double>& stages = hydrostatic ? stages_stress : stages_axial_strain;
  const std::string key = hydrostatic ? "loading.stages_MPa" : "loading.stages_axial_strain";
  if (stages.empty()) throw InvalidParameter("", key, "needs at least one value");
  for (std::size_t i = 1; i < stages.size(); ++i) {
    if (!(stages[i] > stages[i - 1])) throw InvalidParameter("", key, "must be ascending");
  }
}

namespace {

// Figure 18's four waves: P along the axis (z) and across it (x); S along the axis moving
// across it, and across the axis moving along the third axis (y). In 2D the axis is y and
// the only axis across it x, so sxy travels along x moving along the axis.
struct WaveKind {
  const char* name;
  const char* type;
  int propagation, polarisation;
};

template <int D>
std::vector<WaveKind> figure18Waves() {
  constexpr int z = D - 1;
  return {{"pz", "P", z, z}, {"px", "P", 0, 0}, {"szx", "S", z, 0}, {"sxy", "S", 0, 1}};
}

template <int D>
double bulkDensity(const Specimen<D>& sp) {
  const auto& P = sp.sim->particles();
  double mass = 0.0;
  for (std::size_t i = 0; i < P.size(); ++i) mass += P.mass(i);
  return mass / sp.frame->volume();
}

template <int D>
WaveSpec waveSpec(const Specimen<D>& sp, const Settings& s, const WaveKind& k) {
  const auto& walls = sp.sim->walls();
  WaveSpec w = s.wave;
  w.name = k.name;
  w.propagation = k.propagation;
  w.polarisation = k.polarisation;
  // Wall 2a bounds axis a from below, 2a + 1 from above (LoadingFrame).
  w.path_lo = walls[2 * k.propagation].point[k.propagation];
  w.path_hi = walls[2 * k.propagation + 1].point[k.propagation];
  w.slab = s.slab_diameters * 2.0 * sp.mean_radius;
  double half_width = INFINITY;
  w.centre.assign(D, 0.0);
  for (int a = 0; a < D; ++a) {
    w.centre[a] = 0.5 * (walls[2 * a].point[a] + walls[2 * a + 1].point[a]);
    if (a != k.propagation) half_width = std::min(half_width, 0.5 * sp.frame->length(a));
  }
  w.receiver_half_width = s.receiver_half_width * half_width;
  return w;
}

WaveRecord toRecord(const WaveResult& w, const WaveKind& k, const std::string& stage,
                    std::uint64_t step, double time) {
  auto known = [](bool found, double v) { return found ? std::optional<double>(v) : std::nullopt; };
  WaveRecord r;
  r.step = step, r.time = time, r.stage = stage, r.name = k.name, r.type = k.type;
  r.propagation_axis = k.propagation, r.polarisation_axis = k.polarisation;
  r.frequency = w.spec.frequency, r.amplitude = w.spec.amplitude, r.dt = w.dt;
  r.velocity_xcorr = known(w.xcorr.value > 0.0, w.xcorr.value);
  r.velocity_first_break = known(w.first_break.value > 0.0, w.first_break.value);
  r.source = w.source;
  for (const ReceiverTrace& t : w.receivers) {
    WaveRecord::Receiver x;
    x.distance = t.distance;
    x.particles = static_cast<std::int64_t>(t.particles);
    x.picked_samples = static_cast<std::int64_t>(t.picked_samples);
    x.samples = t.velocity;
    x.xcorr_time = known(t.xcorr.found, t.xcorr.time);
    x.xcorr_quality = known(t.xcorr.found, t.xcorr.quality);
    x.first_break_time = known(t.first_break.found, t.first_break.time);
    r.receivers.push_back(std::move(x));
  }
  return r;
}

// Holds every wall still until the copy is at rest (formation.unbalanced_force_ratio), or
// for at most `max_steps` (a sample past failure may never quite come to rest).
template <int D>
void hold(Specimen<D>& sp, const Settings& s, std::uint64_t max_steps) {
  using Axis = typename LoadingFrame<D>::Axis;
  for (int a = 0; a < D; ++a) sp.frame->set(a, Axis{});
  const double ub = s.specimen.formation.unbalanced_force_ratio;
  for (std::uint64_t n = 1; n <= max_steps; ++n) {
    sp.frame->step();
    if (n % 100 == 0 && sp.sim->unbalancedForceRatio() < ub) return;
  }
}

// Moves one axis by `strain` (compression positive) at the static rate, then holds.
template <int D>
void strainBy(Specimen<D>& sp, const Settings& s, int axis, double strain) {
  using Axis = typename LoadingFrame<D>::Axis;
  using Mode = typename LoadingFrame<D>::Mode;
  const double rate = s.static_strain_rate;
  const double target = sp.frame->strain(axis) + strain;
  sp.frame->set(axis, Axis{Mode::StrainRate, strain > 0.0 ? rate : -rate});
  while (strain > 0.0 ? sp.frame->strain(axis) < target : sp.frame->strain(axis) > target) {
    sp.frame->step();
  }
  hold(sp, s, static_cast<std::uint64_t>(s.hold_steps));
}

struct StaticModulus {
  double loading = 0.0, unloading = 0.0;  // Pa
};

// The interior's strain along `axis` between two states of the same copy, compression
// positive: the slope of the particles' displacement against their position, fitted over
// the particles at least a fifth of the sample from every wall. Like gauges glued on a core
// rather than the platens' travel, it leaves out the compliance of the layers at the walls
// (a large share of a sample a dozen grains across), which the waves inside never cross.
template <int D>
double interiorStrain(const Specimen<D>& sp, const std::vector<Vec<D>>& before, int axis) {
  const auto& P = sp.sim->particles();
  const auto& walls = sp.sim->walls();
  std::vector<double> x, u;
  for (std::size_t i = 0; i < P.size(); ++i) {
    const std::uint32_t slot = P.slot_of[i];
    bool inside = true;
    for (int a = 0; a < D; ++a) {
      const double lo = walls[2 * a].point[a], hi = walls[2 * a + 1].point[a];
      const double margin = 0.2 * (hi - lo);
      inside = inside && before[slot][a] > lo + margin && before[slot][a] < hi - margin;
    }
    if (!inside) continue;
    x.push_back(before[slot][axis]);
    u.push_back(P.pos[i][axis] - before[slot][axis]);
  }
  return -signal::fitLine(x, u).slope;
}

template <int D>
std::vector<Vec<D>> positionsBySlot(const Simulation<D>& sim) {
  const auto& P = sim.particles();
  std::vector<Vec<D>> out(P.slotCapacity(), Vec<D>::Zero());
  for (std::size_t i = 0; i < P.size(); ++i) out[P.slot_of[i]] = P.pos[i];
  return out;
}

// The constrained modulus along `axis` from a small strain cycle on a copy, the other walls
// held: loading and unloading slopes of the wall stress against the interior's strain
// between rest states.
template <int D>
StaticModulus staticModulus(const Specimen<D>& sp, const Settings& s, int axis) {
  Specimen<D> copy = sp.branch();
  const double amplitude = s.static_strain_amplitude;
  const auto a = positionsBySlot(*copy.sim);
  const double sa = copy.frame->stress(axis);
  strainBy(copy, s, axis, amplitude);
  const auto b = positionsBySlot(*copy.sim);
  const double sb = copy.frame->stress(axis), ab = interiorStrain(copy, a, axis);
  strainBy(copy, s, axis, -amplitude);
  const double sc = copy.frame->stress(axis), bc = -interiorStrain(copy, b, axis);
  StaticModulus m;
  m.loading = (sb - sa) / ab;
  m.unloading = (sb - sc) / bc;
  return m;
}

struct StageResult {
  std::vector<std::pair<std::string, double>> values;  // name, value (recorded as series)
  double min_wavelength_diameters = INFINITY, max_disagreement = 0.0;
  // Cost of the stage's own work, for the notebook's stage timings: the pulses (each with
  // its background copy) and the static cycles, on copies of the sample.
  double wave_seconds = 0.0, static_seconds = 0.0;
  std::uint64_t pulses = 0, cycles = 0;
  // A measured stage in a checkpoint (rigs/common/journal.hpp).
  template <class Archive>
  void visit(Archive& ar) {
    ar("values", values), ar("min_wavelength_diameters", min_wavelength_diameters);
    ar("max_disagreement", max_disagreement), ar("wave_seconds", wave_seconds);
    ar("static_seconds", static_seconds), ar("pulses", pulses), ar("cycles", cycles);
  }
};

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// What a stage's measurement records: each value as a series at the stage's step, kept for
// the results of the last stage.
struct StageRecord {
  Recorder& rec;
  std::string stage;
  std::uint64_t step;
  double time;
  StageResult out;
  void put(const std::string& name, double v) {
    rec.series(name, step, time, v);
    out.values.emplace_back(name, v);
  }
};

// Figure 18's four waves through copies of the rested sample; returns each velocity found.
template <int D>
std::map<std::string, double> sendWaves(const Specimen<D>& rest, const Settings& s, bool frames,
                                        StageRecord& r, RunControl& control) {
  std::map<std::string, double> v;
  for (const WaveKind& k : figure18Waves<D>()) {
    control.tick(r.stage, r.step, -1.0, std::string("wave ") + k.name);
    Specimen<D> copy = rest.branch();
    WaveSpec spec = waveSpec(copy, s, k);
    spec.frames = frames ? s.frames : 0;
    const auto t0 = std::chrono::steady_clock::now();
    const WaveResult w = measureWave(*copy.sim, spec);
    r.out.wave_seconds += secondsSince(t0);
    ++r.out.pulses;
    r.rec.wave(toRecord(w, k, r.stage, r.step, r.time));
    for (std::size_t f = 0; f < w.frames.size(); ++f) {
      r.rec.snapshot(std::string("wave-") + k.name,
                     "wave front " + std::to_string(f + 1) + " of " + k.name, w.frames[f]);
    }
    const std::string base = std::string(k.type) == "P" ? std::string("vp_") + (k.name + 1)
                                                        : std::string("vs_") + (k.name + 1);
    if (!(w.xcorr.value > 0.0)) {
      r.rec.message(r.step, r.time, "warning",
                    r.stage + ": wave " + k.name +
                        " gave no velocity (the arrivals did not grow "
                        "later with distance); lower wave.frequency_kHz or move the receivers");
      continue;
    }
    v[base] = w.xcorr.value;
    r.put(base, w.xcorr.value);
    r.put(base + "_first_break", w.first_break.value);
    r.put(base + "_error", w.xcorr.error);
    r.out.min_wavelength_diameters =
        std::min(r.out.min_wavelength_diameters, w.wavelength() / (2.0 * rest.mean_radius));
    if (std::isfinite(w.disagreement())) {
      r.out.max_disagreement = std::max(r.out.max_disagreement, std::abs(w.disagreement()));
    }
  }
  return v;
}

// The static constrained moduli along z and x from small strain cycles on copies.
template <int D>
void measureStatic(const Specimen<D>& rest, const Settings& s, StageRecord& r,
                   RunControl& control) {
  constexpr int z = D - 1;
  for (const auto& [axis, name] : {std::pair{z, "modulus_z"}, std::pair{0, "modulus_x"}}) {
    control.tick(r.stage, r.step, -1.0, std::string("static cycle ") + name);
    const auto t0 = std::chrono::steady_clock::now();
    const StaticModulus m = staticModulus(rest, s, axis);
    r.out.static_seconds += secondsSince(t0);
    ++r.out.cycles;
    r.put(std::string(name) + "_static_MPa", m.unloading / 1e6);
    r.put(std::string(name) + "_static_loading_MPa", m.loading / 1e6);
  }
}

template <int D>
StageResult measureStage(Specimen<D>& sp, const Settings& s, const std::string& stage, bool frames,
                         Recorder& rec, RunControl& control) {
  auto& sim = *sp.sim;
  StageRecord r{rec, stage, sim.steps(), sim.time(), {}};
  recordState(sp, rec, "stage.", "loading", 0.0);
  const double rho = bulkDensity(sp);
  r.put("stage.density_kg_per_m3", rho);
  // The pulse goes through a copy at rest: the loading stopped and the walls held until the
  // unbalanced force has died down. Mid-loading, bonds are still breaking; an avalanche in
  // the window would drown the pulse, and would not repeat in the background copy.
  control.tick(stage, r.step, -1.0, "holding a copy at rest");
  Specimen<D> rest = sp.branch();
  hold(rest, s, static_cast<std::uint64_t>(s.hold_steps));
  std::map<std::string, double> v = sendWaves(rest, s, frames, r, control);
  // Dynamic moduli rho v^2 (Figure 18's velocities as stiffnesses): the P-wave (constrained)
  // moduli along and across the axis and the shear moduli of the two S waves.
  auto dynamic = [&](const std::string& vel, const std::string& name) {
    if (v.count(vel)) r.put(name + "_dynamic_MPa", rho * v[vel] * v[vel] / 1e6);
  };
  dynamic("vp_z", "modulus_z");
  dynamic("vp_x", "modulus_x");
  dynamic("vs_zx", "shear_modulus_zx");
  dynamic("vs_xy", "shear_modulus_xy");
  if (s.static_moduli) measureStatic(rest, s, r, control);
  return r.out;
}

// Loads the formed specimen along the protocol's path and measures at each stage; the last
// stage's wave fronts are kept as frames. Each stage's loading and its measurement are units
// of the run's checkpoints: a measurement only reads the sample (its copies do the work).
template <int D>
std::vector<StageResult> loadAndMeasure(Specimen<D>& sp, const Settings& s, Recorder& rec,
                                        RunControl& control) {
  using Axis = typename LoadingFrame<D>::Axis;
  using Mode = typename LoadingFrame<D>::Mode;
  constexpr int ax = Specimen<D>::kAxial;
  auto& frame = *sp.frame;
  const auto record_every = static_cast<std::uint64_t>(s.specimen.output.record_every_steps);
  std::vector<StageResult> stages;
  auto measure = [&](bool last) {
    const std::string stage = "stage " + std::to_string(stages.size() + 1);
    Journal::Unit unit = control.unit("measure " + stage);
    StageResult r;
    if (!unit.done(r)) {
      r = measureStage(sp, s, stage, last, rec, control);
      unit.finish(r);
    }
    stages.push_back(std::move(r));
  };
  sp.resetBrokenCount();
  frame.resetReference();
  if (s.mode == LoadingMode::Hydrostatic) {
    const std::vector<double>& p = s.stages_stress;
    for (std::size_t k = 0; k < p.size(); ++k) {
      servoTo(sp, p[k], p[k], s.stress_rate, "loading", rec, control);
      measure(k + 1 == p.size());
    }
    return stages;
  }
  if (s.mode == LoadingMode::Triaxial) {
    servoTo(sp, s.confining_stress, s.confining_stress, s.stress_rate, "confinement", rec, control);
    frame.resetReference();
  } else {
    for (int a = 0; a < D; ++a) frame.set(a, Axis{});
  }
  const double rate = s.axial_strain_rate;
  frame.set(ax, Axis{Mode::StrainRate, rate});
  const std::vector<double>& at = s.stages_axial_strain;
  for (std::size_t k = 0; k < at.size(); ++k) {
    Journal::Unit unit = control.unit("loading to stage " + std::to_string(k + 1));
    if (!unit.done(sp)) {
      unit.resume(sp);
      do {
        unit.tick(sp);  // before the step: the loop goes on from a checkpoint's state
        frame.step();
        if (sp.sim->steps() % record_every == 0) recordState(sp, rec, "loading.", "loading", rate);
        if (sp.sim->steps() % 200 == 0) {
          control.tick("loading", sp.sim->steps(), frame.strain(ax) / at.back(),
                       "axial stress " + fmt(frame.stress(ax) / 1e6) + " MPa");
        }
      } while (frame.strain(ax) < at[k]);
      unit.finish(sp);
    }
    measure(k + 1 == at.size());
  }
  return stages;
}

// The last stage's values as results, the measurement's quality over every stage, and its
// cost.
template <int D>
void recordStages(const Specimen<D>& sp, const std::vector<StageResult>& stages, Recorder& rec) {
  for (const auto& [name, value] : stages.back().values) rec.result(name, value, "");
  double min_wavelength = INFINITY, disagreement = 0.0;
  StageResult cost;
  for (const StageResult& r : stages) {
    cost.wave_seconds += r.wave_seconds, cost.pulses += r.pulses;
    cost.static_seconds += r.static_seconds, cost.cycles += r.cycles;
    min_wavelength = std::min(min_wavelength, r.min_wavelength_diameters);
    disagreement = std::max(disagreement, r.max_disagreement);
  }
  rec.result("stages", static_cast<double>(stages.size()), "");
  rec.result("wavelength_min_diameters", min_wavelength, "");
  rec.result("pick_disagreement_max", disagreement, "");
  // Below a few grains per wavelength the pack scatters the pulse: the velocity is no longer
  // that of the continuum (Li & Holt 4.1: waves of wavelengths much larger than the grains).
  if (min_wavelength < 4.0) {
    rec.message(sp.sim->steps(), sp.sim->time(), "warning",
                "a wavelength spans only " + fmt(min_wavelength) +
                    " particle diameters: the pulse scatters on the grains; lower "
                    "wave.frequency_kHz");
  }
  recordTimings<D>(rec, {sp.sim.get()});
  rec.stageTiming("waves", cost.wave_seconds, cost.pulses);
  if (cost.cycles > 0) rec.stageTiming("static_cycles", cost.static_seconds, cost.cycles);
}

template <int D>
void runDimension(const Settings& s, Recorder& rec, RunControl& control) {
  Specimen<D> sp = buildSpecimen<D>(s.specimen, control);
  rec.result("particles", static_cast<double>(sp.sim->particles().size()), "");
  formAndCement(sp, rec, control);
  const std::vector<StageResult> stages = loadAndMeasure(sp, s, rec, control);
  snapshot(sp, rec, "loading", "final");
  recordStages(sp, stages, rec);
}

}  // namespace

void run(const Settings& s, Recorder& rec, RunControl& control) {
  byDimension(s.specimen.protocol.dimension,
              [&](auto dim) { runDimension<dim.value>(s, rec, control); });
}

}  // namespace rocklab::rigs::ultrasonic
