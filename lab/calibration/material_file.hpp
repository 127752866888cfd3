#pragma once
// The material file a calibration writes (lab/calibration/README.md, "Outputs"): protocols
// include it, so it must hold the whole material, not only the fitted keys.

#include <string>
#include <utility>
#include <vector>

namespace rocklab::calibration {

// `previous` (the file as it was, empty when there was none) with its leading comment block
// replaced by `header`, and each of `keys` ("table.leaf", TOML literal) written in: on the
// line that gave it, else under its table's header, else in a new table at the end. Every
// other key and comment of the file stays, so that what the calibration did not fit (the
// grains' shape, a bond model set by hand, the reasons in comments) is not lost. Throws
// std::invalid_argument when a key cannot be placed (a dotted or inline-table spelling), so
// that nothing half-written replaces the file.
std::string materialText(const std::string& previous, const std::string& header,
                         const std::vector<std::pair<std::string, std::string>>& keys);

// Whether a key belongs in a material file: the grains', cement's and contacts' tables, not
// the sample's count, the loading or the numerics a calibration's [set] may also fix.
bool isMaterialKey(const std::string& key);

}  // namespace rocklab::calibration
