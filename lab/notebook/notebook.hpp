#pragma once
// The lab notebook: one SQLite database per lab holding every run, its parameters, time
// series, events, stage timings and key results (the records of records.hpp). The schema
// (lab/notebook/README.md) carries its version in PRAGMA user_version and is migrated
// forward on open. WAL journal, foreign keys on, writes batched in transactions.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "lab/notebook/records.hpp"
#include "lab/notebook/sqlite.hpp"

namespace rocklab::notebook {

inline constexpr int kSchemaVersion = 8;

// Opens a lab notebook, creating it if needed, and brings its schema up to date. Runs a
// previous process left `running` on this host and that process is gone are marked failed.
class Notebook {
 public:
  explicit Notebook(const std::string& path);
  Connection& db() { return *db_; }
  const std::string& path() const { return db_->path(); }
  // Files of a run (snapshots, images) live beside the notebook, in <notebook>.files/run-N;
  // the notebook records them by paths relative to its own directory.
  std::string runFilesDir(std::int64_t run) const;
  std::string resolve(const std::string& relative) const;
  // Removes a run: its rows in every table and its files. Refuses a run still running.
  void deleteRun(std::int64_t run);
  // The schema migrations, in order; [k] takes version k to k + 1.
  static const std::vector<std::string_view>& migrations();
  // For tests: open a database and migrate it only up to `version`.
  static void createAtVersion(const std::string& path, int version);

 private:
  void migrate(int to);
  void closeOrphanRuns();
  std::unique_ptr<Connection> db_;
};

enum class RunStatus { Running, Completed, Failed, Interrupted };
std::string_view toString(RunStatus s);

// FNV-1a of a text, as 16 hex digits: a protocol's fingerprint (runs.protocol_hash).
std::string hashText(std::string_view s);

// The SHA-256 of a file's bytes, in hex (what `sha256sum` prints).
std::string fileSha256(const std::string& path);

// A file a run reads (a sample file): the notebook keeps its hash and a copy.
struct InputFile {
  std::string key;   // the protocol key naming it, e.g. sample.file
  std::string path;  // as resolved when the run started
};

struct RunInfo {
  std::string protocol;       // protocol name
  std::string protocol_file;  // path it was read from
  std::string protocol_text;  // the whole file
  std::string protocol_hash;  // of its settings (protocol::Settings::identity); "": of the text
  std::string rig;
  std::string code_version;  // git revision
  std::string build_type;
  std::int64_t seed = 0;
  int threads = 1;
  std::vector<InputFile> inputs;
};

// Records one run. Rows are buffered and written in batched transactions (flush() or
// automatically past a batch size); finish() writes the rest and closes the run with its
// status. A writer destroyed without finish() marks the run failed.
class RunWriter {
 public:
  RunWriter(Notebook& nb, const RunInfo& info, const std::vector<ParamRow>& params);
  // Continues run `run` (rocklab resume): its records after `mark` (what mark() returned at
  // the checkpoint resumed from) are removed, its status is running again.
  RunWriter(Notebook& nb, std::int64_t run, const std::string& mark);
  ~RunWriter();
  RunWriter(const RunWriter&) = delete;
  RunWriter& operator=(const RunWriter&) = delete;

  std::int64_t id() const { return id_; }
  void series(std::string_view name, std::uint64_t step, double time, double value);
  void event(const EventRecord& e);
  void message(std::uint64_t step, double time, std::string_view level, std::string_view text);
  void result(std::string_view name, double value, std::string_view unit);
  void stageTiming(std::string_view stage, double seconds, std::uint64_t calls);
  // Writes a wave with its traces and picks at once (one transaction); returns its id.
  std::int64_t wave(const WaveRecord& w);
  // Writes a file of the run (a state frame, kind "frame") and records it in `snapshots`.
  void snapshot(std::string_view kind, std::string_view stage, std::string_view label,
                std::uint64_t step, double time, const std::string& bytes,
                std::string_view extension);
  void flush();
  // Writes everything buffered and returns how far the run's records go in each table.
  std::string mark();
  void finish(RunStatus status, std::string_view reason = {});

 private:
  struct Series {
    std::string name;
    std::uint64_t step;
    double time, value;
  };
  struct Message {
    std::uint64_t step;
    double time;
    std::string level, text;
  };
  Notebook& nb_;
  std::int64_t id_ = 0;
  std::vector<Series> series_;
  std::vector<EventRecord> events_;
  std::vector<Message> messages_;
  struct Result {
    std::string name;
    double value;
    std::string unit;
  };
  std::vector<Result> results_;
  std::vector<std::tuple<std::string, double, std::uint64_t>> timings_;
  double started_ = 0.0;
  double last_flush_ = 0.0;
  bool finished_ = false;
  void flushIfDue();
  void keepInputs(const std::vector<InputFile>& inputs);
};

// Current UTC time as ISO 8601 text.
std::string utcNow();

}  // namespace rocklab::notebook
