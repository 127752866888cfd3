// The ultrasonic bench's signal processing: FFT cross-correlation against the direct sum,
// picks on synthetic traces with a known delay and noise (within one sample, as the issue
// asks), the spectrum's peak, and the velocity from arrival times.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "lab/signal/signal.hpp"

namespace rocklab::signal {
namespace {

// A one-period sine pulse of frequency f starting at t0, sampled every dt.
std::vector<double> pulse(std::size_t n, double dt, double f, double t0) {
  std::vector<double> x(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * dt - t0;
    if (t >= 0.0 && t <= 1.0 / f) x[i] = std::sin(2.0 * std::numbers::pi * f * t);
  }
  return x;
}

void addNoise(std::vector<double>& x, double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  for (double& v : x) v += noise(rng);
}

TEST(Signal, FftCrossCorrelationEqualsTheDirectSum) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> x(13), y(29);
  for (double& v : x) v = u(rng);
  for (double& v : y) v = u(rng);
  const CrossCorrelation c = crossCorrelate(x, y);
  ASSERT_EQ(c.first_lag, -12);
  ASSERT_EQ(c.r.size(), x.size() + y.size() - 1);
  for (std::size_t k = 0; k < c.r.size(); ++k) {
    const std::ptrdiff_t lag = c.first_lag + static_cast<std::ptrdiff_t>(k);
    double direct = 0.0;
    for (std::ptrdiff_t j = 0; j < static_cast<std::ptrdiff_t>(x.size()); ++j) {
      const std::ptrdiff_t i = j + lag;
      if (i >= 0 && i < static_cast<std::ptrdiff_t>(y.size())) direct += x[j] * y[i];
    }
    EXPECT_NEAR(c.r[k], direct, 1e-12) << "lag " << lag;
  }
}

TEST(Signal, CrossCorrelationPicksAKnownDelayInNoiseWithinOneSample) {
  const double dt = 1e-8, f = 1e6;  // 100 samples per period
  const std::vector<double> wavelet = pulse(2000, dt, f, 0.0);
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const double delay = (300.0 + 37.3 * seed) * dt;  // not on a sample
    std::vector<double> trace = pulse(2000, dt, f, delay);
    for (double& v : trace) v *= 0.2;  // attenuated
    addNoise(trace, 0.02, seed);       // signal-to-noise 10 in amplitude
    const Pick p = crossCorrelationPick(wavelet, trace, dt);
    ASSERT_TRUE(p.found);
    EXPECT_NEAR(p.time, delay, dt) << "seed " << seed;
    EXPECT_GT(p.quality, 0.8);
  }
}

TEST(Signal, CrossCorrelationIsSubSampleOnACleanTrace) {
  const double dt = 1e-8, f = 1e6;
  const double delay = 412.37 * dt;
  const Pick p = crossCorrelationPick(pulse(2000, dt, f, 0.0), pulse(2000, dt, f, delay), dt);
  ASSERT_TRUE(p.found);
  EXPECT_NEAR(p.time, delay, 0.05 * dt);  // the parabola refines to a twentieth of a sample
  EXPECT_NEAR(p.quality, 1.0, 1e-3);
}

TEST(Signal, TheFirstStrongPeakIsTheDirectArrivalBeforeALouderLateEvent) {
  const double dt = 1e-8, f = 1e6;
  const std::vector<double> wavelet = pulse(3000, dt, f, 0.0);
  std::vector<double> trace = pulse(3000, dt, f, 500 * dt);
  const std::vector<double> late = pulse(3000, dt, f, 1800 * dt);
  for (std::size_t i = 0; i < trace.size(); ++i) trace[i] += 1.5 * late[i];
  EXPECT_NEAR(crossCorrelationPick(wavelet, trace, dt).time, 1800 * dt, 0.1 * dt);
  EXPECT_NEAR(crossCorrelationPick(wavelet, trace, dt, 0.6).time, 500 * dt, 0.1 * dt);
  // Alone, the pulse is picked the same either way.
  const std::vector<double> alone = pulse(3000, dt, f, 500 * dt);
  EXPECT_NEAR(crossCorrelationPick(wavelet, alone, dt, 0.6).time, 500 * dt, 0.1 * dt);
}

TEST(Signal, APolarityFlippedTraceGivesAPoorPick) {
  const double dt = 1e-8, f = 1e6;
  std::vector<double> trace = pulse(1000, dt, f, 200 * dt);
  for (double& v : trace) v = -v;
  const Pick p = crossCorrelationPick(pulse(1000, dt, f, 0.0), trace, dt);
  ASSERT_TRUE(p.found);
  // The best causal match is off by half a period: half the pulse matches half the trace
  // under it, 1/sqrt(2), below the bench's gate (WaveSpec::min_xcorr_quality 0.75).
  EXPECT_NEAR(p.quality, std::sqrt(0.5), 0.01);
}

TEST(Signal, FirstBreakPicksTheOnsetInNoiseWithinOneSample) {
  const double dt = 1e-8, f = 1e6;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const double onset = (250.0 + 41.7 * seed) * dt;
    std::vector<double> trace = pulse(2000, dt, f, onset);
    addNoise(trace, 0.005, seed);
    // 5% of the peak: sin(2 pi f t) reaches it 0.8 samples after the onset.
    const Pick p = firstBreakPick(trace, dt, 0.05);
    ASSERT_TRUE(p.found);
    EXPECT_NEAR(p.time, onset + std::asin(0.05) / (2.0 * std::numbers::pi * f), dt)
        << "seed " << seed;
  }
}

TEST(Signal, SilentTracesHaveNoPick) {
  const std::vector<double> zero(100, 0.0), w = pulse(100, 1e-8, 1e6, 0.0);
  EXPECT_FALSE(crossCorrelationPick(w, zero, 1e-8).found);
  EXPECT_FALSE(firstBreakPick(zero, 1e-8, 0.1).found);
  EXPECT_THROW(firstBreakPick(w, 1e-8, 1.5), std::invalid_argument);
  EXPECT_THROW(crossCorrelationPick(w, w, 0.0), std::invalid_argument);
}

TEST(Signal, SpectrumOfASinePeaksAtItsFrequency) {
  const double dt = 1e-7, f = 125e3;  // 80 samples per period, 40 periods
  std::vector<double> x(3200);
  for (std::size_t i = 0; i < x.size(); ++i) {
    x[i] = std::sin(2.0 * std::numbers::pi * f * static_cast<double>(i) * dt);
  }
  const Spectrum s = amplitudeSpectrum(x, dt);
  ASSERT_EQ(s.frequency_hz.size(), s.amplitude.size());
  const auto peak = std::max_element(s.amplitude.begin(), s.amplitude.end()) - s.amplitude.begin();
  EXPECT_NEAR(s.frequency_hz[peak], f, 1.0 / (static_cast<double>(x.size()) * dt));
  // A sine of unit amplitude over duration T has |X(f0)| = T / 2.
  EXPECT_NEAR(s.amplitude[peak], 0.5 * static_cast<double>(x.size()) * dt, 1e-3 * x.size() * dt);
  // Padding refines the grid, not the peak.
  const Spectrum fine = amplitudeSpectrum(x, dt, 4 * x.size());
  EXPECT_GT(fine.frequency_hz.size(), 3 * s.frequency_hz.size());
}

TEST(Signal, VelocityIsTheInverseSlopeOfArrivalTimes) {
  const double v = 2450.0, delay = 3e-7;
  const std::vector<double> d{0.002, 0.004, 0.006, 0.008};
  std::vector<Pick> picks;
  for (double x : d) picks.push_back(Pick{true, delay + x / v, 1.0});
  Velocity fit = velocityFromArrivals(d, picks);
  EXPECT_NEAR(fit.value, v, 1e-9 * v);
  EXPECT_NEAR(fit.delay, delay, 1e-15);
  EXPECT_NEAR(fit.error, 0.0, 1e-6);
  EXPECT_EQ(fit.used, 4u);
  // A receiver without a pick is left out; one pick is not a velocity.
  picks[1].found = false;
  fit = velocityFromArrivals(d, picks);
  EXPECT_EQ(fit.used, 3u);
  EXPECT_NEAR(fit.value, v, 1e-9 * v);
  picks[2].found = picks[3].found = false;
  EXPECT_EQ(velocityFromArrivals(d, picks).value, 0.0);
}

}  // namespace
}  // namespace rocklab::signal
