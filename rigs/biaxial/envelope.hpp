#pragma once
// The failure envelope (Li & Holt, section 2.3, Figure 6): one sample formed and cemented
// once, then a biaxial (2D) or triaxial (3D) test at each confinement of a sweep, each on
// its own copy of the formed state. Each test's critical point (dilatant peak, or the onset
// of shear-enhanced compaction) is a point of the envelope; the dilatant points give the
// Mohr-Coulomb line (equation 1), the compactive ones the end cap.

#include <vector>

#include "rigs/biaxial/loading.hpp"
#include "rigs/common/outputs.hpp"

namespace rocklab::rigs::envelope {

struct Settings {
  SpecimenSettings specimen;
  std::vector<double> confining_stresses{0.0, 4.0 * kMPa, 10.0 * kMPa, 18.0 * kMPa};  // Pa
  biaxial::LoadingTest test;
  biaxial::BandAnalysis analysis;

  template <class F>
  void fields(F& f) {
    f.section("", specimen);
    f.at("envelope.")(confining_stresses,
                      {"confining_stresses_MPa", units::MPa, Range::closed(0, 1e4),
                       "confining stresses of the sweep, rising, one test each (0: the UCS test)"});
    f.section("loading.", test);
    f.section("analysis.", analysis);
  }
  // At least two confinements, rising strictly.
  void validate() const;
};

void run(const Settings& s, Recorder& rec, RunControl& control);

}  // namespace rocklab::rigs::envelope
