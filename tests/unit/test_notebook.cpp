// The lab notebook: schema and migrations, batched writing, run status on every ending,
// queries and CSV.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "lab/notebook/merge.hpp"
#include "lab/notebook/queries.hpp"

namespace rocklab::notebook {
namespace {

class NotebookTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = (std::filesystem::temp_directory_path() /
             ("rocklab-nb-" + std::to_string(::getpid()) + "-" +
              ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".sqlite"))
                .string();
    std::filesystem::remove(path_);
  }
  void TearDown() override {
    for (const char* ext : {"", "-wal", "-shm"}) std::filesystem::remove(path_ + ext);
  }
  RunInfo info() {
    RunInfo i;
    i.protocol = "oedometer-quick";
    i.protocol_file = "protocols/oedometer-quick.toml";
    i.protocol_text = "[protocol]\nname = \"oedometer-quick\"\n";
    i.rig = "oedometer";
    i.code_version = "abc123";
    i.build_type = "Release";
    i.seed = 7;
    return i;
  }
  std::string scalar(Notebook& nb, const std::string& sql) {
    const Table t = query(nb, sql);
    return t.rows.empty() ? "" : t.rows[0][0].str();
  }
  std::string path_;
};

TEST_F(NotebookTest, NewNotebookHasTheSchemaWalAndForeignKeys) {
  Notebook nb(path_);
  EXPECT_EQ(nb.db().userVersion(), kSchemaVersion);
  EXPECT_EQ(scalar(nb, "PRAGMA journal_mode"), "wal");
  EXPECT_EQ(scalar(nb, "PRAGMA foreign_keys"), "1");
  for (const char* t : {"runs", "params", "series", "events", "stage_timings", "results",
                        "messages", "snapshots"}) {
    EXPECT_EQ(
        scalar(nb, std::string("SELECT count(*) FROM sqlite_master WHERE name = '") + t + "'"), "1")
        << t;
  }
}

TEST_F(NotebookTest, RecordsARunAndClosesIt) {
  Notebook nb(path_);
  std::int64_t id;
  {
    RunWriter w(nb, info(), {{"loading.axial_strain_rate_per_s", "0.5", "1/s"}});
    id = w.id();
    EXPECT_EQ(scalar(nb, "SELECT status FROM runs WHERE id = " + std::to_string(id)), "running");
    for (int k = 0; k < 10; ++k) w.series("axial_stress_MPa", k * 100, k * 1e-3, 2.0 * k);
    EventRecord e;
    e.kind = "bond_break";
    e.mode = "tensile";
    e.x = 1e-3;
    e.granular = "inter";
    w.event(e);
    w.result("broken_bonds_total", 1, "");
    w.stageTiming("contacts", 1.5, 1000);
    w.message(5, 0.1, "warning", "not quasi-static");
    w.finish(RunStatus::Completed);
  }
  const std::string where = " WHERE run_id = " + std::to_string(id);
  EXPECT_EQ(scalar(nb, "SELECT status FROM runs WHERE id = " + std::to_string(id)), "completed");
  EXPECT_EQ(scalar(nb, "SELECT count(*) FROM series" + where), "10");
  EXPECT_EQ(scalar(nb, "SELECT value FROM series" + where + " AND step = 900"), "18");
  EXPECT_EQ(scalar(nb, "SELECT mode FROM events" + where), "tensile");
  EXPECT_EQ(scalar(nb, "SELECT unit FROM params" + where), "1/s");
  EXPECT_EQ(scalar(nb, "SELECT value FROM results" + where), "1");
  EXPECT_EQ(scalar(nb, "SELECT calls FROM stage_timings" + where), "1000");
  EXPECT_EQ(scalar(nb, "SELECT level FROM messages" + where), "warning");
  EXPECT_NE(scalar(nb, "SELECT protocol_hash FROM runs"), "");
  EXPECT_NE(scalar(nb, "SELECT finished FROM runs"), "");
  // Deleting a run takes its records with it (foreign keys).
  nb.db().exec("DELETE FROM runs");
  EXPECT_EQ(scalar(nb, "SELECT count(*) FROM series"), "0");
}

TEST_F(NotebookTest, SnapshotFilesLiveBesideTheNotebookAndAreRecorded) {
  Notebook nb(path_);
  RunWriter w(nb, info(), {});
  w.snapshot("frame", "loading", "final", 1234, 0.5, std::string("abc\0def", 7), "rkf");
  w.finish(RunStatus::Completed);
  const std::string rel = scalar(nb, "SELECT path FROM snapshots");
  EXPECT_EQ(rel,
            std::filesystem::path(path_).filename().string() + ".files/run-1/loading-1234.rkf");
  std::ifstream in(nb.resolve(rel), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(bytes, std::string("abc\0def", 7));
  EXPECT_EQ(scalar(nb, "SELECT label || ' ' || kind || ' ' || stage FROM snapshots"),
            "final frame loading");
  std::filesystem::remove_all(nb.runFilesDir(1));
}

TEST_F(NotebookTest, WavesKeepTheirTracesAndPicksSampleForSample) {
  Notebook nb(path_);
  RunWriter w(nb, info(), {});
  WaveRecord row;
  row.step = 77, row.time = 1e-3, row.stage = "stage 2", row.name = "szx", row.type = "S";
  row.propagation_axis = 2, row.polarisation_axis = 0;
  row.frequency = 2e5, row.amplitude = 1e-3, row.dt = 1e-8;
  row.velocity_xcorr = 812.5;  // no first-break velocity: stored as NULL
  row.source = {0.0, 0.5, -0.25, 1.0 / 3.0};
  for (int r = 0; r < 3; ++r) {
    WaveRecord::Receiver x;
    x.distance = 1e-3 * (r + 1), x.particles = 10 + r, x.picked_samples = 2 + r;
    x.samples = {0.1 * r, -1e-300, 3.0e10, 0.0, 7.0};
    if (r != 1) x.xcorr_time = 1e-6 * r, x.xcorr_quality = 0.9;
    x.first_break_time = 5e-7 * r;
    row.receivers.push_back(x);
  }
  const std::int64_t id = w.wave(row);
  w.finish(RunStatus::Completed);
  EXPECT_EQ(id, 1);
  EXPECT_EQ(scalar(nb, "SELECT count(*) FROM picks"), "5");
  EXPECT_EQ(scalar(nb, "SELECT samples FROM traces LIMIT 1"), "<40 bytes>");
  const std::vector<WaveRecord> back = wavesOf(nb, 1);
  ASSERT_EQ(back.size(), 1u);
  const WaveRecord& b = back[0];
  EXPECT_EQ(b.step, 77u);
  EXPECT_EQ(b.stage + b.name + b.type, "stage 2szxS");
  EXPECT_EQ(b.propagation_axis, 2);
  EXPECT_EQ(b.velocity_xcorr, row.velocity_xcorr);
  EXPECT_FALSE(b.velocity_first_break);
  EXPECT_EQ(b.source, row.source);  // bit for bit
  ASSERT_EQ(b.receivers.size(), 3u);
  for (int r = 0; r < 3; ++r) {
    EXPECT_EQ(b.receivers[r].samples, row.receivers[r].samples);
    EXPECT_EQ(b.receivers[r].picked_samples, 2 + r);
    EXPECT_EQ(b.receivers[r].xcorr_time, row.receivers[r].xcorr_time);
    EXPECT_EQ(b.receivers[r].first_break_time, row.receivers[r].first_break_time);
  }
  // Deleting the run takes its waves, traces and picks with it.
  nb.db().exec("DELETE FROM runs");
  EXPECT_EQ(scalar(nb,
                   "SELECT (SELECT count(*) FROM waves) + (SELECT count(*) FROM traces) + "
                   "(SELECT count(*) FROM picks)"),
            "0");
}

TEST_F(NotebookTest, AWriterLeftOpenMarksTheRunFailedAndKeepsItsData) {
  Notebook nb(path_);
  {
    RunWriter w(nb, info(), {});
    w.series("x", 1, 0.0, 1.0);
  }  // as when an exception unwinds the run
  EXPECT_EQ(scalar(nb, "SELECT status FROM runs"), "failed");
  EXPECT_NE(scalar(nb, "SELECT reason FROM runs"), "");
  EXPECT_EQ(scalar(nb, "SELECT count(*) FROM series"), "1");
}

TEST_F(NotebookTest, InterruptedRunsSayWhy) {
  Notebook nb(path_);
  RunWriter w(nb, info(), {});
  w.finish(RunStatus::Interrupted, "SIGTERM received");
  EXPECT_EQ(scalar(nb, "SELECT status || ': ' || reason FROM runs"),
            "interrupted: SIGTERM received");
}

TEST_F(NotebookTest, LargeRunsAreWrittenInBatchesWhileRunning) {
  Notebook nb(path_);
  RunWriter w(nb, info(), {});
  for (int k = 0; k < 50000; ++k) w.series("s", k, k, k);
  // A second connection, as another process would, already sees the committed batches
  // (every 20,000 rows; more if a batch also came of age, as under sanitizers).
  Notebook other(path_);
  EXPECT_GE(std::stoi(scalar(other, "SELECT count(*) FROM series")), 40000);
  w.finish(RunStatus::Completed);
  EXPECT_EQ(scalar(other, "SELECT count(*) FROM series"), "50000");
}

TEST_F(NotebookTest, OldSchemaIsMigratedAndNewerRefused) {
  Notebook::createAtVersion(path_, 1);
  {
    Connection c(path_, Access::ReadWrite);
    c.exec(
        "INSERT INTO runs (protocol, protocol_file, protocol_text, protocol_hash, rig, status, "
        "started, code_version, build_type, host, pid) VALUES ('p', 'f', 't', 'h', 'oedometer', "
        "'completed', 'now', 'v', 'Release', 'h', 1)");
  }
  {
    Notebook nb(path_);
    EXPECT_EQ(nb.db().userVersion(), kSchemaVersion);
    EXPECT_EQ(scalar(nb, "SELECT protocol FROM runs"), "p");
    EXPECT_EQ(scalar(nb, "SELECT count(*) FROM messages"), "0");
    EXPECT_EQ(scalar(nb, "SELECT count(*) FROM events WHERE stage IS NULL"), "0");
  }
  {
    Connection c(path_, Access::ReadWrite);
    c.exec("PRAGMA user_version = 99");
  }
  try {
    Notebook nb(path_);
    FAIL();
  } catch (const SqlError& e) {
    EXPECT_NE(std::string(e.what()).find("newer"), std::string::npos) << e.what();
  }
}

TEST_F(NotebookTest, RunsOfDeadProcessesAreMarkedFailedOnOpen) {
  {
    Notebook nb(path_);
    char host[256] = {};
    gethostname(host, sizeof host - 1);
    auto s = nb.db().prepare(
        "INSERT INTO runs (protocol, protocol_file, protocol_text, protocol_hash, rig, status, "
        "started, code_version, build_type, host, pid) VALUES ('p', 'f', 't', 'h', 'oedometer', "
        "'running', 'now', 'v', 'Release', ?, 2147483646)");
    s.bind(1, std::string(host)).run();
  }
  Notebook nb(path_);
  EXPECT_EQ(scalar(nb, "SELECT status FROM runs"), "failed");
}

TEST_F(NotebookTest, TablesPrintAlignedAndAsCsv) {
  Notebook nb(path_);
  Table t = query(nb, "SELECT 1 AS a, 'x, \"y\"' AS b, 2.5 AS c, NULL AS d");
  std::ostringstream csv, text;
  printTable(csv, t, true);
  printTable(text, t, false);
  EXPECT_EQ(csv.str(), "a,b,c,d\n1,\"x, \"\"y\"\"\",2.5,\n");
  EXPECT_NE(text.str().find("a  b"), std::string::npos) << text.str();
  EXPECT_THROW(showRun(nb, 42), SqlError);
}

// A finished run with a row in every table that hangs off runs, and a file beside the lab.
std::int64_t recordFullRun(Notebook& nb, const RunInfo& info) {
  RunWriter w(nb, info, {{"protocol.seed", "7", ""}});
  w.series("axial_stress_MPa", 0, 0.0, 1.0);
  EventRecord e;
  e.kind = "bond_break";
  w.event(e);
  w.result("peak", 1, "MPa");
  w.stageTiming("contacts", 1.0, 1);
  w.message(0, 0.0, "info", "hello");
  w.snapshot("frame", "loading", "final", 1, 0.1, "bytes", "rkf");
  w.finish(RunStatus::Completed);
  return w.id();
}

TEST_F(NotebookTest, TypedSqlIsReadOnly) {
  std::int64_t id;
  {
    Notebook nb(path_);
    id = recordFullRun(nb, info());
  }
  EXPECT_EQ(readOnlyQuery(path_, "SELECT count(*) FROM runs").rows[0][0].str(), "1");
  EXPECT_FALSE(readOnlyQuery(path_, "PRAGMA table_info(runs)").rows.empty());
  EXPECT_EQ(readOnlyQuery(path_, "PRAGMA user_version").rows[0][0].str(),
            std::to_string(kSchemaVersion));
  const std::string other = path_ + ".other";
  for (const std::string& sql :
       {std::string("DROP TABLE runs"), std::string("DELETE FROM series"),
        std::string("UPDATE runs SET status = 'failed'"),
        std::string("INSERT INTO runs (id) VALUES (9)"), "ATTACH DATABASE '" + other + "' AS o",
        std::string("PRAGMA user_version = 3"), std::string("PRAGMA journal_mode = DELETE"),
        std::string("VACUUM"), std::string("SELECT 1; DROP TABLE runs"),
        std::string("CREATE TABLE t (x)")}) {
    try {
      readOnlyQuery(path_, sql);
      ADD_FAILURE() << "not refused: " << sql;
    } catch (const SqlError& e) {
      const std::string why = e.what();
      EXPECT_TRUE(why.find("read-only") != std::string::npos ||
                  why.find("one statement at a time") != std::string::npos)
          << sql << ": " << why;
    }
  }
  EXPECT_FALSE(std::filesystem::exists(other));
  Notebook nb(path_);
  EXPECT_EQ(nb.db().userVersion(), kSchemaVersion);
  EXPECT_EQ(scalar(nb, "PRAGMA journal_mode"), "wal");
  EXPECT_EQ(scalar(nb, "SELECT status FROM runs WHERE id = " + std::to_string(id)), "completed");
  EXPECT_EQ(scalar(nb, "SELECT count(*) FROM series"), "1");
}

TEST_F(NotebookTest, DeletingARunRemovesItsRowsAndFiles) {
  Notebook nb(path_);
  const std::int64_t gone = recordFullRun(nb, info());
  const std::int64_t kept = recordFullRun(nb, info());
  ASSERT_TRUE(std::filesystem::exists(nb.runFilesDir(gone)));
  nb.deleteRun(gone);
  EXPECT_FALSE(std::filesystem::exists(nb.runFilesDir(gone)));
  EXPECT_TRUE(std::filesystem::exists(nb.runFilesDir(kept)));
  for (const char* table :
       {"params", "series", "events", "results", "stage_timings", "messages", "snapshots"}) {
    EXPECT_EQ(scalar(nb, std::string("SELECT count(*) FROM ") + table +
                             " WHERE run_id = " + std::to_string(gone)),
              "0")
        << table;
    EXPECT_EQ(scalar(nb, std::string("SELECT count(*) FROM ") + table +
                             " WHERE run_id = " + std::to_string(kept)),
              "1")
        << table;
  }
  EXPECT_THROW(nb.deleteRun(gone), SqlError);
  RunWriter live(nb, info(), {});
  EXPECT_THROW(nb.deleteRun(live.id()), SqlError);
  std::filesystem::remove_all(path_ + ".files");
}

// A merge copies every row of every run, and its files, under new ids (the waves' traces and
// picks with their waves), keeps where they came from, and copies nothing the second time.
TEST_F(NotebookTest, MergingCopiesEveryRunOnceWithItsFilesAndOrigin) {
  namespace fs = std::filesystem;
  const std::string shard = path_ + ".shard.sqlite";
  {
    Notebook s(shard);
    recordFullRun(s, info());
    RunWriter w(s, info(), {});
    WaveRecord wave;
    wave.stage = "stage 1";
    wave.name = "pz";
    wave.type = "P";
    wave.source = {0.0, 1.0};
    WaveRecord::Receiver r;
    r.distance = 0.01;
    r.samples = {0.5, 0.25};
    r.xcorr_time = 1e-5;
    r.xcorr_quality = 0.9;
    wave.receivers.push_back(r);
    w.wave(wave);
    w.finish(RunStatus::Failed, "unstable");
  }
  Notebook nb(path_);
  recordFullRun(nb, info());  // the lab has a run of its own: the merged ones get new ids
  const MergeOutcome m = mergeNotebook(nb, shard, {"slurm", "812", 3});
  ASSERT_EQ(m.runs.size(), 2u);
  EXPECT_EQ(m.runs[0], 2);
  EXPECT_EQ(m.source_runs[1], 2);
  EXPECT_EQ(scalar(nb, "SELECT count(*) FROM runs"), "3");
  for (const char* table :
       {"params", "series", "events", "results", "stage_timings", "messages", "snapshots"}) {
    EXPECT_EQ(scalar(nb, std::string("SELECT count(*) FROM ") + table + " WHERE run_id = 2"), "1")
        << table;
  }
  EXPECT_EQ(scalar(nb, "SELECT status || ': ' || reason FROM runs WHERE id = 3"),
            "failed: unstable");
  EXPECT_EQ(scalar(nb,
                   "SELECT count(*) FROM traces t JOIN waves w ON w.id = t.wave_id "
                   "WHERE w.run_id = 3"),
            "1");
  EXPECT_EQ(scalar(nb,
                   "SELECT count(*) FROM picks p JOIN waves w ON w.id = p.wave_id "
                   "WHERE w.run_id = 3"),
            "1");
  // The snapshot file is the lab's now, where its row says.
  const std::string file = scalar(nb, "SELECT path FROM snapshots WHERE run_id = 2");
  EXPECT_NE(file.find(fs::path(path_).filename().string() + ".files/run-2/"), std::string::npos)
      << file;
  EXPECT_TRUE(fs::exists(nb.resolve(file))) << file;
  EXPECT_EQ(scalar(nb,
                   "SELECT scheduler || ' ' || job_id || ' ' || task_id || ' ' || source_run "
                   "FROM run_origins WHERE run_id = 3"),
            "slurm 812 3 2");
  EXPECT_EQ(scalar(nb, "SELECT count(DISTINCT uuid) FROM runs"), "3");
  // Twice is once.
  const MergeOutcome again = mergeNotebook(nb, shard, {});
  EXPECT_TRUE(again.runs.empty());
  EXPECT_EQ(again.already, 2u);
  EXPECT_EQ(scalar(nb, "SELECT count(*) FROM runs"), "3");
  EXPECT_THROW(mergeNotebook(nb, path_, {}), SqlError);  // not into itself
  for (const char* ext : {"", "-wal", "-shm"}) fs::remove(shard + ext);
  fs::remove_all(shard + ".files");
  fs::remove_all(path_ + ".files");
}

// FIPS 180-4's examples, the empty file, and one past a block boundary.
TEST_F(NotebookTest, FileHashIsSha256) {
  auto hashOf = [&](const std::string& bytes) {
    std::ofstream(path_, std::ios::binary) << bytes;
    return fileSha256(path_);
  };
  EXPECT_EQ(hashOf(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(hashOf("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(hashOf("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(hashOf(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

}  // namespace
}  // namespace rocklab::notebook
