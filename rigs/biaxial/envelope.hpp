#pragma once
// The failure envelope (Li & Holt, section 2.3, Figure 6): one sample formed and cemented
// once, then a biaxial (2D) or triaxial (3D) test at each confinement of a sweep, each on
// its own copy of the formed state. Each test's critical point (dilatant peak, or the onset
// of shear-enhanced compaction) is a point of the envelope; the dilatant points give the
// Mohr-Coulomb line (equation 1), the compactive ones the end cap.

#include "lab/protocol/params.hpp"
#include "rigs/common/experiment.hpp"

namespace rocklab::rigs::envelope {

void declare(protocol::Schema& s);
void validate(const protocol::Settings& s);
void run(const protocol::Settings& s, Recorder& rec, RunControl& control);

}  // namespace rocklab::rigs::envelope
