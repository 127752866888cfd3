#pragma once
// The Brazilian test (diametral compression; ISRM 1978, ASTM D3967): a disk (2D) or a
// cylinder lying on its side (3D, axis along y) is cut from the formed, cemented sample after
// its formation stress is relieved, brought between two flat platens and loaded along its
// diameter at a set rate. Its tensile strength is sigma_t = 2 F_peak / (pi D t), the
// elastic solution's tensile stress at the centre (Hondros 1959), t the disk's thickness
// (2D) or the cylinder's length (3D).

#include "rigs/common/loading_keys.hpp"
#include "rigs/common/outputs.hpp"
#include "rigs/common/release.hpp"
#include "rigs/common/specimen.hpp"

namespace rocklab::rigs::brazilian {

struct Settings {
  SpecimenSettings specimen;
  unconfined::Release release;
  unconfined::Loading loading{0.5, 0.05, 0.5, 0.001};
  double diameter_ratio = 0.9;  // the disk's diameter over the box's smaller side

  template <class F>
  void fields(F& f) {
    f.section("", specimen);
    f.section("loading.", loading);
    f.section("release.", release);
    auto cut = f.at("cut.");
    cut(diameter_ratio, unconfined::kCutDiameterRatio);
  }
  // The disk must hold some particles across (a diameter of at least 10 mean diameters is
  // checked when it is cut); clumps cannot be cut through.
  void validate() const;
};

void run(const Settings& s, Recorder& rec, RunControl& control);

}  // namespace rocklab::rigs::brazilian
