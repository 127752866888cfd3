#pragma once
// Protocol files: TOML checked against a schema of keys. Each key's declaration (its dotted
// key with the unit in its name, e.g. `formation.axial_stress_MPa`, its kind, unit,
// default, allowed range and one-line doc) comes from the settings struct that owns it
// (lab/core/fields.hpp; declare.hpp builds the schema and reads the structs back). The
// schema validates protocol files, prints `rocklab keys` and fills the notebook's parameter
// table.

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "lab/core/fields.hpp"
#include "lab/notebook/records.hpp"

namespace rocklab::protocol {

enum class Kind { Real, Integer, Text, Choice, Flag, RealList, TextList };

// A value in the key's unit (numbers are converted to SI only when read into a struct).
using Value = std::variant<double, std::int64_t, std::string, bool, std::vector<double>,
                           std::vector<std::string>>;

struct ParamDecl {
  std::string key;
  Kind kind = Kind::Real;
  Unit unit = units::none;
  std::optional<Value> fallback;  // the default; none means required
  Range range;                    // numbers and the elements of a list of numbers
  std::vector<std::string> choices;
  std::string doc;

  std::string rangeText() const;  // e.g. "(0, 1]" or "one of: skip, resample"
};

class Schema {
 public:
  // Throws std::logic_error for a key declared twice.
  ParamDecl& add(ParamDecl d);
  const ParamDecl* find(const std::string& key) const;
  const std::vector<ParamDecl>& all() const { return decls_; }
  // Narrows a text key to a list of names known only where the schema is assembled (the
  // rigs of `protocol.rig`).
  void setChoices(const std::string& key, std::vector<std::string> choices);

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
  std::vector<ParamDecl> decls_;
  std::string rig_;
  std::vector<std::pair<std::string, std::string>> foreign_;  // key, rig
};

// Every problem found in a protocol file, one per line: "file:line: key ...".
class ProtocolError : public std::runtime_error {
 public:
  explicit ProtocolError(const std::vector<std::string>& problems);
  const std::vector<std::string>& problems() const { return problems_; }

 private:
  std::vector<std::string> problems_;
};

// A value given on the command line instead of in the file: `--set KEY=VALUE` (also the
// values of a study's `--vary`). The value is TOML (`0.3`, `true`, `[1, 2]`, `"text"`); a
// text key also takes it bare (`--set sample.kind=file`).
struct Override {
  std::string key, value;
  std::string origin = "--set";  // what messages and the effective protocol text call it
  std::string label() const { return origin + " " + key + "=" + value; }
};
// "KEY=VALUE" as typed; throws ProtocolError naming `origin` when there is no '='.
Override parseOverride(const std::string& text, const std::string& origin = "--set");

// The validated values of a protocol, in the units their keys name.
class Settings {
 public:
  double real(const std::string& key) const;
  std::int64_t integer(const std::string& key) const;
  const std::string& text(const std::string& key) const;  // texts and choices
  // A path key's value, relative to the protocol file's folder unless absolute ("" stays).
  std::string path(const std::string& key) const;
  bool flag(const std::string& key) const;
  const std::vector<double>& list(const std::string& key) const;
  const std::vector<std::string>& texts(const std::string& key) const;
  bool given(const std::string& key) const { return given_.count(key) > 0; }
  // Where a key was set, for errors found across keys: "file:line" (of the protocol or of
  // the file it includes that gives the key), or the override ("--set KEY=VALUE").
  std::string where(const std::string& key) const;
  // Every parameter with its value (given or default) and unit.
  std::vector<notebook::ParamRow> table() const;
  const std::string& file() const { return file_; }
  // Replaces a value after parsing (the run's own choices: `--threads`, a seed of a seed
  // series), not marked in the effective text; the range is checked.
  void override(const std::string& key, Value v);
  // The same for a choice that leaves the results as they are (`--threads`): the effective
  // text keeps the file's value, so the protocol's hash does not depend on it.
  void runChoice(const std::string& key, Value v);
  // Applies overrides as parseProtocol does: each validated like a key in the file, every
  // problem reported at once naming the override; marked in effectiveText().
  void apply(const std::vector<Override>& overrides);
  bool declared(const std::string& key) const;
  const ParamDecl& decl(const std::string& key) const;  // throws std::logic_error if undeclared
  // The protocol file's text as read.
  const std::string& source() const { return source_; }
  // The files its `include` names (a material's keys), as paths from the working folder,
  // then its base's.
  const std::vector<std::string>& includes() const { return includes_; }
  // The protocol its `base` names (this one gives only what differs from it), or "".
  const std::string& base() const { return base_; }
  // The protocol as run: the file's text when nothing was overridden or included, else the
  // text with each override written in and marked ("# --set ..."), or, when it includes
  // files or has a base, every key written out: parsing it alone gives these settings (the notebook
  // keeps it; `rocklab rerun` runs it again; a changed material file changes its hash).
  std::string effectiveText() const;
  // What the run is, whatever the text says it with: every key away from its default (given
  // by the file, its includes or an override), with its value, in the schema's order.
  // Its hash tells a run in the notebook (a campaign's task already done), so that moving a
  // protocol's material to an included file or editing a comment does not make it another
  // protocol. The run's own choices (`--threads`) and the description are left out.
  std::string identity() const;

 private:
  friend Settings parseProtocol(const std::string&, const std::string&, const Schema&,
                                const std::vector<Override>&);
  const Value& value(const std::string& key) const;
  std::shared_ptr<const Schema> schema_;  // owned: settings outlive the schema they came from
  std::string file_, source_;
  std::map<std::string, Value> values_;
  std::vector<std::string> includes_;
  std::string base_;
  std::map<std::string, int> given_;             // key -> line (0: given by an override)
  std::map<std::string, std::string> given_in_;  // key -> the included file that gave it
  std::map<std::string, Override> overrides_;    // key -> the override that set it last
  std::map<std::string, Value> unchosen_;        // key -> its value before runChoice()
};

// Parses TOML text read from `file`, checks every key against the schema and returns the
// settings; throws ProtocolError with all problems (unknown or missing keys, wrong types,
// values out of range) each naming the file, line, key, allowed range and unit. A top-level
// `include = "materials/NAME.toml"` (or a list of them; relative to `file`'s folder) adds
// the keys of those files, checked the same way at their own lines; a key is given once,
// in the protocol or in one included file. A top-level `base = "OTHER.toml"` (relative to
// `file`'s folder) takes every key of that protocol (with its includes and base) that the
// file and its includes do not give: a variant gives only what differs. Overrides replace or
// add keys after the files', validated the same way.
Settings parseProtocol(const std::string& file, const std::string& text, const Schema& schema,
                       const std::vector<Override>& overrides = {});

// A problem found across several keys, in the same format ("file:line: key: why").
[[noreturn]] void fail(const Settings& s, const std::string& key, const std::string& why);

// Reads a whole file; throws naming it when unreadable.
std::string readFile(const std::string& path);

// The rig a protocol names in `protocol.rig`, read before its schema is known.
std::string rigOf(const std::string& file, const std::string& text);

}  // namespace rocklab::protocol
