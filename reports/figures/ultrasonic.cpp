// The ultrasonic bench's figures (Li & Holt section 4): velocities against the stage's stress
// or strain (Figure 18), dynamic moduli rho v^2 beside the static ones from small strain
// cycles, and, at the last stage, the receivers' traces with their picks and their spectra.
// The wave fronts (Figure 17) are among the run's snapshots.

#include <algorithm>
#include <cmath>

#include "lab/signal/signal.hpp"
#include "reports/figures/figures.hpp"

namespace rocklab::reports {

namespace {

const char* kVelocities[] = {"vp_z", "vp_x", "vs_zx", "vs_xy"};

bool hydrostatic(const RunData& r) {
  return r.param("loading.mode") == "hydrostatic";
}

// Hydrostatic stages are set by stress, the others by axial strain (millistrain, as Figure
// 18b and c).
std::string stageAxis(const RunData& r) {
  return hydrostatic(r) ? "stage.axial_stress_MPa" : "stage.axial_strain";
}

std::string stageLabel(const RunData& r) {
  return hydrostatic(r) ? "hydrostatic stress (MPa)" : "axial strain (millistrain)";
}

double stageScale(const RunData& r) {
  return hydrostatic(r) ? 1.0 : 1e3;
}

Figure velocities(const RunData& r) {
  Figure f;
  f.id = "ultrasonic-velocities-run" + std::to_string(r.id);
  f.title = "Wave velocities at each loading stage, " + r.label();
  f.caption =
      "P waves along the axis (vp_z) and across it (vp_x), S waves along the axis moving across "
      "it (vs_zx) and across it moving along y (vs_xy), from cross-correlation picks over the "
      "receivers (lines) and from first breaks (markers), against the stage's " +
      stageLabel(r) + " (cf. Figure 18).";
  Panel p{stageLabel(r), "velocity (m/s)", {}};
  for (const char* v : kVelocities) {
    Series line{v, {}, {}, false}, fb{std::string(v) + " first break", {}, {}, true};
    pair(r, stageAxis(r), v, line.x, line.y, stageScale(r));
    pair(r, stageAxis(r), std::string(v) + "_first_break", fb.x, fb.y, stageScale(r));
    if (!line.x.empty()) p.series.push_back(line);
    if (!fb.x.empty()) p.series.push_back(fb);
  }
  if (p.series.empty()) return {};
  Panel q{stageLabel(r), "axial stress (MPa)", {}};
  Series axial{"axial", {}, {}, false}, lateral{"lateral", {}, {}, false};
  const std::string x = hydrostatic(r) ? "loading.axial_stress_MPa" : "loading.axial_strain";
  pair(r, x, "loading.axial_stress_MPa", axial.x, axial.y, stageScale(r));
  pair(r, x, "loading.lateral_stress_MPa", lateral.x, lateral.y, stageScale(r));
  f.panels = {p};
  if (!hydrostatic(r) && !axial.x.empty()) {
    q.y_label = "stress (MPa)";
    q.series = {axial, lateral};
    f.panels.push_back(q);
  }
  return f;
}

Figure moduli(const RunData& r) {
  Figure f;
  f.id = "ultrasonic-moduli-run" + std::to_string(r.id);
  f.title = "Dynamic and static moduli, " + r.label();
  f.caption =
      "P-wave moduli rho v^2 along the axis and across it (lines) beside the static constrained "
      "moduli from small strain cycles with the other walls held (markers: unloading slope), "
      "and the shear moduli of the two S waves, against the stage's " +
      stageLabel(r) + ". The paper found dynamic and static moduli equal in the elastic range.";
  Panel p{stageLabel(r), "constrained modulus (MPa)", {}};
  for (const char* m : {"modulus_z", "modulus_x"}) {
    Series d{std::string(m) + " dynamic", {}, {}, false},
        s{std::string(m) + " static", {}, {}, true};
    pair(r, stageAxis(r), std::string(m) + "_dynamic_MPa", d.x, d.y, stageScale(r));
    pair(r, stageAxis(r), std::string(m) + "_static_MPa", s.x, s.y, stageScale(r));
    if (!d.x.empty()) p.series.push_back(d);
    if (!s.x.empty()) p.series.push_back(s);
  }
  Panel g{stageLabel(r), "shear modulus (MPa)", {}};
  for (const char* m : {"shear_modulus_zx", "shear_modulus_xy"}) {
    Series d{std::string(m) + " dynamic", {}, {}, false};
    pair(r, stageAxis(r), std::string(m) + "_dynamic_MPa", d.x, d.y, stageScale(r));
    if (!d.x.empty()) g.series.push_back(d);
  }
  for (Panel* x : {&p, &g}) {
    if (!x->series.empty()) f.panels.push_back(*x);
  }
  return f;
}

// The last stage's waves.
std::vector<const notebook::WaveRecord*> lastStage(const RunData& r) {
  std::vector<const notebook::WaveRecord*> out;
  if (r.waves.empty()) return out;
  const std::string& stage = r.waves.back().stage;
  for (const auto& w : r.waves) {
    if (w.stage == stage) out.push_back(&w);
  }
  return out;
}

// Each receiver's trace drawn at its distance (mm) plus its velocity scaled so the largest
// swing spans one receiver spacing; the picks as markers at their times and distances.
Figure traces(const RunData& r) {
  const auto waves = lastStage(r);
  Figure f;
  f.id = "ultrasonic-traces-run" + std::to_string(r.id);
  f.title = "Receiver traces and picks at the last stage (" +
            (waves.empty() ? std::string() : waves.front()->stage) + "), " + r.label();
  f.caption =
      "Mean velocity of each receiver slab along the polarisation (background motion "
      "subtracted), drawn at its distance from the source and scaled to the receiver spacing; "
      "the source pulse at distance 0. Markers: cross-correlation picks (the time the source "
      "pulse best matches the trace) and first breaks; the velocity is the inverse slope of "
      "their times over distance. Traces end where the echo from the far end could arrive.";
  for (const notebook::WaveRecord* w : waves) {
    if (w->receivers.size() < 2) continue;
    Panel p{"time (microseconds)", w->name + ": distance (mm)", {}};
    const double spacing = (w->receivers[1].distance - w->receivers[0].distance) * 1e3;
    double peak = 0.0;
    for (const auto& rc : w->receivers) {
      for (std::size_t i = 0; i < static_cast<std::size_t>(rc.picked_samples); ++i) {
        peak = std::max(peak, std::abs(rc.samples[i]));
      }
    }
    const double scale = peak > 0.0 ? 0.5 * spacing / peak : 1.0;
    Series src{"source", {}, {}, false};
    for (std::size_t i = 0; i < w->source.size(); ++i) {
      src.x.push_back(i * w->dt * 1e6);
      src.y.push_back(w->source[i] / w->amplitude * 0.5 * spacing);
    }
    p.series.push_back(src);
    Series xc{"cross-correlation picks", {}, {}, true}, fb{"first breaks", {}, {}, true};
    for (std::size_t k = 0; k < w->receivers.size(); ++k) {
      const auto& rc = w->receivers[k];
      const double d = rc.distance * 1e3;
      Series t{"receiver " + std::to_string(k + 1), {}, {}, false};
      for (std::size_t i = 0; i < static_cast<std::size_t>(rc.picked_samples); ++i) {
        t.x.push_back(i * w->dt * 1e6);
        t.y.push_back(d + rc.samples[i] * scale);
      }
      p.series.push_back(t);
      if (rc.xcorr_time) xc.x.push_back(*rc.xcorr_time * 1e6), xc.y.push_back(d);
      if (rc.first_break_time) fb.x.push_back(*rc.first_break_time * 1e6), fb.y.push_back(d);
    }
    p.series.push_back(xc);
    p.series.push_back(fb);
    f.panels.push_back(p);
  }
  return f;
}

// Amplitude spectra of the source and of a near and a far receiver, each normalised
// to its peak: the pack filters the pulse's high frequencies on the way.
Figure spectra(const RunData& r) {
  Figure f;
  f.id = "ultrasonic-spectra-run" + std::to_string(r.id);
  f.title = "Amplitude spectra at the last stage, " + r.label();
  f.caption =
      "FFT amplitude of the source pulse, of the nearest receiver's trace and of the farthest "
      "one whose whole pulse arrives before the far end's echo, each normalised to its peak; "
      "the pulse's nominal frequency is the wave.frequency_kHz of the protocol.";
  for (const notebook::WaveRecord* w : lastStage(r)) {
    if (w->receivers.empty()) continue;
    Panel p{"frequency (kHz)", w->name + ": amplitude / peak", {}};
    const double f_max = 4.0 * w->frequency;  // a one-period pulse holds 99% below 3 f0
    auto add = [&](const std::string& label, const std::vector<double>& x, std::size_t n) {
      if (n < 2) return;
      const signal::Spectrum s =
          signal::amplitudeSpectrum(std::span<const double>(x.data(), n), w->dt, 8 * n);
      const double peak = *std::max_element(s.amplitude.begin(), s.amplitude.end());
      Series line{label, {}, {}, false};
      for (std::size_t k = 0; k < s.frequency_hz.size() && s.frequency_hz[k] <= f_max; ++k) {
        line.x.push_back(s.frequency_hz[k] / 1e3);
        line.y.push_back(peak > 0.0 ? s.amplitude[k] / peak : 0.0);
      }
      p.series.push_back(line);
    };
    add("source", w->source, w->source.size());
    // The farthest receiver whose whole pulse lies before the echo cut: a pulse cut in half
    // would show the cut's spectrum, not the pack's filtering.
    const double period = 1.0 / (w->frequency * w->dt);  // samples
    const notebook::WaveRecord::Receiver* far = nullptr;
    for (const auto& rc : w->receivers) {
      if (rc.xcorr_time && *rc.xcorr_time / w->dt + 1.5 * period <= rc.picked_samples) far = &rc;
    }
    const auto& near = w->receivers.front();
    add("nearest receiver", near.samples, static_cast<std::size_t>(near.picked_samples));
    if (far && far != &near) {
      add("receiver at " + std::to_string(static_cast<int>(std::lround(far->distance * 1e3))) +
              " mm",
          far->samples, static_cast<std::size_t>(far->picked_samples));
    }
    f.panels.push_back(p);
  }
  return f;
}

}  // namespace

std::vector<Figure> ultrasonicFigures(const std::vector<const RunData*>& runs, const Paper&) {
  std::vector<Figure> out;
  for (const RunData* r : runs) {
    for (Figure f : {velocities(*r), moduli(*r), traces(*r), spectra(*r)}) {
      if (!f.panels.empty()) out.push_back(std::move(f));
    }
  }
  return out;
}

}  // namespace rocklab::reports
