#pragma once
// The `loading.*` keys several rigs read, each declared once here: its key, unit, range and
// doc. A rig declares the key with one of these in its settings struct and gives its own
// default there (the value of its reference experiment: Figure 4's confinement for the
// biaxial frame, Figure 18c's for the ultrasonic bench).

#include "lab/core/fields.hpp"

namespace rocklab::rigs::loading_keys {

inline constexpr Field kConfiningStress{
    "confining_stress_MPa", units::MPa, Range::closed(0, 1e4),
    "lateral stress held by servo walls during axial loading (sigma_3); 0: the UCS test"};
inline constexpr Field kAxialStrainRate{"axial_strain_rate_per_s", units::per_s,
                                        Range::leftOpen(0, 1e6),
                                        "axial strain rate; its inertial number is checked"};
inline constexpr Field kAxialStrainMax{
    "axial_strain_max", units::none, Range::leftOpen(0, 0.9),
    "axial strain since the start of loading at which loading stops"};
inline constexpr Field kStopAfterDrop{
    "stop_after_drop", units::none, Range::closed(0, 1),
    "stop once the load (deviatoric stress, platen force) has fallen this fraction below its "
    "peak (0: run to axial_strain_max)"};
inline constexpr Field kStopAfterDropMinStrain{
    "stop_after_drop_min_strain", units::none, Range::closed(0, 0.9),
    "the drop stops the test only past this axial strain: the first grains to break or slip "
    "under a barely loaded sample make no peak"};
inline constexpr Field kStressMax{"stress_max_MPa", units::MPa, Range::leftOpen(0, 1e5),
                                  "peak stress of the hydrostatic ramp"};
inline constexpr Field kStressRate{
    "stress_rate_MPa_per_s", units::MPa_per_s, Range::leftOpen(0, 1e12),
    "stress rate of the hydrostatic ramps (on the ultrasonic bench, of the confinement too)"};

}  // namespace rocklab::rigs::loading_keys
