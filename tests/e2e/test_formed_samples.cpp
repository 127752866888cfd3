// Formed samples shared between runs (formation.reuse; rigs/common/formed_samples.hpp): a
// run that starts from the lab's formed sample with other strengths is the run it would have
// been, bit for bit; one whose grains are weaker than the stresses they carried while the
// sample formed, or whose formation differs, forms its own; the tasks of a campaign share
// the lab's formed samples.
#include <gtest/gtest.h>

#include <filesystem>

#include "tests/e2e/protocol_support.hpp"

namespace rocklab::testing {
namespace {

namespace fs = std::filesystem;

// The 2D superparticle UCS test, small and loaded to 1% strain, with formed samples kept.
std::string smallUcs(const std::string& keys) {
  return "run " + sourceDir() +
         "/protocols/biaxial-ucs.toml --quiet --threads 1 --set sample.count=80 --set "
         "loading.axial_strain_max=0.01 --set formation.reuse=true" +
         keys;
}

// Cement and grains stronger than the material's (28.62 and 47.7 MPa).
constexpr const char* kStronger =
    " --set bonds.tensile_strength_mean_MPa=36 --set bonds.shear_strength_mean_MPa=36"
    " --set grain_bonds.tensile_strength_mean_MPa=60 --set grain_bonds.shear_strength_mean_MPa=60";

// How many of the run's messages are like `like` (SQL LIKE).
int messages(const Lab& lab, const std::string& like) {
  return std::stoi(
      rows(lab.path, "SELECT count(*) FROM messages WHERE text LIKE '" + like + "'").at(0));
}

// `lab`'s formed samples copied to `to`'s.
void shareFormed(const Lab& lab, const Lab& to) {
  fs::copy(lab.path + ".formed", to.path + ".formed", fs::copy_options::recursive);
}

TEST(FormedSamples, ARunFromTheLabsFormedSampleIsTheRunItWouldHaveBeen) {
  Lab forming("formed-forming"), reusing("formed-reusing"), fresh("formed-fresh");
  std::string out;
  ASSERT_EQ(runRocklab(smallUcs("") + " --lab " + forming.path, &out), 0) << out;
  EXPECT_EQ(messages(forming, "formation.reuse: no sample of this formation%"), 1);
  ASSERT_EQ(std::distance(fs::directory_iterator(forming.path + ".formed"), {}), 1);
  shareFormed(forming, reusing);
  ASSERT_EQ(runRocklab(smallUcs(kStronger) + " --lab " + reusing.path, &out), 0) << out;
  EXPECT_EQ(messages(reusing, "formation.reuse: the sample formed by an earlier run%"), 1);
  ASSERT_EQ(
      runRocklab(smallUcs(kStronger) + " --set formation.reuse=false --lab " + fresh.path, &out), 0)
      << out;
  // Every record of the run that formed its own sample, the formation's series included.
  expectSameRun(fresh.path, reusing.path);
  EXPECT_NE(rows(reusing.path, "SELECT count(*) FROM series WHERE name LIKE 'densification.%'"),
            std::vector<std::string>{"0|"});
  // The strengths did act: the stronger sample is another result.
  EXPECT_NE(rows(forming.path, "SELECT value FROM results WHERE name = 'ucs_MPa'"),
            rows(reusing.path, "SELECT value FROM results WHERE name = 'ucs_MPa'"));
}

TEST(FormedSamples, WeakerGrainsOrAnotherFormationFormTheirOwnSample) {
  Lab forming("formed-base"), weak("formed-weak"), other("formed-other");
  std::string out;
  ASSERT_EQ(runRocklab(smallUcs("") + " --lab " + forming.path, &out), 0) << out;
  // Grains of 0.3 MPa break under the 1 MPa of the formation: the formed sample is not theirs.
  shareFormed(forming, weak);
  ASSERT_EQ(runRocklab(smallUcs(" --set grain_bonds.tensile_strength_mean_MPa=0.3 --set "
                                "grain_bonds.tensile_strength_std_MPa=0.05") +
                           " --lab " + weak.path,
                       &out),
            0)
      << out;
  EXPECT_EQ(messages(weak, "formation.reuse: grain bond % is weaker than a stress it carried%"), 1);
  EXPECT_EQ(messages(weak, "formation.reuse: the sample formed by an earlier run%"), 0);
  // Another seed is another packing.
  shareFormed(forming, other);
  ASSERT_EQ(runRocklab(smallUcs(" --set protocol.seed=2") + " --lab " + other.path, &out), 0)
      << out;
  EXPECT_EQ(messages(other, "formation.reuse: no sample of this formation%"), 1);
  EXPECT_EQ(std::distance(fs::directory_iterator(other.path + ".formed"), {}), 2);
  // Grains that left bonds out (draws <= 0 skipped) keep no sample: another run's draws
  // would name other bonds.
  Lab skipping("formed-skipping");
  ASSERT_EQ(runRocklab(smallUcs(" --set grain_bonds.negative_strength=skip --set "
                                "grain_bonds.tensile_strength_mean_MPa=5 --set "
                                "grain_bonds.tensile_strength_std_MPa=5") +
                           " --lab " + skipping.path,
                       &out),
            0)
      << out;
  EXPECT_EQ(messages(skipping,
                     "formation.reuse: the formed sample is not kept: grain strength "
                     "draws <= 0 left bonds out%"),
            1);
  EXPECT_FALSE(fs::exists(skipping.path + ".formed"));
}

// The tasks of a campaign (each in its own process and shard) share the lab's formed
// samples: two points that differ after the formation form one sample.
TEST(FormedSamples, TheTasksOfACampaignShareTheLabsFormedSamples) {
  Lab lab("formed-campaign");
  const std::string file = campaignFile(lab.path, "unloading", R"(seeds = 1
[set]
"sample.count" = 400
"formation.reuse" = true
[sweep]
"loading.unload_to_MPa" = [5.0, 20.0]
)");
  std::string out;
  ASSERT_EQ(runRocklab("campaign run " + file + " --jobs 1 --lab " + lab.path, &out), 0) << out;
  EXPECT_EQ(std::distance(fs::directory_iterator(lab.path + ".formed"), {}), 1);
  EXPECT_EQ(rows(lab.path,
                 "SELECT count(*) FROM messages WHERE text LIKE 'formation.reuse: the sample "
                 "formed by an earlier run%'"),
            std::vector<std::string>{"1|"});
  fs::remove(file);
  fs::remove_all(lab.path + ".campaigns");
}

}  // namespace
}  // namespace rocklab::testing
