#pragma once
// What both tensile tests share: their release and loading keys; taking a formed sample out
// of its box (every wall fixed, the side walls a box length away) and letting it settle once
// cut or glued; watching the load for its peak and the end.

#include <algorithm>

#include "rigs/common/loading_keys.hpp"
#include "rigs/common/specimen.hpp"

namespace rocklab::rigs::unconfined {

// The release (`release.*`): the formation stress relieved, the specimen settled once out
// of its box.
struct Release {
  double unload_to = 0.1 * kMPa;    // Pa
  double unload_rate = 2e4 * kMPa;  // Pa/s
  std::int64_t relax_steps_max = 20000;

  template <class F>
  void fields(F& f) {
    f(unload_to, {"unload_to_MPa", units::MPa, Range::closed(0, 1e5),
                  "the formation stress is relieved to this before the specimen is taken out "
                  "of the box"});
    f(unload_rate, {"unload_rate_MPa_per_s", units::MPa_per_s, Range::leftOpen(0, 1e12),
                    "stress rate of that unloading"});
    f(relax_steps_max,
      {"relax_steps_max", units::none, Range::closed(0, 1e9),
       "out of the box, the specimen settles until its unbalanced force ratio is below "
       "formation.unbalanced_force_ratio, at most this many steps"});
  }
};

// The loading (`loading.*`): its rate and when it ends (PeakWatch::ends). Each rig gives
// its own defaults.
struct Loading {
  double axial_strain_rate = 0.5;  // 1/s
  double axial_strain_max = 0.05;
  double stop_after_drop = 0.5;
  double stop_after_drop_min_strain = 0.0;

  template <class F>
  void fields(F& f) {
    f(axial_strain_rate, loading_keys::kAxialStrainRate);
    f(axial_strain_max, loading_keys::kAxialStrainMax);
    f(stop_after_drop, loading_keys::kStopAfterDrop);
    f(stop_after_drop_min_strain, loading_keys::kStopAfterDropMinStrain);
  }
};

// `cut.diameter_ratio`, the one key of a cut both the Brazilian disk and the UCS cylinder
// take: the cut's diameter over the box's smaller side across the cylinder's axis.
inline constexpr Field kCutDiameterRatio{
    "diameter_ratio", units::none, Range::leftOpen(0, 1),
    "diameter of the disk (Brazilian) or cylinder (UCS) cut from the sample, over the box's "
    "smaller side across its axis"};

// Builds, forms and cements the sample and relieves its formation stress (stage
// `unloading`), ready to be taken out of its box.
template <int D>
Specimen<D> formAndUnload(const SpecimenSettings& s, const Release& release, Recorder& rec,
                          RunControl& control);

// Fixes every wall and takes the walls of every axis but the axial one a box length away.
template <int D>
void clearSides(Specimen<D>& sp);

// Steps the specimen as it stands (stage `relaxation`) until its unbalanced force ratio is
// below formation.unbalanced_force_ratio, at most max_steps: the cut or the unloading freed
// the stress its bonds locked in at the formation.
template <int D>
void relax(Specimen<D>& sp, std::int64_t max_steps, Recorder& rec, RunControl& control);

// A tensile test's watch over its loading: the peak of the load and what was broken at it,
// whether the test ends, when it records, and how calm the loading was.
struct PeakWatch {
  double peak = 0.0, peak_strain = 0.0;
  std::size_t breaks_at_peak = 0;  // the break log's length at the peak
  std::uint64_t tensile_at_peak = 0, shear_at_peak = 0;
  std::uint64_t last_record = 0, records = 0;
  double unbalanced_sum = 0.0;

  // Takes this step's load and strain: true at a new peak, whose breaks it notes.
  template <int D>
  bool see(const Specimen<D>& sp, double load, double strain);
  // Whether the loading ends: at axial_strain_max, or once the load has fallen by
  // stop_after_drop (> 0) below the peak past stop_after_drop_min_strain, a crack having run
  // since the peak (10 bonds broken): near zero load the first steps make and lose small
  // forces without one.
  bool ends(double load, double strain, std::size_t breaks, const Loading& rule) const;
  // Whether to record this step: at the interval, at the end, and at new peaks a tenth of
  // it apart, so that the series holds the peak within a few steps where a brittle
  // specimen fails between two regular records.
  bool recordDue(std::uint64_t stage_step, std::uint64_t step, std::uint64_t every, bool new_peak,
                 bool done) const;
  // The series every tensile test records (the breaks by mode, the unbalanced force ratio)
  // and the break events up to now, under the stage.
  template <int D>
  void record(Specimen<D>& sp, Recorder& rec, const std::string& stage);
  double meanUnbalanced() const {
    return unbalanced_sum / static_cast<double>(std::max<std::uint64_t>(records, 1));
  }
  template <class Archive>
  void visit(Archive& ar) {
    ar("peak", peak), ar("peak_strain", peak_strain), ar("breaks_at_peak", breaks_at_peak);
    ar("tensile_at_peak", tensile_at_peak), ar("shear_at_peak", shear_at_peak);
    ar("last_record", last_record), ar("records", records), ar("unbalanced_sum", unbalanced_sum);
  }
};

// What every tensile test records of its loading: the breaks at the peak by mode and in all,
// its steps, how calm it was (with a warning past the protocol's quasi-static limits).
template <int D>
void recordLoadingResults(const Specimen<D>& sp, const PeakWatch& w, std::uint64_t start_step,
                          double inertial_at_peak, Recorder& rec);

// Rules across keys both tensile tests share: the unloading below the formation stresses, the
// strain limit past the drop's, no clumps (a rigid grain can be neither cut nor glued).
void validate(const SpecimenSettings& specimen, const Release& release, const Loading& loading);

}  // namespace rocklab::rigs::unconfined
