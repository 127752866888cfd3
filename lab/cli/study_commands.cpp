#include "lab/cli/study_commands.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "lab/cli/lab_commands.hpp"
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

}  // namespace rocklab::cli
