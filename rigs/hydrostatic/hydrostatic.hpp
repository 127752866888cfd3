#pragma once
// The hydrostatic cell: every axis servo-controlled to the same stress, ramped from the
// formation state to a peak and optionally back down; records volumetric strain, porosity
// and broken bonds against the mean stress.

#include "lab/protocol/params.hpp"
#include "rigs/common/experiment.hpp"

namespace rocklab::rigs::hydrostatic {

void declare(protocol::Schema& s);
void validate(const protocol::Settings& s);
void run(const protocol::Settings& s, Recorder& rec, RunControl& control);

}  // namespace rocklab::rigs::hydrostatic
