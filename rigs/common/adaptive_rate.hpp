#pragma once
// A loading rate that adapts to the sample's balance: fast while it is calm, the protocol's
// own rate while it breaks. A strain-driven quasi-static test spends most of its steps where
// nothing happens (the elastic rise, the calm between the first isolated breaks); the
// platens may go faster there, and must be back at the set rate whenever a bond or a grain
// breaks or the sample falls out of balance, so that the peak and the failure are loaded as
// the reference rate loads them. `loading.rate_boost_max` = 1 (off) keeps the set rate.
//
// Every kWindowSteps steps: a window with a break, or ending with the unbalanced force ratio
// above `calm_unbalanced`, sets the factor back to 1 at once; a calm window raises it by
// kGrowth, up to `max`. The gradual rise keeps the platens from jolting the sample.

#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "lab/core/fields.hpp"

namespace rocklab::rigs {

struct RateBoost {
  double max = 1.0;
  double calm_unbalanced = 0.005;

  template <class F>
  void fields(F& f) {
    f(max, {"rate_boost_max", units::none, Range::closed(1, 100),
            "the axial strain rate up to this times its set value while the sample is calm "
            "(no break in the last 100 steps, balanced): 1 keeps the set rate"});
    f(calm_unbalanced, {"rate_calm_unbalanced", units::none, Range::leftOpen(0, 1),
                        "the unbalanced force ratio below which the sample counts as calm"});
  }
};

class AdaptiveRate {
 public:
  static constexpr std::uint64_t kWindowSteps = 100;
  static constexpr double kGrowth = 1.25;

  AdaptiveRate() = default;
  explicit AdaptiveRate(const RateBoost& boost) : boost_(boost) {}

  // At the end of a window: the breaks since the loading began and the unbalanced force
  // ratio now. Returns the factor on the set rate for the next window.
  double update(std::size_t breaks, double unbalanced) {
    const bool calm = breaks == breaks_ && unbalanced < boost_.calm_unbalanced;
    breaks_ = breaks;
    factor_ = calm ? std::min(boost_.max, factor_ * kGrowth) : 1.0;
    return factor_;
  }
  // The update at the end of each window of a stage's steps (counted from its start), from
  // the simulation's breaks and balance; true when the factor changed. Nothing while off.
  template <class Sim>
  bool window(std::uint64_t steps, const Sim& sim) {
    if (boost_.max <= 1.0 || steps % kWindowSteps != 0) return false;
    const double before = factor_;
    return update(sim.bondBreaks().size() + sim.clumpBreaks().size(), sim.unbalancedForceRatio()) !=
           before;
  }
  double factor() const { return factor_; }
  // Only the state: the settings come from the protocol again on a resume.
  template <class Archive>
  void visit(Archive& ar) {
    ar("factor", factor_), ar("breaks", breaks_);
  }

 private:
  RateBoost boost_;
  double factor_ = 1.0;
  std::size_t breaks_ = 0;
};

}  // namespace rocklab::rigs
