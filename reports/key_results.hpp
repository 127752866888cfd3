#pragma once
// Key results: the few numbers a protocol is for (peak stress, a modulus at a strain, a band
// angle, k/k0 at a stress, a velocity at a stage). Each rig declares its key results (name,
// unit, meaning: rigs/<rig>/outputs.cpp); here each has its rule, how it is evaluated from a
// run's data in the notebook. A protocol names its own in `protocol.key_results`. Reports
// headline them, `rocklab study accuracy` compares them across numerical settings and the
// regression references (`rocklab regress`) guard them.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "reports/run_data.hpp"

namespace rocklab::reports {

struct KeyResultRule {
  std::string name;  // as the rig declares it ('#' a number: cycle#_modulus_ratio)
  // The value for a run, or nothing when the run did not record what it needs. `prefix` is
  // the part before the name's first dot: a test of an envelope sweep ("test2."), a copy of
  // the oedometer's coring protocol ("cored."), a stage of the ultrasonic bench ("stage3.");
  // `base` the rest.
  std::optional<double> (*evaluate)(const RunData& run, const KeyResultRule& rule,
                                    const std::string& prefix, const std::string& base);
  // What the rule reads: a recorded result (empty: the result named like the key result),
  // or series and abscissae.
  std::string source, x_series;
  double at = 0.0, half_window = 0.0;
};

// Every rule of a rig (empty for an unknown rig).
const std::vector<KeyResultRule>& keyResultRules(std::string_view rig);
// The rule a (possibly prefixed) name refers to, or nullptr.
const KeyResultRule* findKeyResultRule(std::string_view rig, const std::string& name);

struct KeyValue {
  std::string name, unit, doc;
  std::optional<double> value;  // none: the run did not record it
};

// One key result of a run by its (possibly prefixed) name; none when the rig has no rule
// for it or the run did not record what it needs.
std::optional<double> evaluateKeyResult(const RunData& run, const std::string& name);
// The key results a run's protocol names, evaluated on the run, with the rig's unit and doc.
std::vector<KeyValue> keyResults(const RunData& run);
// The names a run's protocol gave in `protocol.key_results`.
std::vector<std::string> keyResultNames(const RunData& run);

}  // namespace rocklab::reports
