#pragma once
// Key results: the few numbers a protocol is for (peak stress, a modulus at a strain, a band
// angle, k/k0 at a stress, a velocity at a stage). Each is defined once here, per rig, and
// evaluated from a run's data in the notebook; a protocol names its own in
// `protocol.key_results`. Reports headline them, `rocklab study accuracy` compares them across
// numerical settings and the regression references (`rocklab regress`) guard them.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "lab/protocol/params.hpp"
#include "reports/run_data.hpp"

namespace rocklab::reports {

struct KeyResultDef {
  std::string name, unit, doc;
  // The value for a run, or nothing when the run did not record what it needs. `prefix` is
  // the part before the name's last dot: a test of an envelope sweep ("test2."), a copy of
  // the oedometer's coring protocol ("cored."), a stage of the ultrasonic bench ("stage3.").
  std::optional<double> (*evaluate)(const RunData& run, const KeyResultDef& def,
                                    const std::string& prefix);
  // What the definition reads: a recorded result, or series and abscissae.
  std::string source, x_series;
  double at = 0.0, half_window = 0.0;
};

// Every key result a rig defines (empty for an unknown rig).
const std::vector<KeyResultDef>& keyResultDefs(std::string_view rig);
// The definition a (possibly prefixed) name refers to, or nullptr.
const KeyResultDef* findKeyResult(std::string_view rig, const std::string& name);
// Throws protocol::ProtocolError naming the file, line and the rig's list when
// `protocol.key_results` names a result its rig does not define.
void checkKeyResults(std::string_view rig, const protocol::Settings& s);
// `rocklab keys RIG`'s second half: the rig's key results with unit and meaning.
std::string keyResultHelp(std::string_view rig);

struct KeyValue {
  std::string name, unit, doc;
  std::optional<double> value;  // none: the run did not record it
};

// One key result of a run by its (possibly prefixed) name; none when the rig does not define
// it or the run did not record what it needs.
std::optional<double> evaluateKeyResult(const RunData& run, const std::string& name);
// The key results a run's protocol names, evaluated on the run.
std::vector<KeyValue> keyResults(const RunData& run);
// The names a run's protocol gave in `protocol.key_results`.
std::vector<std::string> keyResultNames(const RunData& run);

}  // namespace rocklab::reports
