#pragma once
// The records a run leaves in the lab notebook, one type per kind of output: the rigs write
// them (rigs/common/experiment.hpp's Recorder), the notebook stores them (notebook.hpp) and
// reports read them back (reports/run_data.hpp). Header-only and free of SQLite, so that
// whoever makes a record needs nothing else of the notebook.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace rocklab::notebook {

// A protocol parameter as the run used it (the `params` table).
struct ParamRow {
  std::string key, value, unit;  // the value in the key's unit, as a protocol writes it
};

// Something that happened at one place and step (the `events` table): a bond or clump
// break, a pore's steady pressure.
struct EventRecord {
  std::uint64_t step = 0;
  double time = 0.0;
  std::string stage;     // the protocol stage, e.g. formation, loading, cored
  std::string kind;      // bond_break, clump_break, pore_pressure
  std::string mode;      // tensile, shear, crushing
  std::string granular;  // inter (cement) or intra (inside a grain: crushing)
  double x = 0.0, y = 0.0, z = 0.0;
  std::int64_t particle_a = -1, particle_b = -1;  // slots; -1: none
  double value = 0.0;  // e.g. the stress that broke the bond (Pa), a pressure (Pa)
};

// One ultrasonic measurement (the `waves`, `traces` and `picks` tables): a pulse sent through
// a copy of the sample at a loading stage, the receivers' traces and their arrival picks.
struct WaveRecord {
  std::uint64_t step = 0;  // the loading step whose state was copied
  double time = 0.0;
  std::string stage;  // e.g. "stage 3"
  std::string name;   // pz, px, szx, sxy
  std::string type;   // P or S
  int propagation_axis = 0, polarisation_axis = 0;
  double frequency = 0.0, amplitude = 0.0, dt = 0.0;           // Hz, m/s, s
  std::optional<double> velocity_xcorr, velocity_first_break;  // m/s; none: no velocity
  std::vector<double> source;                                  // m/s, every dt
  struct Receiver {
    double distance = 0.0;  // m
    std::int64_t particles = 0;
    std::int64_t picked_samples = 0;  // samples before the far end's echo
    std::vector<double> samples;      // m/s, every dt
    std::optional<double> xcorr_time, xcorr_quality, first_break_time;  // s, -, s; none: no pick
  };
  std::vector<Receiver> receivers;
};

}  // namespace rocklab::notebook
