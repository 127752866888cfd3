#pragma once
// Protocol parameters, each declared once: its dotted key (the unit is part of the name,
// e.g. `formation.axial_stress_MPa`), kind, unit, default (none: required), allowed range
// and a one-line doc. The declarations validate protocol files, print the help text and
// fill the notebook's parameter table.

#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

namespace rocklab::protocol {

enum class Kind { Real, Integer, Text, Choice, Flag, RealList, TextList };

using Value = std::variant<double, std::int64_t, std::string, bool, std::vector<double>,
                           std::vector<std::string>>;

struct ParamDecl {
  std::string key;
  Kind kind = Kind::Real;
  std::string unit;               // as in the key name: "MPa", "1/s", "-"; empty for text
  double to_si = 1.0;             // factor from the key's unit to SI (MPa: 1e6)
  std::optional<Value> fallback;  // the default; none means required
  double lo = -INFINITY, hi = INFINITY;
  bool lo_open = false, hi_open = false;
  std::vector<std::string> choices;
  std::string doc;

  std::string rangeText() const;  // e.g. "(0, 1]" or "one of: skip, resample"
};

// A set of declarations; builders return the declaration to refine.
class Schema {
 public:
  ParamDecl& real(const std::string& key, const std::string& unit, double to_si,
                  std::optional<double> fallback, const std::string& doc);
  ParamDecl& integer(const std::string& key, std::optional<std::int64_t> fallback,
                     const std::string& doc);
  ParamDecl& text(const std::string& key, std::optional<std::string> fallback,
                  const std::string& doc);
  ParamDecl& choice(const std::string& key, std::vector<std::string> choices,
                    std::optional<std::string> fallback, const std::string& doc);
  ParamDecl& flag(const std::string& key, std::optional<bool> fallback, const std::string& doc);
  ParamDecl& realList(const std::string& key, const std::string& unit, double to_si,
                      std::optional<std::vector<double>> fallback, const std::string& doc);
  ParamDecl& textList(const std::string& key, std::optional<std::vector<std::string>> fallback,
                      const std::string& doc);

  const ParamDecl* find(const std::string& key) const;
  const std::vector<ParamDecl>& all() const { return decls_; }

  // The rig these keys are for, and the keys other rigs use for effects this one cannot
  // (a wave source, pore fluid, ...): a protocol giving one is told which rig it belongs to.
  void setRig(std::string name) { rig_ = std::move(name); }
  const std::string& rig() const { return rig_; }
  void addForeign(const std::string& key, const std::string& rig);
  // The rigs that use `key` ("ultrasonic", "biaxial, envelope"), empty when none.
  std::string foreignRigs(const std::string& key) const;
  // The help text: one line per key with unit, default, range and doc.
  std::string help() const;

 private:
  ParamDecl& add(ParamDecl d);
  std::vector<ParamDecl> decls_;
  std::string rig_;
  std::vector<std::pair<std::string, std::string>> foreign_;  // key, rig
};

// Range helpers for declarations.
inline ParamDecl& range(ParamDecl& d, double lo, bool lo_open, double hi, bool hi_open) {
  d.lo = lo, d.lo_open = lo_open, d.hi = hi, d.hi_open = hi_open;
  return d;
}

// Every problem found in a protocol file, one per line: "file:line: key ...".
class ProtocolError : public std::runtime_error {
 public:
  explicit ProtocolError(const std::vector<std::string>& problems);
  const std::vector<std::string>& problems() const { return problems_; }

 private:
  std::vector<std::string> problems_;
};

struct ParamRow {
  std::string key, value, unit;
};

// The validated values of a protocol.
class Settings {
 public:
  // In the unit the key names (e.g. MPa for `..._MPa`).
  double real(const std::string& key) const;
  // Converted to SI.
  double si(const std::string& key) const;
  std::int64_t integer(const std::string& key) const;
  const std::string& text(const std::string& key) const;
  bool flag(const std::string& key) const;
  std::vector<double> list(const std::string& key) const;  // in the key's unit
  std::vector<double> listSi(const std::string& key) const;
  const std::vector<std::string>& texts(const std::string& key) const;
  bool given(const std::string& key) const { return given_.count(key) > 0; }
  // Where a key was set, for errors found across keys ("file:line").
  std::string where(const std::string& key) const;
  // Every parameter with its value (given or default) and unit.
  std::vector<ParamRow> table() const;
  const std::string& file() const { return file_; }
  // Replaces a value after parsing (a command-line override); the range is checked.
  void override(const std::string& key, Value v);
  // The same from command-line text (`--vary numerics.timestep_safety=0.3`), read as the
  // key's kind; lists cannot be given this way.
  void overrideText(const std::string& key, const std::string& text);
  bool declared(const std::string& key) const;
  const std::string& source() const { return source_; }

 private:
  friend Settings parseProtocol(const std::string&, const std::string&, const Schema&);
  const Value& value(const std::string& key) const;
  const ParamDecl& decl(const std::string& key) const;
  std::shared_ptr<const Schema> schema_;  // owned: settings outlive the schema they came from
  std::string file_, source_;
  std::map<std::string, Value> values_;
  std::map<std::string, int> given_;  // key -> line
};

// Parses TOML text read from `file`, checks every key against the schema and returns the
// settings; throws ProtocolError with all problems (unknown or missing keys, wrong types,
// values out of range) each naming the file, line, key, allowed range and unit.
Settings parseProtocol(const std::string& file, const std::string& text, const Schema& schema);

// A problem found across several keys, in the same format.
[[noreturn]] void fail(const Settings& s, const std::string& key, const std::string& why);

// Reads a whole file; throws naming it when unreadable.
std::string readFile(const std::string& path);

// The rig a protocol names in `protocol.rig`, read before its schema is known.
std::string rigOf(const std::string& file, const std::string& text);

}  // namespace rocklab::protocol
