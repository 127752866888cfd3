// The rocklab command end to end: version, bench (thread-count determinism), pack, errors.

#include <gtest/gtest.h>

#include "tests/e2e/command.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
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

// 2,000 spheres: the particle passes take a thread per 1,000 particles at most, so fewer would
// run the serial pass on both.
TEST(Cli, BenchGivesTheSameStateOnOneAndTwoThreads) {
  const auto packing = tempPath("bench.txt");
  const auto r =
      run("bench --n 2000 --steps 60 --warmup 10 --threads 1,2 --json --save-packing " + packing);
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
  // Each run's stages are timed over its timed steps alone: the contact pass took time, and
  // the stages together took no more than the run (the warm-up's time is not theirs).
  std::regex run_line("\"seconds\": ([0-9.e+-]+),.*\"stage_seconds\": \\{([^}]*)\\}");
  std::regex stage("\"([a-z_]+)\": ([0-9.e+-]+)");
  int timed = 0;
  for (auto it = std::sregex_iterator(r.out.begin(), r.out.end(), run_line);
       it != std::sregex_iterator(); ++it, ++timed) {
    const std::string stages = (*it)[2];
    double sum = 0.0;
    bool contacts = false;
    for (auto s = std::sregex_iterator(stages.begin(), stages.end(), stage);
         s != std::sregex_iterator(); ++s) {
      sum += std::stod((*s)[2]);
      contacts |= (*s)[1] == "contacts" && std::stod((*s)[2]) > 0.0;
    }
    EXPECT_TRUE(contacts) << stages;
    EXPECT_LE(sum, std::stod((*it)[1])) << stages;
  }
  EXPECT_EQ(timed, 2) << r.out;
  // The saved packing runs again from the file and gives the same state.
  const auto again = run("bench --packing " + packing + " --steps 60 --warmup 10 --json");
  ASSERT_EQ(again.status, 0) << again.out;
  EXPECT_NE(again.out.find(hashes[0]), std::string::npos) << again.out;
  std::filesystem::remove(packing);
}

// The bench's larger and richer scenes (issue 9): mirrored tiles keep the packing's
// structure, the bonded variant gives the same state on one and two threads and with the
// bonds one at a time (`--scalar-bonds`), the pore network and the snapshot are timed on
// the same packing.
TEST(Cli, BenchVariantsTileBondFlowAndRender) {
  const std::string packing = std::string(ROCKLAB_SOURCE_DIR) + "/data/peers/packing_3k.txt";
  auto number = [](const std::string& text, const std::string& key) {
    std::smatch m;
    EXPECT_TRUE(std::regex_search(text, m, std::regex("\"" + key + "\": ([-0-9.e+]+)"))) << key;
    return m.size() > 1 ? std::stod(m[1]) : NAN;
  };
  const auto one = run("bench --packing " + packing + " --steps 20 --warmup 5 --json");
  const auto tiled =
      run("bench --packing " + packing + " --tile 2,1,2 --steps 20 --warmup 5 --json");
  ASSERT_EQ(tiled.status, 0) << tiled.out;
  EXPECT_EQ(number(tiled.out, "particles"), 4.0 * number(one.out, "particles"));
  // Copies meet face to face: the coordination stays within 3% of the packing's own (plain
  // copies meeting misaligned lost 4%), and no particle moves far enough for a rebuild.
  EXPECT_NEAR(number(tiled.out, "coordination_start") / number(one.out, "coordination_start"), 1.0,
              0.03);
  EXPECT_EQ(number(tiled.out, "rebuilds"), 0.0);
  EXPECT_LT(number(tiled.out, "peak_rss_bytes"), 1e9);

  const auto bonded =
      run("bench --packing " + packing + " --bonded --threads 1,2 --steps 20 --warmup 5 --json");
  ASSERT_EQ(bonded.status, 0) << bonded.out;
  EXPECT_GT(number(bonded.out, "bonds"),
            0.45 * number(bonded.out, "coordination_start") * number(one.out, "particles"));
  std::regex hash("\"state_hash\": \"([0-9a-f]+)\"");
  std::vector<std::string> hashes;
  for (auto it = std::sregex_iterator(bonded.out.begin(), bonded.out.end(), hash);
       it != std::sregex_iterator(); ++it) {
    hashes.push_back((*it)[1]);
  }
  const auto scalar = run("bench --packing " + packing +
                          " --bonded --scalar-bonds --threads 1 --steps 20 --warmup 5 --json");
  ASSERT_EQ(scalar.status, 0) << scalar.out;
  EXPECT_NE(scalar.out.find("\"bond_lane_width\": 0"), std::string::npos) << scalar.out;
  for (auto it = std::sregex_iterator(scalar.out.begin(), scalar.out.end(), hash);
       it != std::sregex_iterator(); ++it) {
    hashes.push_back((*it)[1]);
  }
  ASSERT_EQ(hashes.size(), 3u);
  EXPECT_EQ(hashes[0], hashes[1]);
  EXPECT_EQ(hashes[0], hashes[2]);
  // Flat joints on the same contacts, one at a time beside the lanes: the same state on
  // one and two threads; a model without --bonded is refused.
  const auto joints = run("bench --packing " + packing +
                          " --bonded --bond-model flat_joint --threads 1,2 --steps 20 --warmup 5 "
                          "--json");
  ASSERT_EQ(joints.status, 0) << joints.out;
  EXPECT_NE(joints.out.find("\"flat_joints\": true"), std::string::npos) << joints.out;
  EXPECT_EQ(number(joints.out, "bonds"), number(bonded.out, "bonds"));
  std::vector<std::string> joint_hashes;
  for (auto it = std::sregex_iterator(joints.out.begin(), joints.out.end(), hash);
       it != std::sregex_iterator(); ++it) {
    joint_hashes.push_back((*it)[1]);
  }
  ASSERT_EQ(joint_hashes.size(), 2u);
  EXPECT_EQ(joint_hashes[0], joint_hashes[1]);
  EXPECT_NE(run("bench --packing " + packing + " --bond-model flat_joint --steps 1").status, 0);

  const auto flow = run("bench --packing " + packing + " --flow --json");
  ASSERT_EQ(flow.status, 0) << flow.out;
  EXPECT_GT(number(flow.out, "pores"), 3.0 * number(one.out, "particles"));
  // Hagen-Poiseuille pipes (alpha 1) against Kozeny-Carman: the same order (the permeameter
  // calibrates alpha); the peers' Yade figure is 1.39.
  const double ratio = number(flow.out, "permeability_m2") / number(flow.out, "kozeny_carman_m2");
  EXPECT_GT(ratio, 0.3);
  EXPECT_LT(ratio, 3.0);

  const std::string dir = tempPath("render");
  std::filesystem::create_directories(dir);
  const auto render =
      run("bench --packing " + packing + " --render --render-dir " + dir + " --json");
  ASSERT_EQ(render.status, 0) << render.out;
  EXPECT_GT(std::filesystem::file_size(dir + "/bench-view.png"), 10000u);
  EXPECT_GT(std::filesystem::file_size(dir + "/bench-slice.png"), 10000u);
  std::filesystem::remove_all(dir);
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

// The packings shipped compressed under data/peers are the very files the comparisons with
// LIGGGHTS and Yade were made on: decompressed, they give the states recorded beside them.
TEST(Cli, ShippedBenchPackingsKeepTheirStates) {
  const std::string dir = std::string(ROCKLAB_SOURCE_DIR) + "/data/peers/";
  std::ifstream states_file(dir + "bench-states.json");
  const std::string states((std::istreambuf_iterator<char>(states_file)),
                           std::istreambuf_iterator<char>());
  for (const std::string name : {"packing_3k.txt", "packing_10k.txt", "packing_20k.txt"}) {
    std::string packing = dir + name;
    if (!std::filesystem::exists(packing)) {
      packing = tempPath(name);
      ASSERT_EQ(std::system(("xz -dc " + dir + name + ".xz > " + packing).c_str()), 0) << name;
    }
    std::smatch m;
    ASSERT_TRUE(std::regex_search(
        states, m, std::regex("\"" + name + "\": \\{[^}]*\"state_hash\": \"([0-9a-f]+)\"")))
        << name;
    const auto r = run("bench --packing " + packing + " --threads 2 --json");
    ASSERT_EQ(r.status, 0) << r.out;
    EXPECT_NE(r.out.find("\"state_hash\": \"" + std::string(m[1]) + "\""), std::string::npos)
        << name << ": " << r.out;
    if (packing != dir + name) std::filesystem::remove(packing);
  }
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
  EXPECT_NE(r.out.find("(mm)"), std::string::npos) << r.out;
  r = run("frobnicate");
  EXPECT_NE(r.status, 0);
  // A generated sample needs its count; a lattice its cells in its dimension.
  const std::string protocol = tempPath("no-count.toml");
  std::ofstream(protocol) << "[protocol]\nname = \"n\"\nrig = \"hydrostatic\"\n";
  r = run("check " + protocol);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("sample.count: missing"), std::string::npos) << r.out;
  r = run("pack --lattice fcc --cells 3,3 --out /tmp/x.txt");
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("give 3 counts"), std::string::npos) << r.out;
}

// A study or a regression check with bad input says what is wrong and runs nothing: every
// setting of a study is checked before its first run.
TEST(Cli, StudyAndRegressRefuseBadInputBeforeRunning) {
  const std::string lab = tempPath("study-refused.sqlite"), out = tempPath("study-refused");
  const std::string protocol =
      std::string(ROCKLAB_SOURCE_DIR) + "/protocols/biaxial-ucs-quick.toml";
  auto study = [&](const std::string& vary) {
    return run("study accuracy " + protocol + " --lab " + lab + " --out " + out + " " + vary);
  };
  auto r = study("--vary numerics.timestep_safety=0.3,7");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("numerics.timestep_safety = 7 is outside the allowed range"),
            std::string::npos)
      << r.out;
  r = study("--vary numerics.timestep=0.3");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("--vary numerics.timestep=0.3: unknown key 'numerics.timestep' (`rocklab "
                       "keys biaxial` lists them)"),
            std::string::npos)
      << r.out;
  r = study("--vary sample.count=many");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("--vary sample.count=many: 'many' is not a value"), std::string::npos)
      << r.out;
  r = study("--vary sample.count=1.5");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("--vary sample.count=1.5: 'sample.count' (-) expects an integer"),
            std::string::npos)
      << r.out;
  r = study("--vary numerics.timestep_safety");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("expects KEY=v1,v2"), std::string::npos) << r.out;
  r = study("--vary numerics.timestep_safety=0.3 --vary numerics.timestep_safety=0.4");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("varied twice"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(lab));
  EXPECT_FALSE(std::filesystem::exists(out));

  r = run("regress check /nonexistent/reference.toml --lab " + lab);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("no such reference file"), std::string::npos) << r.out;
  r = run("regress update " + protocol + " --seeds 1");
  EXPECT_NE(r.status, 0);
}

// The protocols that ship are valid, each named as its file. Every quick twin has the
// regression reference its e2e test holds it to, and runs the rig of its full-size twin.
TEST(Cli, ShippedProtocolsCheck) {
  namespace fs = std::filesystem;
  const fs::path source = ROCKLAB_SOURCE_DIR;
  // A key's text as the protocol runs it (with its base and includes).
  const auto field = [](const fs::path& file, const std::string& key) {
    const std::string text = run("check " + file.string() + " --print").out;
    std::smatch m;
    return std::regex_search(text, m, std::regex("\\n" + key + " = \"([^\"]+)\"")) ? m[1].str()
                                                                                   : std::string();
  };
  int checked = 0;
  for (const auto& f : fs::directory_iterator(source / "protocols")) {
    if (f.path().extension() != ".toml") continue;
    const auto r = run("check " + f.path().string());
    EXPECT_EQ(r.status, 0) << r.out;
    const std::string stem = f.path().stem().string();
    EXPECT_EQ(field(f.path(), "name"), stem) << f.path();
    if (stem.ends_with("-quick")) {
      EXPECT_TRUE(fs::exists(source / "tests/reference" / (stem + ".toml"))) << stem;
      const fs::path full = source / "protocols" / (stem.substr(0, stem.size() - 6) + ".toml");
      if (fs::exists(full)) {
        EXPECT_EQ(field(full, "rig"), field(f.path(), "rig")) << full;
      }
    }
    ++checked;
  }
  EXPECT_GE(checked, 30);
}

}  // namespace
