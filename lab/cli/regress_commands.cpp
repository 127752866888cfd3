#include "lab/cli/regress_commands.hpp"

#include <sys/wait.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <toml.hpp>

#include "lab/campaign/statistics.hpp"
#include "lab/cli/build_info.hpp"
#include "lab/cli/child_process.hpp"
#include "lab/cli/lab_commands.hpp"
#include "lab/notebook/merge.hpp"
#include "reports/key_results.hpp"
#include "reports/run_data.hpp"

namespace rocklab::cli {

namespace {

// A check's interval: the 99.5% quantile of Student's t (a key result of an unchanged
// physics fails one check in a hundred at most, where rounding redraws its samples).
constexpr double kGuardQuantile = 0.995;
// A key result whose interval is wider than this share of its mean is not guarded at the
// seeds a check has (a physics change could hide in it); more seeds narrow it.
constexpr double kWidestGuard = 0.15;
// An interval at least this share of the mean: a result the seeds do not scatter (the stress
// a servo reached) still moves by a last bit or two.
constexpr double kNarrowestGuard = 1e-6;
// The seeds of a new reference: a key result scattering up to 8.6% of its mean is guarded
// at all of them (t(0.995, 7) s sqrt(1/8 + 1/8) = 1.75 s <= 15%).
constexpr int kDefaultSeeds = 8;

struct Reference {
  std::string protocol;
  std::vector<std::int64_t> seeds;
  struct Key {
    std::string name, unit;
    std::vector<double> values;  // at each seed
    campaign::Summary summary;   // over the seeds
  };
  std::vector<Key> keys;
};

// The half-width of a check of a key result at m seeds: the means over the reference's n seeds
// and over the m checked are two draws of the sample's scatter once anything changes the
// rounding (a reordered sum, another compiler), so their difference spreads as
// s sqrt(1/n + 1/m), s the reference's standard deviation.
double halfWidth(const campaign::Summary& s, std::size_t m) {
  const double n = static_cast<double>(s.n);
  const double half = campaign::studentT(kGuardQuantile, n - 1.0) * s.std *
                      std::sqrt(1.0 / n + 1.0 / static_cast<double>(m));
  return std::max(half, kNarrowestGuard * std::abs(s.mean));
}

bool guarded(const campaign::Summary& s, std::size_t m) {
  return halfWidth(s, m) <= kWidestGuard * std::abs(s.mean);
}

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
    if (!root.contains("seeds")) {
      throw std::invalid_argument(
          "no `seeds`: a reference of an older rocklab (one seed's value); write it anew with "
          "`rocklab regress update`");
    }
    r.seeds = toml::find<std::vector<std::int64_t>>(root, "seeds");
    if (r.seeds.size() < 2) throw std::invalid_argument("`seeds`: at least two");
    // A prefixed name ("stage1.vp_z") is written quoted; unquoted, TOML reads it as nested
    // tables, which are walked down to the entries that hold values.
    auto walk = [&](auto&& self, const auto& table, const std::string& prefix) -> void {
      for (const auto& [key, v] : table) {
        if (!v.is_table()) continue;
        if (!v.contains("values")) {
          self(self, v.as_table(), prefix + key + ".");
          continue;
        }
        Reference::Key k;
        k.name = prefix + key;
        k.values = toml::find<std::vector<double>>(v, "values");
        k.unit = toml::find_or<std::string>(v, "unit", "");
        if (k.values.size() != r.seeds.size()) {
          throw std::invalid_argument("results." + k.name + ": " + std::to_string(k.values.size()) +
                                      " values for " + std::to_string(r.seeds.size()) + " seeds");
        }
        k.summary = campaign::summarize(k.values);
        r.keys.push_back(k);
      }
    };
    walk(walk, toml::find(root, "results").as_table(), "");
  } catch (const std::exception& e) {
    throw std::invalid_argument(path + ": not a reference file: " + e.what());
  }
  return r;
}

// A TOML float: always with a point or an exponent, so that it reads back as one.
std::string fmt(double v, int digits = 7) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  std::ostringstream s;
  s.precision(digits);
  s << v;
  std::string t = s.str();
  if (t.find_first_of(".e") == std::string::npos) t += ".0";
  return t;
}

// The newest run of a protocol at a seed, or 0.
std::int64_t newestRunAt(notebook::Notebook& nb, const std::string& protocol, std::int64_t seed) {
  auto s = nb.db().prepare("SELECT max(id) FROM runs WHERE protocol = ? AND seed = ?");
  s.bind(1, std::string_view(protocol));
  s.bind(2, seed);
  return s.step() && !s.isNull(0) ? s.integer(0) : 0;
}

std::int64_t seedOf(notebook::Notebook& nb, std::int64_t run) {
  auto s = nb.db().prepare("SELECT seed FROM runs WHERE id = ?");
  s.bind(1, run);
  return s.step() && !s.isNull(0) ? s.integer(0) : -1;
}

}  // namespace

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
  // The runs to check, each at a seed of the reference.
  std::vector<std::pair<std::int64_t, std::int64_t>> runs;  // run, seed
  if (run != 0) {
    const std::int64_t seed = seedOf(nb, run);
    if (std::find(ref.seeds.begin(), ref.seeds.end(), seed) == ref.seeds.end()) {
      std::cerr << "run " << run << " is not at a seed of the reference\n";
      return 2;
    }
    runs.emplace_back(run, seed);
  } else {
    for (const std::int64_t seed : ref.seeds) {
      if (const std::int64_t id = newestRunAt(nb, ref.protocol, seed)) runs.emplace_back(id, seed);
    }
  }
  if (runs.empty()) {
    std::cerr << lab << ": no run of protocol '" << ref.protocol
              << "' at a seed of the reference\n";
    return 2;
  }
  std::vector<reports::RunData> data;
  bool ok = true;
  std::string seeds;
  for (const auto& [id, seed] : runs) {
    data.push_back(reports::loadRun(nb, id));
    if (data.back().protocol != ref.protocol) {
      std::cerr << "run " << id << " is of protocol '" << data.back().protocol
                << "', the reference of '" << ref.protocol << "'\n";
      return 2;
    }
    ok = ok && data.back().status == "completed";
    seeds += (seeds.empty() ? "" : ", ") + std::to_string(seed) + " (run " + std::to_string(id) +
             ", " + data.back().status + ")";
  }
  const std::size_t m = runs.size();
  std::cout << ref.protocol << " at seed" << (m > 1 ? "s " : " ") << seeds << " against "
            << reference << " (" << ref.seeds.size() << " seeds):\n";
  for (const Reference::Key& key : ref.keys) {
    std::vector<double> values;
    for (const reports::RunData& r : data) {
      if (const std::optional<double> v = reports::evaluateKeyResult(r, key.name)) {
        values.push_back(*v);
      }
    }
    const campaign::Summary s = key.summary;
    const std::string unit = key.unit.empty() || key.unit == "-" ? "" : " " + key.unit;
    const bool recorded = values.size() == m;
    const double mean = recorded ? campaign::summarize(values).mean : NAN;
    const std::string shown = recorded ? fmt(mean) + unit : "not recorded";
    if (!guarded(s, m)) {
      std::cout << "  --   " << key.name << " = " << shown << ": not guarded at " << m << " seed"
                << (m > 1 ? "s" : "") << " (the reference's scatter, "
                << fmt(100.0 * s.std / std::abs(s.mean), 2) << "% of the mean, leaves +-"
                << fmt(100.0 * halfWidth(s, m) / std::abs(s.mean), 2) << "%)\n";
      continue;
    }
    const double half = halfWidth(s, m);
    const bool within = recorded && std::abs(mean - s.mean) <= half;
    ok = ok && within;
    std::cout << "  " << (within ? "ok  " : "FAIL") << " " << key.name << " = " << shown
              << ", reference " << fmt(s.mean) << " +- " << fmt(half) << unit << "\n";
  }
  if (!ok) {
    std::cout << "key results moved beyond the sample's scatter: if the change is meant, "
                 "regenerate the references (make references) and review their diff\n";
  }
  return ok ? 0 : 1;
}

namespace {

std::atomic<int> g_stop{0};
extern "C" void onUpdateSignal(int sig) {
  g_stop.store(sig);
}

// The completed run at `seed` of these very settings and input files that this very build
// made, if the lab has one: an update killed or failed part-way and run again keeps the seeds
// it finished (a reference of eight half-hour runs outlives a session). A run of another build
// is run again.
std::optional<reports::RunData> keptRun(notebook::Notebook& lab, protocol::Settings settings,
                                        std::int64_t seed, const std::string& file) {
  settings.override("protocol.seed", seed);
  auto q = lab.db().prepare(
      "SELECT id FROM runs WHERE protocol_hash = ? AND seed = ? AND status = 'completed' AND "
      "code_version = ? AND build_type = ? ORDER BY id DESC LIMIT 1");
  q.bind(1, notebook::hashText(settings.identity())).bind(2, seed);
  q.bind(3, codeVersion()).bind(4, std::string(kBuildType));
  if (!q.step()) return std::nullopt;
  const std::int64_t run = q.integer(0);
  // A file the run read (a packing, a table) that has changed since makes it another run.
  auto in = lab.db().prepare("SELECT path, sha256 FROM inputs WHERE run_id = ?");
  in.bind(1, run);
  while (in.step()) {
    const std::string path = in.text(0);
    if (!std::filesystem::is_regular_file(path) || notebook::fileSha256(path) != in.text(1)) {
      return std::nullopt;
    }
  }
  std::cout << file << ": seed " << seed << " is run " << run
            << " of the lab, completed by this build: kept\n";
  return reports::loadRun(lab, run);
}

// A protocol run at `seeds` seeds from its own; the runs' data, or fewer when one failed.
// Here the runs are in this process, one after the other.
std::vector<reports::RunData> runAtSeeds(const rigs::CheckedProtocol& c, const std::string& file,
                                         int seeds, const RegressUpdateOptions& o,
                                         bool& interrupted) {
  const std::int64_t seed0 = c.settings.integer("protocol.seed");
  std::vector<reports::RunData> runs;
  for (int k = 0; k < seeds; ++k) {
    {
      notebook::Notebook nb(o.lab);
      if (auto kept = keptRun(nb, c.settings, seed0 + k, file)) {
        runs.push_back(std::move(*kept));
        continue;
      }
    }
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

// The runs at the seeds `jobs` at a time (--jobs), each `rocklab run` in a process of its own
// into a shard notebook beside the lab (<lab>.regress/), merged into the lab when it ends, as
// a campaign's tasks are: a reference of eight slow runs in a quarter of the time on 4 cores.
// A signal stops starting runs and reaches the running ones, which end interrupted, their
// data merged all the same.
std::vector<reports::RunData> runAtSeedsAtOnce(const rigs::CheckedProtocol& c,
                                               const std::string& file, int seeds,
                                               const RegressUpdateOptions& o, bool& interrupted) {
  const std::int64_t seed0 = c.settings.integer("protocol.seed");
  const std::string dir = std::filesystem::absolute(o.lab).string() + ".regress";
  std::filesystem::create_directories(dir);
  auto shard = [&](int k) {
    return dir + "/" + c.settings.text("protocol.name") + "-seed-" + std::to_string(seed0 + k);
  };
  notebook::Notebook lab(o.lab);
  std::vector<std::optional<reports::RunData>> done(static_cast<std::size_t>(seeds));
  std::map<pid_t, int> running;
  bool failed = false;
  int next = 0, forwarded = 0;
  g_stop.store(0);
  std::signal(SIGINT, onUpdateSignal);
  std::signal(SIGTERM, onUpdateSignal);
  while (next < seeds || !running.empty()) {
    while (g_stop.load() == 0 && !failed && next < seeds &&
           static_cast<int>(running.size()) < o.jobs) {
      if ((done[static_cast<std::size_t>(next)] = keptRun(lab, c.settings, seed0 + next, file))) {
        ++next;
        continue;
      }
      std::vector<std::string> args = {selfExecutable(),
                                       "run",
                                       std::filesystem::absolute(file).string(),
                                       "--quiet",
                                       "--set",
                                       "protocol.seed=" + std::to_string(seed0 + next),
                                       "--lab",
                                       shard(next) + ".sqlite"};
      if (o.threads > 0) args.insert(args.end(), {"--threads", std::to_string(o.threads)});
      notebook::removeNotebook(shard(next) + ".sqlite");  // a shard an earlier update left
      running[spawnLogged(args, shard(next) + ".log")] = next;
      ++next;
    }
    int status = 0;
    const pid_t pid = waitpid(-1, &status, 0);
    if (g_stop.load() != 0 && forwarded == 0) {  // reaches the runs if sent to this process alone
      forwarded = g_stop.load();
      for (const auto& r : running) kill(r.first, forwarded);
    }
    if (pid < 0) {
      if (errno == EINTR) continue;
      break;
    }
    const auto it = running.find(pid);
    if (it == running.end()) continue;
    const int k = it->second;
    running.erase(it);
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    const std::string notebook_file = shard(k) + ".sqlite";
    if (std::filesystem::exists(notebook_file)) {
      try {
        const notebook::MergeOutcome m = notebook::mergeNotebook(lab, notebook_file, {});
        if (code == 0 && !m.runs.empty()) done[k] = reports::loadRun(lab, m.runs.back());
        notebook::removeNotebook(notebook_file);
      } catch (const std::exception& e) {  // the shard stays, for `rocklab notebook merge`
        std::cerr << notebook_file << " is not merged into the lab: " << e.what() << "\n";
      }
    }
    if (done[k]) std::filesystem::remove(shard(k) + ".log");
    if (code == 130 || g_stop.load() != 0) {
      interrupted = true;
    } else if (!done[k]) {
      failed = true;
      std::cerr << file << ": the run at seed " << seed0 + k
                << " did not complete (its output: " << shard(k)
                << ".log): no reference written for it\n";
    }
  }
  if (interrupted) {
    std::cerr << file << ": interrupted; the runs so far are in " << o.lab
              << " (their output: " << dir << ")\n";
  }
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  std::error_code kept;  // the folder goes when no shard or log is left in it
  std::filesystem::remove(dir, kept);
  std::vector<reports::RunData> runs;
  for (auto& r : done) {
    if (!r) break;
    runs.push_back(std::move(*r));
  }
  return runs;
}

// The reference file of a protocol from its runs at successive seeds.
std::string referenceFile(const rigs::CheckedProtocol& c,
                          const std::vector<reports::RunData>& runs) {
  const std::string name = c.settings.text("protocol.name");
  const std::int64_t seed0 = c.settings.integer("protocol.seed");
  const std::size_t n = runs.size();
  std::ostringstream file;
  file << "# Key results of " << name << " guarded by the regression test (tests/e2e).\n"
       << "# Written by `rocklab regress update` at git " << codeVersion()
       << "; review the diff before committing.\n"
       << "# values: at each seed. A check at m of the seeds holds the mean of its values to "
          "the mean of\n# these within t("
       << kGuardQuantile << ", n - 1) s sqrt(1/n + 1/m) "
       << "(s: their standard deviation, n their\n# count); a key result whose interval passes "
       << 100.0 * kWidestGuard << "% of the mean is not guarded at m seeds.\n"
       << "protocol = \"" << name << "\"\nseeds = [";
  for (std::size_t k = 0; k < n; ++k) {
    file << (k ? ", " : "") << seed0 + static_cast<std::int64_t>(k);
  }
  file << "]\n";
  std::string notes;
  for (const std::string& key : c.settings.texts("protocol.key_results")) {
    std::vector<double> v;
    for (const reports::RunData& r : runs) {
      if (const auto x = reports::evaluateKeyResult(r, key)) v.push_back(*x);
    }
    // A key result some seed does not record (no band found, a pulse drowned) cannot be
    // held to a value: it is listed, not guarded.
    if (v.size() < n) {
      notes += "#   " + key + ": not guarded, recorded at " + std::to_string(v.size()) + " of " +
               std::to_string(n) + " seeds\n";
      std::cerr << name << ": key result '" << key << "' recorded at " << v.size() << " of " << n
                << " seeds: not guarded\n";
      continue;
    }
    const campaign::Summary s = campaign::summarize(v);
    auto percent = [&](std::size_t m) {
      return fmt(100.0 * halfWidth(s, m) / std::abs(s.mean), 2);
    };
    notes += "#   " + key + ": +-" + percent(1) + "% at one seed" +
             (guarded(s, 1) ? "" : " (not guarded)") + ", +-" + percent(n) + "% at all " +
             std::to_string(n) + (guarded(s, n) ? "" : " (not guarded)") + "\n";
    const std::string quoted = key.find('.') == std::string::npos ? key : "\"" + key + "\"";
    file << "\n[results." << quoted << "]\nunit = \"" << c.rig->outputs().keyResult(key)->unit
         << "\"\nvalues = [";
    for (std::size_t k = 0; k < n; ++k) file << (k ? ", " : "") << fmt(v[k], 10);
    file << "]\nmean = " << fmt(s.mean) << "\nstandard_deviation = " << fmt(s.std) << "\n";
  }
  file << "\n# The check's half-width, as a share of the mean:\n" << notes;
  return file.str();
}

// The seeds to write a reference at: --seeds, else as many as the reference being replaced
// has (a result guarded only at more than 8 stays guarded), else kDefaultSeeds.
int seedsOf(const RegressUpdateOptions& o, const std::string& reference) {
  if (o.seeds > 0) return o.seeds;
  if (!std::filesystem::exists(reference)) return kDefaultSeeds;
  try {
    return static_cast<int>(readReference(reference).seeds.size());
  } catch (const std::exception& e) {  // an older format: written anew at the default
    std::cerr << e.what() << "\n"
              << reference << ": written anew at " << kDefaultSeeds << " seeds\n";
    return kDefaultSeeds;
  }
}

}  // namespace

int regressUpdate(const RegressUpdateOptions& o) {
  if (o.seeds != 0 && o.seeds < 2) {
    std::cerr << "regress update: --seeds must be at least 2 (the interval is their scatter)\n";
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
    const std::string path = o.out + "/" + checked[p].settings.text("protocol.name") + ".toml";
    const int seeds = seedsOf(o, path);
    const auto runs = o.jobs > 1
                          ? runAtSeedsAtOnce(checked[p], o.protocols[p], seeds, o, interrupted)
                          : runAtSeeds(checked[p], o.protocols[p], seeds, o, interrupted);
    if (interrupted) return 130;
    if (runs.size() < static_cast<std::size_t>(seeds)) {
      failed = true;
      continue;
    }
    const std::string temporary = path + ".tmp";
    std::ofstream out(temporary);
    out << referenceFile(checked[p], runs);
    out.close();
    if (!out) {
      std::cerr << "cannot write " << temporary << "\n";
      return 1;
    }
    std::filesystem::rename(temporary, path);  // a killed update leaves the old file whole
    std::cout << "wrote " << path << "\n";
  }
  std::cout << "review with `git diff " << o.out << "` before committing\n";
  return failed ? 1 : 0;
}

}  // namespace rocklab::cli
