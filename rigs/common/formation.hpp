#pragma once
// Forming a specimen under stress and moving it between stress states by servo (Li & Holt
// section 1: the sample is formed under stress, then cemented, so the bonds take only
// what comes after).

#include <string>

#include "rigs/common/specimen.hpp"

namespace rocklab::rigs {

// Servo-controls the frame to the formation state (axial and lateral stress), settles it to
// equilibrium, then sets the material's own friction and, when bonds are enabled, cements
// every contact with zero initial load. The formation's breaks are recorded with it.
template <int D>
void formAndCement(Specimen<D>& sp, Recorder& rec, RunControl& control);

// Moves the frame by servo from its present stresses to (axial, lateral) targets (Pa) at a
// stress rate (Pa/s), and holds there until settled: the stresses on target and the sample
// in balance, and with `rest_speed` (m/s) above 0 the grains' mean speed below it. Used by
// coring, reloading and confinement.
template <int D>
void servoTo(Specimen<D>& sp, double axial, double lateral, double rate, const std::string& stage,
             Recorder& rec, RunControl& control, double rest_speed = 0.0);

}  // namespace rocklab::rigs
