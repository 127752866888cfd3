#pragma once
// What the end-to-end tests of protocols share: a notebook of their own per test, queries of
// it, and a quick protocol run into it and held to its regression reference.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "lab/notebook/queries.hpp"
#include "tests/e2e/command.hpp"

namespace rocklab::testing {

namespace nb = rocklab::notebook;

inline std::string sourceDir() {
  return ROCKLAB_SOURCE_DIR;
}

struct Lab {
  std::string path;
  explicit Lab(const std::string& name)
      : path((std::filesystem::temp_directory_path() /
              ("rocklab-e2e-" + std::to_string(::getpid()) + "-" + name + ".sqlite"))
                 .string()) {
    clean();
  }
  ~Lab() { clean(); }
  void clean() {
    for (const char* ext : {"", "-wal", "-shm"}) std::filesystem::remove(path + ext);
    for (const char* ext : {".files", ".formed"}) std::filesystem::remove_all(path + ext);
  }
};

inline double result(nb::Notebook& n, const std::string& name) {
  const auto t = nb::query(n, "SELECT value FROM results WHERE name = '" + name + "'");
  EXPECT_EQ(t.rows.size(), 1u) << name;
  return t.rows.empty() ? NAN : t.rows[0][0].real;
}

inline std::string scalar(nb::Notebook& n, const std::string& sql) {
  const auto t = nb::query(n, sql);
  return t.rows.empty() ? "" : t.rows[0][0].str();
}

// A series' values in step order.
inline std::vector<double> seriesValues(nb::Notebook& n, const std::string& name) {
  const auto t = nb::query(n, "SELECT value FROM series WHERE name = '" + name + "' ORDER BY step");
  std::vector<double> v;
  for (const auto& row : t.rows) v.push_back(row[0].real);
  return v;
}

// Runs a quick protocol into its own notebook and returns it. Every quick protocol passes
// here, so every one is also held to its regression reference at its own seed: each key
// result within the interval one seed has about the mean of the reference's eight
// (tests/reference/<protocol>.toml; `make references` regenerates the files, for review).
inline nb::Notebook runQuick(const Lab& lab, const std::string& protocol) {
  std::string out;
  EXPECT_EQ(rocklab::testing::runRocklab("run " + sourceDir() + "/protocols/" + protocol +
                                             ".toml --quiet --threads 1 --lab " + lab.path,
                                         &out),
            0)
      << out;
  EXPECT_EQ(rocklab::testing::runRocklab("regress check " + sourceDir() + "/tests/reference/" +
                                             protocol + ".toml --lab " + lab.path,
                                         &out),
            0)
      << out;
  return nb::Notebook(lab.path);
}

// Every row of a query of the notebook at `lab`, each as one text: what two notebooks must
// agree on.
inline std::vector<std::string> rows(const std::string& lab, const std::string& sql) {
  std::vector<std::string> out;
  for (const auto& row : nb::readOnlyQuery(lab, sql).rows) {
    std::string line;
    for (const auto& cell : row) line += cell.str() + "|";
    out.push_back(line);
  }
  return out;
}

// A run (killed and resumed, or started from a formed sample) against the run made in one
// go: every series row, event, result and snapshot, and the final state's hash (not the
// wall times some series and results measure).
inline void expectSameRun(const std::string& reference, const std::string& other) {
  for (const char* sql :
       {"SELECT name, step, time_s, value FROM series WHERE name NOT LIKE '%seconds' ORDER BY "
        "name, step",
        "SELECT kind, step, stage, mode, x, y, z, particle_a, particle_b, granular, value FROM "
        "events ORDER BY step, particle_a, particle_b, kind",
        "SELECT name, value, unit FROM results WHERE name NOT LIKE '%seconds' ORDER BY name",
        "SELECT text FROM messages WHERE text LIKE 'final state hash%' ORDER BY text",
        "SELECT stage, label, step FROM snapshots ORDER BY step, label",
        "SELECT status FROM runs"}) {
    const auto a = rows(reference, sql), b = rows(other, sql);
    EXPECT_EQ(a.size(), b.size()) << sql;
    EXPECT_TRUE(a == b) << sql;
  }
  EXPECT_EQ(rows(other, "SELECT count(*) FROM messages WHERE text LIKE 'final state hash%'"),
            std::vector<std::string>{"1|"});
}

// A campaign file beside `lab` over the quick hydrostatic protocol; `body` continues its
// [campaign] table.
inline std::string campaignFile(const std::string& lab, const std::string& name,
                                const std::string& body) {
  const std::string path = lab + "." + name + ".toml";
  std::ofstream(path) << "[campaign]\nname = \"" << name << "\"\nprotocol = \"" << sourceDir()
                      << "/protocols/hydrostatic-quick.toml\"\n"
                      << body;
  return path;
}

// A campaign of two seeds of a small sample that checkpoints often: a task killed or
// cancelled a little into its run has a checkpoint to resume from.
inline constexpr const char* kCheckpointedCampaign = R"(seeds = [3, 4]
[set]
"sample.count" = 400
"output.checkpoint_every_s" = 0.2
)";

// Removes what a lab keeps beside its file: its runs' files and its campaigns' folders.
inline void removeLabFiles(const Lab& lab) {
  std::filesystem::remove_all(lab.path + ".files");
  std::filesystem::remove_all(lab.path + ".campaigns");
}

}  // namespace rocklab::testing
