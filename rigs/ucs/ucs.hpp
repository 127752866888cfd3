#pragma once
// The unconfined compression test (ISRM suggested method, Fairhurst & Hudson 1999): the
// formed, cemented sample is unloaded, taken out of its box (a prism, or in 3D a cylinder cut
// from it) and compressed between two platens with free sides. Its strength (UCS) is the
// peak platen force over the cross-section; Young's modulus and Poisson's ratio are taken at
// half the peak, secant and tangent; the crack damage stress is where the volumetric strain
// turns from compaction to dilatancy (Martin & Chandler 1994). The lateral strain is
// measured on the particles of a gauge section at mid-height, as strain gauges are on a
// laboratory core.

#include "rigs/common/loading_keys.hpp"
#include "rigs/common/outputs.hpp"
#include "rigs/common/release.hpp"
#include "rigs/common/specimen.hpp"

namespace rocklab::rigs::ucs {

enum class Shape { Prism, Cylinder };

struct Settings {
  SpecimenSettings specimen;
  unconfined::Release release;
  unconfined::Loading loading{0.5, 0.03, 0.3, 0.002};
  double platen_friction = 0.0;  // frictionless platens: a uniform stress, no end cones
  Shape shape = Shape::Prism;
  double diameter_ratio = 0.9;  // the cylinder's diameter over the box's smaller side
  double gauge_height = 0.5;    // the gauge section's height over the specimen's

  template <class F>
  void fields(F& f) {
    f.section("", specimen);
    f.section("loading.", loading);
    f.at("loading.")(platen_friction,
                     {"platen_friction", units::none, Range::closed(0, 10),
                      "friction coefficient between the platens and the specimen's ends"});
    f.section("release.", release);
    static constexpr Choice<Shape> kShape[] = {{"prism", Shape::Prism},
                                               {"cylinder", Shape::Cylinder}};
    auto cut = f.at("cut.");
    cut(shape,
        {"shape", units::text, {}, "prism: the box's sample as formed; cylinder (3D): cut from it"},
        kShape);
    cut(diameter_ratio, unconfined::kCutDiameterRatio);
    f.at("gauge.")(gauge_height,
                   {"height_ratio", units::none, Range::leftOpen(0, 1),
                    "height of the mid-height section whose particles measure the strains, "
                    "over the specimen's"});
  }
  // Rules across keys: those of every test out of its box, and a cylinder only in 3D.
  void validate() const;
};

void run(const Settings& s, Recorder& rec, RunControl& control);

}  // namespace rocklab::rigs::ucs
