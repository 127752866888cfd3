#include "lab/cli/study_commands.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <toml.hpp>

#include "lab/cli/build_info.hpp"
#include "lab/cli/lab_commands.hpp"
#include "reports/key_results.hpp"
#include "reports/run_data.hpp"
#include "reports/study.hpp"

namespace rocklab::cli {

namespace {

struct Ladder {
  std::string key;
  std::vector<std::string> values;
};

Ladder parseVary(const std::string& arg) {
  const auto eq = arg.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == arg.size()) {
    throw protocol::ProtocolError(
        {"--vary " + arg + ": expects KEY=v1,v2,... (the protocol's dotted key, finest first)"});
  }
  Ladder l{arg.substr(0, eq), {}};
  std::stringstream in(arg.substr(eq + 1));
  for (std::string v; std::getline(in, v, ',');) {
    if (v.empty()) throw protocol::ProtocolError({"--vary " + arg + ": an empty value"});
    l.values.push_back(v);
  }
  return l;
}

// Every combination of the ladders' values, the first ladder varying slowest; combination 0
// is the finest of all.
std::vector<std::vector<std::pair<std::string, std::string>>> combinations(
    const std::vector<Ladder>& ladders) {
  std::vector<std::vector<std::pair<std::string, std::string>>> out = {{}};
  for (const Ladder& l : ladders) {
    std::vector<std::vector<std::pair<std::string, std::string>>> next;
    for (const auto& c : out) {
      for (const std::string& v : l.values) {
        next.push_back(c);
        next.back().emplace_back(l.key, v);
      }
    }
    out = std::move(next);
  }
  return out;
}

std::string describe(const std::vector<std::pair<std::string, std::string>>& combo) {
  std::string s;
  for (const auto& [k, v] : combo) s += (s.empty() ? "" : ", ") + k + " = " + v;
  return s;
}

struct Reference {
  std::string protocol;
  struct Key {
    std::string name, unit;
    double value = 0.0, tolerance = 0.0;
  };
  std::vector<Key> keys;
};

Reference readReference(const std::string& path) {
  if (!std::filesystem::exists(path)) {
    throw std::invalid_argument(path +
                                ": no such reference file (`rocklab regress update` "
                                "writes them)");
  }
  Reference r;
  try {
    // Ordered by name, so that a check lists them the same way every time.
    const auto root = toml::parse<toml::discard_comments, std::map, std::vector>(path);
    r.protocol = toml::find<std::string>(root, "protocol");
    // A prefixed name ("stage1.vp_z") is written quoted; unquoted, TOML reads it as nested
    // tables, which are walked down to the entries that hold a value.
    auto walk = [&](auto&& self, const auto& table, const std::string& prefix) -> void {
      for (const auto& [key, v] : table) {
        if (!v.is_table()) continue;
        if (!v.contains("value")) {
          self(self, v.as_table(), prefix + key + ".");
          continue;
        }
        Reference::Key k;
        k.name = prefix + key;
        k.value = toml::find<double>(v, "value");
        k.tolerance = toml::find<double>(v, "tolerance");
        k.unit = toml::find_or<std::string>(v, "unit", "");
        if (!(k.tolerance >= 0.0)) {
          throw std::invalid_argument("results." + k.name + ".tolerance must be >= 0");
        }
        r.keys.push_back(k);
      }
    };
    walk(walk, toml::find(root, "results").as_table(), "");
  } catch (const std::exception& e) {
    throw std::invalid_argument(path + ": not a reference file: " + e.what());
  }
  return r;
}

std::int64_t newestRunOf(notebook::Notebook& nb, const std::string& protocol) {
  auto s = nb.db().prepare("SELECT max(id) FROM runs WHERE protocol = ?");
  s.bind(1, std::string_view(protocol));
  return s.step() && !s.isNull(0) ? s.integer(0) : 0;
}

// A TOML float: always with a point or an exponent, so that it reads back as one.
std::string fmt(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  std::ostringstream s;
  s.precision(7);
  s << v;
  std::string t = s.str();
  if (t.find_first_of(".e") == std::string::npos) t += ".0";
  return t;
}

}  // namespace

int studyAccuracy(const StudyOptions& o) {
  rigs::CheckedProtocol c{nullptr, {}};
  std::vector<protocol::Settings> runs;
  std::vector<std::string> labels;
  try {
    c = rigs::checkProtocol(o.protocol, overridesOf(o.sets));
    if (c.settings.texts("protocol.key_results").empty()) {
      protocol::fail(c.settings, "protocol.key_results",
                     "the protocol names no key results: a study has nothing to compare "
                     "(`rocklab keys " +
                         std::string(c.rig->name) + "` lists them)");
    }
    if (o.vary.empty()) throw protocol::ProtocolError({"study: give at least one --vary"});
    if (!(o.tolerance_percent > 0.0)) {
      throw protocol::ProtocolError({"study: --tolerance must be > 0 (%)"});
    }
    std::vector<Ladder> ladders;
    for (const std::string& v : o.vary) {
      ladders.push_back(parseVary(v));
      for (std::size_t k = 0; k + 1 < ladders.size(); ++k) {
        if (ladders[k].key == ladders.back().key) {
          throw protocol::ProtocolError({"--vary " + v + ": " + ladders[k].key + " varied twice"});
        }
      }
    }
    if (o.seeds < 1) throw protocol::ProtocolError({"study: --seeds must be at least 1"});
    for (const Ladder& l : ladders) {
      if (l.key == "protocol.seed" && o.seeds > 1) {
        throw protocol::ProtocolError(
            {"--vary protocol.seed with --seeds: the seeds of each setting are --seeds'"});
      }
    }
    // Every setting is checked before the first run: a bad value writes nothing. Each runs
    // at the protocol's seed and the seeds - 1 after it.
    const std::int64_t seed0 = c.settings.integer("protocol.seed");
    for (const auto& combo : combinations(ladders)) {
      for (int k = 0; k < o.seeds; ++k) {
        protocol::Settings s = c.settings;
        for (const auto& [key, value] : combo) {
          s.apply({{key, value, "--vary"}});
        }
        if (o.seeds > 1) s.override("protocol.seed", seed0 + k);
        if (o.threads > 0) s.runChoice("numerics.threads", static_cast<std::int64_t>(o.threads));
        rigs::validateProtocol(*c.rig, s);
        runs.push_back(std::move(s));
        labels.push_back(describe(combo) +
                         (o.seeds > 1 ? ", seed " + std::to_string(seed0 + k) : ""));
      }
    }
  } catch (const protocol::ProtocolError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
  if (o.dry_run) {
    std::cout << o.protocol << ": " << runs.size() << " settings, all valid\n";
    for (const std::string& l : labels) std::cout << "  " << l << "\n";
    return 0;
  }
  std::filesystem::create_directories(o.out);
  std::vector<std::int64_t> ids;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    std::cerr << "study: setting " << k + 1 << " of " << runs.size() << ": " << labels[k] << "\n";
    const RunOutcome r = runSettings(*c.rig, runs[k], o.protocol, o.lab, o.quiet);
    ids.push_back(r.run);
    if (r.code == 130) {
      std::cerr << "study interrupted: its runs so far are in " << o.lab << "\n";
      return 130;
    }
  }
  return studyReport(ids, o.lab, o.out, o.tolerance_percent);
}

int studyReport(const std::vector<std::int64_t>& runs, const std::string& lab,
                const std::string& out, double tolerance_percent) {
  const reports::Study study = reports::evaluateStudy(lab, runs, tolerance_percent / 100.0);
  reports::writeStudyReport(study, out);
  std::cout << "wrote " << out << "/index.html\n" << reports::studySummary(study) << "\n";
  return 0;
}

int regressCheck(const std::string& reference, const std::string& lab, std::int64_t run) {
  Reference ref;
  try {
    ref = readReference(reference);
  } catch (const std::invalid_argument& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
  if (!std::filesystem::exists(lab)) {
    std::cerr << "no lab notebook at '" << lab << "'\n";
    return 2;
  }
  notebook::Notebook nb(lab);
  if (run == 0) run = newestRunOf(nb, ref.protocol);
  if (run == 0) {
    std::cerr << lab << ": no run of protocol '" << ref.protocol << "'\n";
    return 2;
  }
  const reports::RunData r = reports::loadRun(nb, run);
  if (r.protocol != ref.protocol) {
    std::cerr << "run " << run << " is of protocol '" << r.protocol << "', the reference of '"
              << ref.protocol << "'\n";
    return 2;
  }
  bool ok = r.status == "completed";
  std::cout << "run " << run << " (" << r.protocol << ", " << r.status << ") against " << reference
            << ":\n";
  for (const Reference::Key& k : ref.keys) {
    const std::optional<double> v = reports::evaluateKeyResult(r, k.name);
    const bool within = v && std::abs(*v - k.value) <= k.tolerance;
    ok = ok && within;
    const std::string unit = k.unit.empty() || k.unit == "-" ? "" : " " + k.unit;
    std::cout << "  " << (within ? "ok  " : "FAIL") << " " << k.name << " = "
              << (v ? fmt(*v) + unit : "not recorded") << ", reference " << fmt(k.value) << " +- "
              << fmt(k.tolerance) << unit << "\n";
  }
  if (!ok) {
    std::cout << "key results moved beyond their tolerance: if the change is meant, regenerate "
                 "the references (make references) and review their diff\n";
  }
  return ok ? 0 : 1;
}

namespace {

// A protocol run at `seeds` seeds from its own; the runs' data, or fewer when one failed.
std::vector<reports::RunData> runAtSeeds(const rigs::CheckedProtocol& c, const std::string& file,
                                         const RegressUpdateOptions& o, bool& interrupted) {
  const std::int64_t seed0 = c.settings.integer("protocol.seed");
  std::vector<reports::RunData> runs;
  for (int k = 0; k < o.seeds; ++k) {
    protocol::Settings s = c.settings;
    s.override("protocol.seed", seed0 + k);
    if (o.threads > 0) s.runChoice("numerics.threads", static_cast<std::int64_t>(o.threads));
    const RunOutcome r = runSettings(*c.rig, s, file, o.lab, true);
    if (r.code == 130) interrupted = true;
    if (r.code != 0) {
      if (!interrupted) {
        std::cerr << file << ": run " << r.run << " at seed " << seed0 + k
                  << " did not complete: no reference written for it\n";
      }
      break;
    }
    notebook::Notebook nb(o.lab);
    runs.push_back(reports::loadRun(nb, r.run));
  }
  return runs;
}

// The reference file of a protocol from its runs at successive seeds: each key result's
// value at the protocol's own seed and a tolerance from their spread.
std::string referenceFile(const rigs::CheckedProtocol& c,
                          const std::vector<reports::RunData>& runs) {
  const std::string name = c.settings.text("protocol.name");
  const std::int64_t seed0 = c.settings.integer("protocol.seed");
  std::ostringstream file;
  file << "# Key results of " << name << " guarded by the regression test (tests/e2e).\n"
       << "# Written by `rocklab regress update` at git " << kGitRevision
       << "; review the diff before committing.\n"
       << "# value: at the protocol's own seed (" << seed0 << "), as the test runs it.\n"
       << "# tolerance: twice the spread over seeds " << seed0 << "-"
       << seed0 + static_cast<std::int64_t>(runs.size()) - 1
       << ", at least 1% of the value: a change that only\n"
       << "# reorders floating-point sums moves a result like another seed does; one beyond "
          "that\n# changed the physics.\n"
       << "protocol = \"" << name << "\"\n";
  std::string unguarded;
  for (const std::string& key : c.settings.texts("protocol.key_results")) {
    std::vector<double> v;
    for (const reports::RunData& r : runs) {
      if (const auto x = reports::evaluateKeyResult(r, key)) v.push_back(*x);
    }
    // A key result some seed does not record (no band found, a pulse drowned) cannot be
    // held to a value: it is listed, not guarded.
    if (v.size() < runs.size()) {
      unguarded += "#   " + key + ": recorded at " + std::to_string(v.size()) + " of " +
                   std::to_string(runs.size()) + " seeds\n";
      std::cerr << name << ": key result '" << key << "' recorded at " << v.size() << " of "
                << runs.size() << " seeds: not guarded\n";
      continue;
    }
    const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
    const double tolerance = std::max(2.0 * (*hi - *lo), 0.01 * std::abs(v.front()));
    const std::string quoted = key.find('.') == std::string::npos ? key : "\"" + key + "\"";
    file << "\n[results." << quoted << "]\nvalue = " << fmt(v.front())
         << "\ntolerance = " << fmt(tolerance) << "\nunit = \""
         << c.rig->outputs().keyResult(key)->unit << "\"\nseeds = [";
    for (std::size_t k = 0; k < v.size(); ++k) file << (k ? ", " : "") << fmt(v[k]);
    file << "]\n";
  }
  if (!unguarded.empty()) file << "\n# Not guarded (not recorded at every seed):\n" << unguarded;
  return file.str();
}

}  // namespace

int regressUpdate(const RegressUpdateOptions& o) {
  if (o.seeds < 2) {
    std::cerr << "regress update: --seeds must be at least 2 (the tolerance is their spread)\n";
    return 2;
  }
  std::vector<rigs::CheckedProtocol> checked;
  try {
    for (const std::string& p : o.protocols) {
      checked.push_back(rigs::checkProtocol(p));
      if (checked.back().settings.texts("protocol.key_results").empty()) {
        protocol::fail(checked.back().settings, "protocol.key_results",
                       "the protocol names no key results: there is nothing to guard");
      }
    }
  } catch (const protocol::ProtocolError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
  std::filesystem::create_directories(o.out);
  bool failed = false;
  for (std::size_t p = 0; p < checked.size(); ++p) {
    bool interrupted = false;
    const auto runs = runAtSeeds(checked[p], o.protocols[p], o, interrupted);
    if (interrupted) return 130;
    if (runs.size() < static_cast<std::size_t>(o.seeds)) {
      failed = true;
      continue;
    }
    const std::string path = o.out + "/" + checked[p].settings.text("protocol.name") + ".toml";
    std::ofstream out(path);
    out << referenceFile(checked[p], runs);
    if (!out) {
      std::cerr << "cannot write " << path << "\n";
      return 1;
    }
    std::cout << "wrote " << path << "\n";
  }
  std::cout << "review with `git diff " << o.out << "` before committing\n";
  return failed ? 1 : 0;
}

}  // namespace rocklab::cli
