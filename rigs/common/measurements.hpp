#pragma once
// What every rig records of a specimen: the standard series of its state, its bond and
// clump breaks as events, state frames, the simulations' stage timings, and whether a
// loading stage was quasi-static. These only read the specimen's simulation.

#include <string>
#include <vector>

#include "rigs/common/specimen.hpp"

namespace rocklab::rigs {

// A number for a message: `precision` significant digits.
std::string fmt(double v, int precision = 3);

// Records the standard measurements as series `prefix + name` and the breaks since the last
// record as events of `stage`; `strain_rate` (1/s, 0: not strain-driven) gives the
// inertial number.
template <int D>
void recordState(Specimen<D>& sp, Recorder& rec, const std::string& prefix,
                 const std::string& stage, double strain_rate);
// The bond and clump breaks the simulation logged since the last call, as events of `stage`.
template <int D>
void recordBreaks(Specimen<D>& sp, Recorder& rec, const std::string& stage);

// A frame of the state, when the protocol asks for snapshots (output.snapshots).
template <int D>
void snapshot(Specimen<D>& sp, Recorder& rec, const std::string& stage, const std::string& label);

// The stage timings of the simulations an experiment ran (branches summed), to the recorder,
// and each one's final state hash (a message).
template <int D>
void recordTimings(Recorder& rec, const std::vector<const Simulation<D>*>& sims);

// Quasi-static control is measured, not assumed: warns (a notebook message) when a
// loading stage's mean unbalanced force ratio or largest inertial number (0: not measured)
// passed the protocol's limits (numerics.quasi_static_*).
template <int D>
void warnIfNotQuasiStatic(const Specimen<D>& sp, Recorder& rec, const std::string& stage,
                          double mean_unbalanced, double inertial_max);

// The inertial number I = edot d sqrt(rho / p) of the present loading: below about 1e-3 a
// granular test is quasi-static (GDR MiDi 2004; da Cruz et al. 2005).
template <int D>
double inertialNumber(const Specimen<D>& sp, double strain_rate);
// The same at a stress scale p (Pa) of the rig's own: a disk's nominal stress, say.
template <int D>
double inertialNumber(const Specimen<D>& sp, double strain_rate, double p);

}  // namespace rocklab::rigs
