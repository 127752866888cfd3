#include "lab/signal/signal.hpp"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <memory>
#include <mutex>
#include <stdexcept>

namespace rocklab::signal {

namespace {

// FFTW's planner is not thread-safe (only fftw_execute is): plans are made and destroyed
// under one lock (https://fftw.org/fftw3_doc/Thread-safety.html).
std::mutex& plannerLock() {
  static std::mutex m;
  return m;
}

// The smallest 2^a 3^b 5^c 7^d at or above n: sizes FFTW transforms fastest.
std::size_t fastSize(std::size_t n) {
  for (std::size_t m = std::max<std::size_t>(n, 1);; ++m) {
    std::size_t k = m;
    for (std::size_t p : {2, 3, 5, 7}) {
      while (k % p == 0) k /= p;
    }
    if (k == 1) return m;
  }
}

struct FftwFree {
  void operator()(void* p) const { fftw_free(p); }
};
using RealBuffer = std::unique_ptr<double[], FftwFree>;
using ComplexBuffer = std::unique_ptr<fftw_complex[], FftwFree>;

// A real-to-complex transform of size n and its inverse, on buffers of their own.
class RealFft {
 public:
  explicit RealFft(std::size_t n)
      : n_(n), real_(fftw_alloc_real(n)), spectrum_(fftw_alloc_complex(n / 2 + 1)) {
    if (!real_ || !spectrum_) throw std::bad_alloc();
    const int size = static_cast<int>(n);
    std::lock_guard lock(plannerLock());
    forward_ = fftw_plan_dft_r2c_1d(size, real_.get(), spectrum_.get(), FFTW_ESTIMATE);
    backward_ = fftw_plan_dft_c2r_1d(size, spectrum_.get(), real_.get(), FFTW_ESTIMATE);
    if (!forward_ || !backward_) throw std::runtime_error("FFTW could not plan a transform");
  }
  ~RealFft() {
    std::lock_guard lock(plannerLock());
    fftw_destroy_plan(forward_);
    fftw_destroy_plan(backward_);
  }
  RealFft(const RealFft&) = delete;
  RealFft& operator=(const RealFft&) = delete;

  // The spectrum of x zero-padded to n (n / 2 + 1 bins).
  std::vector<std::complex<double>> forward(std::span<const double> x) {
    std::fill_n(real_.get(), n_, 0.0);
    std::copy(x.begin(), x.end(), real_.get());
    fftw_execute(forward_);
    std::vector<std::complex<double>> out(n_ / 2 + 1);
    for (std::size_t k = 0; k < out.size(); ++k) out[k] = {spectrum_[k][0], spectrum_[k][1]};
    return out;
  }
  // The real signal of spectrum X, normalised (FFTW's transforms are not: forward then
  // backward multiplies by n).
  std::vector<double> backward(const std::vector<std::complex<double>>& X) {
    for (std::size_t k = 0; k < X.size(); ++k) {
      spectrum_[k][0] = X[k].real();
      spectrum_[k][1] = X[k].imag();
    }
    fftw_execute(backward_);
    std::vector<double> out(real_.get(), real_.get() + n_);
    for (double& v : out) v /= static_cast<double>(n_);
    return out;
  }

 private:
  std::size_t n_;
  RealBuffer real_;
  ComplexBuffer spectrum_;
  fftw_plan forward_ = nullptr, backward_ = nullptr;
};

void requireStep(double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt)) throw std::invalid_argument("signal: dt must be > 0");
}

}  // namespace

Spectrum amplitudeSpectrum(std::span<const double> x, double dt, std::size_t pad_to) {
  requireStep(dt);
  if (x.empty()) throw std::invalid_argument("signal: the spectrum of an empty trace");
  const std::size_t n = fastSize(std::max(pad_to, x.size()));
  RealFft fft(n);
  const auto X = fft.forward(x);
  Spectrum s;
  for (std::size_t k = 0; k < X.size(); ++k) {
    s.frequency_hz.push_back(static_cast<double>(k) / (static_cast<double>(n) * dt));
    // One-sided, scaled by dt: the continuous transform's magnitude (V·s for a velocity).
    s.amplitude.push_back(std::abs(X[k]) * dt);
  }
  return s;
}

CrossCorrelation crossCorrelate(std::span<const double> x, std::span<const double> y) {
  if (x.empty() || y.empty()) throw std::invalid_argument("signal: correlating an empty trace");
  // Zero padding to at least x + y - 1 samples keeps the circular correlation free of
  // wrap-around: lag tau >= 0 lands at index tau, tau < 0 at n + tau.
  const std::size_t n = fastSize(x.size() + y.size() - 1);
  RealFft fft(n);
  const auto X = fft.forward(x);
  auto Y = fft.forward(y);
  for (std::size_t k = 0; k < Y.size(); ++k) Y[k] *= std::conj(X[k]);
  const std::vector<double> circular = fft.backward(Y);
  CrossCorrelation c;
  c.first_lag = -static_cast<std::ptrdiff_t>(x.size() - 1);
  c.r.reserve(x.size() + y.size() - 1);
  for (std::ptrdiff_t lag = c.first_lag; lag < static_cast<std::ptrdiff_t>(y.size()); ++lag) {
    c.r.push_back(circular[lag >= 0 ? lag : static_cast<std::ptrdiff_t>(n) + lag]);
  }
  return c;
}

Pick crossCorrelationPick(std::span<const double> wavelet, std::span<const double> trace, double dt,
                          double first_peak_fraction) {
  requireStep(dt);
  Pick p;
  double ex = 0.0, ey = 0.0;
  for (double v : wavelet) ex += v * v;
  for (double v : trace) ey += v * v;
  if (!(ex > 0.0) || !(ey > 0.0)) return p;  // a silent trace has no arrival
  const CrossCorrelation c = crossCorrelate(wavelet, trace);
  // Causal lags only: a receiver cannot hear the source before it sounds.
  const auto zero = static_cast<std::size_t>(-c.first_lag);
  auto peak = static_cast<std::size_t>(
      std::max_element(c.r.begin() + static_cast<std::ptrdiff_t>(zero), c.r.end()) - c.r.begin());
  if (first_peak_fraction < 1.0) {
    const double level = first_peak_fraction * c.r[peak];
    for (std::size_t i = zero; i < peak; ++i) {
      // Lag 0 counts only as a peak of its own, not as the tail of one at negative lag.
      const bool local_max = (i == 0 || c.r[i] >= c.r[i - 1]) && c.r[i] >= c.r[i + 1];
      if (local_max && c.r[i] >= level) {
        peak = i;
        break;
      }
    }
  }
  double shift = 0.0;
  if (peak > zero && peak + 1 < c.r.size()) {
    const double a = c.r[peak - 1], b = c.r[peak], g = c.r[peak + 1];
    const double curvature = a - 2.0 * b + g;
    if (curvature < 0.0) shift = std::clamp(0.5 * (a - g) / curvature, -0.5, 0.5);
  }
  p.found = true;
  p.time = (static_cast<double>(peak - zero) + shift) * dt;
  // Normalised by the trace's energy under the wavelet at that lag (the local normalised
  // cross-correlation): the match there, whatever else the trace holds elsewhere.
  const std::size_t lag = peak - zero;
  double local = 0.0;
  for (std::size_t i = lag; i < std::min(trace.size(), lag + wavelet.size()); ++i) {
    local += trace[i] * trace[i];
  }
  p.quality = local > 0.0 ? c.r[peak] / std::sqrt(ex * local) : 0.0;
  return p;
}

Pick firstBreakPick(std::span<const double> trace, double dt, double fraction) {
  requireStep(dt);
  if (!(fraction > 0.0 && fraction < 1.0)) {
    throw std::invalid_argument("signal: the first-break fraction must be in (0, 1)");
  }
  Pick p;
  double peak = 0.0;
  for (double v : trace) peak = std::max(peak, std::abs(v));
  if (!(peak > 0.0)) return p;
  const double level = fraction * peak;
  for (std::size_t i = 0; i < trace.size(); ++i) {
    if (std::abs(trace[i]) < level) continue;
    double t = static_cast<double>(i);
    if (i > 0) {  // between the last sample below the level and this one
      const double a = std::abs(trace[i - 1]), b = std::abs(trace[i]);
      t -= (b - level) / (b - a);
    }
    p.found = true;
    p.time = t * dt;
    p.quality = peak;
    break;
  }
  return p;
}

LineFit fitLine(std::span<const double> x, std::span<const double> y) {
  const std::size_t n = x.size();
  if (n != y.size() || n < 2) throw std::invalid_argument("signal: a line needs two points");
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < n; ++i) mx += x[i], my += y[i];
  mx /= static_cast<double>(n), my /= static_cast<double>(n);
  double sxx = 0.0, sxy = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
  }
  if (!(sxx > 0.0)) throw std::invalid_argument("signal: a line through points at one x");
  LineFit f;
  f.slope = sxy / sxx;
  f.intercept = my - f.slope * mx;
  if (n > 2) {
    double ss = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double r = y[i] - (f.intercept + f.slope * x[i]);
      ss += r * r;
    }
    f.slope_error = std::sqrt(ss / static_cast<double>(n - 2) / sxx);
  }
  return f;
}

Velocity velocityFromArrivals(std::span<const double> distance, std::span<const Pick> picks) {
  if (distance.size() != picks.size()) {
    throw std::invalid_argument("signal: one pick per receiver distance");
  }
  std::vector<double> d, t;
  for (std::size_t i = 0; i < picks.size(); ++i) {
    if (!picks[i].found) continue;
    d.push_back(distance[i]);
    t.push_back(picks[i].time);
  }
  Velocity v;
  v.used = d.size();
  if (d.size() < 2) return v;
  const LineFit f = fitLine(d, t);
  if (!(f.slope > 0.0)) return v;  // arrivals not later with distance: no velocity
  v.value = 1.0 / f.slope;
  v.error = f.slope_error / (f.slope * f.slope);
  v.delay = f.intercept;
  return v;
}

}  // namespace rocklab::signal
