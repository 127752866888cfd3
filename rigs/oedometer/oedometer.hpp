#pragma once
// The oedometer cell (uniaxial strain): lateral walls fixed, the axial walls driven at a
// strain rate (or a stress ramp), with optional unload-reload cycles; the sample formed
// and cemented under stress first (Li & Holt, section 1, Figures 1 and 2). With coring on,
// the formed sample is also unloaded to near zero stress and reloaded before the same test
// (core damage), beside an untouched (virgin) copy of it.

#include <vector>

#include "rigs/common/adaptive_rate.hpp"
#include "rigs/common/loading_keys.hpp"
#include "rigs/common/outputs.hpp"
#include "rigs/common/specimen.hpp"

namespace rocklab::rigs::oedometer {

enum class Control { StrainRate, StressRamp };

struct Settings {
  SpecimenSettings specimen;
  Control control = Control::StrainRate;
  double axial_strain_rate = 5.0;          // 1/s
  double axial_strain_max = 0.03;          // strain control: the end of loading
  double axial_stress_rate = 1e5 * kMPa;   // Pa/s, stress ramp
  double axial_stress_max = 100.0 * kMPa;  // Pa, stress ramp: the end of loading
  std::vector<double> cycle_at_axial_strain;
  double cycle_unload_fraction = 0.5;
  bool coring = false;
  double coring_unload_to = 0.5 * kMPa;    // Pa
  double coring_stress_rate = 2e4 * kMPa;  // Pa/s
  RateBoost boost;                         // rigs/common/adaptive_rate.hpp (strain control)

  template <class F>
  void fields(F& f) {
    static constexpr Choice<Control> kControls[] = {{"strain_rate", Control::StrainRate},
                                                    {"stress_ramp", Control::StressRamp}};
    f.section("", specimen);
    auto loading = f.at("loading.");
    loading(control,
            {"control",
             units::text,
             {},
             "drive the axial walls at a strain rate, or servo them along a stress ramp"},
            kControls);
    loading(axial_strain_rate, loading_keys::kAxialStrainRate);
    loading(axial_strain_max, loading_keys::kAxialStrainMax);
    loading(axial_stress_rate,
            {"axial_stress_rate_MPa_per_s", units::MPa_per_s, Range::leftOpen(0, 1e12),
             "axial stress rate (stress_ramp control)"});
    loading(axial_stress_max, {"axial_stress_max_MPa", units::MPa, Range::leftOpen(0, 1e5),
                               "axial stress at which a stress ramp stops"});
    loading(cycle_at_axial_strain,
            {"cycle_at_axial_strain", units::none, Range::leftOpen(0, 0.9),
             "axial strains at which the axial stress is cycled: unloaded, then reloaded"});
    loading(cycle_unload_fraction,
            {"cycle_unload_fraction", units::none, Range::leftOpen(0, 1),
             "each cycle unloads this fraction of the axial stress gained since formation "
             "(below 1: a cycle never unloads past the formation state, which would core)"});
    boost.fields(loading);
    auto core = f.at("coring.");
    core(coring, {"enabled",
                  units::text,
                  {},
                  "also core the formed sample (unload to near zero stress, reload) and test it "
                  "beside the virgin one"});
    core(coring_unload_to, {"unload_to_MPa", units::MPa, Range::leftOpen(0, 1e4),
                            "the stress coring unloads to, all axes"});
    core(coring_stress_rate, {"stress_rate_MPa_per_s", units::MPa_per_s, Range::leftOpen(0, 1e12),
                              "stress rate of the coring unload and the reload"});
  }
  // Cycles under strain control, rising, below the end of loading; coring below formation.
  void validate() const;
};

void run(const Settings& s, Recorder& rec, RunControl& control);

}  // namespace rocklab::rigs::oedometer
