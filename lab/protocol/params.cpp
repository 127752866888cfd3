#include "lab/protocol/params.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <toml.hpp>
#include <tuple>

namespace rocklab::protocol {

namespace {

using TomlValue = toml::basic_value<toml::discard_comments, std::map, std::vector>;

std::string number(double v) {
  return Range::formatNumber(v);
}

// A value as text: numbers by `real`, a text by `text`, the texts of a list by `listed`.
template <class Real, class Text, class Listed>
std::string render(const Value& v, Real real, Text text, Listed listed) {
  return std::visit(
      [&](const auto& x) -> std::string {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, double>) {
          return real(x);
        } else if constexpr (std::is_same_v<T, std::int64_t>) {
          return std::to_string(x);
        } else if constexpr (std::is_same_v<T, std::string>) {
          return text(x);
        } else if constexpr (std::is_same_v<T, bool>) {
          return x ? "true" : "false";
        } else {
          std::string t = "[";
          for (std::size_t k = 0; k < x.size(); ++k) {
            if constexpr (std::is_same_v<T, std::vector<double>>) {
              t += (k ? ", " : "") + real(x[k]);
            } else {
              t += (k ? ", " : "") + listed(x[k]);
            }
          }
          return t + "]";
        }
      },
      v);
}

// As `rocklab keys` and the notebook's parameters show it (10 significant digits).
std::string show(const Value& v) {
  return render(
      v, number, [](const std::string& t) { return t; },
      [](const std::string& t) { return "\"" + t + "\""; });
}

std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] != b[j - 1])});
    }
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

bool inRange(const ParamDecl& d, double v) {
  return d.range.contains(v);
}

std::string unitText(const ParamDecl& d) {
  return d.unit.name.empty() ? "" : " (" + std::string(d.unit.name) + ")";
}

}  // namespace

std::string ParamDecl::rangeText() const {
  if (kind == Kind::Choice) {
    std::string s = "one of: ";
    for (std::size_t k = 0; k < choices.size(); ++k) s += (k ? ", " : "") + choices[k];
    return s;
  }
  if (kind == Kind::Text || kind == Kind::Flag || kind == Kind::TextList) return "";
  return range.text();
}

ParamDecl& Schema::add(ParamDecl d) {
  if (find(d.key)) throw std::logic_error("parameter declared twice: " + d.key);
  decls_.push_back(std::move(d));
  return decls_.back();
}

void Schema::setChoices(const std::string& key, std::vector<std::string> choices) {
  for (ParamDecl& d : decls_) {
    if (d.key != key) continue;
    d.kind = Kind::Choice;
    d.choices = std::move(choices);
    return;
  }
  throw std::logic_error("setChoices: no key " + key);
}

void Schema::addForeign(const std::string& key, const std::string& rig) {
  foreign_.emplace_back(key, rig);
}

std::string Schema::foreignRigs(const std::string& key) const {
  std::string rigs;
  for (const auto& [k, r] : foreign_) {
    if (k == key) rigs += (rigs.empty() ? "" : ", ") + r;
  }
  return rigs;
}

const ParamDecl* Schema::find(const std::string& key) const {
  for (const ParamDecl& d : decls_) {
    if (d.key == key) return &d;
  }
  return nullptr;
}

std::string Schema::help() const {
  std::ostringstream s;
  for (const ParamDecl& d : decls_) {
    s << "  " << d.key << unitText(d);
    if (d.fallback) {
      s << " = " << show(*d.fallback);
    } else {
      s << "  (required)";
    }
    const std::string r = d.rangeText();
    if (!r.empty()) s << "  " << r;
    s << "\n      " << d.doc << "\n";
  }
  return s.str();
}

ProtocolError::ProtocolError(const std::vector<std::string>& problems)
    : std::runtime_error([&] {
        std::string s;
        for (const auto& p : problems) s += (s.empty() ? "" : "\n") + p;
        return s;
      }()),
      problems_(problems) {}

const ParamDecl& Settings::decl(const std::string& key) const {
  const ParamDecl* d = schema_ ? schema_->find(key) : nullptr;
  if (!d) throw std::logic_error("protocol key not declared: " + key);
  return *d;
}

const Value& Settings::value(const std::string& key) const {
  decl(key);
  return values_.at(key);
}

double Settings::real(const std::string& key) const {
  return std::get<double>(value(key));
}
std::int64_t Settings::integer(const std::string& key) const {
  return std::get<std::int64_t>(value(key));
}
const std::string& Settings::text(const std::string& key) const {
  return std::get<std::string>(value(key));
}
std::string Settings::path(const std::string& key) const {
  const std::string& v = text(key);
  if (v.empty() || std::filesystem::path(v).is_absolute()) return v;
  return (std::filesystem::path(file_).parent_path() / v).lexically_normal().string();
}

bool Settings::flag(const std::string& key) const {
  return std::get<bool>(value(key));
}
const std::vector<double>& Settings::list(const std::string& key) const {
  return std::get<std::vector<double>>(value(key));
}
const std::vector<std::string>& Settings::texts(const std::string& key) const {
  return std::get<std::vector<std::string>>(value(key));
}

std::string Settings::where(const std::string& key) const {
  if (auto o = overrides_.find(key); o != overrides_.end()) return o->second.label();
  auto it = given_.find(key);
  const auto in = given_in_.find(key);
  return (in == given_in_.end() ? file_ : in->second) +
         (it == given_.end() ? "" : ":" + std::to_string(it->second));
}

std::vector<notebook::ParamRow> Settings::table() const {
  std::vector<notebook::ParamRow> rows;
  for (const ParamDecl& d : schema_->all()) {
    rows.push_back({d.key, show(values_.at(d.key)), std::string(d.unit.name)});
  }
  return rows;
}

void Settings::override(const std::string& key, Value v) {
  const ParamDecl& d = decl(key);
  if (std::holds_alternative<double>(v) && !inRange(d, std::get<double>(v))) {
    throw ProtocolError({key + " = " + show(v) + " is outside the allowed range " + d.rangeText()});
  }
  if (std::holds_alternative<std::int64_t>(v) &&
      !inRange(d, static_cast<double>(std::get<std::int64_t>(v)))) {
    throw ProtocolError({key + " = " + show(v) + " is outside the allowed range " + d.rangeText()});
  }
  values_[key] = std::move(v);
}

void Settings::runChoice(const std::string& key, Value v) {
  if (!unchosen_.count(key)) unchosen_[key] = value(key);
  override(key, std::move(v));
}

bool Settings::declared(const std::string& key) const {
  return schema_ && schema_->find(key);
}

void fail(const Settings& s, const std::string& key, const std::string& why) {
  s.decl(key);  // a key no schema declares is the caller's mistake, not the protocol's
  throw ProtocolError({s.where(key) + ": " + key + ": " + why});
}

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ProtocolError({path + ": cannot read the protocol file"});
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

namespace {

TomlValue parseToml(const std::string& file, const std::string& text) {
  std::istringstream in(text);
  try {
    return toml::parse<toml::discard_comments, std::map, std::vector>(in, file);
  } catch (const std::exception& e) {
    throw ProtocolError({file + ": not valid TOML:\n" + e.what()});
  }
}

}  // namespace

namespace {

// A file a protocol names (an include, its base), resolved against the protocol's folder.
std::string besideProtocol(const std::string& file, const std::string& name) {
  const std::filesystem::path p(name);
  const std::filesystem::path folder = std::filesystem::path(file).parent_path();
  return (p.is_absolute() ? p : folder / p).lexically_normal().string();
}

constexpr const char* kBase = "base";
// A chain of bases longer than this is taken for a cycle (a protocol based on itself).
constexpr int kMaxBases = 16;

// The file a protocol's top-level `base` names, resolved against the protocol's folder;
// empty when it names none; throws when `base` is not a text.
std::string baseFile(const std::string& file, const TomlValue& root) {
  if (!root.contains(kBase)) return "";
  const TomlValue& v = root.at(kBase);
  if (!v.is_string()) {
    throw ProtocolError({file + ":" + std::to_string(v.location().line()) + ": " + kBase +
                         " expects the file of the protocol this one varies, e.g. base = "
                         "\"biaxial-ucs.toml\" (relative to the protocol's folder)"});
  }
  return besideProtocol(file, v.as_string().str);
}

std::string rigOf(const std::string& file, const std::string& text, int depth) {
  const TomlValue root = parseToml(file, text);
  if (root.contains("protocol") && root.at("protocol").is_table() &&
      root.at("protocol").contains("rig") && root.at("protocol").at("rig").is_string()) {
    return root.at("protocol").at("rig").as_string().str;
  }
  const std::string base = baseFile(file, root);
  if (base.empty()) {
    throw ProtocolError({file + ": missing key 'protocol.rig' (text): the rig that runs the "
                                "protocol, e.g. rig = \"oedometer\""});
  }
  if (depth >= kMaxBases) {
    throw ProtocolError({file + ": " + kBase + ": more than " + std::to_string(kMaxBases) +
                         " bases in a chain (does a protocol name itself as its base?)"});
  }
  return rigOf(base, readFile(base), depth + 1);
}

}  // namespace

std::string rigOf(const std::string& file, const std::string& text) {
  return rigOf(file, text, 0);
}

namespace {

// Where a value was given: a line of the file, or an override on the command line.
struct Place {
  int order;         // problems are reported in this order: the file's lines, then overrides
  std::string text;  // "p.toml:12", "--set loading.rate_per_s=3"
};

// The problems found in a protocol, each at its place, reported in order.
class Problems {
 public:
  explicit Problems(std::string file) : file_(std::move(file)) {}
  void at(const Place& place, const std::string& what) {
    list_.emplace_back(place.order, place.text + ": " + what);
  }
  void unplaced(const std::string& what) { list_.emplace_back(1 << 30, file_ + ": " + what); }
  void throwIfAny() {
    if (list_.empty()) return;
    std::stable_sort(list_.begin(), list_.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<std::string> lines;
    for (auto& p : list_) lines.push_back(std::move(p.second));
    throw ProtocolError(lines);
  }

 private:
  std::string file_;
  std::vector<std::pair<int, std::string>> list_;
};

// The declaration of a key the file gives, or nullptr with the problem noted: a key of
// another rig, or an unknown key with the nearest known one.
const ParamDecl* declarationOf(const Schema& schema, const std::string& key, const Place& line,
                               Problems& problems) {
  if (const ParamDecl* d = schema.find(key)) return d;
  if (!schema.foreignRigs(key).empty()) {
    problems.at(line, "'" + key + "' is a key of the " + schema.foreignRigs(key) + " rig: the " +
                          schema.rig() +
                          " rig has no use for it (a scene runs only the effects its rig can "
                          "use; remove the key or name that rig in protocol.rig)");
    return nullptr;
  }
  std::string best;
  std::size_t best_d = 4;
  for (const ParamDecl& c : schema.all()) {
    const std::size_t e = editDistance(key, c.key);
    if (e < best_d) best_d = e, best = c.key;
  }
  problems.at(line, "unknown key '" + key + "'" +
                        (best.empty() ? "" : "; did you mean '" + best + "'?") +
                        " (`rocklab keys " + (schema.rig().empty() ? "RIG" : schema.rig()) +
                        "` lists them)");
  return nullptr;
}

// A TOML value as the declared kind, its range and choices checked; none (the problem
// noted) when it is not of that kind.
std::optional<Value> valueOf(const ParamDecl& d, const TomlValue& v, const Place& line,
                             Problems& problems) {
  const std::string expect = "'" + d.key + "'" + unitText(d) + " expects ";
  auto checkRange = [&](double x) {
    if (!inRange(d, x)) {
      problems.at(line, d.key + " = " + number(x) + " is outside the allowed range " +
                            d.rangeText() + unitText(d));
    }
  };
  auto wrong = [&](const std::string& what) -> std::optional<Value> {
    problems.at(line, expect + what);
    return std::nullopt;
  };
  switch (d.kind) {
    case Kind::Real: {
      if (!v.is_floating() && !v.is_integer()) return wrong("a number");
      const double x = v.is_floating() ? v.as_floating() : static_cast<double>(v.as_integer());
      checkRange(x);
      return x;
    }
    case Kind::Integer:
      if (!v.is_integer()) return wrong("an integer");
      checkRange(static_cast<double>(v.as_integer()));
      return static_cast<std::int64_t>(v.as_integer());
    case Kind::Text:
    case Kind::Choice: {
      if (!v.is_string()) {
        return wrong("a string" + (d.kind == Kind::Choice ? " (" + d.rangeText() + ")" : ""));
      }
      const std::string& text = v.as_string().str;
      if (d.kind == Kind::Choice &&
          std::find(d.choices.begin(), d.choices.end(), text) == d.choices.end()) {
        problems.at(line, d.key + " = \"" + text + "\" is not allowed: " + d.rangeText());
      }
      return text;
    }
    case Kind::Flag:
      if (!v.is_boolean()) return wrong("true or false");
      return v.as_boolean();
    case Kind::RealList: {
      if (!v.is_array()) return wrong("a list of numbers, e.g. [0.01, 0.02]");
      std::vector<double> list;
      bool ok = true;
      for (const auto& e : v.as_array()) {
        if (e.is_floating() || e.is_integer()) {
          list.push_back(e.is_floating() ? e.as_floating() : static_cast<double>(e.as_integer()));
          checkRange(list.back());
        } else {
          ok = false;
        }
      }
      if (!ok) problems.at(line, expect + "a list of numbers only");
      return list;
    }
    case Kind::TextList: {
      std::vector<std::string> list;
      bool ok = v.is_array();
      if (ok) {
        for (const auto& e : v.as_array()) {
          if (e.is_string()) list.push_back(e.as_string().str);
          ok = ok && e.is_string();
        }
      }
      if (!ok) problems.at(line, expect + "a list of strings, e.g. [\"a\", \"b\"]");
      return list;
    }
  }
  return std::nullopt;
}

// An override's value as TOML; bare text for a text key when it is not a TOML string.
std::optional<TomlValue> overrideValue(const ParamDecl& d, const Override& o, const Place& place,
                                       Problems& problems) {
  const bool text = d.kind == Kind::Text || d.kind == Kind::Choice;
  try {
    std::istringstream in("v = " + o.value);
    const TomlValue v =
        toml::parse<toml::discard_comments, std::map, std::vector>(in, o.origin).at("v");
    if (!text || v.is_string()) return v;
  } catch (const std::exception&) {
    if (!text) {
      problems.at(place, "'" + o.value +
                             "' is not a value (a number, true or false, a list in [], "
                             "or text)");
      return std::nullopt;
    }
  }
  return TomlValue(o.value);
}

// Validates overrides into `values`, like keys of the file.
void applyOverrides(const Schema& schema, const std::vector<Override>& overrides,
                    std::map<std::string, Value>& values, std::map<std::string, int>& given,
                    std::map<std::string, Override>& applied, Problems& problems) {
  for (std::size_t k = 0; k < overrides.size(); ++k) {
    const Override& o = overrides[k];
    const Place place{(1 << 29) + static_cast<int>(k), o.label()};
    const ParamDecl* d = declarationOf(schema, o.key, place, problems);
    if (!d) continue;
    const auto v = overrideValue(*d, o, place, problems);
    if (!v) continue;
    if (auto value = valueOf(*d, *v, place, problems)) {
      values[o.key] = std::move(*value);
      given.try_emplace(o.key, 0);
      applied[o.key] = o;
    }
  }
}

}  // namespace

Override parseOverride(const std::string& text, const std::string& origin) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw ProtocolError({origin + " " + text + ": expects KEY=VALUE, e.g. " + origin +
                         " loading.confining_stress_MPa=10"});
  }
  auto trim = [](std::string t) {
    const auto a = t.find_first_not_of(" \t"), b = t.find_last_not_of(" \t");
    return a == std::string::npos ? std::string() : t.substr(a, b - a + 1);
  };
  return {trim(text.substr(0, eq)), trim(text.substr(eq + 1)), origin};
}

void Settings::apply(const std::vector<Override>& overrides) {
  Problems problems(file_);
  std::map<std::string, Value> values = values_;
  std::map<std::string, int> given = given_;
  std::map<std::string, Override> applied = overrides_;
  applyOverrides(*schema_, overrides, values, given, applied, problems);
  problems.throwIfAny();
  values_ = std::move(values);
  given_ = std::move(given);
  overrides_ = std::move(applied);
}

namespace {

constexpr const char* kInclude = "include";

// The files a protocol's top-level `include` names (a text or a list of texts), resolved
// against the protocol's folder, each with the place that names it.
std::vector<std::pair<std::string, Place>> includedFiles(const std::string& file,
                                                         const TomlValue& root,
                                                         Problems& problems) {
  std::vector<std::pair<std::string, Place>> files;
  if (!root.contains(kInclude)) return files;
  const TomlValue& v = root.at(kInclude);
  const int line = static_cast<int>(v.location().line());
  const Place place{line, file + ":" + std::to_string(line)};
  std::vector<std::string> names;
  if (v.is_string()) {
    names.push_back(v.as_string().str);
  } else if (v.is_array()) {
    for (const auto& e : v.as_array()) {
      if (e.is_string()) names.push_back(e.as_string().str);
    }
  }
  if (names.empty() || (v.is_array() && names.size() != v.as_array().size())) {
    problems.at(place, std::string(kInclude) +
                           " expects a file or a list of files, e.g. include = "
                           "\"materials/sandstone.toml\" (relative to the protocol's folder)");
    return files;
  }
  for (const std::string& n : names) files.emplace_back(besideProtocol(file, n), place);
  return files;
}

// The bases being parsed, innermost last: a protocol met again is a cycle.
thread_local std::vector<std::string> t_bases;

// The protocol `root` names as its base (with its own includes and base), parsed; none when
// it names none or has problems (added to `problems` at the `base` line).
std::optional<Settings> readBase(const std::string& file, const TomlValue& root,
                                 const Schema& schema, Problems& problems) {
  if (!root.contains(kBase)) return std::nullopt;
  const int line = static_cast<int>(root.at(kBase).location().line());
  const Place place{line, file + ":" + std::to_string(line)};
  std::string path;
  try {
    path = baseFile(file, root);
  } catch (const ProtocolError& e) {
    for (const auto& p : e.problems()) problems.at(place, p.substr(p.find(": ") + 2));
    return std::nullopt;
  }
  std::error_code ec;
  const std::string id = std::filesystem::weakly_canonical(path, ec).string();
  if (std::find(t_bases.begin(), t_bases.end(), id) != t_bases.end()) {
    problems.at(place, std::string(kBase) + ": " + path +
                           " is already a base of this protocol (a cycle of bases)");
    return std::nullopt;
  }
  t_bases.push_back(id);
  try {
    Settings base = parseProtocol(path, readFile(path), schema);
    t_bases.pop_back();
    return base;
  } catch (const ProtocolError& e) {
    t_bases.pop_back();
    for (const auto& p : e.problems()) problems.at(place, std::string(kBase) + ": " + p);
    return std::nullopt;
  }
}

}  // namespace

Settings parseProtocol(const std::string& file, const std::string& text, const Schema& schema,
                       const std::vector<Override>& overrides) {
  const TomlValue root = parseToml(file, text);
  Settings s;
  s.schema_ = std::make_shared<const Schema>(schema);
  s.file_ = file;
  s.source_ = text;
  Problems problems(file);
  // The keys of `table` given in `from` (the protocol or a file it includes); problems are
  // ordered by `order` + line.
  auto walk = [&](auto&& self, const TomlValue& table, const std::string& prefix,
                  const std::string& from, int order) -> void {
    for (const auto& [k, v] : table.as_table()) {
      if (prefix.empty() && (k == kInclude || k == kBase)) continue;
      const std::string key = prefix.empty() ? k : prefix + "." + k;
      const int line = static_cast<int>(v.location().line());
      if (v.is_table()) {
        self(self, v, key, from, order);
        continue;
      }
      const Place place{order + line, from + ":" + std::to_string(line)};
      const ParamDecl* d = declarationOf(schema, key, place, problems);
      if (!d) continue;
      if (s.given_.count(key)) {
        problems.at(place, key + " is given again: " + s.where(key) +
                               " gives it too (give a key in one file; --set overrides it "
                               "wherever it is given)");
        continue;
      }
      s.given_[key] = line;
      if (from != file) s.given_in_[key] = from;
      if (auto value = valueOf(*d, v, place, problems)) s.values_[key] = std::move(*value);
    }
  };
  walk(walk, root, "", file, 0);
  int order = 1 << 27;  // an included file's problems after the protocol's
  for (const auto& [path, place] : includedFiles(file, root, problems)) {
    order += 1 << 20;
    std::string included;
    try {
      included = readFile(path);
    } catch (const ProtocolError&) {
      problems.at(place, std::string(kInclude) + ": cannot read " + path);
      continue;
    }
    TomlValue inc;
    try {
      inc = parseToml(path, included);
    } catch (const ProtocolError& e) {
      for (const auto& p : e.problems()) problems.at(place, std::string(kInclude) + ": " + p);
      continue;
    }
    if (inc.contains(kInclude) || inc.contains("protocol")) {
      problems.at(place, std::string(kInclude) + ": " + path +
                             " may hold a material's keys only: no include of its own and no "
                             "protocol.* key (the protocol names the run)");
      continue;
    }
    s.includes_.push_back(path);
    walk(walk, inc, "", path, order);
  }
  // The base's keys that neither the file nor its includes give: a variant of a protocol
  // (its quick twin: the same material and loading on fewer particles) gives only what
  // differs. A relative path given in the base stays relative to the base's folder.
  if (const std::optional<Settings> base = readBase(file, root, schema, problems)) {
    const auto folder = std::filesystem::absolute(file).parent_path();
    for (const auto& [key, line] : base->given_) {
      if (s.given_.count(key)) continue;
      Value v = base->values_.at(key);
      const auto* given = std::get_if<std::string>(&v);
      if (given && !given->empty() && !std::filesystem::path(*given).is_absolute() &&
          schema.find(key)->unit.name == units::path.name) {
        v = std::filesystem::absolute(base->path(key))
                .lexically_normal()
                .lexically_relative(folder.lexically_normal())
                .string();
      }
      s.given_[key] = line;
      s.given_in_[key] = base->given_in_.count(key) ? base->given_in_.at(key) : base->file_;
      s.values_[key] = std::move(v);
    }
    s.base_ = base->file_;
    for (const std::string& inc : base->includes_) s.includes_.push_back(inc);
  }
  applyOverrides(schema, overrides, s.values_, s.given_, s.overrides_, problems);
  for (const ParamDecl& d : schema.all()) {
    if (s.given_.count(d.key)) continue;
    if (d.fallback) {
      s.values_[d.key] = *d.fallback;
    } else {
      problems.unplaced("missing required key '" + d.key + "'" + unitText(d) + ": " + d.doc);
    }
  }
  problems.throwIfAny();
  return s;
}

namespace {

// A value written as TOML that reads back to the same bits: numbers by the shortest
// round-trip form (std::to_chars), texts quoted.
std::string tomlLiteral(const Value& v) {
  auto real = [](double x) {
    if (std::isinf(x)) return std::string(x > 0 ? "inf" : "-inf");
    if (std::isnan(x)) return std::string("nan");
    char buf[32];
    const auto end = std::to_chars(buf, buf + sizeof buf, x).ptr;
    std::string t(buf, end);
    if (t.find_first_of(".en") == std::string::npos) t += ".0";
    return t;
  };
  auto quoted = [](const std::string& t) {
    std::string q = "\"";
    for (char c : t) {
      if (c == '"' || c == '\\') q += '\\';
      q += c;
    }
    return q + "\"";
  };
  return render(v, real, quoted, quoted);
}

std::vector<std::string> splitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}

std::string joinLines(const std::vector<std::string>& lines) {
  std::string t;
  for (const auto& l : lines) t += l + "\n";
  return t;
}

// The table a key lives in and its last part: "loading.rate" -> {"loading", "rate"}.
std::pair<std::string, std::string> splitKey(const std::string& key) {
  const auto dot = key.rfind('.');
  if (dot == std::string::npos) return {"", key};
  return {key.substr(0, dot), key.substr(dot + 1)};
}

bool isHeaderOf(const std::string& line, const std::string& table) {
  const auto a = line.find_first_not_of(" \t");
  if (a == std::string::npos || line[a] != '[' || line.compare(a, 2, "[[") == 0) return false;
  const auto b = line.find(']', a);
  if (b == std::string::npos) return false;
  std::string name;
  for (char c : line.substr(a + 1, b - a - 1)) {
    if (c != ' ' && c != '\t') name += c;
  }
  return name == table;
}

// The file's text with each override written in: on the line that gave the key (a line
// holding the whole value), or under its table's header, or in a new table at the end.
std::string editedText(const std::string& source,
                       const std::vector<std::tuple<std::string, int, std::string>>& edits) {
  std::vector<std::string> lines = splitLines(source);
  std::vector<std::vector<std::string>> after(lines.size() + 1);  // lines to insert after [k]
  std::string appended;
  for (const auto& [key, line, written] : edits) {
    const auto [table, leaf] = splitKey(key);
    if (line > 0 && line <= static_cast<int>(lines.size())) {
      std::string& l = lines[line - 1];
      const auto eq = l.find('=');
      if (eq == std::string::npos) return {};
      std::string was = l.substr(eq + 1);
      was.erase(0, was.find_first_not_of(" \t"));
      l = l.substr(0, eq) + "= " + written + " (the file had: " + was + ")";
      continue;
    }
    bool placed = false;
    for (std::size_t k = 0; k < lines.size() && !placed; ++k) {
      if (isHeaderOf(lines[k], table))
        after[k + 1].push_back(leaf + " = " + written), placed = true;
    }
    if (!placed) appended += "\n[" + table + "]\n" + leaf + " = " + written + "\n";
  }
  std::vector<std::string> out;
  for (std::size_t k = 0; k <= lines.size(); ++k) {
    for (auto& l : after[k]) out.push_back(std::move(l));
    if (k < lines.size()) out.push_back(std::move(lines[k]));
  }
  return joinLines(out) + appended;
}

}  // namespace

std::string Settings::effectiveText() const {
  if (overrides_.empty() && includes_.empty() && base_.empty()) return source_;
  std::map<std::string, Value> values = values_;  // as given: the run's choices left out
  for (const auto& [key, v] : unchosen_) values[key] = v;
  std::string with = base_.empty() ? "" : "base " + base_;
  for (const std::string& inc : includes_) with += (with.empty() ? "" : ", ") + ("include " + inc);
  std::vector<std::tuple<std::string, int, std::string>> edits;
  for (const auto& [key, o] : overrides_) {
    with += (with.empty() ? "" : ", ") + o.label();
    const int line = given_.count(key) ? given_.at(key) : 0;
    edits.emplace_back(key, line, tomlLiteral(values.at(key)) + "  # " + o.label());
  }
  // The file by its canonical path: the notebook names the file it ran, however the path was
  // spelled ("protocols/p.toml" from the repository, the same file from elsewhere).
  std::error_code ec;
  const std::filesystem::path canonical = std::filesystem::weakly_canonical(file_, ec);
  const std::string head =
      "# The protocol as run: " + (ec ? file_ : canonical.string()) + " with " + with + "\n";
  // The edited file reads back to these settings, or (an override inside a multi-line value
  // or a table the file defines by dotted keys; an included file, whose keys must be in the
  // text for it to stand alone) every key is written out, table by table.
  std::string text = includes_.empty() && base_.empty() ? editedText(source_, edits) : "";
  auto readsBack = [&](const std::string& t) {
    try {
      const Settings back = parseProtocol(file_, t, *schema_);
      return back.values_ == values;
    } catch (const ProtocolError&) {
      return false;
    }
  };
  if (!text.empty() && readsBack(head + text)) return head + text;
  std::map<std::string, std::vector<std::string>> tables;
  std::vector<std::string> order;
  for (const ParamDecl& d : schema_->all()) {
    if (!given_.count(d.key)) continue;
    const auto [table, leaf] = splitKey(d.key);
    if (!tables.count(table)) order.push_back(table);
    const auto o = overrides_.find(d.key);
    const auto in = given_in_.find(d.key);
    const std::string note = o != overrides_.end()   ? "  # " + o->second.label()
                             : in != given_in_.end() ? "  # " + in->second
                                                     : "";
    tables[table].push_back(leaf + " = " + tomlLiteral(values.at(d.key)) + note);
  }
  text = head + "# (every key the file, its includes and the overrides give, written out)\n";
  for (const std::string& t : order) {
    text += "\n[" + t + "]\n";
    for (const auto& l : tables[t]) text += l + "\n";
  }
  return text;
}

std::string Settings::identity() const {
  std::map<std::string, Value> values = values_;
  for (const auto& [key, v] : unchosen_) values[key] = v;
  std::string out;
  for (const ParamDecl& d : schema_->all()) {
    const auto it = values.find(d.key);
    if (it == values.end() || d.key == "protocol.description") continue;
    const std::string v = tomlLiteral(it->second);
    if (d.fallback && tomlLiteral(*d.fallback) == v) continue;  // given or not, the same run
    out += d.key + " = " + v + "\n";
  }
  return out;
}

}  // namespace rocklab::protocol
