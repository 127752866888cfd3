// Calibration end to end: `rocklab calibrate` runs its batches through the campaign engine,
// keeps every evaluation in the notebook, goes on after being killed without running a task
// twice, checks the best point on fresh seeds, writes a material file protocols include and
// a report; a target out of reach is found so and reported with the closest value.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <thread>

#include "tests/e2e/protocol_support.hpp"

namespace rocklab::testing {
namespace {

namespace fs = std::filesystem;

// A calibration of the cement strength of a small UCS sample (60 grains: about 10 s a run).
std::string calibrationFile(const Lab& lab, const std::string& name, double ucs,
                            const std::string& extra = "") {
  const std::string path = lab.path + "." + name + ".toml";
  std::ofstream(path) << "[calibration]\nname = \"" << name
                      << "\"\nbudget = 12\nbatch = 2\nseeds = 2\n"
                      << extra << "\n[set]\n\"sample.count\" = 60\n\n[[target]]\nprotocol = \""
                      << sourceDir()
                      << "/protocols/biaxial-ucs-hand-set.toml\"\nresult = \"ucs_MPa\"\nvalue = "
                      << ucs << "\ntolerance_percent = 4\n\n[[parameter]]\nname = \"cement\"\n"
                      << "keys = { \"bonds.tensile_strength_mean_MPa\" = 1.0, "
                         "\"bonds.shear_strength_mean_MPa\" = 1.0 }\nlow = 5.0\nhigh = 100.0\n"
                         "scale = \"log\"\nstart = 16.5\n";
  return path;
}

void removeCalibrationFiles(const Lab& lab) {
  removeLabFiles(lab);
  fs::remove_all(lab.path + ".calibrations");
}

TEST(Calibrate, GoesOnAfterAKillChecksTheBestPointAndWritesAMaterialProtocolsInclude) {
  Lab lab("calibrate");
  removeCalibrationFiles(lab);
  const std::string material = lab.path + ".material/cement.toml";
  fs::remove_all(lab.path + ".material");
  // The material file as a user left it: its comments stay when the calibration writes it.
  fs::create_directories(lab.path + ".material");
  std::ofstream(material) << "# An old header\n\n[bonds]\n# The cement of the test.\n";
  const std::string file =
      calibrationFile(lab, "cement", 12.0, "check_seeds = 2\nmaterial = \"" + material + "\"\n");
  std::string out;
  ASSERT_EQ(runRocklab("calibrate " + file + " --check", &out), 0) << out;
  EXPECT_NE(out.find("a valid calibration: 1 targets from 1 protocols, 1 parameters"),
            std::string::npos)
      << out;
  const pid_t calibration = fork();
  if (calibration == 0) {
    setpgid(0, 0);
    std::freopen("/dev/null", "w", stderr);
    execl(ROCKLAB_BINARY, ROCKLAB_BINARY, "calibrate", file.c_str(), "--jobs", "2", "--quiet",
          "--lab", lab.path.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  // Killed (the whole process group, as a lost node would) once a run of its second batch
  // is loading: the UCS protocol's loading stage writes the unprefixed series.
  const std::string shard = lab.path + ".campaigns/cement-b1-x0/task-0.sqlite";
  bool loading = false;
  for (int k = 0; k < 6000 && !loading; ++k) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    try {
      loading = fs::exists(shard) &&
                rows(shard, "SELECT 1 FROM series WHERE name = 'axial_strain' LIMIT 1").size() == 1;
    } catch (const std::exception&) {  // not there yet
    }
  }
  ASSERT_TRUE(loading) << "the second batch's first run never reached its loading";
  kill(-calibration, SIGKILL);
  waitpid(calibration, nullptr, 0);
  // Its task processes die with it, a moment later: a task whose process is still there
  // would rightly be found running.
  for (int k = 0; k < 200 && kill(-calibration, 0) == 0; ++k) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_EQ(rows(lab.path, "SELECT status FROM calibrations"),
            std::vector<std::string>{"running|"});
  const auto before = rows(lab.path,
                           "SELECT evaluation, value FROM calibration_values WHERE role = "
                           "'parameter' AND evaluation < 4 ORDER BY evaluation");
  ASSERT_EQ(before.size(), 4u);

  const int code = runRocklab("calibrate " + file + " --jobs 2 --quiet --lab " + lab.path, &out);
  std::string unfinished;
  for (const auto& r : rows(lab.path,
                            "SELECT id, status, reason FROM runs WHERE status != "
                            "'completed'")) {
    unfinished += r + "\n";
  }
  ASSERT_EQ(code, 0) << out << "runs not completed:\n" << unfinished;
  EXPECT_NE(out.find("(going on)"), std::string::npos) << out;
  EXPECT_EQ(rows(lab.path, "SELECT status FROM calibrations"),
            std::vector<std::string>{"reached|"});
  // The evaluations before the kill are those after it, and none was run again: each task of
  // the calibration's campaigns has one completed run.
  EXPECT_EQ(rows(lab.path,
                 "SELECT evaluation, value FROM calibration_values WHERE role = 'parameter' AND "
                 "evaluation < 4 ORDER BY evaluation"),
            before);
  EXPECT_EQ(rows(lab.path,
                 "SELECT count(*) = (SELECT count(*) FROM runs WHERE status = 'completed') FROM "
                 "campaign_points p JOIN runs r ON r.id = p.run_id WHERE r.status = 'completed'"),
            std::vector<std::string>{"1|"});
  // Every evaluation's target is the statistics of its campaign point's runs.
  EXPECT_EQ(
      rows(lab.path,
           "SELECT count(*) FROM calibration_values v JOIN calibration_evaluations e USING "
           "(calibration_id, evaluation) WHERE v.role = 'target' AND e.status = "
           "'evaluated' AND v.n = 2"),
      rows(lab.path, "SELECT count(*) FROM calibration_evaluations WHERE status = 'evaluated'"));
  // The best point within tolerance, then on two fresh seeds (3 and 4).
  const auto best = rows(lab.path, "SELECT best_evaluation FROM calibrations");
  ASSERT_EQ(best.size(), 1u);
  const std::string b = best[0].substr(0, best[0].size() - 1);
  EXPECT_EQ(rows(lab.path,
                 "SELECT within_tolerance FROM calibration_evaluations WHERE "
                 "evaluation = " +
                     b),
            std::vector<std::string>{"1|"});
  EXPECT_EQ(rows(lab.path,
                 "SELECT group_concat(seed) FROM (SELECT p.seed FROM campaign_points p JOIN "
                 "campaigns c ON c.id = p.campaign_id WHERE c.name = 'cement-check-x0' ORDER BY "
                 "p.seed)"),
            std::vector<std::string>{"3,4|"});
  // The material: the best evaluation's value in both keys, and a protocol includes it.
  const std::string value =
      rows(lab.path,
           "SELECT value FROM calibration_values WHERE role = 'parameter' AND "
           "evaluation = " +
               b)[0];
  std::ifstream in(material);
  const std::string text(std::istreambuf_iterator<char>(in), {});
  EXPECT_NE(text.find("[bonds]\nshear_strength_mean_MPa = " + value.substr(0, value.size() - 1)),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("# The cement of the test.\n"), std::string::npos) << text;
  EXPECT_EQ(text.find("# An old header"), std::string::npos) << text;
  EXPECT_EQ(text.find("count"), std::string::npos) << text;  // [set], but not the material's
  const std::string protocol = lab.path + ".material/ucs.toml";
  {
    std::ifstream p(sourceDir() + "/protocols/biaxial-ucs-hand-set.toml");
    std::string original(std::istreambuf_iterator<char>(p), {});
    for (const char* key :
         {"tensile_strength_mean_MPa = 33.0\n", "shear_strength_mean_MPa = 33.0\n"}) {
      const auto at = original.find(key, original.find("[bonds]"));
      ASSERT_NE(at, std::string::npos) << key;
      original.erase(at, std::string(key).size());
    }
    std::ofstream(protocol) << "include = \"cement.toml\"\n" << original;
  }
  ASSERT_EQ(runRocklab("check " + protocol, &out), 0) << out;
  // The report.
  EXPECT_TRUE(fs::exists(lab.path + ".calibrations/cement/report/index.html"));
  EXPECT_TRUE(fs::exists(lab.path + ".calibrations/cement/report/targets.png"));
  // Run again: nothing left to do, the same answer.
  ASSERT_EQ(runRocklab("calibrate " + file + " --quiet --lab " + lab.path, &out), 0) << out;
  EXPECT_EQ(out.find("campaign cement-b"), std::string::npos) << out;
  removeCalibrationFiles(lab);
  fs::remove_all(lab.path + ".material");
  fs::remove(file);
}

TEST(Calibrate, ATargetOutOfReachIsReportedWithTheClosestValueBeforeTheBudgetIsSpent) {
  Lab lab("calibrate-reach");
  removeCalibrationFiles(lab);
  // 500 MPa: the cement's upper bound gives a few tens.
  const std::string file = calibrationFile(lab, "too-strong", 500.0);
  std::string out;
  EXPECT_EQ(runRocklab("calibrate " + file + " --jobs 2 --quiet --lab " + lab.path, &out), 1)
      << out;
  EXPECT_EQ(rows(lab.path, "SELECT status FROM calibrations"),
            std::vector<std::string>{"unreachable|"});
  EXPECT_NE(out.find("no point inside the bounds meets every target"), std::string::npos) << out;
  EXPECT_NE(out.find("the closest predicted: ucs_MPa"), std::string::npos) << out;
  const auto n = rows(lab.path, "SELECT count(*) < 12 FROM calibration_evaluations");
  EXPECT_EQ(n, std::vector<std::string>{"1|"}) << "the budget of 12 was spent";
  // An evaluation lost to the machine (every run of a target failed: a node gone, the binary
  // replaced under the pool) is run again when the calibration is. Here one is marked so in
  // the ledger while its runs are in the lab: it is evaluated again to the same misfit, and
  // nothing runs twice.
  const std::string misfit =
      "SELECT status, misfit FROM calibration_evaluations WHERE evaluation = 1";
  const auto before = rows(lab.path, misfit);
  const auto runs = rows(lab.path, "SELECT count(*) FROM runs");
  {
    nb::Notebook notebook(lab.path);
    notebook.db().exec("UPDATE calibration_evaluations SET status = 'failed' WHERE evaluation = 1");
  }
  EXPECT_EQ(runRocklab("calibrate " + file + " --jobs 2 --quiet --lab " + lab.path, &out), 1)
      << out;
  EXPECT_EQ(rows(lab.path, misfit), before);
  EXPECT_EQ(rows(lab.path, "SELECT count(*) FROM runs"), runs);
  EXPECT_EQ(rows(lab.path, "SELECT status FROM calibrations"),
            std::vector<std::string>{"unreachable|"});
  removeCalibrationFiles(lab);
  fs::remove(file);
}

// The calibrations that ship with the protocols are valid, every target protocol with its
// parameters at their bounds.
TEST(Calibrate, ShippedCalibrationsCheck) {
  int checked = 0;
  for (const auto& f : fs::directory_iterator(sourceDir() + "/protocols/calibrations")) {
    if (f.path().extension() != ".toml") continue;
    std::string out;
    EXPECT_EQ(runRocklab("calibrate " + f.path().string() + " --check", &out), 0) << out;
    ++checked;
  }
  EXPECT_GE(checked, 2);
}

}  // namespace
}  // namespace rocklab::testing
