#pragma once
// What the campaign and calibration readers share of TOML: values written back as protocol
// text, and the [slurm] table both files take.

#include <map>
#include <string>
#include <toml.hpp>
#include <vector>

#include "lab/campaign/campaign.hpp"

namespace rocklab::campaign {

using TomlValue = toml::basic_value<toml::discard_comments, std::map, std::vector>;

// A number in its shortest form that reads back to the same double ("2.0", not "2").
std::string numberText(double x);
// A TOML value written back as TOML that reads to the same value (the protocol parser reads
// the overrides): numbers in their shortest round-trip form, texts quoted; "" for tables and
// dates.
std::string tomlLiteral(const TomlValue& v);
// Reads a [slurm] table; each problem as "file:line: slurm.KEY: why".
void readSlurmTable(const TomlValue& t, const std::string& file, SlurmOptions& s,
                    std::vector<std::string>& problems);
// The [slurm] table that reads back to `s` ("" when it is all defaults).
std::string slurmTableText(const SlurmOptions& s);

// A file's problems, collected to be thrown together, each with its file:line.
class TomlReader {
 public:
  explicit TomlReader(std::string file) : file_(std::move(file)) {}
  std::string at(const TomlValue& v) const {
    return file_ + ":" + std::to_string(v.location().line());
  }
  void problem(const TomlValue& v, const std::string& what) {
    problems_.push_back(at(v) + ": " + what);
  }
  void problem(const std::string& placed) { problems_.push_back(placed); }  // says where itself
  void slurm(const TomlValue& t, SlurmOptions& s) { readSlurmTable(t, file_, s, problems_); }
  bool any() const { return !problems_.empty(); }
  void throwIfAny() const {
    if (!problems_.empty()) throw protocol::ProtocolError(problems_);
  }
  const std::string& file() const { return file_; }
  // The keys of a table and its nested tables, dotted ("loading.rate" from [set.loading]).
  static void flatten(const TomlValue& table, const std::string& prefix,
                      std::vector<std::pair<std::string, const TomlValue*>>& out) {
    for (const auto& [k, v] : table.as_table()) {
      const std::string key = prefix.empty() ? k : prefix + "." + k;
      if (v.is_table()) {
        flatten(v, key, out);
      } else {
        out.emplace_back(key, &v);
      }
    }
  }

 private:
  std::string file_;
  std::vector<std::string> problems_;
};

}  // namespace rocklab::campaign
