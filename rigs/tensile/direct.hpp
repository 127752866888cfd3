#pragma once
// The direct tension test: the formed, cemented sample is unloaded and taken out of its box,
// its end layers glued to the platens (driven particles) and pulled apart along the axis at a
// set rate. Its tensile strength is the peak force over the cross-section, its modulus in
// tension the slope of that stress against the strain between the glued layers.

#include "rigs/common/loading_keys.hpp"
#include "rigs/common/outputs.hpp"
#include "rigs/common/release.hpp"
#include "rigs/common/specimen.hpp"

namespace rocklab::rigs::direct_tension {

struct Settings {
  SpecimenSettings specimen;
  unconfined::Release release;
  unconfined::Loading loading{0.5, 0.02, 0.5, 0.0};
  double layer_diameters = 2.0;  // glued layers' thickness, in mean particle diameters

  template <class F>
  void fields(F& f) {
    f.section("", specimen);
    f.section("loading.", loading);
    f.section("release.", release);
    auto glue = f.at("glue.");
    glue(layer_diameters,
         {"layer_diameters", units::none, Range::closed(0.5, 20),
          "thickness of each end layer glued to its platen, in mean particle diameters"});
  }
  // Rules across keys: the unloading below the formation stresses, the strain limit past
  // the drop's, no clumps (a rigid grain cannot be glued by some of its pebbles).
  void validate() const;
};

void run(const Settings& s, Recorder& rec, RunControl& control);

}  // namespace rocklab::rigs::direct_tension
