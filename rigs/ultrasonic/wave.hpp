#pragma once
// One ultrasonic measurement (Li & Holt section 4.1, Figures 16-17). On a copy of a loaded
// sample, a slab of particles across the path is driven with a one-period sine velocity
// pulse, along the path (P) or across it (S); receiver slabs further along record their
// mean velocity along the polarisation every step. Arrivals are picked by cross-correlation
// with the source's velocity and by first break (lab/signal), and each pick's velocity is
// the inverse slope of arrival time against distance over the receivers, so the source's
// own delay drops out. Damping is off and the walls stand still during the window.

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "lab/core/frame.hpp"
#include "lab/core/simulation.hpp"
#include "lab/signal/signal.hpp"

namespace rocklab::rigs::ultrasonic {

struct WaveSpec {
  std::string name;                     // pz, px, szx, sxy (Figure 18)
  int propagation = 0;                  // axis the wave travels along
  int polarisation = 0;                 // axis of the particle motion: the propagation axis for P
  double frequency = 0.0;               // Hz, of the one-period sine pulse
  double amplitude = 1e-3;              // m/s, the source's peak velocity
  double path_lo = 0.0, path_hi = 0.0;  // m, the sample's extent along the path
  double source_at = 0.1;               // source slab centre, fraction of the path from path_lo
  std::vector<double> receivers_at{0.35, 0.5, 0.65, 0.8};  // receiver slab centres, likewise
  double slab = 0.0;  // m, thickness of the source and receiver slabs along the path
  // Receivers keep the particles within this distance of the sample's axis across the path
  // (m, a disc in 3D; 0: the whole section). Inside the sample they hear the plane wave before
  // anything the sides send (section 4.1: "the transmitter and receiver can be placed inside").
  double receiver_half_width = 0.0;
  std::vector<double> centre;         // m, the sample's centre (D values) for receiver_half_width
  double first_break_fraction = 0.1;  // of each trace's peak magnitude
  // A cross-correlation pick whose normalised coefficient is below this matched noise, not
  // the pulse: it is left out of the velocity fit.
  double min_xcorr_quality = 0.75;  // a half-period misfit scores 1/sqrt(2)
  // The arrival is the earliest correlation peak reaching this fraction of the largest
  // (signal::crossCorrelationPick): a late burst cannot pass for it.
  double first_peak_fraction = 0.6;
  // The farthest receiver has heard the wave when its magnitude reaches this fraction of
  // the nearest one's peak; recording goes on `tail_periods` pulse periods after that:
  // enough for the pulse's main lobe, and short, because in a sample near failure the pulse
  // can set off an avalanche of breaks whose motion, later and louder, would bury it.
  double arrival_fraction = 0.1;
  double tail_periods = 1.25;
  std::uint64_t max_steps = 200000;
  // The receivers' own motion without the pulse (a loaded sample still creeps and rings when
  // its walls stop) comes from a second copy run without it, and is subtracted.
  bool subtract_background = true;
  // The receivers' sampling: one sample every this many steps (a digitiser's rate, 1 / (k dt)),
  // the instantaneous velocity at that step. 1 records every step; coarser sampling is
  // cheaper to store and pick, and coarser in time. At least four samples per pulse period.
  int sample_every = 1;
  int frames = 0;  // wave-front frames: one every pulse period from the pulse's end

  // The keys a protocol sets (its `wave.*` section; the geometry is the bench's).
  template <class F>
  void fields(F& f) {
    f(frequency, {"frequency_kHz", units::kHz, Range::leftOpen(0, 1e9),
                  "frequency of the one-period sine velocity pulse; its wavelength should span "
                  "several grains (checked)",
                  true});
    f(amplitude, {"amplitude_m_per_s", units::m_per_s, Range::leftOpen(0, 1e3),
                  "peak velocity of the source: small, so that contacts stay in their elastic "
                  "range"});
    f(source_at, {"source_at", units::none, Range::leftOpen(0, 1),
                  "source slab centre along the path, as a fraction of the sample from its low "
                  "face"});
    f(receivers_at, {"receivers_at", units::none, Range::leftOpen(0, 1),
                     "receiver slab centres along the path, fractions of the sample, ascending"});
    f(first_break_fraction, {"first_break_fraction", units::none, Range::open(0, 1),
                             "first-break level, as a fraction of each trace's peak magnitude"});
    f(sample_every, {"sample_every_steps", units::none, Range::closed(1, 1e6),
                     "the receivers' sampling: one sample every this many steps (1: every step; "
                     "at least four samples per pulse period, checked)"});
    f(max_steps, {"max_window_steps", units::none, Range::closed(100, 1e9),
                  "longest recording of one wave; it stops earlier once the farthest receiver "
                  "has heard the pulse"});
  }
  // At least two receivers, ascending beyond the source (their spacing against the slab
  // thickness is checked on the sample, by measureWave).
  void validate() const;
};

struct ReceiverTrace {
  double distance = 0.0;  // m, from the source slab's centre
  std::size_t particles = 0;
  std::vector<double> velocity;    // m/s, mean along the polarisation, every sample
  std::size_t picked_samples = 0;  // samples before the far end's echo can arrive
  signal::Pick xcorr, first_break;
};

struct WaveResult {
  WaveSpec spec;
  double dt = 0.0;  // s, the sampling step: sample_every simulation steps
  std::uint64_t steps = 0;
  std::size_t source_particles = 0;
  std::vector<double> source;  // m/s, the source's velocity every step (the wavelet)
  std::vector<ReceiverTrace> receivers;
  signal::Velocity xcorr, first_break;
  std::vector<Frame> frames;
  double wavelength() const { return xcorr.value / spec.frequency; }  // m
  // (first break - cross-correlation) / cross-correlation velocity.
  double disagreement() const;
};

// A measurement that cannot be made: an empty slab, or no arrival within max_steps.
class WaveError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Runs the wave on `sim`, which it changes (a copy of the loaded sample: Simulation::clone).
template <int D>
WaveResult measureWave(Simulation<D>& sim, const WaveSpec& spec);

}  // namespace rocklab::rigs::ultrasonic
