#pragma once
// The paper's numbers (data/paper.toml) with where each comes from, for reports to show
// beside what a run gave.

#include <optional>
#include <string>
#include <vector>

namespace rocklab::reports {

struct PaperNumber {
  std::string key, unit, source, note, param, result;
  double value = 0.0;
};

struct Paper {
  std::vector<PaperNumber> numbers;
  const PaperNumber* byKey(const std::string& key) const;
  const PaperNumber* byParam(const std::string& param) const;
  const PaperNumber* byResult(const std::string& result) const;
};

// Reads data/paper.toml; throws naming the file on a malformed entry.
Paper loadPaper(const std::string& path);

}  // namespace rocklab::reports
