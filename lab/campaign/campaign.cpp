#include "lab/campaign/campaign.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "lab/campaign/toml_text.hpp"
#include "reports/key_results.hpp"
#include "rigs/common/outputs.hpp"
#include "rigs/registry.hpp"

namespace rocklab::campaign {

namespace {

// A problem without a line is the file's.
class Reader : public TomlReader {
 public:
  using TomlReader::problem;
  using TomlReader::TomlReader;
  void problem(const std::string& what) { TomlReader::problem(file() + ": " + what); }
};

std::string readText(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw protocol::ProtocolError({path + ": cannot read the campaign file"});
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The [campaign] table.
void readHead(const TomlValue& t, Campaign& c, Reader& r, const TomlValue*& seeds) {
  for (const auto& [k, v] : t.as_table()) {
    if (k == "name") {
      if (!v.is_string() || v.as_string().str.empty() ||
          v.as_string().str.find_first_of("/\\ \t") != std::string::npos) {
        r.problem(v,
                  "campaign.name: a text without spaces or slashes (it names the "
                  "campaign's folder and its rows in the notebook)");
      } else {
        c.name = v.as_string().str;
      }
    } else if (k == "protocol") {
      if (!v.is_string()) {
        r.problem(v, "campaign.protocol: the protocol file (text), relative to this file");
      } else {
        c.protocol = v.as_string().str;
      }
    } else if (k == "seeds") {
      seeds = &v;
    } else if (k == "combine") {
      if (v.is_string() && v.as_string().str == "product") {
        continue;
      } else if (!(v.is_string() && v.as_string().str == "zip")) {
        r.problem(v, "campaign.combine: one of product, zip");
      }
    } else if (k == "threads") {
      if (!v.is_integer() || v.as_integer() < 1 || v.as_integer() > 1024) {
        r.problem(v, "campaign.threads: each run's threads, an integer in [1, 1024]");
      } else {
        c.threads = static_cast<int>(v.as_integer());
      }
    } else {
      r.problem(
          v, "campaign." + k + ": unknown key (campaign.name, protocol, seeds, combine, threads)");
    }
  }
  if (c.name.empty() && t.as_table().count("name") == 0) r.problem("missing campaign.name");
  if (c.protocol.empty() && t.as_table().count("protocol") == 0) {
    r.problem("missing campaign.protocol: the protocol file the campaign runs");
  }
}

// A [[paper]] table: what the paper says of one of the campaign's results.
void readPaperClaim(const TomlValue& t, Campaign& c, Reader& r) {
  if (!t.is_table()) {
    r.problem(t, "paper: a table per claim ([[paper]] with result, and number or says)");
    return;
  }
  PaperClaim claim;
  claim.at = r.at(t);
  for (const auto& [k, v] : t.as_table()) {
    auto text = [&](std::string& out, const char* what) {
      if (!v.is_string() || v.as_string().str.empty()) {
        r.problem(v, std::string("paper.") + k + ": " + what);
      } else {
        out = v.as_string().str;
      }
    };
    if (k == "result") {
      text(claim.result, "the key result the claim is about (text)");
    } else if (k == "number") {
      text(claim.number, "a [[number]] key of data/paper.toml (text)");
    } else if (k == "says") {
      text(claim.says, "what the paper says (text)");
    } else if (k == "within") {
      const bool pair = v.is_array() && v.as_array().size() == 2 &&
                        (v.as_array()[0].is_floating() || v.as_array()[0].is_integer()) &&
                        (v.as_array()[1].is_floating() || v.as_array()[1].is_integer());
      auto number = [](const TomlValue& x) {
        return x.is_integer() ? static_cast<double>(x.as_integer()) : x.as_floating();
      };
      const double low = pair ? number(v.as_array()[0]) : 0.0;
      const double high = pair ? number(v.as_array()[1]) : 0.0;
      if (!pair || !(low < high)) {
        r.problem(v, "paper.within: [low, high], low < high, in the result's unit");
      } else {
        claim.fraction = true, claim.low = low, claim.high = high;
      }
    } else if (k == "point") {
      std::vector<std::pair<std::string, const TomlValue*>> keys;
      if (v.is_table() && !v.as_table().empty()) Reader::flatten(v, "", keys);
      if (keys.empty()) r.problem(v, "paper.point: a table of swept keys and their values");
      for (const auto& [key, value] : keys) {
        claim.point.push_back({key, tomlLiteral(*value), r.at(*value)});
      }
    } else {
      r.problem(v, "paper." + k + ": unknown key (paper.result, number, says, within, point)");
    }
  }
  if (!t.as_table().count("result")) r.problem(t, "paper: missing paper.result");
  if (!t.as_table().count("number") && !t.as_table().count("says")) {
    r.problem(t, "paper: give paper.number (the paper's value) or paper.says (its words)");
  }
  c.paper.push_back(std::move(claim));
}

// Every claim's result is a key result of the protocol's rig, with a rule to evaluate it.
void checkPaperResults(const Campaign& c, Reader& r) {
  if (c.paper.empty()) return;
  std::string rig;
  try {
    rig = rigs::checkProtocol(c.protocol, c.fixed).rig->name;
  } catch (const protocol::ProtocolError&) {
    return;  // the protocol's own problems are reported where it is checked
  }
  const rigs::Outputs* outputs = rigs::rigOutputs(rig);
  for (const PaperClaim& p : c.paper) {
    if (p.result.empty()) continue;
    if (!outputs || !outputs->keyResult(p.result) || !reports::findKeyResultRule(rig, p.result)) {
      r.TomlReader::problem(p.at + ": paper.result = \"" + p.result +
                            "\" is not a key result of the " + rig + " rig (`rocklab keys " + rig +
                            "` lists them)");
    }
  }
}

// Two values of a key alike: the same text, or the same number (2 and 2.0).
bool sameValue(const std::string& a, const std::string& b) {
  if (a == b) return true;
  double x = 0.0, y = 0.0;
  const auto rx = std::from_chars(a.data(), a.data() + a.size(), x);
  const auto ry = std::from_chars(b.data(), b.data() + b.size(), y);
  return rx.ec == std::errc() && rx.ptr == a.data() + a.size() && ry.ec == std::errc() &&
         ry.ptr == b.data() + b.size() && x == y;
}

// A claim's `point` names swept keys, and some point of the campaign has all its values.
void checkPaperPoints(const Campaign& c, Reader& r) {
  for (const PaperClaim& p : c.paper) {
    if (p.point.empty()) continue;
    bool swept = true;
    for (const auto& o : p.point) {
      const bool found = std::any_of(c.points.begin(), c.points.end(), [&](const Point& q) {
        return std::any_of(q.settings.begin(), q.settings.end(),
                           [&](const protocol::Override& s) { return s.key == o.key; });
      });
      if (!found) {
        r.TomlReader::problem(o.origin + ": paper.point." + o.key + ": not a key of the [sweep]");
        swept = false;
      }
    }
    if (swept && std::none_of(c.points.begin(), c.points.end(),
                              [&](const Point& q) { return p.concerns(q); })) {
      std::string labels;
      for (const Point& q : c.points) labels += (labels.empty() ? "" : "; ") + q.label();
      r.TomlReader::problem(p.point.front().origin +
                            ": paper.point: no point of the campaign has these values (its "
                            "points: " +
                            labels + ")");
    }
  }
}

}  // namespace

bool PaperClaim::concerns(const Point& p) const {
  return std::all_of(point.begin(), point.end(), [&](const protocol::Override& o) {
    return std::any_of(p.settings.begin(), p.settings.end(), [&](const protocol::Override& s) {
      return s.key == o.key && sameValue(s.value, o.value);
    });
  });
}

std::string Point::label() const {
  if (settings.empty()) return "base";
  std::string s;
  for (const auto& o : settings) s += (s.empty() ? "" : ", ") + o.key + "=" + o.value;
  return s;
}

std::vector<Task> Campaign::tasks() const {
  std::vector<Task> out;
  for (const Point& p : points) {
    for (std::int64_t seed : seeds) {
      out.push_back({static_cast<int>(out.size()), p.index, seed});
    }
  }
  return out;
}

std::vector<protocol::Override> Campaign::overrides(const Task& t, bool with_lines) const {
  std::vector<protocol::Override> o = fixed;
  const Point& p = points.at(static_cast<std::size_t>(t.point));
  o.insert(o.end(), p.settings.begin(), p.settings.end());
  o.push_back({"protocol.seed", std::to_string(t.seed), file + ": campaign.seeds"});
  if (!with_lines) {
    for (auto& x : o) x.origin = "campaign " + name;
  }
  return o;
}

Campaign readCampaign(const std::string& path) {
  Campaign c;
  c.file = path;
  c.text = readText(path);
  TomlValue root;
  try {
    std::istringstream in(c.text);
    root = toml::parse<toml::discard_comments, std::map, std::vector>(in, path);
  } catch (const std::exception& e) {
    throw protocol::ProtocolError({path + ": not valid TOML:\n" + e.what()});
  }
  Reader r(path);
  const TomlValue* seeds = nullptr;
  std::vector<std::pair<std::string, const TomlValue*>> fixed, sweeps;
  bool zip = false;
  for (const auto& [k, v] : root.as_table()) {
    if (k == "paper" && v.is_array()) {
      for (const auto& t : v.as_array()) readPaperClaim(t, c, r);
    } else if (!v.is_table()) {
      r.problem(v, k + ": a key outside a table ([campaign], [set], [sweep], [slurm], [[paper]])");
    } else if (k == "campaign") {
      readHead(v, c, r, seeds);
      zip = v.as_table().count("combine") && v.at("combine").is_string() &&
            v.at("combine").as_string().str == "zip";
    } else if (k == "set") {
      Reader::flatten(v, "", fixed);
    } else if (k == "sweep") {
      Reader::flatten(v, "", sweeps);
    } else if (k == "slurm") {
      r.slurm(v, c.slurm);
    } else {
      r.problem(v, "[" + k + "]: unknown table ([campaign], [set], [sweep], [slurm], [[paper]])");
    }
  }
  if (!root.as_table().count("campaign")) r.problem("missing the [campaign] table");
  // In the file's order (the tables are read sorted by name): the first sweep varies slowest.
  for (auto* keys : {&fixed, &sweeps}) {
    std::stable_sort(keys->begin(), keys->end(), [](const auto& a, const auto& b) {
      return a.second->location().line() < b.second->location().line();
    });
  }
  r.throwIfAny();

  namespace fs = std::filesystem;
  if (fs::path(c.protocol).is_relative()) {
    c.protocol = (fs::path(path).parent_path() / c.protocol).lexically_normal().string();
  }
  for (const auto& [key, v] : fixed) {
    const std::string text = tomlLiteral(*v);
    if (text.empty()) {
      r.problem(*v, "set." + key + ": a number, text, boolean or list");
    } else {
      c.fixed.push_back({key, text, r.at(*v)});
    }
  }
  // Each sweep's values, then the points they make.
  std::vector<std::vector<protocol::Override>> values;
  for (const auto& [key, v] : sweeps) {
    if (!v->is_array() || v->as_array().empty()) {
      r.problem(*v, "sweep." + key + ": a non-empty list of the values the key takes");
      continue;
    }
    std::vector<protocol::Override> list;
    for (const auto& e : v->as_array()) {
      const std::string text = tomlLiteral(e);
      if (text.empty()) {
        r.problem(e, "sweep." + key + ": a value is a table or date, not a protocol value");
      } else {
        list.push_back({key, text, r.at(e)});
      }
    }
    values.push_back(std::move(list));
  }
  if (zip) {
    for (std::size_t k = 1; k < values.size(); ++k) {
      if (values[k].size() != values[0].size()) {
        r.problem(*sweeps[k].second,
                  "sweep." + sweeps[k].first + ": " + std::to_string(values[k].size()) +
                      " values, but combine = \"zip\" needs as many as sweep." + sweeps[0].first +
                      " has (" + std::to_string(values[0].size()) + ")");
      }
    }
  }
  // The seeds: a list, or a count from the protocol's own seed on.
  if (!seeds) {
    r.problem(
        "missing campaign.seeds: a count (the protocol's seed and the ones after it) or "
        "a list of seeds");
  } else if (seeds->is_integer()) {
    const auto n = seeds->as_integer();
    if (n < 1 || n > 100000) {
      r.problem(*seeds, "campaign.seeds: a count in [1, 100000], or a list of seeds");
    } else {
      std::int64_t first = 1;
      try {
        first = rigs::checkProtocol(c.protocol, c.fixed).settings.integer("protocol.seed");
      } catch (const protocol::ProtocolError& e) {
        for (const auto& p : e.problems()) r.problem(p);
      }
      for (std::int64_t k = 0; k < n; ++k) c.seeds.push_back(first + k);
    }
  } else if (seeds->is_array() && !seeds->as_array().empty()) {
    for (const auto& s : seeds->as_array()) {
      if (!s.is_integer() || s.as_integer() < 0) {
        r.problem(s, "campaign.seeds: every seed an integer >= 0");
      } else {
        for (std::int64_t known : c.seeds) {
          if (known == s.as_integer())
            r.problem(s, "campaign.seeds: seed " + std::to_string(known) + " twice");
        }
        c.seeds.push_back(s.as_integer());
      }
    }
  } else {
    r.problem(*seeds, "campaign.seeds: a count, or a non-empty list of seeds");
  }
  r.throwIfAny();
  std::vector<std::vector<protocol::Override>> points = {{}};
  if (zip && !values.empty()) {
    points.assign(values[0].size(), {});
    for (const auto& list : values) {
      for (std::size_t k = 0; k < list.size(); ++k) points[k].push_back(list[k]);
    }
  } else {
    for (const auto& list : values) {
      std::vector<std::vector<protocol::Override>> next;
      for (const auto& p : points) {
        for (const auto& o : list) {
          next.push_back(p);
          next.back().push_back(o);
        }
      }
      points = std::move(next);
    }
  }
  for (std::size_t k = 0; k < points.size(); ++k) {
    c.points.push_back({static_cast<int>(k), points[k]});
  }
  checkPaperResults(c, r);
  checkPaperPoints(c, r);

  r.throwIfAny();
  return c;
}

std::string numberText(double x) {
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  if (std::isnan(x)) return "nan";
  char buf[32];
  std::string t(buf, std::to_chars(buf, buf + sizeof buf, x).ptr);
  if (t.find_first_of(".en") == std::string::npos) t += ".0";
  return t;
}

std::string tomlLiteral(const TomlValue& v) {
  if (v.is_floating()) return numberText(v.as_floating());
  if (v.is_integer()) return std::to_string(v.as_integer());
  if (v.is_boolean()) return v.as_boolean() ? "true" : "false";
  if (v.is_string()) {
    std::string q = "\"";
    for (char c : v.as_string().str) {
      if (c == '"' || c == '\\') q += '\\';
      q += c;
    }
    return q + "\"";
  }
  if (v.is_array()) {
    std::string t = "[";
    for (std::size_t k = 0; k < v.as_array().size(); ++k) {
      const std::string e = tomlLiteral(v.as_array()[k]);
      if (e.empty()) return "";
      t += (k ? ", " : "") + e;
    }
    return t + "]";
  }
  return "";  // tables and dates: refused by the caller
}

void readSlurmTable(const TomlValue& t, const std::string& file, SlurmOptions& s,
                    std::vector<std::string>& problems) {
  for (const auto& [k, v] : t.as_table()) {
    auto problem = [&](const std::string& what) {
      problems.push_back(file + ":" + std::to_string(v.location().line()) + ": slurm." + k + ": " +
                         what);
    };
    auto text = [&](std::string& out) {
      if (v.is_string()) {
        out = v.as_string().str;
      } else {
        problem("a text");
      }
    };
    if (k == "partition") {
      text(s.partition);
    } else if (k == "time") {
      text(s.time);
    } else if (k == "account") {
      text(s.account);
    } else if (k == "cpus_per_task") {
      if (!v.is_integer() || v.as_integer() < 1 || v.as_integer() > 1024) {
        problem("an integer in [1, 1024]");
      } else {
        s.cpus_per_task = static_cast<int>(v.as_integer());
      }
    } else if (k == "options") {
      bool texts = v.is_array();
      if (texts) {
        for (const auto& o : v.as_array()) texts = texts && o.is_string();
      }
      if (!texts) {
        problem("a list of sbatch options, e.g. [\"--mem=2G\"]");
      } else {
        for (const auto& o : v.as_array()) s.options.push_back(o.as_string().str);
      }
    } else {
      problem("unknown key (slurm.partition, time, account, cpus_per_task, options)");
    }
  }
}

std::string slurmTableText(const SlurmOptions& s) {
  auto quoted = [](const std::string& x) { return tomlLiteral(TomlValue(x)); };
  std::string t;
  if (!s.partition.empty()) t += "partition = " + quoted(s.partition) + "\n";
  if (!s.time.empty()) t += "time = " + quoted(s.time) + "\n";
  if (!s.account.empty()) t += "account = " + quoted(s.account) + "\n";
  if (s.cpus_per_task > 0) t += "cpus_per_task = " + std::to_string(s.cpus_per_task) + "\n";
  if (!s.options.empty()) {
    t += "options = [";
    for (std::size_t k = 0; k < s.options.size(); ++k) t += (k ? ", " : "") + quoted(s.options[k]);
    t += "]\n";
  }
  return t.empty() ? t : "[slurm]\n" + t;
}

}  // namespace rocklab::campaign
