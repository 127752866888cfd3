#pragma once
// One loading test of the biaxial frame / triaxial cell, shared by the single-test rig
// (`biaxial`) and the confinement sweep (`envelope`): confinement held by servo walls,
// axial strain rate through the peak, the critical point and the failure band.

#include <string>

#include "rigs/common/envelope.hpp"
#include "rigs/common/specimen.hpp"

namespace rocklab::rigs::biaxial {

// The loading keys (rate, end of the test, localisation analysis), without the
// confinement, which each rig declares its own way.
void declareLoading(protocol::Schema& s);
void validateLoading(const Settings& s);

struct TestOutcome {
  double sigma3 = 0.0;     // Pa
  CriticalPoint critical;  // q in Pa
};

// The sample's measured make-up (particles, grains and their aspect ratios) as results.
template <int D>
void recordSample(const Specimen<D>& sp, Recorder& rec);

// Servos the formed specimen to `sigma3` (plus the seating stress axially), then loads it.
// Series, results and stages are prefixed with `branch` + "." when a branch is named.
template <int D>
TestOutcome confineAndLoad(Specimen<D>& sp, const Settings& s, double sigma3,
                           const std::string& branch, Recorder& rec, RunControl& control);

}  // namespace rocklab::rigs::biaxial
