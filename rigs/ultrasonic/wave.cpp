#include "rigs/ultrasonic/wave.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <sstream>

namespace rocklab::rigs::ultrasonic {

void WaveSpec::validate() const {
  if (receivers_at.size() < 2) {
    throw InvalidParameter("", "receivers_at", "needs at least two receivers for a velocity");
  }
  for (std::size_t i = 0; i < receivers_at.size(); ++i) {
    if (!(receivers_at[i] > (i == 0 ? source_at : receivers_at[i - 1]))) {
      throw InvalidParameter("", "receivers_at",
                             "must be ascending, beyond wave.source_at (fractions of the sample)");
    }
  }
}

namespace {

void check(const WaveSpec& s, int dimension) {
  auto fail = [&](const std::string& what) { throw WaveError("wave " + s.name + ": " + what); };
  if (s.propagation < 0 || s.propagation >= dimension || s.polarisation < 0 ||
      s.polarisation >= dimension) {
    fail("the propagation and polarisation axes must be axes of the sample");
  }
  if (!(s.frequency > 0.0) || !(s.amplitude > 0.0) || !(s.slab > 0.0)) {
    fail("frequency, amplitude and slab thickness must be positive");
  }
  if (!(s.path_hi > s.path_lo)) fail("the path has no length");
  if (s.receivers_at.size() < 2) fail("a velocity needs at least two receivers");
  const double length = s.path_hi - s.path_lo;
  double last = s.source_at;
  for (double r : s.receivers_at) {
    if (!((r - last) * length >= s.slab) || r > 1.0) {
      fail(
          "receivers must lie beyond the source, each a slab thickness beyond the last, "
          "within the sample");
    }
    last = r;
  }
  if (s.sample_every < 1) fail("the receivers sample every step or less often, not never");
  if (s.receiver_half_width > 0.0 && static_cast<int>(s.centre.size()) != dimension) {
    fail("a receiver half width needs the sample's centre");
  }
}

// Slots of the particles whose centre lies within half a slab of `at` along the path (and,
// for receivers, within the half width of the sample's axis).
template <int D>
std::vector<std::uint32_t> slab(const Simulation<D>& sim, const WaveSpec& s, double at, bool narrow,
                                bool skip_pebbles) {
  const auto& P = sim.particles();
  std::vector<std::uint32_t> out;
  for (std::size_t i = 0; i < P.size(); ++i) {
    if (std::abs(P.pos[i][s.propagation] - at) > 0.5 * s.slab) continue;
    if (skip_pebbles && P.body[i] != kNoBody) continue;
    if (narrow && s.receiver_half_width > 0.0) {
      double r2 = 0.0;
      for (int d = 0; d < D; ++d) {
        if (d != s.propagation) r2 += std::pow(P.pos[i][d] - s.centre[d], 2);
      }
      if (r2 > s.receiver_half_width * s.receiver_half_width) continue;
    }
    out.push_back(P.slot_of[i]);
  }
  std::sort(out.begin(), out.end());  // a stable order for the mean's summation
  return out;
}

// Mean centre position of the slab's particles along `axis`: the distances between slabs are
// measured between their particles, not between the nominal slab centres.
template <int D>
double meanPosition(const Simulation<D>& sim, const std::vector<std::uint32_t>& slots, int axis) {
  const auto& P = sim.particles();
  double sum = 0.0;
  for (std::uint32_t s : slots) sum += P.pos[P.indexOfSlot(s)][axis];
  return sum / static_cast<double>(slots.size());
}

template <int D>
double meanVelocity(const Simulation<D>& sim, const std::vector<std::uint32_t>& slots, int axis) {
  const auto& P = sim.particles();
  double sum = 0.0;
  for (std::uint32_t s : slots) sum += P.vel[P.indexOfSlot(s)][axis];
  return sum / static_cast<double>(slots.size());
}

// Picks on each receiver's trace up to its cut, and the velocity from them.
void pick(WaveResult& w) {
  // The wavelet is the pulse itself, not the silence after it.
  const auto pulse = static_cast<std::size_t>(std::ceil(1.0 / (w.spec.frequency * w.dt))) + 1;
  const std::span<const double> wavelet(w.source.data(), std::min(pulse, w.source.size()));
  std::vector<double> distance;
  std::vector<signal::Pick> xc, fb;
  for (ReceiverTrace& r : w.receivers) {
    const std::span<const double> trace(r.velocity.data(), r.picked_samples);
    r.xcorr = signal::crossCorrelationPick(wavelet, trace, w.dt, w.spec.first_peak_fraction);
    if (r.xcorr.quality < w.spec.min_xcorr_quality) r.xcorr.found = false;
    // The first break's level is a fraction of the direct pulse's peak: the trace up to one
    // source length past the cross-correlation pick, when there is one.
    std::size_t direct = trace.size();
    if (r.xcorr.found) {
      direct = std::min(direct, static_cast<std::size_t>(r.xcorr.time / w.dt) + wavelet.size());
    }
    r.first_break = signal::firstBreakPick(trace.first(direct), w.dt, w.spec.first_break_fraction);
    distance.push_back(r.distance);
    xc.push_back(r.xcorr);
    fb.push_back(r.first_break);
  }
  w.xcorr = signal::velocityFromArrivals(distance, xc);
  w.first_break = signal::velocityFromArrivals(distance, fb);
}

}  // namespace

double WaveResult::disagreement() const {
  if (!(xcorr.value > 0.0) || !(first_break.value > 0.0)) return NAN;
  return (first_break.value - xcorr.value) / xcorr.value;
}

template <int D>
WaveResult measureWave(Simulation<D>& sim, const WaveSpec& spec) {
  check(spec, D);
  // The window is the wave's alone: no damping, walls that neither move nor servo, and no
  // bond breaks. A lab pulse lasts microseconds, in which the rock breaks nothing; a DEM
  // sample loaded fast past its peak keeps breaking bonds long after the loading stops, and
  // each break rings louder than the pulse and at a different moment in the background copy
  // (the pulse shifts it), so nothing would subtract it.
  sim.setLocalDamping(0.0);
  sim.setBondBreakage(false);
  sim.setDensityScaling(1.0);  // a wave travels at the speed the physical masses give
  for (std::size_t i = 0; i < sim.walls().size(); ++i) {
    Wall<D>& w = sim.wall(i);
    w.servo.enabled = false;
    w.velocity.setZero();
  }
  sim.prepare();
  const double length = spec.path_hi - spec.path_lo;
  const double x_source = spec.path_lo + spec.source_at * length;
  WaveResult w;
  w.spec = spec;
  const std::vector<std::uint32_t> source = slab(sim, spec, x_source, false, true);
  if (source.empty()) {
    throw WaveError("wave " + spec.name + ": no particle in the source slab at " +
                    std::to_string(x_source) + " m (thicken the slab)");
  }
  w.source_particles = source.size();
  const double source_centre = meanPosition(sim, source, spec.propagation);
  std::vector<std::vector<std::uint32_t>> receivers;
  for (double at : spec.receivers_at) {
    const double x = spec.path_lo + at * length;
    receivers.push_back(slab(sim, spec, x, true, false));
    if (receivers.back().empty()) {
      throw WaveError("wave " + spec.name + ": no particle in the receiver slab at " +
                      std::to_string(x) + " m (thicken the slab or widen the receivers)");
    }
    ReceiverTrace r;
    r.distance = meanPosition(sim, receivers.back(), spec.propagation) - source_centre;
    r.particles = receivers.back().size();
    w.receivers.push_back(std::move(r));
  }
  sim.drive(source);
  // One step throughout: the samples, the pulse and the background copy's steps must line
  // up (the automatic step is re-estimated as the run goes, and the driven source leaves it).
  sim.setFixedTimeStep(sim.dt());
  std::optional<Simulation<D>> background;
  if (spec.subtract_background) {
    background.emplace(sim.clone());
    background->setDrivenVelocity(source, Vec<D>::Zero());  // the source held still
  }
  const double step_dt = sim.dt();
  w.dt = step_dt * spec.sample_every;
  const double period = 1.0 / spec.frequency, omega = 2.0 * std::numbers::pi * spec.frequency;
  if (period < 4.0 * w.dt) {
    std::ostringstream why;
    why.precision(3);
    why << "wave " << spec.name << ": a sample every " << w.dt
        << " s gives fewer than four per pulse period (" << period
        << " s): sample more often (wave.sample_every_steps) or lower the frequency";
    throw WaveError(why.str());
  }
  Vec<D> direction = Vec<D>::Zero();
  direction[spec.polarisation] = 1.0;
  double near_peak = 0.0, heard_at = -1.0;
  const double t0 = sim.time();
  for (std::uint64_t n = 0;; ++n) {
    if (n == spec.max_steps) {
      throw WaveError("wave " + spec.name + ": the farthest receiver heard nothing in " +
                      std::to_string(n) + " steps (" + std::to_string(n * step_dt) +
                      " s): the wave is slower or weaker than expected; raise the window "
                      "(wave.max_window_steps) or lower the frequency");
    }
    // The source moves at the pulse's mid-step velocity (the midpoint rule); the source's
    // samples are thus half a step ahead of the receivers', which the slope does not see.
    const double t_mid = (static_cast<double>(n) + 0.5) * step_dt;
    const double v = t_mid < period ? spec.amplitude * std::sin(omega * t_mid) : 0.0;
    sim.setDrivenVelocity(source, v * direction);
    sim.step();
    if (background) background->step();  // in lockstep: the arrival test sees the pulse alone
    const double t = sim.time() - t0;
    if (static_cast<int>(w.frames.size()) < spec.frames &&
        t >= period * static_cast<double>(1 + w.frames.size())) {
      w.frames.push_back(captureFrame(sim));
    }
    if ((n + 1) % static_cast<std::uint64_t>(spec.sample_every) != 0) continue;
    w.source.push_back(v);
    for (std::size_t r = 0; r < receivers.size(); ++r) {
      double u = meanVelocity(sim, receivers[r], spec.polarisation);
      if (background) u -= meanVelocity(*background, receivers[r], spec.polarisation);
      w.receivers[r].velocity.push_back(u);
    }
    if (t <= period) continue;
    near_peak = std::max(near_peak, std::abs(w.receivers.front().velocity.back()));
    if (heard_at < 0.0 && near_peak > 0.0 &&
        std::abs(w.receivers.back().velocity.back()) >= spec.arrival_fraction * near_peak) {
      heard_at = t;
    }
    if (heard_at >= 0.0 && t >= heard_at + spec.tail_periods * period) {
      w.steps = n + 1;
      break;
    }
  }
  // First picks on whole traces; then each trace is cut where the echo from the sample's far
  // end can first reach it (out to the end and back: 2 L_far - d), and picked again, so an
  // echo cannot pass for the arrival. The echo is timed with the faster of the two first
  // velocities: a first break is read off the leading edge, which no echo precedes.
  for (ReceiverTrace& r : w.receivers) r.picked_samples = r.velocity.size();
  pick(w);
  const signal::Velocity& fast = w.first_break.value > w.xcorr.value ? w.first_break : w.xcorr;
  if (fast.value > 0.0) {
    const double far = spec.path_hi - source_centre;
    for (ReceiverTrace& r : w.receivers) {
      const double echo = fast.delay + (2.0 * far - r.distance) / fast.value;
      const auto cut = static_cast<std::size_t>(std::max(0.0, echo / w.dt));
      r.picked_samples = std::clamp<std::size_t>(cut, 1, r.velocity.size());
    }
    pick(w);
  }
  return w;
}

template WaveResult measureWave<2>(Simulation<2>&, const WaveSpec&);
template WaveResult measureWave<3>(Simulation<3>&, const WaveSpec&);

}  // namespace rocklab::rigs::ultrasonic
