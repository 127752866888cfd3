#include "lab/notebook/notebook.hpp"

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <tuple>

namespace rocklab::notebook {

namespace {

// A batch is written when it reaches this many rows or this age, so a run killed outright
// loses at most a few seconds of records.
constexpr std::size_t kBatchRows = 20000;
constexpr double kBatchSeconds = 2.0;

double monotonicSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string hostName() {
  char buf[256] = {};
  if (gethostname(buf, sizeof buf - 1) != 0) return "unknown";
  return buf;
}

}  // namespace

// FNV-1a, as text: the protocol's fingerprint.
std::string hashText(std::string_view s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  char out[17];
  std::snprintf(out, sizeof out, "%016llx", static_cast<unsigned long long>(h));
  return out;
}

namespace {

// The tables a run's records go to, in the order a mark lists them.
constexpr const char* kRecordTables[] = {"series",        "events",    "messages", "results",
                                         "stage_timings", "snapshots", "waves"};

}  // namespace

std::string utcNow() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

std::string_view toString(RunStatus s) {
  switch (s) {
    case RunStatus::Running:
      return "running";
    case RunStatus::Completed:
      return "completed";
    case RunStatus::Failed:
      return "failed";
    case RunStatus::Interrupted:
      return "interrupted";
  }
  return "failed";
}

const std::vector<std::string_view>& Notebook::migrations() {
  static const std::vector<std::string_view> m = {
      // 0 -> 1: runs and what they record.
      R"sql(
CREATE TABLE runs (
  id INTEGER PRIMARY KEY,
  protocol TEXT NOT NULL,
  protocol_file TEXT NOT NULL,
  protocol_text TEXT NOT NULL,
  protocol_hash TEXT NOT NULL,
  rig TEXT NOT NULL,
  status TEXT NOT NULL CHECK (status IN ('running', 'completed', 'failed', 'interrupted')),
  reason TEXT,
  started TEXT NOT NULL,
  finished TEXT,
  wall_seconds REAL,
  code_version TEXT NOT NULL,
  build_type TEXT NOT NULL,
  seed INTEGER,
  threads INTEGER,
  host TEXT NOT NULL,
  pid INTEGER NOT NULL
);
CREATE TABLE params (
  run_id INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  key TEXT NOT NULL,
  value TEXT NOT NULL,
  unit TEXT NOT NULL DEFAULT '',
  PRIMARY KEY (run_id, key)
);
CREATE TABLE series (
  run_id INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  name TEXT NOT NULL,
  step INTEGER NOT NULL,
  time_s REAL NOT NULL,
  value REAL
);
CREATE INDEX series_by_run ON series (run_id, name, step);
CREATE TABLE events (
  run_id INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  step INTEGER NOT NULL,
  time_s REAL NOT NULL,
  kind TEXT NOT NULL,
  mode TEXT,
  x REAL, y REAL, z REAL,
  particle_a INTEGER,
  particle_b INTEGER,
  granular TEXT,
  value REAL
);
CREATE INDEX events_by_run ON events (run_id, kind, step);
CREATE TABLE stage_timings (
  run_id INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  stage TEXT NOT NULL,
  seconds REAL NOT NULL,
  calls INTEGER NOT NULL,
  PRIMARY KEY (run_id, stage)
);
CREATE TABLE results (
  run_id INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  name TEXT NOT NULL,
  value REAL,
  unit TEXT NOT NULL DEFAULT '',
  PRIMARY KEY (run_id, name)
);
)sql",
      // 1 -> 2: warnings and notes a run makes (e.g. a test that was not quasi-static).
      R"sql(
CREATE TABLE messages (
  run_id INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  step INTEGER NOT NULL,
  time_s REAL NOT NULL,
  level TEXT NOT NULL CHECK (level IN ('info', 'warning')),
  text TEXT NOT NULL
);
CREATE INDEX messages_by_run ON messages (run_id, step);
)sql",
      // 2 -> 3: the protocol stage an event happened in.
      R"sql(
ALTER TABLE events ADD COLUMN stage TEXT;
)sql",
      // 3 -> 4: snapshot files (state frames, rendered images) of a run.
      R"sql(
CREATE TABLE snapshots (
  run_id INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  step INTEGER NOT NULL,
  time_s REAL NOT NULL,
  stage TEXT NOT NULL,
  label TEXT NOT NULL,
  kind TEXT NOT NULL,
  path TEXT NOT NULL
);
CREATE INDEX snapshots_by_run ON snapshots (run_id, step);
)sql",
      // 4 -> 5: ultrasonic measurements. Traces are BLOBs of little-endian float64 samples,
      // one every dt_s from the pulse's start (a window of thousands of steps per receiver).
      R"sql(
CREATE TABLE waves (
  id INTEGER PRIMARY KEY,
  run_id INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  step INTEGER NOT NULL,
  time_s REAL NOT NULL,
  stage TEXT NOT NULL,
  name TEXT NOT NULL,
  wave_type TEXT NOT NULL CHECK (wave_type IN ('P', 'S')),
  propagation_axis INTEGER NOT NULL,
  polarisation_axis INTEGER NOT NULL,
  frequency_hz REAL NOT NULL,
  amplitude_m_per_s REAL NOT NULL,
  dt_s REAL NOT NULL,
  velocity_xcorr_m_per_s REAL,
  velocity_first_break_m_per_s REAL,
  source BLOB NOT NULL
);
CREATE INDEX waves_by_run ON waves (run_id, step);
CREATE TABLE traces (
  wave_id INTEGER NOT NULL REFERENCES waves(id) ON DELETE CASCADE,
  receiver INTEGER NOT NULL,
  distance_m REAL NOT NULL,
  particles INTEGER NOT NULL,
  picked_samples INTEGER NOT NULL,
  samples BLOB NOT NULL,
  PRIMARY KEY (wave_id, receiver)
);
CREATE TABLE picks (
  wave_id INTEGER NOT NULL REFERENCES waves(id) ON DELETE CASCADE,
  receiver INTEGER NOT NULL,
  method TEXT NOT NULL CHECK (method IN ('xcorr', 'first_break')),
  time_s REAL NOT NULL,
  quality REAL,
  PRIMARY KEY (wave_id, receiver, method)
);
)sql",
      // 5 -> 6: the files a run read (sample files): name, hash and the copy kept.
      R"sql(
CREATE TABLE inputs (
  run_id INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  key TEXT NOT NULL,
  path TEXT NOT NULL,
  sha256 TEXT NOT NULL,
  bytes INTEGER NOT NULL,
  copy TEXT NOT NULL,
  PRIMARY KEY (run_id, key)
);
)sql",
      // 6 -> 7: runs known by a uuid wherever they are merged (run_origins says from where),
      // and campaigns: their points, the runs made for them, the ensembles' statistics.
      R"sql(
ALTER TABLE runs ADD COLUMN uuid TEXT;
UPDATE runs SET uuid = lower(hex(randomblob(16)));
CREATE UNIQUE INDEX runs_by_uuid ON runs (uuid);
CREATE TABLE run_origins (
  run_id INTEGER PRIMARY KEY REFERENCES runs(id) ON DELETE CASCADE,
  notebook TEXT NOT NULL,
  source_run INTEGER NOT NULL,
  scheduler TEXT NOT NULL,
  job_id TEXT,
  task_id INTEGER
);
CREATE TABLE campaigns (
  id INTEGER PRIMARY KEY,
  name TEXT NOT NULL UNIQUE,
  file TEXT NOT NULL,
  text TEXT NOT NULL,
  protocol TEXT NOT NULL,
  updated TEXT NOT NULL
);
CREATE TABLE campaign_points (
  campaign_id INTEGER NOT NULL REFERENCES campaigns(id) ON DELETE CASCADE,
  point INTEGER NOT NULL,
  seed INTEGER NOT NULL,
  settings TEXT NOT NULL,
  protocol_hash TEXT NOT NULL,
  run_id INTEGER REFERENCES runs(id) ON DELETE SET NULL,
  PRIMARY KEY (campaign_id, point, seed)
);
CREATE TABLE campaign_statistics (
  campaign_id INTEGER NOT NULL REFERENCES campaigns(id) ON DELETE CASCADE,
  point INTEGER NOT NULL,
  settings TEXT NOT NULL,
  name TEXT NOT NULL,
  unit TEXT NOT NULL,
  n INTEGER NOT NULL,
  mean REAL,
  std REAL,
  ci95_low REAL,
  ci95_high REAL,
  PRIMARY KEY (campaign_id, point, name)
);
)sql",
      // 7 -> 8: calibrations, each evaluation's parameters and targets (lab/calibration).
      R"sql(
CREATE TABLE calibrations (
  id INTEGER PRIMARY KEY,
  name TEXT NOT NULL UNIQUE,
  file TEXT NOT NULL,
  text TEXT NOT NULL,
  status TEXT NOT NULL,
  reason TEXT,
  best_evaluation INTEGER,
  material TEXT,
  updated TEXT NOT NULL
);
CREATE TABLE calibration_evaluations (
  calibration_id INTEGER NOT NULL REFERENCES calibrations(id) ON DELETE CASCADE,
  evaluation INTEGER NOT NULL,
  batch INTEGER NOT NULL,
  kind TEXT NOT NULL,
  status TEXT NOT NULL,
  misfit REAL,
  within_tolerance INTEGER,
  PRIMARY KEY (calibration_id, evaluation)
);
CREATE TABLE calibration_values (
  calibration_id INTEGER NOT NULL REFERENCES calibrations(id) ON DELETE CASCADE,
  evaluation INTEGER NOT NULL,
  role TEXT NOT NULL,
  name TEXT NOT NULL,
  value REAL,
  n INTEGER,
  std REAL,
  ci95_low REAL,
  ci95_high REAL,
  PRIMARY KEY (calibration_id, evaluation, role, name)
);
)sql",
  };
  return m;
}

Notebook::Notebook(const std::string& path)
    : db_(std::make_unique<Connection>(path, Access::Create)) {
  db_->exec("PRAGMA journal_mode = WAL");
  db_->exec("PRAGMA foreign_keys = ON");
  db_->exec("PRAGMA synchronous = NORMAL");
  migrate(kSchemaVersion);
  closeOrphanRuns();
}

std::string Notebook::runFilesDir(std::int64_t run) const {
  return path() + ".files/run-" + std::to_string(run);
}

std::string Notebook::resolve(const std::string& relative) const {
  return (std::filesystem::path(path()).parent_path() / relative).string();
}

void Notebook::deleteRun(std::int64_t run) {
  {
    auto s = db_->prepare("SELECT status, host, pid FROM runs WHERE id = ?");
    s.bind(1, run);
    if (!s.step()) {
      throw SqlError("no run " + std::to_string(run) + " in lab notebook '" + path() + "'");
    }
    if (s.text(0) == "running") {
      throw SqlError("run " + std::to_string(run) + " is still running (pid " + s.text(2) + " on " +
                     s.text(1) + "): stop it first");
    }
  }
  Transaction t(*db_);
  // Every other table's rows go with the run's (ON DELETE CASCADE, foreign_keys on).
  db_->prepare("DELETE FROM runs WHERE id = ?").bind(1, run).run();
  t.commit();
  std::filesystem::remove_all(runFilesDir(run));
}

void Notebook::createAtVersion(const std::string& path, int version) {
  Connection c(path, Access::Create);
  for (int v = 0; v < version; ++v) {
    c.exec(migrations()[v]);
    c.exec("PRAGMA user_version = " + std::to_string(v + 1));
  }
}

void Notebook::migrate(int to) {
  const int from = db_->userVersion();
  if (from > to) {
    throw SqlError("lab notebook '" + path() + "' has schema version " + std::to_string(from) +
                   ", newer than this rocklab knows (" + std::to_string(to) +
                   "): use a newer rocklab");
  }
  for (int v = from; v < to; ++v) {
    Transaction t(*db_);
    db_->exec(migrations()[v]);
    db_->exec("PRAGMA user_version = " + std::to_string(v + 1));
    t.commit();
  }
}

void Notebook::closeOrphanRuns() {
  const std::string host = hostName();
  std::vector<std::int64_t> orphans;
  {
    auto s = db_->prepare("SELECT id, pid FROM runs WHERE status = 'running' AND host = ?");
    s.bind(1, host);
    while (s.step()) {
      const auto pid = static_cast<pid_t>(s.integer(1));
      if (kill(pid, 0) != 0 && errno == ESRCH) orphans.push_back(s.integer(0));
    }
  }
  for (std::int64_t id : orphans) {
    auto u = db_->prepare(
        "UPDATE runs SET status = 'failed', reason = 'the process ended without closing the run "
        "(killed or crashed); data up to its last batch are kept' WHERE id = ?");
    u.bind(1, id).run();
  }
}

RunWriter::RunWriter(Notebook& nb, const RunInfo& info, const std::vector<ParamRow>& params)
    : nb_(nb), started_(monotonicSeconds()), last_flush_(started_) {
  Connection& db = nb_.db();
  Transaction t(db);
  auto s = db.prepare(
      "INSERT INTO runs (protocol, protocol_file, protocol_text, protocol_hash, rig, status, "
      "started, code_version, build_type, seed, threads, host, pid, uuid) "
      "VALUES (?, ?, ?, ?, ?, 'running', ?, ?, ?, ?, ?, ?, ?, lower(hex(randomblob(16))))");
  s.bind(1, info.protocol).bind(2, info.protocol_file).bind(3, info.protocol_text);
  s.bind(4, info.protocol_hash.empty() ? hashText(info.protocol_text) : info.protocol_hash);
  s.bind(5, info.rig).bind(6, utcNow());
  s.bind(7, info.code_version).bind(8, info.build_type).bind(9, info.seed);
  s.bind(10, info.threads).bind(11, hostName()).bind(12, static_cast<std::int64_t>(getpid()));
  s.run();
  id_ = db.lastInsertId();
  auto p = db.prepare("INSERT INTO params (run_id, key, value, unit) VALUES (?, ?, ?, ?)");
  for (const ParamRow& r : params)
    p.bind(1, id_).bind(2, r.key).bind(3, r.value).bind(4, r.unit).run();
  keepInputs(info.inputs);
  t.commit();
}

void RunWriter::keepInputs(const std::vector<InputFile>& inputs) {
  namespace fs = std::filesystem;
  auto s = nb_.db().prepare(
      "INSERT INTO inputs (run_id, key, path, sha256, bytes, copy) VALUES (?, ?, ?, ?, ?, ?)");
  for (const InputFile& in : inputs) {
    // The copy makes the notebook enough to rerun the run, whatever becomes of the file.
    const fs::path dir = fs::path(nb_.runFilesDir(id_)) / "inputs";
    fs::create_directories(dir);
    const fs::path copy = dir / fs::path(in.path).filename();
    fs::copy_file(in.path, copy, fs::copy_options::overwrite_existing);
    const std::string relative =
        fs::relative(fs::absolute(copy), fs::absolute(nb_.path()).parent_path()).string();
    s.bind(1, id_).bind(2, in.key).bind(3, in.path).bind(4, fileSha256(in.path));
    s.bind(5, static_cast<std::int64_t>(fs::file_size(in.path))).bind(6, relative).run();
  }
}

RunWriter::RunWriter(Notebook& nb, std::int64_t run, const std::string& mark)
    : nb_(nb), id_(run), started_(monotonicSeconds()), last_flush_(started_) {
  Connection& db = nb_.db();
  Transaction t(db);
  // What the run recorded after the checkpoint it resumes from goes: it is recorded again.
  std::istringstream in(mark);
  for (std::string item; in >> item;) {
    const auto colon = item.find(':');
    const std::string table = item.substr(0, colon);
    bool known = false;
    for (const char* k : kRecordTables) known = known || table == k;
    if (!known || colon == std::string::npos) {
      throw SqlError("a checkpoint's notebook mark names no record table: '" + item + "'");
    }
    db.prepare("DELETE FROM " + table + " WHERE run_id = ? AND rowid > ?")
        .bind(1, run)
        .bind(2, static_cast<std::int64_t>(std::stoll(item.substr(colon + 1))))
        .run();
  }
  auto s = db.prepare(
      "UPDATE runs SET status = 'running', reason = NULL, finished = NULL, host = ?, pid = ? "
      "WHERE id = ?");
  s.bind(1, hostName()).bind(2, static_cast<std::int64_t>(getpid())).bind(3, run).run();
  auto w = db.prepare("SELECT coalesce(wall_seconds, 0) FROM runs WHERE id = ?");
  w.bind(1, run);
  if (w.step()) started_ -= w.real(0);  // the wall time counts both parts
  t.commit();
}

std::string RunWriter::mark() {
  flush();
  std::string m;
  for (const char* table : kRecordTables) {
    auto s = nb_.db().prepare(std::string("SELECT coalesce(max(rowid), 0) FROM ") + table +
                              " WHERE run_id = ?");
    s.bind(1, id_);
    s.step();
    if (!m.empty()) m += ' ';
    m.append(table).append(":").append(std::to_string(s.integer(0)));
  }
  return m;
}

RunWriter::~RunWriter() {
  if (finished_) return;
  try {
    finish(RunStatus::Failed, "the run ended without being closed");
  } catch (...) {
  }
}

void RunWriter::snapshot(std::string_view kind, std::string_view stage, std::string_view label,
                         std::uint64_t step, double time, const std::string& bytes,
                         std::string_view extension) {
  namespace fs = std::filesystem;
  const fs::path dir = nb_.runFilesDir(id_);
  fs::create_directories(dir);
  const std::string name =
      std::string(stage) + "-" + std::to_string(step) + "." + std::string(extension);
  const fs::path file = dir / name;
  {
    std::ofstream out(file.string() + ".partial", std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out) throw SqlError("cannot write '" + file.string() + "'");
  }
  fs::rename(file.string() + ".partial", file);
  const std::string relative =
      fs::relative(fs::absolute(file), fs::absolute(nb_.path()).parent_path()).string();
  auto s = nb_.db().prepare(
      "INSERT INTO snapshots (run_id, step, time_s, stage, label, kind, path) "
      "VALUES (?, ?, ?, ?, ?, ?, ?)");
  s.bind(1, id_).bind(2, step).bind(3, time).bind(4, stage).bind(5, label).bind(6, kind);
  s.bind(7, relative).run();
}

std::int64_t RunWriter::wave(const WaveRecord& w) {
  auto& db = nb_.db();
  Transaction tx(db);
  auto ws = db.prepare(
      "INSERT INTO waves (run_id, step, time_s, stage, name, wave_type, propagation_axis, "
      "polarisation_axis, frequency_hz, amplitude_m_per_s, dt_s, velocity_xcorr_m_per_s, "
      "velocity_first_break_m_per_s, source) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  ws.bind(1, id_).bind(2, w.step).bind(3, w.time).bind(4, w.stage).bind(5, w.name);
  ws.bind(6, w.type).bind(7, w.propagation_axis).bind(8, w.polarisation_axis);
  ws.bind(9, w.frequency).bind(10, w.amplitude).bind(11, w.dt).bind(12, w.velocity_xcorr);
  ws.bind(13, w.velocity_first_break).bindDoubles(14, w.source).run();
  const std::int64_t wave_id = db.lastInsertId();
  auto ts = db.prepare(
      "INSERT INTO traces (wave_id, receiver, distance_m, particles, picked_samples, samples) "
      "VALUES (?, ?, ?, ?, ?, ?)");
  auto ps = db.prepare(
      "INSERT INTO picks (wave_id, receiver, method, time_s, quality) VALUES (?, ?, ?, ?, ?)");
  for (std::size_t r = 0; r < w.receivers.size(); ++r) {
    const WaveRecord::Receiver& x = w.receivers[r];
    const auto index = static_cast<std::int64_t>(r);
    ts.bind(1, wave_id).bind(2, index).bind(3, x.distance).bind(4, x.particles);
    ts.bind(5, x.picked_samples).bindDoubles(6, x.samples).run();
    if (x.xcorr_time) {
      ps.bind(1, wave_id).bind(2, index).bind(3, "xcorr").bind(4, *x.xcorr_time);
      ps.bind(5, x.xcorr_quality).run();
    }
    if (x.first_break_time) {
      ps.bind(1, wave_id).bind(2, index).bind(3, "first_break").bind(4, *x.first_break_time);
      ps.bindNull(5).run();
    }
  }
  tx.commit();
  return wave_id;
}

void RunWriter::flushIfDue() {
  if (series_.size() + events_.size() >= kBatchRows ||
      monotonicSeconds() - last_flush_ > kBatchSeconds) {
    flush();
  }
}

void RunWriter::series(std::string_view name, std::uint64_t step, double time, double value) {
  series_.push_back({std::string(name), step, time, value});
  flushIfDue();
}

void RunWriter::event(const EventRecord& e) {
  events_.push_back(e);
  flushIfDue();
}

void RunWriter::message(std::uint64_t step, double time, std::string_view level,
                        std::string_view text) {
  messages_.push_back({step, time, std::string(level), std::string(text)});
}

void RunWriter::result(std::string_view name, double value, std::string_view unit) {
  results_.push_back({std::string(name), value, std::string(unit)});
}

void RunWriter::stageTiming(std::string_view stage, double seconds, std::uint64_t calls) {
  timings_.emplace_back(std::string(stage), seconds, calls);
}

void RunWriter::flush() {
  if (series_.empty() && events_.empty() && messages_.empty() && results_.empty() &&
      timings_.empty()) {
    return;
  }
  last_flush_ = monotonicSeconds();
  Connection& db = nb_.db();
  Transaction t(db);
  {
    auto s =
        db.prepare("INSERT INTO series (run_id, name, step, time_s, value) VALUES (?, ?, ?, ?, ?)");
    for (const Series& r : series_) {
      s.bind(1, id_).bind(2, r.name).bind(3, r.step).bind(4, r.time).bind(5, r.value).run();
    }
  }
  {
    auto s = db.prepare(
        "INSERT INTO events (run_id, step, time_s, kind, mode, x, y, z, particle_a, particle_b, "
        "granular, value, stage) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
    for (const EventRecord& e : events_) {
      s.bind(1, id_).bind(2, e.step).bind(3, e.time).bind(4, e.kind).bind(5, e.mode);
      s.bind(6, e.x).bind(7, e.y).bind(8, e.z).bind(9, e.particle_a).bind(10, e.particle_b);
      s.bind(11, e.granular).bind(12, e.value).bind(13, e.stage).run();
    }
  }
  {
    auto s = db.prepare(
        "INSERT INTO messages (run_id, step, time_s, level, text) VALUES (?, ?, ?, ?, ?)");
    for (const Message& m : messages_) {
      s.bind(1, id_).bind(2, m.step).bind(3, m.time).bind(4, m.level).bind(5, m.text).run();
    }
  }
  {
    auto s = db.prepare(
        "INSERT OR REPLACE INTO results (run_id, name, value, unit) VALUES (?, ?, ?, ?)");
    for (const Result& r : results_) {
      s.bind(1, id_).bind(2, r.name).bind(3, r.value).bind(4, r.unit).run();
    }
  }
  {
    auto s = db.prepare(
        "INSERT OR REPLACE INTO stage_timings (run_id, stage, seconds, calls) VALUES (?, ?, ?, ?)");
    for (const auto& [stage, seconds, calls] : timings_) {
      s.bind(1, id_).bind(2, stage).bind(3, seconds).bind(4, calls).run();
    }
  }
  t.commit();
  series_.clear();
  events_.clear();
  messages_.clear();
  results_.clear();
  timings_.clear();
}

void RunWriter::finish(RunStatus status, std::string_view reason) {
  if (finished_) return;
  flush();
  auto s = nb_.db().prepare(
      "UPDATE runs SET status = ?, reason = ?, finished = ?, wall_seconds = ? WHERE id = ?");
  s.bind(1, toString(status));
  if (reason.empty()) {
    s.bindNull(2);
  } else {
    s.bind(2, reason);
  }
  s.bind(3, utcNow()).bind(4, monotonicSeconds() - started_).bind(5, id_).run();
  finished_ = true;
}

}  // namespace rocklab::notebook
