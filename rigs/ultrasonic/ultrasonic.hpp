#pragma once
// The ultrasonic bench (Li & Holt section 4, Figure 18): a sample loaded hydrostatically, in
// uniaxial strain or triaxially; at each stress or strain stage the state is copied and
// P and S waves are sent through the copy along and across the axis (pz, px, szx, sxy), and
// small strain cycles on further copies give the static moduli to set beside the dynamic
// ones. The loading itself never sees the measurements.

#include <cstdint>
#include <vector>

#include "rigs/common/loading_keys.hpp"
#include "rigs/common/outputs.hpp"
#include "rigs/common/specimen.hpp"
#include "rigs/ultrasonic/wave.hpp"

namespace rocklab::rigs::ultrasonic {

enum class LoadingMode { Hydrostatic, UniaxialStrain, Triaxial };

struct Settings {
  SpecimenSettings specimen;
  LoadingMode mode = LoadingMode::Hydrostatic;
  std::vector<double> stages_stress{1.0 * kMPa, 2.0 * kMPa, 4.0 * kMPa, 8.0 * kMPa};  // Pa
  std::vector<double> stages_axial_strain{0.001, 0.002, 0.003};
  double stress_rate = 2e3 * kMPa;        // Pa/s
  double confining_stress = 2.85 * kMPa;  // Pa, Figure 18c
  double axial_strain_rate = 0.5;         // 1/s
  WaveSpec wave;
  double slab_diameters = 2.0;       // source and receiver slabs' thickness, mean diameters
  double receiver_half_width = 0.5;  // of the sample's smaller half width across the path
  std::int64_t hold_steps = 20000;
  int frames = 3;  // wave-front frames of each wave at the last stage
  bool static_moduli = true;
  double static_strain_amplitude = 1e-4;
  double static_strain_rate = 1.0;  // 1/s

  template <class F>
  void fields(F& f) {
    static constexpr Choice<LoadingMode> kModes[] = {
        {"hydrostatic", LoadingMode::Hydrostatic},
        {"uniaxial-strain", LoadingMode::UniaxialStrain},
        {"triaxial", LoadingMode::Triaxial}};
    f.section("", specimen);
    auto loading = f.at("loading.");
    loading(mode,
            {"mode",
             units::text,
             {},
             "the loading the waves are measured along: every wall servoed to one stress; "
             "lateral walls fixed and an axial strain rate; or a confining stress and an "
             "axial strain rate"},
            kModes);
    loading(stages_stress, {"stages_MPa", units::MPa, Range::leftOpen(0, 1e5),
                            "hydrostatic: the stresses, ascending, at which waves are measured"});
    loading(stages_axial_strain,
            {"stages_axial_strain", units::none, Range::leftOpen(0, 0.5),
             "uniaxial-strain and triaxial: the axial strains, ascending, at which waves are "
             "measured; loading ends at the last"});
    loading(stress_rate, loading_keys::kStressRate);
    loading(confining_stress, loading_keys::kConfiningStress);
    loading(axial_strain_rate, loading_keys::kAxialStrainRate);
    f.section("wave.", wave);
    auto w = f.at("wave.");
    w(slab_diameters, {"slab_diameters", units::none, Range::leftOpen(0, 100),
                       "thickness of the source and receiver slabs, in mean particle diameters"});
    w(receiver_half_width,
      {"receiver_half_width", units::none, Range::leftOpen(0, 10),
       "receivers keep the particles within this fraction of the sample's smaller half width of "
       "its axis (a disc in 3D)"});
    w(hold_steps, {"hold_steps", units::none, Range::closed(0, 1e9),
                   "most steps a copy is held at rest (walls still, damped) before its waves and "
                   "static cycles"});
    w(frames, {"frames", units::none, Range::closed(0, 20),
               "wave-front frames of each wave at the last stage, one every pulse period "
               "(Figure 17)"});
    auto statics = f.at("static.");
    statics(static_moduli, {"enabled",
                            units::text,
                            {},
                            "measure static moduli by small strain cycles (lateral walls held) at "
                            "each stage"});
    // 1e-5 was lost in what is left of the unbalanced force at "rest": the loading and
    // unloading slopes disagreed. 1e-4 is still a tenth of a Hertzian overlap at 0.5 MPa.
    statics(static_strain_amplitude,
            {"strain_amplitude", units::none, Range::leftOpen(0, 1e-2),
             "strain of the static cycle: small, to stay in the elastic range, but large enough "
             "to stand out of the residual unbalanced force"});
    // The moduli come from rest states between the moves (each move is followed by a hold
    // until the copy is at rest), so the rate only sets how long a move takes.
    statics(static_strain_rate, {"strain_rate_per_s", units::per_s, Range::leftOpen(0, 1e6),
                                 "strain rate of the static cycle's moves; the stresses are read "
                                 "at rest after each"});
  }
  // Spheres or grains (a clump's pebbles move with their body: they can be neither driven
  // nor weighed one by one), and the stages of the loading's mode, ascending.
  void validate() const;
};

void run(const Settings& s, Recorder& rec, RunControl& control);

}  // namespace rocklab::rigs::ultrasonic
