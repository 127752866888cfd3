#pragma once
// The oedometer cell (uniaxial strain): lateral walls fixed, the axial walls driven at a
// strain rate (or a stress ramp), with optional unload-reload cycles; the sample formed
// and cemented under stress first (Li & Holt, section 1, Figures 1 and 2). With coring on,
// the formed sample is also unloaded to near zero stress and reloaded before the same test
// (core damage), beside an untouched (virgin) copy of it.

#include "lab/protocol/params.hpp"
#include "rigs/common/experiment.hpp"

namespace rocklab::rigs::oedometer {

void declare(protocol::Schema& s);
void validate(const protocol::Settings& s);
void run(const protocol::Settings& s, Recorder& rec, RunControl& control);

}  // namespace rocklab::rigs::oedometer
