#pragma once
// The direct tension test: the formed, cemented sample is unloaded and taken out of its box,
// its end layers glued to the platens (driven particles) and pulled apart along the axis at a
// set rate. Its tensile strength is the peak force over the cross-section, its modulus in
// tension the slope of that stress against the strain between the glued layers.

#include "rigs/common/loading_keys.hpp"
#include "rigs/common/outputs.hpp"
#include "rigs/common/specimen.hpp"
#include "rigs/tensile/release.hpp"

namespace rocklab::rigs::direct_tension {

struct Settings {
  SpecimenSettings specimen;
  double unload_to = 0.1 * kMPa;    // Pa
  double unload_rate = 2e4 * kMPa;  // Pa/s
  std::int64_t relax_steps_max = 20000;
  double layer_diameters = 2.0;    // glued layers' thickness, in mean particle diameters
  double axial_strain_rate = 0.5;  // 1/s
  double axial_strain_max = 0.02;
  double stop_after_drop = 0.5;
  double stop_after_drop_min_strain = 0.0;

  template <class F>
  void fields(F& f) {
    f.section("", specimen);
    auto loading = f.at("loading.");
    loading(axial_strain_rate, loading_keys::kAxialStrainRate);
    loading(axial_strain_max, loading_keys::kAxialStrainMax);
    loading(stop_after_drop, loading_keys::kStopAfterDrop);
    loading(stop_after_drop_min_strain, loading_keys::kStopAfterDropMinStrain);
    auto release = f.at("release.");
    release(unload_to, tensile::kUnloadTo);
    release(unload_rate, tensile::kUnloadRate);
    release(relax_steps_max, tensile::kRelaxStepsMax);
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
