// Campaign files read like protocols (every problem with its line), the points their sweeps
// make, and the statistics of an ensemble (Student's t against tabulated quantiles).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "lab/campaign/campaign.hpp"
#include "lab/campaign/statistics.hpp"

namespace fs = std::filesystem;
using namespace rocklab::campaign;

namespace {

class CampaignFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        fs::temp_directory_path() /
        ("rocklab-campaign-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
         "-" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    fs::copy_file(fs::path(ROCKLAB_SOURCE_DIR) / "protocols/biaxial-ucs-hand-set.toml",
                  dir_ / "ucs.toml");
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& text) {
    const std::string path = (dir_ / "c.toml").string();
    std::ofstream(path) << text;
    return path;
  }
  // The problems a file gets, joined.
  std::string problems(const std::string& text) {
    try {
      readCampaign(write(text));
    } catch (const rocklab::protocol::ProtocolError& e) {
      std::string all;
      for (const auto& p : e.problems()) all += p + "\n";
      return all;
    }
    return "";
  }
  fs::path dir_;
};

}  // namespace

TEST_F(CampaignFile, SweepsMakeProductOrZippedPointsTimesSeeds) {
  Campaign c = readCampaign(write(R"(
[campaign]
name = "ucs-sweep"
protocol = "ucs.toml"
seeds = 3
[set]
"sample.count" = 300
[sweep]
"bonds.tensile_strength_mean_MPa" = [4.0, 8.0]
"loading.confining_stress_MPa" = [0, 1, 2]
)"));
  EXPECT_EQ(c.name, "ucs-sweep");
  EXPECT_EQ(c.protocol, (dir_ / "ucs.toml").string());
  ASSERT_EQ(c.points.size(), 6u);  // 2 x 3, the first key varying slowest
  EXPECT_EQ(c.points[1].label(),
            "bonds.tensile_strength_mean_MPa=4.0, loading.confining_stress_MPa=1");
  EXPECT_EQ(c.points[3].label(),
            "bonds.tensile_strength_mean_MPa=8.0, loading.confining_stress_MPa=0");
  // A count of seeds: the protocol's own seed and the ones after it.
  ASSERT_EQ(c.seeds.size(), 3u);
  EXPECT_EQ(c.seeds[1], c.seeds[0] + 1);
  const auto tasks = c.tasks();
  ASSERT_EQ(tasks.size(), 18u);
  EXPECT_EQ(tasks[4].point, 1);
  EXPECT_EQ(tasks[4].seed, c.seeds[1]);
  // A task's overrides: the fixed keys, the point's, the seed; named by the campaign.
  const auto o = c.overrides(tasks[4]);
  ASSERT_EQ(o.size(), 4u);
  EXPECT_EQ(o[0].key, "sample.count");
  EXPECT_EQ(o[3].key, "protocol.seed");
  EXPECT_EQ(o[3].value, std::to_string(c.seeds[1]));
  EXPECT_EQ(o[1].origin, "campaign ucs-sweep");
  EXPECT_NE(c.overrides(tasks[4], true)[1].origin.find("c.toml:"), std::string::npos);

  c = readCampaign(write(R"(
[campaign]
name = "zipped"
protocol = "ucs.toml"
seeds = [5, 9]
combine = "zip"
[sweep.loading]
confining_stress_MPa = [0, 1, 2]
axial_strain_rate_per_s = [0.1, 0.2, 0.4]
)"));
  ASSERT_EQ(c.points.size(), 3u);
  EXPECT_EQ(c.points[2].label(),  // the keys in the file's order
            "loading.confining_stress_MPa=2, loading.axial_strain_rate_per_s=0.4");
  EXPECT_EQ(c.seeds, (std::vector<std::int64_t>{5, 9}));
}

TEST_F(CampaignFile, EveryProblemIsNamedWithItsLine) {
  const std::string p = problems(R"(
[campaign]
name = "has space"
protocol = "ucs.toml"
seeds = 0
combine = "cartesian"
colour = "red"
[sweep]
"loading.confining_stress_MPa" = 3
[slurm]
cpus_per_task = 0
queue = "x"
[extras]
a = 1
)");
  EXPECT_NE(p.find("c.toml:3: campaign.name: a text without spaces"), std::string::npos) << p;
  EXPECT_NE(p.find("c.toml:6: campaign.combine: one of product, zip"), std::string::npos) << p;
  EXPECT_NE(p.find("c.toml:7: campaign.colour: unknown key"), std::string::npos) << p;
  EXPECT_NE(p.find("c.toml:11: slurm.cpus_per_task: an integer in [1, 1024]"), std::string::npos)
      << p;
  EXPECT_NE(p.find("c.toml:12: slurm.queue: unknown key"), std::string::npos) << p;
  EXPECT_NE(p.find("[extras]: unknown table"), std::string::npos) << p;
  const std::string q = problems(R"(
[campaign]
name = "n"
protocol = "ucs.toml"
seeds = [1, 1]
combine = "zip"
[sweep]
"loading.confining_stress_MPa" = [0, 1]
"loading.axial_strain_rate_per_s" = [0.1]
)");
  EXPECT_NE(q.find("c.toml:5: campaign.seeds: seed 1 twice"), std::string::npos) << q;
  EXPECT_NE(q.find("1 values, but combine = \"zip\" needs as many"), std::string::npos) << q;
  EXPECT_NE(
      problems("[campaign]\nprotocol = \"ucs.toml\"\nseeds = 2\n").find("missing campaign.name"),
      std::string::npos);
  EXPECT_NE(problems("[campaign\n").find("not valid TOML"), std::string::npos);
}

// What the paper says of a result: read with the key result checked against the rig's,
// every problem with its line.
TEST_F(CampaignFile, PaperClaimsAreReadAndChecked) {
  const Campaign c = readCampaign(write(R"([campaign]
name = "n"
protocol = "ucs.toml"
seeds = 2
[[paper]]
result = "ucs_MPa"
number = "ucs"
[[paper]]
result = "band_angle_deg"
says = "nearly normal"
within = [70, 90.0]
)"));
  ASSERT_EQ(c.paper.size(), 2u);
  EXPECT_EQ(c.paper[0].result, "ucs_MPa");
  EXPECT_EQ(c.paper[0].number, "ucs");
  EXPECT_FALSE(c.paper[0].fraction);
  EXPECT_TRUE(c.paper[1].fraction);
  EXPECT_EQ(c.paper[1].low, 70.0);
  EXPECT_EQ(c.paper[1].high, 90.0);
  EXPECT_NE(c.paper[1].at.find("c.toml:8"), std::string::npos) << c.paper[1].at;  // its [[paper]]
  const std::string p = problems(R"([campaign]
name = "n"
protocol = "ucs.toml"
seeds = 2
[[paper]]
result = "ucs"
within = [2, 1]
colour = 3
[[paper]]
says = "x"
)");
  EXPECT_NE(p.find("c.toml:7: paper.within: [low, high], low < high"), std::string::npos) << p;
  EXPECT_NE(p.find("c.toml:8: paper.colour: unknown key"), std::string::npos) << p;
  EXPECT_NE(p.find("c.toml:5: paper: give paper.number"), std::string::npos) << p;
  EXPECT_NE(p.find("c.toml:9: paper: missing paper.result"), std::string::npos) << p;
  const std::string q = problems(R"([campaign]
name = "n"
protocol = "ucs.toml"
seeds = 2
[[paper]]
result = "vp_z"
number = "ucs"
)");
  EXPECT_NE(q.find("c.toml:5: paper.result = \"vp_z\" is not a key result of the biaxial rig"),
            std::string::npos)
      << q;
}

// Two points, each sweep's values zipped (the claims' file lines count from this head's).
constexpr const char* kZipped = R"([campaign]
name = "n"
protocol = "ucs.toml"
seeds = 2
combine = "zip"
[sweep]
"loading.confining_stress_MPa" = [0, 2.0]
"bonds.tensile_strength_mean_MPa" = [5.0, 6.0]
)";

// A claim about some of the points (Figure 14's two samples, each its own claim): the points
// whose swept values match, 2 and 2.0 alike; a key not swept, or values no point has, refused.
TEST_F(CampaignFile, APaperClaimCanBeAboutSomePoints) {
  const Campaign c = readCampaign(write(std::string(kZipped) + R"([[paper]]
result = "ucs_MPa"
number = "ucs"
point = { "loading.confining_stress_MPa" = 2 }
[[paper]]
result = "ucs_MPa"
says = "any"
)"));
  ASSERT_EQ(c.points.size(), 2u);
  EXPECT_FALSE(c.paper[0].concerns(c.points[0]));
  EXPECT_TRUE(c.paper[0].concerns(c.points[1]));
  EXPECT_TRUE(c.paper[1].concerns(c.points[0]));
  EXPECT_TRUE(c.paper[1].concerns(c.points[1]));
  const std::string p = problems(std::string(kZipped) + R"([[paper]]
result = "ucs_MPa"
says = "x"
point = { "loading.confining_stress_MPa" = 0, "bonds.tensile_strength_mean_MPa" = 6 }
[[paper]]
result = "ucs_MPa"
says = "y"
point = { "material.friction" = 0.5 }
)");
  EXPECT_NE(p.find("c.toml:12: paper.point: no point of the campaign has these values (its "
                   "points: loading.confining_stress_MPa=0, bonds.tensile_strength_mean_MPa=5.0; "),
            std::string::npos)
      << p;
  EXPECT_NE(p.find("c.toml:16: paper.point.material.friction: not a key of the [sweep]"),
            std::string::npos)
      << p;
  const std::string q = problems(R"([campaign]
name = "n"
protocol = "ucs.toml"
seeds = 2
[[paper]]
result = "ucs_MPa"
says = "z"
point = 3
)");
  EXPECT_NE(q.find("c.toml:8: paper.point: a table of swept keys"), std::string::npos) << q;
}

TEST(CampaignStatistics, StudentQuantilesMatchTheTables) {
  // t(0.975, df), e.g. Abramowitz & Stegun table 26.10 (to the 4 decimals they give).
  const std::pair<std::size_t, double> table[] = {{1, 12.7062}, {2, 4.3027},  {3, 3.1824},
                                                  {4, 2.7764},  {5, 2.5706},  {9, 2.2622},
                                                  {10, 2.2281}, {30, 2.0423}, {120, 1.9799}};
  for (const auto& [df, t] : table) EXPECT_NEAR(studentT975(df), t, 5e-5) << "df " << df;
  EXPECT_NEAR(studentT975(100000), 1.95996, 1e-4);  // the normal quantile
  EXPECT_THROW(studentT975(0), std::invalid_argument);
  // Between the whole degrees of freedom (Welch's are not whole), the quantile falls
  // monotonically: t(2.5) lies between t(2) and t(3).
  EXPECT_LT(studentT975(2.5), 4.3027);
  EXPECT_GT(studentT975(2.5), 3.1824);
  // Other quantiles (the regression guard's 99.5%), from the same tables: t(0.995, df), and
  // t(0.5) = 0; one degree of freedom is Cauchy's, tan(pi (p - 1/2)).
  const std::pair<std::size_t, double> t995[] = {{4, 4.6041}, {7, 3.4995}, {9, 3.2498}};
  for (const auto& [df, t] : t995) EXPECT_NEAR(studentT(0.995, df), t, 5e-5) << "df " << df;
  EXPECT_NEAR(studentT(0.9, 1), std::tan(0.4 * std::numbers::pi), 1e-9);
  EXPECT_NEAR(studentT(0.5, 7), 0.0, 1e-9);
  EXPECT_THROW(studentT(1.0, 7), std::invalid_argument);
}

// Welch's interval in the two cases with a closed form: equal sizes and scatters give
// 2(n - 1) degrees of freedom and a half-width t sqrt(2 s^2 / n); one ensemble without
// scatter leaves the other's own 95% interval.
TEST(CampaignStatistics, WelchIntervalOfADifferenceOfMeans) {
  const Summary a = summarize({1.0, 2.0, 3.0}), b = summarize({2.0, 3.0, 4.0});
  const Difference d = compareMeans(a, b);
  EXPECT_TRUE(d.known);
  EXPECT_DOUBLE_EQ(d.delta, 1.0);
  EXPECT_NEAR(d.half, 2.7764 * std::sqrt(2.0 / 3.0), 1e-4);
  EXPECT_FALSE(d.resolved());  // one apart, 2.27 the interval's half: the seeds do not tell
  EXPECT_TRUE(compareMeans(a, summarize({11.0, 12.0, 13.0})).resolved());
  const Summary flat = summarize({5.0, 5.0, 5.0, 5.0}), c = summarize({4.0, 6.0, 7.0});
  const Difference e = compareMeans(flat, c);
  EXPECT_NEAR(e.half, c.high - c.mean, 1e-9);
  EXPECT_FALSE(compareMeans(summarize({1.0}), b).known);
  EXPECT_FALSE(compareMeans(summarize({1.0}), b).resolved());
}

// Wilson's score interval of a fraction against the worked examples of Newcombe (1998,
// Statistics in Medicine 17, Table I, method 3, to the 4 decimals given), and at the ends.
TEST(CampaignStatistics, WilsonIntervalOfAFraction) {
  struct Row {
    std::size_t k, n;
    double low, high;
  };
  for (const Row& r : {Row{81, 263, 0.2553, 0.3662}, Row{15, 148, 0.0624, 0.1605},
                       Row{0, 20, 0.0, 0.1611}, Row{1, 29, 0.0061, 0.1718}}) {
    const Proportion p = proportion(r.k, r.n);
    EXPECT_NEAR(p.low, r.low, 5e-5) << r.k << " of " << r.n;
    EXPECT_NEAR(p.high, r.high, 5e-5) << r.k << " of " << r.n;
    EXPECT_DOUBLE_EQ(p.fraction, static_cast<double>(r.k) / r.n);
  }
  // 5 of 5 seeds: the mirror of 0 of 5, and never above 1.
  const Proportion all = proportion(5, 5), none = proportion(0, 5);
  EXPECT_DOUBLE_EQ(all.high, 1.0);
  EXPECT_NEAR(all.low, 1.0 - none.high, 1e-12);
  EXPECT_THROW(proportion(6, 5), std::invalid_argument);
  EXPECT_THROW(proportion(0, 0), std::invalid_argument);
}

TEST(CampaignStatistics, SummaryOfAnEnsemble) {
  const Summary s = summarize({9.77, 11.3, 11.75, 10.2, 10.9});
  EXPECT_EQ(s.n, 5u);
  EXPECT_NEAR(s.mean, 10.784, 1e-12);
  double ss = 0.0;
  for (double v : {9.77, 11.3, 11.75, 10.2, 10.9}) ss += (v - 10.784) * (v - 10.784);
  EXPECT_NEAR(s.std, std::sqrt(ss / 4.0), 1e-12);
  EXPECT_NEAR(s.high - s.mean, 2.7764 * s.std / std::sqrt(5.0), 1e-4);
  EXPECT_NEAR(s.mean - s.low, s.high - s.mean, 1e-12);
  const Summary one = summarize({3.0});
  EXPECT_EQ(one.n, 1u);
  EXPECT_EQ(one.std, 0.0);
  EXPECT_TRUE(std::isnan(one.low));
}
