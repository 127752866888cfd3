#pragma once
// One loading test of the biaxial frame / triaxial cell, shared by the single-test rig
// (`biaxial`), the confinement sweep (`envelope`) and the permeameter's biaxial mode:
// confinement held by servo walls, axial strain rate through the peak, the critical point
// and the failure band.

#include <string>

#include "rigs/common/adaptive_rate.hpp"
#include "rigs/common/envelope.hpp"
#include "rigs/common/loading_keys.hpp"
#include "rigs/common/specimen.hpp"

namespace rocklab::rigs::biaxial {

// The test's `loading.*` keys, without the confinement, which each rig declares its own way.
struct LoadingTest {
  double confining_rate = 2e4 * kMPa;  // Pa/s
  double seating_stress = 0.1 * kMPa;  // Pa
  double axial_strain_rate = 1.0;      // 1/s
  double axial_strain_max = 0.05;
  double stop_after_drop = 0.0;
  double stop_after_drop_min_strain = 0.002;
  bool stop_after_drop_dilating = false;
  double rest_speed_ratio = 0.0;
  RateBoost boost;  // rigs/common/adaptive_rate.hpp

  template <class F>
  void fields(F& f) {
    f(confining_rate, {"confining_rate_MPa_per_s", units::MPa_per_s, Range::leftOpen(0, 1e12),
                       "stress rate from the formation state to the confinement"});
    f(seating_stress, {"seating_stress_MPa", units::MPa, Range::closed(0, 1e3),
                       "axial stress above the confinement the platens keep before loading"});
    f(rest_speed_ratio,
      {"rest_speed_ratio", units::none, Range::closed(0, 10),
       "the confinement ends once the grains' mean speed is below this fraction of the "
       "platens' speed at the axial strain rate, besides the stresses on target and the "
       "balance (0: those alone)"});
    f(axial_strain_rate, loading_keys::kAxialStrainRate);
    f(axial_strain_max, loading_keys::kAxialStrainMax);
    f(stop_after_drop, loading_keys::kStopAfterDrop);
    f(stop_after_drop_min_strain, loading_keys::kStopAfterDropMinStrain);
    f(stop_after_drop_dilating,
      {"stop_after_drop_dilating",
       units::text,
       {},
       "the drop stops the test only if the sample has dilated since its peak (volumetric "
       "strain 0.001 below the peak's, more than the elastic swelling of the drop): a "
       "compacting sample's load falls at a burst of crushing and hardens again, where a "
       "dilatant failure does not recover"});
    boost.fields(f);
  }
  // A test that stops after the peak must get past it: a drop needs room to show.
  void validate() const;
  // Whether the test ends at this state: at the strain limit, or past its peak (`peak` the
  // highest load so far, at `peak_strain` and volumetric strain `peak_volumetric`) once the
  // load has fallen by stop_after_drop. Volumetric strains compaction positive.
  bool ends(double strain, double load, double volumetric, double peak, double peak_strain,
            double peak_volumetric) const;
};

// The localisation analysis (`analysis.*`, rigs/common/localisation.hpp).
struct BandAnalysis {
  double band_width_radii = 8.0;
  double strained_fraction = 0.15;

  template <class F>
  void fields(F& f) {
    f(band_width_radii,
      {"band_width_radii", units::none, Range::closed(1, 1e3),
       "width of the trial band of the localisation analysis, in mean particle radii"});
    f(strained_fraction, {"strained_fraction", units::none, Range::leftOpen(0, 1),
                          "fraction of the particles, the most strained from the critical point "
                          "to the end, in which the band of the strain field is sought"});
  }
};

struct TestOutcome {
  double sigma3 = 0.0;     // Pa
  CriticalPoint critical;  // q in Pa
};

// The sample's measured make-up (particles, grains and their aspect ratios) as results.
template <int D>
void recordSample(const Specimen<D>& sp, Recorder& rec);

// Servos the formed specimen to `sigma3` (Pa; plus the seating stress axially), then loads
// it. Series, results and stages are prefixed with `branch` + "." when a branch is named.
template <int D>
TestOutcome confineAndLoad(Specimen<D>& sp, const LoadingTest& test, const BandAnalysis& analysis,
                           double sigma3, const std::string& branch, Recorder& rec,
                           RunControl& control);

}  // namespace rocklab::rigs::biaxial
