// Campaigns on a real Slurm: a one-node cluster started for the test (tests/slurm/cluster.sh,
// as root), a campaign submitted as a job array whose merged notebook holds the very results
// the local pool makes, and an array task cancelled by the scheduler, reported and resumed.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <thread>

#include "tests/e2e/protocol_support.hpp"

namespace rocklab::testing {
namespace {

namespace fs = std::filesystem;

std::string shell(const std::string& command, int* code = nullptr) {
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  std::string out;
  char buf[4096];
  while (p && std::fgets(buf, sizeof buf, p)) out += buf;
  const int status = p ? pclose(p) : -1;
  if (code) *code = WEXITSTATUS(status);
  return out;
}

class SlurmCluster : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = (fs::temp_directory_path() / ("rocklab-slurm-" + std::to_string(getpid()))).string();
    int code = 0;
    const std::string out = shell(sourceDir() + "/tests/slurm/cluster.sh start " + dir_, &code);
    up_ = code == 0;
    if (up_) setenv("SLURM_CONF", (dir_ + "/slurm.conf").c_str(), 1);
    why_ = out;
  }
  static void TearDownTestSuite() {
    shell(sourceDir() + "/tests/slurm/cluster.sh stop " + dir_);
    fs::remove_all(dir_);
  }
  void SetUp() override {
    ASSERT_TRUE(up_) << "the one-node Slurm cluster did not start (it needs root and Debian's "
                        "munge, slurmctld, slurmd, slurm-client):\n"
                     << why_;
  }
  static std::string dir_, why_;
  static bool up_;
};

std::string SlurmCluster::dir_, SlurmCluster::why_;
bool SlurmCluster::up_ = false;

// The key results and final states of every task, by point and seed.
std::vector<std::string> outcome(const std::string& lab) {
  return rows(lab,
              "SELECT p.point, p.seed, r.name, r.value FROM campaign_points p JOIN results r ON "
              "r.run_id = p.run_id WHERE r.name NOT LIKE '%seconds' UNION ALL SELECT p.point, "
              "p.seed, 'hash', m.text FROM campaign_points p JOIN messages m ON m.run_id = "
              "p.run_id WHERE m.text LIKE 'final state hash%' ORDER BY 1, 2, 3");
}

TEST_F(SlurmCluster, AJobArrayGivesTheLocalPoolsResultsBitForBit) {
  Lab slurm("slurm-array"), local("slurm-local");
  const std::string body = R"(seeds = 2
[set]
"sample.count" = 200
[sweep]
"material.friction" = [0.3, 0.5]
[slurm]
partition = "debug"
time = "00:10:00"
options = ["--mem=1G"]
)";
  const std::string a = campaignFile(slurm.path, "array", body),
                    b = campaignFile(local.path, "array", body);
  std::string out;
  ASSERT_EQ(runRocklab("campaign run " + a + " --scheduler slurm --wait --lab " + slurm.path, &out),
            0)
      << out;
  EXPECT_NE(out.find("submitted as Slurm job array"), std::string::npos) << out;
  ASSERT_EQ(runRocklab("campaign run " + b + " --jobs 2 --quiet --lab " + local.path, &out), 0)
      << out;
  EXPECT_EQ(rows(slurm.path, "SELECT count(*) FROM runs WHERE status = 'completed'"),
            std::vector<std::string>{"4|"});
  const auto from_slurm = outcome(slurm.path);
  EXPECT_GT(from_slurm.size(), 40u);
  EXPECT_EQ(from_slurm, outcome(local.path));
  // Each run knows its scheduler's job and array task.
  EXPECT_EQ(rows(slurm.path,
                 "SELECT count(*) FROM run_origins WHERE scheduler = 'slurm' AND "
                 "job_id IS NOT NULL AND task_id IS NOT NULL"),
            std::vector<std::string>{"4|"});
  for (const auto& f : {a, b}) fs::remove(f);
  removeLabFiles(slurm);
  removeLabFiles(local);
}

// scancel sends the task SIGTERM: the run closes as interrupted with its checkpoint kept;
// the collect job merges it; --rerun-failed resumes it to the uninterrupted run.
TEST_F(SlurmCluster, ATaskCancelledByTheSchedulerIsReportedAndResumed) {
  Lab lab("slurm-cancel"), reference("slurm-cancel-reference");
  const std::string body = kCheckpointedCampaign;
  const std::string file = campaignFile(lab.path, "cancel", body);
  std::string out;
  ASSERT_EQ(runRocklab("campaign run " + file + " --scheduler slurm --lab " + lab.path, &out), 0)
      << out;
  const std::string job = out.substr(out.rfind('\n', out.size() - 2) + 1);
  const std::string job_id = job.substr(0, job.find_first_of("\n "));
  ASSERT_FALSE(job_id.empty()) << out;
  // Task 0 works on the node's local storage: wait until it is running and has checkpointed.
  bool running = false;
  for (int k = 0; k < 600 && !running; ++k) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    running = shell("squeue -h -j " + job_id + "_0 -o %T").find("RUNNING") != std::string::npos;
  }
  ASSERT_TRUE(running) << shell("squeue");
  std::this_thread::sleep_for(std::chrono::seconds(3));
  shell("scancel " + job_id + "_0");
  // The array and its collect job leave the queue.
  for (int k = 0; k < 1200; ++k) {
    if (shell("squeue -h -o %i").empty()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_EQ(runRocklab("campaign show " + file + " --lab " + lab.path, &out), 0) << out;
  EXPECT_NE(out.find("(base, seed 3): run"), std::string::npos) << out;
  EXPECT_NE(out.find("interrupted: terminated (SIGTERM)"), std::string::npos) << out;
  ASSERT_EQ(runRocklab("campaign run " + file + " --scheduler slurm --wait --rerun-failed --lab " +
                           lab.path,
                       &out),
            0)
      << out;
  EXPECT_EQ(rows(lab.path, "SELECT count(*) FROM runs WHERE status = 'completed'"),
            std::vector<std::string>{"2|"});
  // The cancelled task against the same task never cancelled.
  const std::string ref =
      campaignFile(reference.path, "cancel", std::regex_replace(body, std::regex("3, 4"), "3"));
  ASSERT_EQ(runRocklab("campaign run " + ref + " --quiet --lab " + reference.path, &out), 0) << out;
  auto seed3 = [](std::vector<std::string> rows) {
    std::erase_if(rows, [](const std::string& r) { return r.rfind("0|3|", 0) != 0; });
    return rows;
  };
  EXPECT_GT(seed3(outcome(lab.path)).size(), 10u);
  EXPECT_EQ(seed3(outcome(lab.path)), outcome(reference.path));
  fs::remove(file);
  fs::remove(ref);
  removeLabFiles(lab);
  removeLabFiles(reference);
}

// A calibration's batches as job arrays: each evaluation's runs made by Slurm, merged, and
// its target read from them.
TEST_F(SlurmCluster, ACalibrationRunsItsBatchesAsJobArrays) {
  Lab lab("slurm-calibration");
  const std::string file = lab.path + ".calibration.toml";
  std::ofstream(file) << "[calibration]\nname = \"slurm-cement\"\nbudget = 4\nbatch = 2\nseeds = "
                         "2\n\n[set]\n\"sample.count\" = 60\n\n[[target]]\nprotocol = \""
                      << sourceDir()
                      << "/protocols/biaxial-ucs-hand-set.toml\"\nresult = \"ucs_MPa\"\nvalue = "
                         "6.0\ntolerance_percent = 10\n\n[[parameter]]\nkey = "
                         "\"bonds.tensile_strength_mean_MPa\"\nlow = 5.0\nhigh = 100.0\nscale = "
                         "\"log\"\nstart = 16.5\n\n[slurm]\npartition = \"debug\"\ntime = "
                         "\"00:10:00\"\n";
  std::string out;
  const int code = runRocklab("calibrate " + file + " --scheduler slurm --lab " + lab.path, &out);
  EXPECT_TRUE(code == 0 || code == 1) << out;
  EXPECT_NE(out.find("submitted as Slurm job array"), std::string::npos) << out;
  // Every evaluation of the first batch evaluated from two runs Slurm made.
  EXPECT_EQ(rows(lab.path,
                 "SELECT count(*) FROM calibration_evaluations WHERE batch = 0 AND status = "
                 "'evaluated'"),
            std::vector<std::string>{"4|"});
  EXPECT_EQ(rows(lab.path,
                 "SELECT count(*) = (SELECT count(*) FROM runs WHERE status = 'completed') FROM "
                 "run_origins WHERE scheduler = 'slurm' AND job_id IS NOT NULL"),
            std::vector<std::string>{"1|"});
  EXPECT_EQ(
      rows(lab.path, "SELECT count(*) FROM calibration_values WHERE role = 'target' AND n = 2"),
      rows(lab.path, "SELECT count(*) FROM calibration_evaluations WHERE status = 'evaluated'"));
  fs::remove(file);
  removeLabFiles(lab);
  fs::remove_all(lab.path + ".calibrations");
}

}  // namespace
}  // namespace rocklab::testing
