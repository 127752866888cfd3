#include "lab/calibration/calibration.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

#include "lab/campaign/toml_text.hpp"
#include "rigs/registry.hpp"

namespace rocklab::calibration {

namespace {

namespace fs = std::filesystem;
using campaign::numberText;
using campaign::TomlValue;

constexpr std::size_t kMaxParameters = 10;  // the Halton sets' dimensions (optimizer.hpp)

class Reader : public campaign::TomlReader {
 public:
  using TomlReader::TomlReader;

  // A number (integers too) in [low, high], or nothing with a problem.
  std::optional<double> real(const TomlValue& v, const std::string& key, double low, double high,
                             const std::string& what) {
    if ((v.is_floating() || v.is_integer())) {
      const double x = v.is_floating() ? v.as_floating() : static_cast<double>(v.as_integer());
      if (std::isfinite(x) && x >= low && x <= high) return x;
    }
    problem(v, key + ": " + what);
    return std::nullopt;
  }
  std::optional<int> integer(const TomlValue& v, const std::string& key, int low, int high,
                             const std::string& what) {
    if (v.is_integer() && v.as_integer() >= low && v.as_integer() <= high) {
      return static_cast<int>(v.as_integer());
    }
    problem(v, key + ": " + what + ", an integer in [" + std::to_string(low) + ", " +
                   std::to_string(high) + "]");
    return std::nullopt;
  }
  std::optional<std::string> text(const TomlValue& v, const std::string& key,
                                  const std::string& what) {
    if (v.is_string() && !v.as_string().str.empty()) return v.as_string().str;
    problem(v, key + ": " + what);
    return std::nullopt;
  }

  std::vector<protocol::Override> keys(const TomlValue& table, const std::string& where) {
    std::vector<std::pair<std::string, const TomlValue*>> flat;
    flatten(table, "", flat);
    std::vector<protocol::Override> out;
    for (const auto& [key, v] : flat) {
      const std::string text = campaign::tomlLiteral(*v);
      if (text.empty()) {
        problem(*v, where + "." + key + ": a number, text, boolean or list");
      } else {
        out.push_back({key, text, at(*v)});
      }
    }
    return out;
  }
};

bool validName(const std::string& s) {
  return !s.empty() && s.find_first_of("/\\ \t\"'") == std::string::npos;
}

// The [calibration] table.
void readHead(const TomlValue& t, Calibration& c, Reader& r, const TomlValue*& seeds) {
  for (const auto& [k, v] : t.as_table()) {
    const std::string key = "calibration." + k;
    if (k == "name") {
      if (v.is_string() && validName(v.as_string().str)) {
        c.name = v.as_string().str;
      } else {
        r.problem(v, key +
                         ": a text without spaces, quotes or slashes (it names the "
                         "calibration's folder, its campaigns and its rows in the notebook)");
      }
    } else if (k == "optimizer") {
      if (v.is_string() && v.as_string().str == "bayesian") {
        c.optimizer = Optimizer::Bayesian;
      } else if (v.is_string() && v.as_string().str == "latin_hypercube") {
        c.optimizer = Optimizer::LatinHypercube;
      } else {
        r.problem(v, key + ": one of bayesian, latin_hypercube");
      }
    } else if (k == "budget") {
      if (auto n = r.integer(v, key, 2, 10000, "the evaluations at most")) c.budget = *n;
    } else if (k == "batch") {
      if (auto n = r.integer(v, key, 1, 1000, "the evaluations run at once")) c.batch = *n;
    } else if (k == "threads") {
      if (auto n = r.integer(v, key, 1, 1024, "each run's threads")) c.threads = *n;
    } else if (k == "check_seeds") {
      if (auto n = r.integer(v, key, 0, 10000, "fresh seeds the best point is checked on")) {
        c.check_seeds = *n;
      }
    } else if (k == "seed") {
      if (auto n = r.integer(v, key, 0, 1 << 30, "the optimiser's random numbers")) {
        c.seed = static_cast<std::uint64_t>(*n);
      }
    } else if (k == "seeds") {
      seeds = &v;
    } else if (k == "material") {
      if (auto m = r.text(v, key, "the material file to write (.toml), relative to this file")) {
        if (fs::path(*m).extension() != ".toml") {
          r.problem(v, key + ": a .toml file (protocols include it)");
        } else {
          c.material = *m;
        }
      }
    } else {
      r.problem(v, key +
                       ": unknown key (calibration.name, optimizer, budget, batch, seeds, "
                       "check_seeds, threads, seed, material)");
    }
  }
  if (!t.as_table().count("name")) r.problem(c.file + ": missing calibration.name");
}

struct RawTarget {
  Target t;
  std::string protocol;
  std::vector<protocol::Override> set;
  const TomlValue* node = nullptr;
  const TomlValue* result = nullptr;
  std::string result_where;  // file:line of target.result
};

RawTarget readTarget(const TomlValue& v, Reader& r, const std::string& base) {
  RawTarget raw;
  raw.node = &v;
  raw.t.where = r.at(v);
  if (!v.is_table()) {
    r.problem(v, "target: a table ([[target]])");
    return raw;
  }
  std::optional<double> tolerance, percent;
  bool has_value = false;
  for (const auto& [k, x] : v.as_table()) {
    const std::string key = "target." + k;
    if (k == "protocol") {
      if (auto p = r.text(x, key, "the protocol file, relative to this file")) {
        raw.protocol =
            fs::path(*p).is_relative() ? (fs::path(base) / *p).lexically_normal().string() : *p;
      }
    } else if (k == "result") {
      raw.result = &x;
      raw.result_where = r.at(x);
      if (auto p = r.text(x, key, "a key result of the protocol's rig")) raw.t.result = *p;
    } else if (k == "name") {
      if (x.is_string() && validName(x.as_string().str)) {
        raw.t.name = x.as_string().str;
      } else {
        r.problem(x, key + ": a text without spaces, quotes or slashes");
      }
    } else if (k == "value") {
      has_value = true;
      if (auto p =
              r.real(x, key, -1e300, 1e300, "the measured value, a number in the result's unit")) {
        raw.t.value = *p;
      }
    } else if (k == "tolerance") {
      tolerance = r.real(x, key, 1e-300, 1e300, "a number > 0, in the result's unit");
    } else if (k == "tolerance_percent") {
      percent = r.real(x, key, 1e-9, 100.0, "a percentage of the value in (0, 100]");
    } else if (k == "source") {
      if (auto p = r.text(x, key, "where the value was measured (a citation)")) raw.t.source = *p;
    } else if (k == "set") {
      if (!x.is_table()) {
        r.problem(x, key + ": a table of protocol keys this target's protocol takes");
      } else {
        raw.set = r.keys(x, "target.set");
      }
    } else {
      r.problem(x, key +
                       ": unknown key (target.protocol, result, name, value, tolerance, "
                       "tolerance_percent, source, set)");
    }
  }
  if (raw.protocol.empty() && !v.as_table().count("protocol")) {
    r.problem(v, "target: missing target.protocol");
  }
  if (!raw.result) r.problem(v, "target: missing target.result");
  if (!has_value) r.problem(v, "target: missing target.value");
  if (tolerance && percent) {
    r.problem(v, "target: give target.tolerance or target.tolerance_percent, not both");
  } else if (tolerance) {
    raw.t.tolerance = *tolerance;
  } else if (percent) {
    raw.t.tolerance = std::abs(raw.t.value) * *percent / 100.0;
    if (raw.t.tolerance <= 0.0) {
      r.problem(v, "target.tolerance_percent: the value is 0; give target.tolerance instead");
    }
  } else if (!v.as_table().count("tolerance") && !v.as_table().count("tolerance_percent")) {
    r.problem(v, "target: missing target.tolerance (in the result's unit) or tolerance_percent");
  }
  if (raw.t.name.empty()) raw.t.name = raw.t.result;
  return raw;
}

Parameter readParameter(const TomlValue& v, Reader& r) {
  Parameter p;
  p.where = r.at(v);
  if (!v.is_table()) {
    r.problem(v, "parameter: a table ([[parameter]])");
    return p;
  }
  const std::string scale_help = "one of linear, log";
  bool low = false, high = false;
  const TomlValue* low_node = &v;
  const TomlValue* start_node = &v;
  for (const auto& [k, x] : v.as_table()) {
    const std::string key = "parameter." + k;
    if (k == "name") {
      if (x.is_string() && validName(x.as_string().str)) {
        p.name = x.as_string().str;
      } else {
        r.problem(x, key + ": a text without spaces, quotes or slashes");
      }
    } else if (k == "key") {
      if (auto t = r.text(x, key, "the protocol key the parameter sets"))
        p.keys.push_back({*t, 1.0});
    } else if (k == "keys") {
      if (!x.is_table() || x.as_table().empty()) {
        r.problem(x, key +
                         ": a table of the protocol keys the parameter sets, each with its "
                         "factor: { \"bonds.tensile_strength_mean_MPa\" = 1.0, ... }");
        continue;
      }
      std::vector<std::pair<std::string, const TomlValue*>> flat;
      Reader::flatten(x, "", flat);
      for (const auto& [name, f] : flat) {
        if (auto factor = r.real(*f, key + "." + name, 1e-12, 1e12,
                                 "the key's factor: the key takes the parameter times it, > 0")) {
          p.keys.push_back({name, *factor});
        }
      }
    } else if (k == "low") {
      low = true;
      low_node = &x;
      if (auto a = r.real(x, key, -1e300, 1e300, "the lower bound, a number")) p.low = *a;
    } else if (k == "high") {
      high = true;
      if (auto a = r.real(x, key, -1e300, 1e300, "the upper bound, a number")) p.high = *a;
    } else if (k == "start") {
      start_node = &x;
      p.start = r.real(x, key, -1e300, 1e300, "the first evaluation's value, a number");
    } else if (k == "scale") {
      if (x.is_string() && (x.as_string().str == "linear" || x.as_string().str == "log")) {
        p.log = x.as_string().str == "log";
      } else {
        r.problem(x, key + ": " + scale_help);
      }
    } else {
      r.problem(x, key + ": unknown key (parameter.name, key, keys, low, high, scale, start)");
    }
  }
  if (p.keys.empty() && !v.as_table().count("key") && !v.as_table().count("keys")) {
    r.problem(v, "parameter: missing parameter.key (or parameter.keys)");
  }
  if (v.as_table().count("key") && v.as_table().count("keys")) {
    r.problem(v, "parameter: give parameter.key or parameter.keys, not both");
  }
  if (!low) r.problem(v, "parameter: missing parameter.low");
  if (!high) r.problem(v, "parameter: missing parameter.high");
  if (p.name.empty() && !p.keys.empty()) p.name = p.keys.front().first;
  if (low && high && !(p.low < p.high)) {
    r.problem(*low_node, "parameter " + p.name + ": low (" + numberText(p.low) +
                             ") must be below high (" + numberText(p.high) + ")");
  } else if (p.log && p.low <= 0.0) {
    r.problem(*low_node, "parameter " + p.name + ": a log scale needs low > 0");
  } else if (p.start && low && high && (*p.start < p.low || *p.start > p.high)) {
    r.problem(*start_node, "parameter " + p.name + ": start " + numberText(*p.start) +
                               " outside [" + numberText(p.low) + ", " + numberText(p.high) + "]");
  }
  return p;
}

// The seeds a count or list means, from a protocol's own seed.
std::vector<std::int64_t> seedList(const TomlValue* seeds, std::int64_t first, Reader& r) {
  std::vector<std::int64_t> out;
  if (!seeds) {
    for (std::int64_t k = 0; k < 5; ++k) out.push_back(first + k);
  } else if (seeds->is_integer() && seeds->as_integer() >= 1 && seeds->as_integer() <= 1000) {
    for (std::int64_t k = 0; k < seeds->as_integer(); ++k) out.push_back(first + k);
  } else if (seeds->is_array() && !seeds->as_array().empty()) {
    std::set<std::int64_t> seen;
    for (const auto& s : seeds->as_array()) {
      if (!s.is_integer() || s.as_integer() < 0 || !seen.insert(s.as_integer()).second) {
        r.problem(s, "calibration.seeds: every seed an integer >= 0, each once");
      } else {
        out.push_back(s.as_integer());
      }
    }
  } else {
    r.problem(*seeds,
              "calibration.seeds: a count in [1, 1000] (the protocol's seed and the ones after "
              "it) or a list of seeds");
  }
  return out;
}

std::string joined(const std::vector<std::string>& v) {
  std::string s = "[";
  for (std::size_t k = 0; k < v.size(); ++k) s += (k ? ", \"" : "\"") + v[k] + "\"";
  return s + "]";
}

}  // namespace

double Parameter::toUnit(double value) const {
  return log ? std::log(value / low) / std::log(high / low) : (value - low) / (high - low);
}

double Parameter::fromUnit(double u) const {
  return log ? low * std::pow(high / low, u) : low + u * (high - low);
}

double Parameter::rounded(double v) const {
  // Four significant digits: the material file then holds exactly the values evaluated, in
  // a form a reader takes in, and 0.1% is finer than any seed mean resolves.
  if (v == 0.0) return 0.0;
  const double scale = std::pow(10.0, 3 - std::floor(std::log10(std::abs(v))));
  return std::clamp(std::round(v * scale) / scale, low, high);
}

int Calibration::designSize() const {
  const int d = static_cast<int>(parameters.size());
  return std::min(budget, std::max(batch, 2 * d + 2));
}

std::vector<protocol::Override> Calibration::overrides(int experiment,
                                                       const std::vector<double>& values,
                                                       const std::string& origin) const {
  const std::string& path = experiments.at(static_cast<std::size_t>(experiment)).protocol;
  const rigs::CheckedProtocol p = rigs::checkProtocol(path);
  const protocol::Schema schema = rigs::schemaOf(*p.rig);
  std::vector<protocol::Override> out;
  for (std::size_t k = 0; k < parameters.size(); ++k) {
    for (const auto& [key, factor] : parameters[k].keys) {
      if (schema.find(key)) out.push_back({key, numberText(values.at(k) * factor), origin});
    }
  }
  return out;
}

std::vector<double> Calibration::values(const Point& u) const {
  std::vector<double> v;
  for (std::size_t k = 0; k < parameters.size(); ++k)
    v.push_back(parameters[k].rounded(parameters[k].fromUnit(u.at(k))));
  return v;
}

Point Calibration::unit(const std::vector<double>& values) const {
  Point u;
  for (std::size_t k = 0; k < parameters.size(); ++k)
    u.push_back(parameters[k].toUnit(values.at(k)));
  return u;
}

std::optional<std::vector<double>> Calibration::start() const {
  std::vector<double> v;
  for (const Parameter& p : parameters) {
    if (!p.start) return std::nullopt;
    v.push_back(*p.start);
  }
  return v;
}

std::string batchCampaignName(const Calibration& c, int batch, int experiment) {
  return c.name + "-b" + std::to_string(batch) + "-x" + std::to_string(experiment);
}

std::string checkCampaignName(const Calibration& c, int experiment) {
  return c.name + "-check-x" + std::to_string(experiment);
}

Calibration readCalibration(const std::string& path) {
  Calibration c;
  c.file = path;
  try {
    c.text = protocol::readFile(path);
  } catch (const std::exception&) {
    throw protocol::ProtocolError({path + ": cannot read the calibration file"});
  }
  TomlValue root;
  try {
    std::istringstream in(c.text);
    root = toml::parse<toml::discard_comments, std::map, std::vector>(in, path);
  } catch (const std::exception& e) {
    throw protocol::ProtocolError({path + ": not valid TOML:\n" + e.what()});
  }
  Reader r(path);
  const std::string base = fs::path(path).parent_path().string();
  const TomlValue* seeds = nullptr;
  std::vector<RawTarget> targets;
  std::vector<protocol::Override> fixed;
  for (const auto& [k, v] : root.as_table()) {
    if (k == "calibration" && v.is_table()) {
      readHead(v, c, r, seeds);
    } else if (k == "target" && v.is_array()) {
      for (const auto& t : v.as_array()) targets.push_back(readTarget(t, r, base));
    } else if (k == "parameter" && v.is_array()) {
      for (const auto& p : v.as_array()) c.parameters.push_back(readParameter(p, r));
    } else if (k == "set" && v.is_table()) {
      fixed = r.keys(v, "set");
      c.fixed = fixed;
    } else if (k == "slurm" && v.is_table()) {
      r.slurm(v, c.slurm);
    } else {
      r.problem(v, k + ": unknown (the tables: [calibration], [[target]], [[parameter]], [set], "
                       "[slurm])");
    }
  }
  if (!root.as_table().count("calibration")) r.problem(path + ": missing the [calibration] table");
  if (targets.empty()) r.problem(path + ": no [[target]]: what the calibration fits");
  if (c.parameters.empty()) r.problem(path + ": no [[parameter]]: what the calibration varies");
  if (c.parameters.size() > kMaxParameters) {
    r.problem(path + ": " + std::to_string(c.parameters.size()) + " parameters; at most " +
              std::to_string(kMaxParameters));
  }
  {
    std::set<std::string> names, keys;
    for (const Parameter& p : c.parameters) {
      if (!names.insert(p.name).second) r.problem(p.where + ": parameter " + p.name + " twice");
      for (const auto& [key, f] : p.keys) {
        if (!keys.insert(key).second) {
          r.problem(p.where + ": key " + key + " is set by two parameters");
        }
        for (const auto& o : fixed) {
          if (o.key == key) r.problem(o.origin + ": set." + key + " is a free parameter's key");
        }
      }
    }
    std::set<std::string> tnames;
    for (const RawTarget& t : targets) {
      if (!tnames.insert(t.t.name).second) {
        r.problem(t.t.where + ": target " + t.t.name + " twice (give each a target.name)");
      }
    }
  }
  if (!c.material.empty() && fs::path(c.material).is_relative()) {
    c.material = (fs::path(base) / c.material).lexically_normal().string();
  }
  r.throwIfAny();

  // The experiments: one per protocol and keys.
  for (RawTarget& raw : targets) {
    std::vector<protocol::Override> set = fixed;
    set.insert(set.end(), raw.set.begin(), raw.set.end());
    auto same = [&](const Experiment& e) {
      if (e.protocol != raw.protocol || e.set.size() != set.size()) return false;
      for (std::size_t k = 0; k < set.size(); ++k) {
        if (e.set[k].key != set[k].key || e.set[k].value != set[k].value) return false;
      }
      return true;
    };
    auto it = std::find_if(c.experiments.begin(), c.experiments.end(), same);
    if (it == c.experiments.end()) {
      c.experiments.push_back({raw.protocol, set, {}, {}, {}});
      it = c.experiments.end() - 1;
    }
    raw.t.experiment = static_cast<int>(it - c.experiments.begin());
    if (std::find(it->results.begin(), it->results.end(), raw.t.result) == it->results.end()) {
      it->results.push_back(raw.t.result);
    }
  }
  // Each experiment's protocol with the parameters at their bounds and start: its keys,
  // ranges and rules, and its targets' results among its rig's key results.
  std::vector<bool> declared(c.parameters.size(), false);
  for (std::size_t e = 0; e < c.experiments.size(); ++e) {
    Experiment& x = c.experiments[e];
    try {
      const rigs::CheckedProtocol p = rigs::checkProtocol(x.protocol, x.set);
      const protocol::Schema schema = rigs::schemaOf(*p.rig);
      for (std::size_t k = 0; k < c.parameters.size(); ++k) {
        for (const auto& [key, f] : c.parameters[k].keys) {
          const protocol::ParamDecl* d = schema.find(key);
          if (!d) continue;
          declared[k] = true;
          if (d->kind != protocol::Kind::Real) {
            r.problem(c.parameters[k].where + ": parameter " + c.parameters[k].name + ": " + key +
                      " is not a real number key (the " + std::string(p.rig->name) +
                      " rig's is an integer, text or list)");
          }
          if (c.parameters[k].unit.empty()) c.parameters[k].unit = std::string(d->unit.name);
        }
      }
      for (RawTarget& raw : targets) {
        if (raw.t.experiment != static_cast<int>(e)) continue;
        if (const rigs::OutputDecl* d = p.rig->outputs().keyResult(raw.t.result)) {
          raw.t.unit = std::string(d->unit);
        }
      }
      // The protocol's key results and the targets' (checked against the rig).
      std::vector<std::string> results = p.settings.texts("protocol.key_results");
      for (const std::string& name : x.results) {
        if (std::find(results.begin(), results.end(), name) == results.end()) {
          results.push_back(name);
        }
      }
      std::string where;
      for (const RawTarget& raw : targets) {
        if (raw.t.experiment == static_cast<int>(e)) where = raw.result_where + ": target.result";
      }
      x.set.push_back({"protocol.key_results", joined(results), where});
      const std::int64_t first = p.settings.integer("protocol.seed");
      x.seeds = seedList(seeds, first, r);
      const std::int64_t after =
          x.seeds.empty() ? first : *std::max_element(x.seeds.begin(), x.seeds.end()) + 1;
      for (int k = 0; k < c.check_seeds; ++k) x.check_seeds.push_back(after + k);
      for (const auto& bound : {0.0, 1.0}) {
        std::vector<double> v;
        for (const Parameter& q : c.parameters) v.push_back(bound == 0.0 ? q.low : q.high);
        std::vector<protocol::Override> o = x.set;
        const auto po =
            c.overrides(static_cast<int>(e), v,
                        path + ": the parameters at their " +
                            (bound == 0.0 ? std::string("low") : std::string("high")) + " bounds:");
        o.insert(o.end(), po.begin(), po.end());
        rigs::checkProtocol(x.protocol, o);
      }
      if (const auto s = c.start()) {
        std::vector<protocol::Override> o = x.set;
        const auto po = c.overrides(static_cast<int>(e), *s, path + ": the parameters' start:");
        o.insert(o.end(), po.begin(), po.end());
        rigs::checkProtocol(x.protocol, o);
      }
    } catch (const protocol::ProtocolError& err) {
      for (const auto& q : err.problems()) r.problem(q);
    }
  }
  for (std::size_t k = 0; k < c.parameters.size(); ++k) {
    if (!declared[k] && !r.any()) {
      r.problem(c.parameters[k].where + ": parameter " + c.parameters[k].name +
                ": no target's protocol has its keys");
    }
  }
  for (const RawTarget& raw : targets) c.targets.push_back(raw.t);
  r.throwIfAny();
  return c;
}

}  // namespace rocklab::calibration
