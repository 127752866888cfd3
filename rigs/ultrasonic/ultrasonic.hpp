#pragma once
// The ultrasonic bench (Li & Holt section 4, Figure 18): a sample loaded hydrostatically, in
// uniaxial strain or triaxially; at each stress or strain stage the state is copied and
// P and S waves are sent through the copy along and across the axis (pz, px, szx, sxy), and
// small strain cycles on further copies give the static moduli to set beside the dynamic
// ones. The loading itself never sees the measurements.

#include "lab/protocol/params.hpp"
#include "rigs/common/experiment.hpp"

namespace rocklab::rigs::ultrasonic {

void declare(protocol::Schema& s);
void validate(const protocol::Settings& s);
void run(const protocol::Settings& s, Recorder& rec, RunControl& control);

}  // namespace rocklab::rigs::ultrasonic
