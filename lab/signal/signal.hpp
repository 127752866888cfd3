#pragma once
// Signals of the ultrasonic bench (rigs/ultrasonic/README.md): amplitude spectra, FFT cross-
// correlation, arrival picks and the velocity from arrival times over several receivers.
// FFTW stays inside signal.cpp; callers see plain vectors of samples at a constant step.

#include <cstddef>
#include <span>
#include <vector>

namespace rocklab::signal {

// One-sided amplitude spectrum |X(f)| of a real trace sampled every dt seconds, zero-padded
// to `pad_to` samples (at least the trace's length) for a finer frequency grid.
struct Spectrum {
  std::vector<double> frequency_hz, amplitude;
};
Spectrum amplitudeSpectrum(std::span<const double> x, double dt, std::size_t pad_to = 0);

// The linear (not circular) cross-correlation r(tau) = sum_j x[j] y[j + tau], for lags
// tau = first_lag ... first_lag + r.size() - 1 = -(x.size() - 1) ... y.size() - 1.
struct CrossCorrelation {
  std::vector<double> r;
  std::ptrdiff_t first_lag = 0;
};
CrossCorrelation crossCorrelate(std::span<const double> x, std::span<const double> y);

struct Pick {
  bool found = false;
  double time = 0.0;     // s, from the first sample
  double quality = 0.0;  // cross-correlation: coefficient at the peak normalised by the
                         // wavelet's energy and the trace's under it, in [-1, 1];
                         // first break: the trace's peak magnitude
};

// The delay of `trace` behind `wavelet` (both sampled every dt, sample 0 at one instant): the
// lag >= 0 of the largest cross-correlation, refined between samples by the parabola
// through the peak and its two neighbours (J. O. Smith, "Spectral Audio Signal Processing",
// quadratic interpolation of spectral peaks).
// With `first_peak_fraction` < 1 the pick is the earliest local maximum reaching that
// fraction of the largest: the direct arrival, when a later event (an echo, a burst of
// breaking bonds) correlates better.
Pick crossCorrelationPick(std::span<const double> wavelet, std::span<const double> trace, double dt,
                          double first_peak_fraction = 1.0);

// The first break: the first instant the trace's magnitude reaches `fraction` of its peak
// magnitude, interpolated linearly between the two samples around the crossing.
Pick firstBreakPick(std::span<const double> trace, double dt, double fraction);

// Least-squares line y = intercept + slope x, with the slope's standard error (0 for two
// points).
struct LineFit {
  double slope = 0.0, intercept = 0.0, slope_error = 0.0;
};
LineFit fitLine(std::span<const double> x, std::span<const double> y);

// A wave's velocity from its arrival times at receivers at known distances from the source:
// the inverse slope of time against distance (distances are exact, times carry the error),
// so the source's own delay (near field, the picks' offset) drops out.
struct Velocity {
  double value = 0.0;    // m/s
  double error = 0.0;    // m/s, one standard error from the fit
  double delay = 0.0;    // s, the fit's time at zero distance
  std::size_t used = 0;  // receivers with a pick
};
Velocity velocityFromArrivals(std::span<const double> distance, std::span<const Pick> picks);

}  // namespace rocklab::signal
