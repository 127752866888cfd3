#pragma once
// The biaxial frame (2D) and the triaxial cell (3D): the sample formed and cemented under
// stress, brought to a confining stress held by servo walls, then loaded axially at a
// strain rate through its peak (Li & Holt, section 2.3, Figures 4-6). Zero confinement is
// the uniaxial compressive strength (UCS) test.

#include "rigs/biaxial/loading.hpp"
#include "rigs/common/outputs.hpp"

namespace rocklab::rigs::biaxial {

struct Settings {
  SpecimenSettings specimen;
  double confining_stress = 4.0 * kMPa;  // Pa, Figure 4's shear band
  LoadingTest test;
  BandAnalysis analysis;

  template <class F>
  void fields(F& f) {
    f.section("", specimen);
    f.at("loading.")(confining_stress, loading_keys::kConfiningStress);
    f.section("loading.", test);
    f.section("analysis.", analysis);
  }
};

void run(const Settings& s, Recorder& rec, RunControl& control);

}  // namespace rocklab::rigs::biaxial
