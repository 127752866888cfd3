#pragma once
// The hydrostatic cell: every wall servo-controlled to one stress, ramped from the formation
// state up to a peak and optionally down again; the bulk modulus and the bonds broken.

#include "rigs/common/loading_keys.hpp"
#include "rigs/common/outputs.hpp"
#include "rigs/common/specimen.hpp"

namespace rocklab::rigs::hydrostatic {

struct Settings {
  SpecimenSettings specimen;
  double stress_max = 60.0 * kMPa;  // Pa
  double stress_rate = 2e4 * kMPa;  // Pa/s
  double unload_to = 0.0;           // Pa; 0: no unloading

  template <class F>
  void fields(F& f) {
    f.section("", specimen);
    auto loading = f.at("loading.");
    loading(stress_max, loading_keys::kStressMax);
    loading(stress_rate, loading_keys::kStressRate);
    loading(unload_to, {"unload_to_MPa", units::MPa, Range::closed(0, 1e5),
                        "after the peak, unload to this stress (0: no unloading)"});
  }
  // The peak above the formation stresses, the unloading below the peak.
  void validate() const;
};

void run(const Settings& s, Recorder& rec, RunControl& control);

}  // namespace rocklab::rigs::hydrostatic
