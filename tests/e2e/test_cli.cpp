// The rocklab command end to end: version, bench (thread-count determinism), pack, errors.

#include <gtest/gtest.h>

#include "tests/e2e/command.hpp"

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

#include "lab/core/packing_io.hpp"

namespace {

struct Result {
  int status;
  std::string out;
};

Result run(const std::string& args) {
  Result r;
  r.status = rocklab::testing::runRocklab(args, &r.out);
  return r;
}

std::string tempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("rocklab-" + std::to_string(::getpid()) + "-" + name))
      .string();
}

TEST(Cli, VersionNamesRevisionAndBuildType) {
  const auto r = run("version");
  EXPECT_EQ(r.status, 0);
  EXPECT_TRUE(std::regex_search(r.out, std::regex("rocklab [0-9.]+ \\(git [0-9a-f]+|unknown")))
      << r.out;
  EXPECT_NE(r.out.find("build"), std::string::npos) << r.out;
}

TEST(Cli, HelpListsCommands) {
  const auto r = run("--help");
  EXPECT_EQ(r.status, 0);
  for (const char* c : {"bench", "pack", "version", "laws"}) {
    EXPECT_NE(r.out.find(c), std::string::npos) << c;
  }
}

TEST(Cli, BenchGivesTheSameStateOnOneAndTwoThreads) {
  const auto packing = tempPath("bench.txt");
  const auto r =
      run("bench --n 600 --steps 60 --warmup 10 --threads 1,2 --json --save-packing " + packing);
  ASSERT_EQ(r.status, 0) << r.out;
  std::regex hash("\"state_hash\": \"([0-9a-f]+)\"");
  std::vector<std::string> hashes;
  for (auto it = std::sregex_iterator(r.out.begin(), r.out.end(), hash);
       it != std::sregex_iterator(); ++it) {
    hashes.push_back((*it)[1]);
  }
  ASSERT_EQ(hashes.size(), 2u) << r.out;
  EXPECT_EQ(hashes[0], hashes[1]);
  EXPECT_NE(r.out.find("\"particle_steps_per_second\""), std::string::npos);
  // The saved packing runs again from the file and gives the same state.
  const auto again = run("bench --packing " + packing + " --steps 60 --warmup 10 --json");
  ASSERT_EQ(again.status, 0) << again.out;
  EXPECT_NE(again.out.find(hashes[0]), std::string::npos) << again.out;
  std::filesystem::remove(packing);
}

// The benchmark scene on the peers' 3,000-sphere packing against what LIGGGHTS 3.8 reports
// for the same packing (data/peers): a different code, the same physics. Tolerances:
// coordination numbers are counts of 3000 particles (0.5% is 7 contacts); the stress
// 1% (LIGGGHTS walls are triangle meshes, its contact point and torque arms differ).
TEST(Cli, BenchAgreesWithLiggghts) {
  const std::string dir = std::string(ROCKLAB_SOURCE_DIR) + "/data/peers/";
  std::ifstream ref_file(dir + "liggghts-3.8-packing_3k.json");
  const std::string ref((std::istreambuf_iterator<char>(ref_file)),
                        std::istreambuf_iterator<char>());
  auto number = [](const std::string& text, const std::string& key) {
    std::smatch m;
    EXPECT_TRUE(std::regex_search(text, m, std::regex("\"" + key + "\": \\[?([-0-9.e+]+)"))) << key;
    return std::stod(m[1]);
  };
  auto mean3 = [](const std::string& text, const std::string& key) {
    std::smatch m;
    std::regex_search(
        text, m, std::regex("\"" + key + "\": \\[([-0-9.e+]+), ([-0-9.e+]+), ([-0-9.e+]+)\\]"));
    return (std::stod(m[1]) + std::stod(m[2]) + std::stod(m[3])) / 3.0;
  };
  const auto r = run("bench --packing " + dir + "packing_3k.txt --json");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NEAR(number(r.out, "coordination_start") / number(ref, "coordination_start"), 1.0, 0.005);
  EXPECT_NEAR(number(r.out, "coordination_end") / number(ref, "coordination_end"), 1.0, 0.005);
  EXPECT_NEAR(number(r.out, "wall_stress_start_Pa") / mean3(ref, "wall_stress_start_Pa"), 1.0,
              0.01);
  EXPECT_NEAR(number(r.out, "wall_stress_end_Pa") / mean3(ref, "wall_stress_end_Pa"), 1.0, 0.01);
}

TEST(Cli, PackWritesAReadablePacking) {
  const auto out = tempPath("pack2d.txt");
  const auto r =
      run("pack --dim 2 --n 300 --dist phi --phi-mean -1 --phi-std 0.3 --d-min-mm 0.5 "
          "--d-max-mm 5 --porosity 0.25 --out " +
          out);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(rocklab::packingFileDimension(out), 2);
  const auto p = rocklab::readPacking<2>(out);
  EXPECT_EQ(p.centers.size(), 300u);
  EXPECT_NEAR(p.porosity(), 0.25, 1e-6);
  std::filesystem::remove(out);
}

TEST(Cli, BadInputIsRefusedClearly) {
  auto r = run("bench --packing /nonexistent/file.txt");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("/nonexistent/file.txt"), std::string::npos) << r.out;
  r = run("pack --porosity 2 --out /tmp/x.txt");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("porosity"), std::string::npos) << r.out;
  r = run("pack --dist normal --d-mean-mm 9 --d-min-mm 1 --d-max-mm 2 --out /tmp/x.txt");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("d_mean"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("(m)"), std::string::npos) << r.out;
  r = run("frobnicate");
  EXPECT_NE(r.status, 0);
}

}  // namespace
