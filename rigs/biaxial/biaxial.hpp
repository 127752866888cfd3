#pragma once
// The biaxial frame (2D) and the triaxial cell (3D): the sample formed and cemented under
// stress, brought to a confining stress held by servo walls, then loaded axially at a
// strain rate through its peak (Li & Holt, section 2.3, Figures 4-6). Zero confinement is
// the uniaxial compressive strength (UCS) test.

#include "lab/protocol/params.hpp"
#include "rigs/common/experiment.hpp"

namespace rocklab::rigs::biaxial {

void declare(protocol::Schema& s);
void validate(const protocol::Settings& s);
void run(const protocol::Settings& s, Recorder& rec, RunControl& control);

}  // namespace rocklab::rigs::biaxial
