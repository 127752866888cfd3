#include "lab/cli/lab_commands.hpp"

#include <unistd.h>

#include <atomic>
#include <csignal>
#include <filesystem>
#include <iostream>

#include "lab/cli/build_info.hpp"
#include "lab/core/simulation.hpp"
#include "lab/notebook/queries.hpp"
#include "reports/key_results.hpp"
#include "reports/run_data.hpp"
#include "rigs/common/checked_recorder.hpp"
#include "rigs/registry.hpp"

namespace rocklab::cli {

namespace {

std::atomic<int> g_signal{0};

extern "C" void onSignal(int sig) {
  g_signal.store(sig);
}

const char* interruption() {
  switch (g_signal.load()) {
    case 0:
      return nullptr;
    case SIGINT:
      return "interrupted by the user (SIGINT)";
    case SIGTERM:
      return "terminated (SIGTERM)";
    default:
      return "stopped by a signal";
  }
}

// The notebook behind the rigs' Recorder interface.
class NotebookRecorder : public rigs::Recorder {
 public:
  explicit NotebookRecorder(notebook::RunWriter& w) : w_(w) {}
  void series(std::string_view name, std::uint64_t step, double time, double value) override {
    w_.series(name, step, time, value);
  }
  void event(const rigs::EventRecord& e) override { w_.event(e); }
  void result(std::string_view name, double value, std::string_view unit) override {
    w_.result(name, value, unit);
  }
  void message(std::uint64_t step, double time, std::string_view level,
               std::string_view text) override {
    if (level == "warning") std::cerr << "warning: " << text << "\n";
    w_.message(step, time, level, text);
  }
  void stageTiming(std::string_view stage, double seconds, std::uint64_t calls) override {
    w_.stageTiming(stage, seconds, calls);
  }
  void snapshot(std::string_view stage, std::string_view label, const Frame& frame) override {
    w_.snapshot("frame", stage, label, frame.step, frame.time, encodeFrame(frame), "rkf");
  }
  void wave(const rigs::WaveRecord& w) override { w_.wave(w); }

 private:
  notebook::RunWriter& w_;
};

// `rocklab notebook delete`: without confirmation it only says what would go.
int deleteRuns(notebook::Notebook& nb, const std::vector<std::int64_t>& runs, bool yes) {
  for (std::int64_t run : runs) notebook::requireRun(nb, run);
  for (std::int64_t run : runs) {
    const auto row = notebook::query(
        nb, "SELECT protocol, status, started FROM runs WHERE id = " + std::to_string(run));
    const auto& r = row.rows.front();
    std::cout << (yes ? "deleted" : "would delete") << " run " << run << " (" << r[0].str() << ", "
              << r[1].str() << ", started " << r[2].str() << ") and " << nb.runFilesDir(run)
              << "\n";
    if (yes) nb.deleteRun(run);
  }
  if (!yes) {
    std::cerr << "nothing deleted: add --yes to delete these runs and their files\n";
    return 2;
  }
  return 0;
}

}  // namespace

std::vector<protocol::Override> overridesOf(const std::vector<std::string>& sets) {
  std::vector<protocol::Override> o;
  for (const std::string& s : sets) o.push_back(protocol::parseOverride(s));
  return o;
}

int checkProtocol(const std::string& path, const std::vector<std::string>& sets) {
  try {
    const auto c = rigs::checkProtocol(path, overridesOf(sets));
    std::size_t given = 0, total = 0;
    for (const auto& row : c.settings.table()) {
      ++total;
      given += c.settings.given(row.key);
    }
    std::cout << path << ": a valid " << c.rig->name << " protocol (" << given << " keys set, "
              << total - given << " defaults)\n";
    return 0;
  } catch (const protocol::ProtocolError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
}

int listKeys(const std::string& rig) {
  try {
    const auto& r = rigs::findRig(rig, "rocklab keys");
    std::cout << "Keys of " << r.name << " protocols (" << r.doc << "):\n"
              << rigs::schemaOf(r).help() << "\n"
              << r.outputs().help();
    return 0;
  } catch (const protocol::ProtocolError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
}

// The files the settings name (path keys) that exist: the notebook keeps their hash and a copy.
std::vector<notebook::InputFile> inputsOf(const protocol::Settings& settings) {
  std::vector<notebook::InputFile> inputs;
  for (const auto& row : settings.table()) {
    if (row.unit != units::path.name) continue;
    const std::string path = settings.path(row.key);
    if (!path.empty() && std::filesystem::is_regular_file(path)) {
      inputs.push_back({row.key, std::filesystem::absolute(path).string()});
    }
  }
  return inputs;
}

RunOutcome runSettings(const rigs::RigEntry& rig, const protocol::Settings& settings,
                       const std::string& protocol_file, const std::string& lab, bool quiet) {
  notebook::Notebook nb(lab);
  notebook::RunInfo info;
  info.protocol = settings.text("protocol.name");
  info.protocol_file = std::filesystem::absolute(protocol_file).string();
  info.protocol_text = settings.effectiveText();
  info.rig = std::string(rig.name);
  info.code_version = kGitRevision;
  info.build_type = kBuildType;
  info.seed = settings.integer("protocol.seed");
  info.threads = static_cast<int>(settings.integer("numerics.threads"));
  info.inputs = inputsOf(settings);
  notebook::RunWriter writer(nb, info, settings.table());
  NotebookRecorder notebook_rec(writer);
  rigs::CheckedRecorder rec(notebook_rec, rig.outputs(), std::string(rig.name));

  g_signal.store(0);
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  rigs::RunControl control(!quiet && isatty(STDERR_FILENO), interruption);
  std::cerr << "run " << writer.id() << ": " << info.protocol << " (" << info.rig << ") -> " << lab
            << "\n";
  RunOutcome out{0, writer.id()};
  try {
    rig.run(settings, rec, control);
    control.done();
    writer.finish(notebook::RunStatus::Completed);
    std::cerr << "run " << writer.id() << " completed\n";
  } catch (const rigs::Interrupted& e) {
    control.done();
    writer.finish(notebook::RunStatus::Interrupted, e.what());
    std::cerr << "run " << writer.id() << " interrupted: " << e.what() << "\n";
    out.code = 130;
  } catch (const std::exception& e) {
    control.done();
    writer.finish(notebook::RunStatus::Failed, e.what());
    std::cerr << "run " << writer.id() << " failed: " << e.what() << "\n";
    out.code = 1;
  }
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  return out;
}

int runProtocol(const RunOptions& o) {
  // Everything about the protocol is checked before the notebook is touched: an invalid
  // protocol writes nothing.
  rigs::CheckedProtocol c{nullptr, {}};
  try {
    c = rigs::checkProtocol(o.protocol, overridesOf(o.sets));
  } catch (const protocol::ProtocolError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
  protocol::Settings settings = c.settings;
  if (o.threads > 0) settings.override("numerics.threads", static_cast<std::int64_t>(o.threads));
  return runSettings(*c.rig, settings, o.protocol, o.lab, o.quiet).code;
}

int rerunProtocol(std::int64_t run, const RunOptions& o) {
  if (!std::filesystem::exists(o.lab)) {
    std::cerr << "no lab notebook at '" << o.lab << "' (--lab PATH)\n";
    return 2;
  }
  std::string file, text, version;
  std::vector<protocol::Override> overrides = overridesOf(o.sets);
  {
    notebook::Notebook nb(o.lab);
    notebook::requireRun(nb, run);
    auto s =
        nb.db().prepare("SELECT protocol_file, protocol_text, code_version FROM runs WHERE id = ?");
    s.bind(1, run);
    s.step();
    file = s.text(0), text = s.text(1), version = s.text(2);
    // A file the run read that is gone or changed since: the notebook's copy stands in.
    auto in = nb.db().prepare("SELECT key, path, sha256, copy FROM inputs WHERE run_id = ?");
    in.bind(1, run);
    while (in.step()) {
      const std::string path = in.text(1);
      if (std::filesystem::is_regular_file(path) && notebook::fileSha256(path) == in.text(2)) {
        continue;
      }
      const std::string copy = std::filesystem::absolute(nb.resolve(in.text(3))).string();
      std::cerr << "rerun: " << path << " is gone or changed since run " << run
                << ": reading the notebook's copy " << copy << "\n";
      overrides.insert(overrides.begin(), {in.text(0), "\"" + copy + "\"", "rerun"});
    }
  }
  if (version != kGitRevision) {
    std::cerr << "warning: run " << run << " was made by rocklab " << version << ", this is "
              << kGitRevision << ": results may differ where the code changed\n";
  }
  rigs::CheckedProtocol c{nullptr, {}};
  try {
    c = rigs::checkProtocolText(file, text, overrides);
  } catch (const protocol::ProtocolError& e) {
    std::cerr << "run " << run << "'s protocol (" << file << "):\n" << e.what() << "\n";
    return 2;
  }
  protocol::Settings settings = c.settings;
  if (o.threads > 0) settings.override("numerics.threads", static_cast<std::int64_t>(o.threads));
  std::cerr << "rerun of run " << run << "\n";
  return runSettings(*c.rig, settings, file, o.lab, o.quiet).code;
}

int notebookCommand(const NotebookOptions& o) {
  if (!std::filesystem::exists(o.lab)) {
    std::cerr << "no lab notebook at '" << o.lab << "' (rocklab run creates it; --lab PATH)\n";
    return 2;
  }
  if (o.what == "sql") {
    notebook::printTable(std::cout, notebook::readOnlyQuery(o.lab, o.sql), o.csv);
    return 0;
  }
  notebook::Notebook nb(o.lab);
  if (o.what == "delete") return deleteRuns(nb, o.runs, o.yes);
  if (o.what == "runs") {
    notebook::printTable(std::cout, notebook::listRuns(nb), o.csv);
  } else if (o.what == "show") {
    auto sections = notebook::showRun(nb, o.run);
    // The protocol's key results first after the run's row: what the run was for.
    notebook::Table keys{{"key_result", "value", "unit"}, {}};
    for (const reports::KeyValue& k : reports::keyResults(reports::loadRun(nb, o.run))) {
      notebook::Cell name, value, unit;
      name.type = unit.type = notebook::Cell::Type::Text;
      name.text = k.name, unit.text = k.unit;
      if (k.value) value.type = notebook::Cell::Type::Real, value.real = *k.value;
      keys.rows.push_back({name, value, unit});
    }
    sections.insert(sections.begin() + 1, {"key results", keys});
    for (const auto& [title, table] : sections) {
      if (table.rows.empty() && title != "run") continue;
      if (!o.csv) std::cout << "== " << title << "\n";
      notebook::printTable(std::cout, table, o.csv);
      if (!o.csv) std::cout << "\n";
    }
  } else if (o.what == "series") {
    notebook::printTable(std::cout, notebook::seriesOf(nb, o.run, o.names), o.csv);
  } else if (o.what == "events") {
    notebook::printTable(std::cout, notebook::eventsOf(nb, o.run, o.kind), o.csv);
  }
  return 0;
}

}  // namespace rocklab::cli
