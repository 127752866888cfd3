#pragma once
// The permeameter (Li & Holt section 3.5, Figure 10): a sample in the loading frame with a
// pore fluid driven through it by fixed pressures at its two ends along the flow and no
// flow through its sides. The network is solved to steady state every n particle steps,
// its pressures act on the particles, and the Darcy permeability k is recorded against
// stress, strain and porosity, normalised by its value before loading, beside the
// Kozeny-Carman estimate (equation 8).
//
// Loading: hydrostatic (every axis to one stress; in 2D the paper's "plane strain, equal
// loading in x and y"), or biaxial / triaxial (confinement, then axial strain through
// failure). The flow goes along the loading axis, normal to it, or both ways at once: the
// permeability anisotropy of Figure 14 measured on one test.

#include "lab/protocol/params.hpp"
#include "rigs/common/experiment.hpp"

namespace rocklab::rigs::permeameter {

void declare(protocol::Schema& s);
void validate(const protocol::Settings& s);
void run(const protocol::Settings& s, Recorder& rec, RunControl& control);

}  // namespace rocklab::rigs::permeameter
