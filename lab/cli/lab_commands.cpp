#include "lab/cli/lab_commands.hpp"

#include <unistd.h>

#include <atomic>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <stdexcept>

#include "lab/cli/build_info.hpp"
#include "lab/core/simulation.hpp"
#include "lab/notebook/queries.hpp"
#include "reports/key_results.hpp"
#include "reports/run_data.hpp"
#include "rigs/common/checked_recorder.hpp"
#include "rigs/common/formed_samples.hpp"
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

void writeWhole(const std::string& path, const std::string& text) {
  const auto dir = std::filesystem::path(path).parent_path();
  if (!dir.empty()) std::filesystem::create_directories(dir);
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    out << text;
    if (!out) throw std::runtime_error("cannot write " + tmp);
  }
  std::filesystem::rename(tmp, path);
}

int checkProtocol(const std::string& path, const std::vector<std::string>& sets, bool print) {
  try {
    const auto c = rigs::checkProtocol(path, overridesOf(sets));
    for (const std::string& w : rigs::unusedKeys(c.settings)) std::cerr << "warning: " << w << "\n";
    if (print) {
      std::cout << c.settings.effectiveText();
      std::cerr << path << ": a valid " << c.rig->name << " protocol\n";
      return 0;
    }
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

namespace {

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

// The recorder of a resumed run: what the rig records while it replays what it had done is
// in the notebook already.
class SkippedWhileReplaying : public rigs::Recorder {
 public:
  SkippedWhileReplaying(rigs::Recorder& inner, const rigs::RunControl& control)
      : inner_(inner), control_(control) {}
  void series(std::string_view name, std::uint64_t step, double time, double value) override {
    if (!control_.replaying()) inner_.series(name, step, time, value);
  }
  void event(const rigs::EventRecord& e) override {
    if (!control_.replaying()) inner_.event(e);
  }
  void result(std::string_view name, double value, std::string_view unit) override {
    if (!control_.replaying()) inner_.result(name, value, unit);
  }
  void message(std::uint64_t step, double time, std::string_view level,
               std::string_view text) override {
    if (!control_.replaying()) inner_.message(step, time, level, text);
  }
  void stageTiming(std::string_view stage, double seconds, std::uint64_t calls) override {
    if (!control_.replaying()) inner_.stageTiming(stage, seconds, calls);
  }
  void snapshot(std::string_view stage, std::string_view label, const Frame& frame) override {
    if (!control_.replaying()) inner_.snapshot(stage, label, frame);
  }
  void wave(const rigs::WaveRecord& w) override {
    if (!control_.replaying()) inner_.wave(w);
  }

 private:
  rigs::Recorder& inner_;
  const rigs::RunControl& control_;
};

// The name of a run's formed sample (formation.reuse): its formation's keys, the files they
// name by their bytes (a sample file edited in place, or another one under the same name, is
// another sample), and this very build by its bytes (a dirty build keeps its revision's
// name: the formed samples outlive builds).
std::string formationKey(const protocol::Settings& settings) {
  std::string identity = rigs::formationIdentity(settings);
  for (const notebook::InputFile& f : inputsOf(settings)) {
    identity += f.key + " sha256 = " + notebook::fileSha256(f.path) + "\n";
  }
  static const std::string build = notebook::fileSha256("/proc/self/exe");
  return notebook::hashText(identity + "build sha256 = " + build);
}

rigs::Journal::Options journalOptions(const protocol::Settings& settings) {
  rigs::Journal::Options o;
  o.every_s = settings.real("output.checkpoint_every_s");
  o.protocol_hash = notebook::hashText(settings.identity());
  o.code_version = codeVersion();
  return o;
}

}  // namespace

RunOutcome runSettings(const rigs::RigEntry& rig, const protocol::Settings& settings,
                       const std::string& protocol_file, const std::string& lab, bool quiet,
                       std::int64_t resume_run, const std::string& formed_dir) {
  notebook::Notebook nb(lab);
  std::unique_ptr<notebook::RunWriter> writer;
  std::optional<rigs::Journal> journal;
  // The protocol as run (its text re-parsed to check it when keys were overridden): once.
  const std::string protocol_text = settings.effectiveText();
  rigs::Journal::Options jo = journalOptions(settings);
  if (resume_run > 0) {
    jo.dir = nb.runFilesDir(resume_run) + "/checkpoints";
    try {
      journal.emplace(rigs::Journal::resuming(jo));
    } catch (const std::runtime_error& e) {
      std::cerr << "run " << resume_run << " cannot resume: " << e.what() << "\n";
      return {2, resume_run};
    }
    writer = std::make_unique<notebook::RunWriter>(nb, resume_run, journal->resumeMark());
  } else {
    notebook::RunInfo info;
    info.protocol = settings.text("protocol.name");
    info.protocol_file = std::filesystem::absolute(protocol_file).string();
    info.protocol_text = protocol_text;
    info.protocol_hash = jo.protocol_hash;
    info.rig = std::string(rig.name);
    info.code_version = codeVersion();
    info.build_type = kBuildType;
    info.seed = settings.integer("protocol.seed");
    info.threads = static_cast<int>(settings.integer("numerics.threads"));
    info.inputs = inputsOf(settings);
    writer = std::make_unique<notebook::RunWriter>(nb, info, settings.table());
    jo.dir = nb.runFilesDir(writer->id()) + "/checkpoints";
    journal.emplace(jo);
  }
  journal->setMark([w = writer.get()] { return w->mark(); });

  g_signal.store(0);
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  rigs::RunControl control(!quiet && isatty(STDERR_FILENO), interruption);
  control.setJournal(&*journal);
  if (settings.flag("formation.reuse")) {
    control.setFormedSamples(
        {formed_dir.empty() ? rigs::formedSamplesDir(lab) : formed_dir, formationKey(settings)});
  }
  NotebookRecorder notebook_rec(*writer);
  SkippedWhileReplaying replay_rec(notebook_rec, control);
  rigs::CheckedRecorder rec(replay_rec, rig.outputs(), std::string(rig.name));
  const std::int64_t id = writer->id();
  if (resume_run > 0) {
    std::cerr << "run " << id << ": " << settings.text("protocol.name") << " (" << rig.name
              << ") resumes from " << journal->resumePoint() << " -> " << lab << "\n";
  } else {
    std::cerr << "run " << id << ": " << settings.text("protocol.name") << " (" << rig.name
              << ") -> " << lab << "\n";
  }
  RunOutcome out{0, id};
  auto checkpointTime = [&] {
    rec.stageTiming("checkpoints", journal->writeSeconds(), journal->writes());
  };
  try {
    for (const std::string& w : rigs::unusedKeys(settings)) rec.message(0, 0.0, "warning", w);
    rig.run(settings, rec, control);
    control.done();
    checkpointTime();
    writer->finish(notebook::RunStatus::Completed);
    journal->clear();  // a completed run has nothing to resume
    std::cerr << "run " << id << " completed\n";
  } catch (const rigs::Interrupted& e) {
    control.done();
    writer->finish(notebook::RunStatus::Interrupted, e.what());
    std::cerr << "run " << id << " interrupted: " << e.what() << " (rocklab resume " << id
              << " --lab " << lab << " continues it)\n";
    out.code = 130;
  } catch (const std::exception& e) {
    control.done();
    writer->finish(notebook::RunStatus::Failed, e.what());
    std::cerr << "run " << id << " failed: " << e.what() << "\n";
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
  if (o.threads > 0) settings.runChoice("numerics.threads", static_cast<std::int64_t>(o.threads));
  return runSettings(*c.rig, settings, o.protocol, o.lab, o.quiet).code;
}

namespace {

// What the notebook kept of a run to run it again or continue it.
struct StoredRun {
  std::string file, text, version, status, host, pid;
};

StoredRun storedRun(notebook::Notebook& nb, std::int64_t run) {
  notebook::requireRun(nb, run);
  auto s = nb.db().prepare(
      "SELECT protocol_file, protocol_text, code_version, status, host, pid FROM runs WHERE id = "
      "?");
  s.bind(1, run);
  s.step();
  return {s.text(0), s.text(1), s.text(2), s.text(3), s.text(4), s.text(5)};
}

// The stored protocol checked again, with the command's --threads; none after saying why.
std::optional<rigs::CheckedProtocol> recheck(std::int64_t run, const StoredRun& r,
                                             const std::vector<protocol::Override>& overrides,
                                             int threads) {
  try {
    rigs::CheckedProtocol c = rigs::checkProtocolText(r.file, r.text, overrides);
    if (threads > 0) c.settings.runChoice("numerics.threads", static_cast<std::int64_t>(threads));
    return c;
  } catch (const protocol::ProtocolError& e) {
    std::cerr << "run " << run << "'s protocol (" << r.file << "):\n" << e.what() << "\n";
    return std::nullopt;
  }
}

}  // namespace

int rerunProtocol(std::int64_t run, const RunOptions& o) {
  if (!std::filesystem::exists(o.lab)) {
    std::cerr << "no lab notebook at '" << o.lab << "' (--lab PATH)\n";
    return 2;
  }
  StoredRun r;
  std::vector<protocol::Override> overrides = overridesOf(o.sets);
  {
    notebook::Notebook nb(o.lab);
    r = storedRun(nb, run);
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
  if (r.version != codeVersion()) {
    std::cerr << "warning: run " << run << " was made by rocklab " << r.version << ", this is "
              << codeVersion() << ": results may differ where the code changed\n";
  }
  const auto c = recheck(run, r, overrides, o.threads);
  if (!c) return 2;
  std::cerr << "rerun of run " << run << "\n";
  return runSettings(*c->rig, c->settings, r.file, o.lab, o.quiet).code;
}

int resumeRun(std::int64_t run, const RunOptions& o) {
  if (!std::filesystem::exists(o.lab)) {
    std::cerr << "no lab notebook at '" << o.lab << "' (--lab PATH)\n";
    return 2;
  }
  StoredRun r;
  {
    notebook::Notebook nb(o.lab);  // a run left running by a dead process is failed from here
    r = storedRun(nb, run);
  }
  if (r.status == "completed") {
    std::cerr << "run " << run << " is completed: nothing to resume (rocklab rerun " << run
              << " runs it again)\n";
    return 2;
  }
  if (r.status == "running") {
    std::cerr << "run " << run << " is still running (pid " << r.pid << " on " << r.host << ")\n";
    return 2;
  }
  if (r.version != codeVersion()) {
    std::cerr << "run " << run << " cannot resume: it was made by rocklab " << r.version
              << ", this is " << codeVersion()
              << ": only the same code continues a run bit for bit\n";
    return 2;
  }
  const auto c = recheck(run, r, {}, o.threads);
  if (!c) return 2;
  return runSettings(*c->rig, c->settings, r.file, o.lab, o.quiet, run, o.formed_dir).code;
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
