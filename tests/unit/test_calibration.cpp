// The calibration's pieces: the Gaussian process against closed forms, the simplex search,
// the Latin hypercube and Halton sets, the Bayesian optimiser against the Latin hypercube on
// analytic targets, reach, spread and sensitivity on functions whose answers are known, and
// the calibration file read like a protocol (every problem with its file:line).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <set>

#include "lab/calibration/calibration.hpp"
#include "lab/calibration/gaussian_process.hpp"
#include "lab/calibration/material_file.hpp"
#include "lab/calibration/minimize.hpp"
#include "lab/calibration/optimizer.hpp"

namespace fs = std::filesystem;
using namespace rocklab::calibration;

namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(GaussianProcess, OnePointHasTheClosedFormLikelihoodAndPosterior) {
  // One observation y at x0 with noise n: the posterior at x0 has mean y (the constant mean is
  // y itself) and variance s^2 - s^4 / (s^2 + n + g); log p(y) = -log(2 pi (s^2 + n + g)) / 2.
  GaussianProcess gp;
  const double s = 2.0, n = 0.5, g = 0.1;
  gp.condition({{0.3}}, {7.0}, {n}, {s, {0.4}, g});
  const Prediction p = gp.predict({0.3});
  EXPECT_NEAR(p.mean, 7.0, 1e-12);
  EXPECT_NEAR(p.variance, s * s - std::pow(s, 4) / (s * s + n + g), 1e-12);
  EXPECT_NEAR(gp.logMarginalLikelihood(), -0.5 * std::log(2.0 * kPi * (s * s + n + g)), 1e-12);
  // Far away the prior comes back: the mean and the whole signal variance.
  const Prediction far = gp.predict({30.0});
  EXPECT_NEAR(far.mean, 7.0, 1e-12);
  EXPECT_NEAR(far.variance, s * s, 1e-9);
}

TEST(GaussianProcess, InterpolatesASmoothFunctionAndKnowsWhereItHasNoData) {
  std::vector<Point> x;
  std::vector<double> y, noise;
  for (int k = 0; k < 9; ++k) {
    const double u = k / 8.0;
    x.push_back({u});
    y.push_back(std::sin(2.0 * kPi * u));
    noise.push_back(0.0);
  }
  GaussianProcess gp;
  gp.fit(x, y, noise);
  for (int k = 0; k < 8; ++k) {
    const double u = (k + 0.5) / 8.0;
    EXPECT_NEAR(gp.predict({u}).mean, std::sin(2.0 * kPi * u), 0.03) << "at " << u;
  }
  EXPECT_LT(gp.predict({0.5}).variance, 1e-4);
  EXPECT_GT(gp.predict({1.6}).variance, 0.1);  // outside the data
}

TEST(GaussianProcess, NoisyRepeatsAverageAndAFlatInputGetsALongLength) {
  // y depends on the first input only, observed with noise of variance 0.01: the fit
  // averages the noise out, and finds the second input's length much longer.
  Random rng(7);
  std::vector<Point> x;
  std::vector<double> y, noise;
  for (int k = 0; k < 40; ++k) {
    const Point u = {rng.uniform(), rng.uniform()};
    x.push_back(u);
    y.push_back(std::sin(2.0 * kPi * u[0]) + 0.1 * rng.normal());
    noise.push_back(0.01);
  }
  GaussianProcess gp;
  gp.fit(x, y, noise);
  EXPECT_NEAR(gp.predict({0.25, 0.2}).mean, 1.0, 0.1);
  EXPECT_NEAR(gp.predict({0.25, 0.9}).mean, 1.0, 0.1);
  EXPECT_NEAR(gp.predict({0.75, 0.5}).mean, -1.0, 0.1);
  const auto& h = gp.hyperparameters();
  EXPECT_GT(h.length[1], 3.0 * h.length[0]) << h.length[0] << " " << h.length[1];
}

TEST(NelderMead, FindsRosenbrocksMinimum) {
  const auto rosenbrock = [](const std::vector<double>& v) {
    return 100.0 * std::pow(v[1] - v[0] * v[0], 2) + std::pow(1.0 - v[0], 2);
  };
  const Minimum m = nelderMead(rosenbrock, {-1.2, 1.0}, 0.5, 4000, 1e-14);
  EXPECT_NEAR(m.x[0], 1.0, 1e-3);
  EXPECT_NEAR(m.x[1], 1.0, 2e-3);
}

TEST(Designs, HaltonAndLatinHypercubeFillTheCube) {
  // Van der Corput in bases 2 and 3.
  EXPECT_EQ(halton(1, 2), (Point{0.5, 1.0 / 3.0}));
  EXPECT_DOUBLE_EQ(halton(3, 2)[0], 0.75);
  EXPECT_DOUBLE_EQ(halton(4, 2)[1], 4.0 / 9.0);
  const int n = 12;
  const auto p = latinHypercube(n, 3, 5);
  ASSERT_EQ(p.size(), 12u);
  for (std::size_t j = 0; j < 3; ++j) {
    std::set<int> slices;
    for (const Point& u : p) {
      EXPECT_GE(u[j], 0.0);
      EXPECT_LT(u[j], 1.0);
      slices.insert(static_cast<int>(u[j] * n));
    }
    EXPECT_EQ(slices.size(), 12u) << "axis " << j << ": one point in each slice";
  }
  // The same seed, the same design (a calibration goes on from the notebook).
  EXPECT_EQ(latinHypercube(n, 3, 5), p);
}

// A UCS-like response to two strengths on the unit cube (it rises with both, more with the
// first), measured as errors in tolerances against `target`.
double response(const Point& u) {
  return 2.0 + 20.0 * std::pow(u[0], 1.3) * (0.3 + 0.7 * u[1]);
}

Evaluated measure(const Point& u, double target, double tolerance) {
  return {u, {(response(u) - target) / tolerance}, {0.05}};
}

// Evaluations a strategy takes to land within tolerance (the budget + 1 if never).
int bayesianEvaluations(double target, double tolerance, int budget) {
  std::vector<Evaluated> done;
  for (const Point& u : latinHypercube(6, 2, 1)) done.push_back(measure(u, target, tolerance));
  for (std::size_t k = 0; k < done.size(); ++k) {
    if (withinTolerance(done[k].error)) return static_cast<int>(k) + 1;
  }
  for (std::uint64_t batch = 1; static_cast<int>(done.size()) < budget; ++batch) {
    for (const Point& u : proposeBatch(done, 4, batch)) {
      done.push_back(measure(u, target, tolerance));
      if (withinTolerance(done.back().error)) return static_cast<int>(done.size());
    }
  }
  return budget + 1;
}

int latinEvaluations(double target, double tolerance, int budget) {
  const auto design = latinHypercube(budget, 2, 1);
  for (std::size_t k = 0; k < design.size(); ++k) {
    if (withinTolerance(measure(design[k], target, tolerance).error))
      return static_cast<int>(k) + 1;
  }
  return budget + 1;
}

TEST(BayesianOptimisation, ReachesEveryTargetInFewerEvaluationsThanALatinHypercube) {
  // Targets across the response's range, each within 1%: the band of points within
  // tolerance is a thin curve through the square.
  const int budget = 40;
  double bo = 0.0, lhs = 0.0;
  for (double target : {5.0, 8.0, 9.9, 12.0, 16.0}) {
    const int b = bayesianEvaluations(target, 0.01 * target, budget);
    const int l = latinEvaluations(target, 0.01 * target, budget);
    EXPECT_LE(b, 22) << "target " << target;
    bo += b;
    lhs += l;
    std::cout << "target " << target << ": bayesian " << b << ", latin hypercube " << l << "\n";
  }
  EXPECT_LT(bo, 0.5 * lhs);
}

TEST(Reach, ATargetOutsideTheResponsesRangeIsSeenOutOfReach) {
  std::vector<Evaluated> far, near;
  for (const Point& u : latinHypercube(14, 2, 3)) {
    far.push_back(measure(u, 40.0, 0.3));  // the response is at most 22
    near.push_back(measure(u, 9.9, 0.3));
  }
  const Reach out = assessReach(Surrogate(far), far);
  EXPECT_LT(out.probability, 0.01);
  // The closest predicted is the corner of the largest response.
  EXPECT_GT(out.closest[0], 0.9);
  EXPECT_GT(out.closest[1], 0.9);
  EXPECT_NEAR(40.0 + 0.3 * out.at_closest[0].mean, 22.0, 1.0);
  EXPECT_GT(assessReach(Surrogate(near), near).probability, 0.5);
}

TEST(Surrogates, SpreadAndSensitivityOfAResponseToOneInput) {
  // y = u0 on the square, target 0.5 within 0.05: the points within have u0 in [0.45, 0.55]
  // and any u1; the first input explains all the variance.
  std::vector<Evaluated> done;
  for (const Point& u : latinHypercube(20, 2, 9)) done.push_back({u, {(u[0] - 0.5) / 0.05}, {0.0}});
  const Surrogate s(done);
  const auto spread = parameterSpread(s);
  ASSERT_TRUE(spread[0].any);
  EXPECT_NEAR(spread[0].low, 0.45, 0.02);
  EXPECT_NEAR(spread[0].high, 0.55, 0.02);
  EXPECT_NEAR(spread[0].mean, 0.5, 0.01);
  EXPECT_LT(spread[1].low, 0.05);
  EXPECT_GT(spread[1].high, 0.95);
  const auto sens = sensitivity(s);
  EXPECT_GT(sens[0][0], 0.95);
  EXPECT_LT(sens[0][1], 0.02);
}

class CalibrationFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("rocklab-calibration-" +
            std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_ / "materials");
    // The quick twins with the protocols they vary and the material those include.
    for (const char* p :
         {"biaxial-ucs-quick.toml", "biaxial-ucs.toml", "materials/superparticle-2d.toml",
          "brazilian-2d-quick.toml", "brazilian-2d.toml"}) {
      fs::copy_file(fs::path(ROCKLAB_SOURCE_DIR) / "protocols" / p, dir_ / p);
    }
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& text) {
    const std::string path = (dir_ / "c.toml").string();
    std::ofstream(path) << text;
    return path;
  }
  std::string problems(const std::string& text) {
    try {
      readCalibration(write(text));
    } catch (const rocklab::protocol::ProtocolError& e) {
      std::string all;
      for (const auto& p : e.problems()) all += p + "\n";
      return all;
    }
    return "";
  }
  fs::path dir_;
};

constexpr const char* kHead = R"([calibration]
name = "c1"
budget = 20
seeds = 3
check_seeds = 4
material = "materials/m.toml"
)";

constexpr const char* kUcsTarget = R"(
[[target]]
protocol = "biaxial-ucs-quick.toml"
result = "ucs_MPa"
value = 9.9
tolerance_percent = 3
)";

constexpr const char* kCement = R"(
[[parameter]]
name = "cement"
keys = { "bonds.tensile_strength_mean_MPa" = 1.0, "bonds.tensile_strength_std_MPa" = 0.25 }
low = 5.0
high = 100.0
scale = "log"
start = 16.5
)";

TEST_F(CalibrationFile, ReadsTargetsParametersAndTheirExperiments) {
  const Calibration c = readCalibration(write(std::string(kHead) + kUcsTarget + R"(
[[target]]
name = "modulus"
protocol = "biaxial-ucs-quick.toml"
result = "secant_modulus_50_MPa"
value = 3000
tolerance = 150

[[target]]
protocol = "brazilian-2d-quick.toml"
result = "tensile_strength_MPa"
value = 1.0
tolerance = 0.1
[target.set]
"sample.count" = 900
)" + kCement));
  ASSERT_EQ(c.targets.size(), 3u);
  EXPECT_NEAR(c.targets[0].tolerance, 0.297, 1e-12);
  EXPECT_EQ(c.targets[0].unit, "MPa");
  // Two targets of one protocol share its runs; the third has its own.
  ASSERT_EQ(c.experiments.size(), 2u);
  EXPECT_EQ(c.targets[1].experiment, 0);
  EXPECT_EQ(c.targets[2].experiment, 1);
  EXPECT_EQ(c.experiments[0].seeds, (std::vector<std::int64_t>{1, 2, 3}));
  EXPECT_EQ(c.experiments[0].check_seeds, (std::vector<std::int64_t>{4, 5, 6, 7}));
  EXPECT_EQ(c.material, (dir_ / "materials/m.toml").lexically_normal().string());
  // A parameter's keys take its value times their factors, in the protocols that have them.
  const auto o = c.overrides(0, {20.0}, "x");
  ASSERT_EQ(o.size(), 2u);
  EXPECT_EQ(o[0].key, "bonds.tensile_strength_mean_MPa");
  EXPECT_EQ(o[0].value, "20.0");
  EXPECT_EQ(o[1].value, "5.0");
  const Parameter& p = c.parameters[0];
  EXPECT_EQ(p.unit, "MPa");
  EXPECT_NEAR(p.toUnit(std::sqrt(500.0)), 0.5, 1e-12);  // the log scale's middle
  EXPECT_NEAR(p.fromUnit(0.5), std::sqrt(500.0), 1e-12);
  EXPECT_EQ(p.rounded(22.360679), 22.36);  // four significant digits
  EXPECT_EQ(p.rounded(4.0), 5.0);          // inside the bounds
  EXPECT_EQ(c.designSize(), 4);            // max(batch 4, 2 d + 2)
}

TEST_F(CalibrationFile, EveryProblemIsNamedWithItsLine) {
  const std::string all = problems(R"([calibration]
name = "has space"
budget = 1
optimizer = "genetic"
wobble = 2

[[target]]
protocol = "biaxial-ucs-quick.toml"
result = "ucs_MPa"
value = 9.9
tolerance = 0.3
tolerance_percent = 3

[[parameter]]
key = "bonds.tensile_strength_mean_MPa"
low = 10.0
high = 5.0
scale = "cubic"
)");
  EXPECT_NE(all.find("c.toml:2: calibration.name: a text without spaces"), std::string::npos)
      << all;
  EXPECT_NE(all.find("c.toml:3: calibration.budget: the evaluations at most, an integer in [2, "
                     "10000]"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("c.toml:4: calibration.optimizer: one of bayesian, latin_hypercube"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("c.toml:5: calibration.wobble: unknown key"), std::string::npos) << all;
  EXPECT_NE(all.find("target: give target.tolerance or target.tolerance_percent, not both"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("c.toml:16: parameter bonds.tensile_strength_mean_MPa: low (10.0) must be "
                     "below high (5.0)"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("c.toml:18: parameter.scale: one of linear, log"), std::string::npos) << all;
}

TEST_F(CalibrationFile, TheProtocolsAreCheckedWithTheParametersAtTheirBounds) {
  // A key no target protocol has, a key of the wrong kind, a bound outside the key's range,
  // a result the rig does not have.
  std::string all = problems(std::string(kHead) + kUcsTarget + R"(
[[parameter]]
key = "bonds.no_such_key"
low = 1.0
high = 2.0
)");
  EXPECT_NE(all.find("no target's protocol has its keys"), std::string::npos) << all;
  all = problems(std::string(kHead) + kUcsTarget + R"(
[[parameter]]
key = "sample.count"
low = 100.0
high = 200.0
)");
  EXPECT_NE(all.find("sample.count is not a real number key"), std::string::npos) << all;
  all = problems(std::string(kHead) + kUcsTarget + R"(
[[parameter]]
key = "material.friction"
low = 0.2
high = 50.0
)");
  EXPECT_NE(all.find("the parameters at their high bounds: material.friction=50.0"),
            std::string::npos)
      << all;
  all = problems(std::string(kHead) + R"(
[[target]]
protocol = "biaxial-ucs-quick.toml"
result = "ucs_kPa"
value = 9.9
tolerance = 1
)" + kCement);
  EXPECT_NE(all.find("c.toml:10: target.result"), std::string::npos) << all;
  EXPECT_NE(all.find("'ucs_kPa' is not a key result of the biaxial rig"), std::string::npos) << all;
  all = problems(std::string(kHead) + kUcsTarget + kUcsTarget + kCement + kCement);
  EXPECT_NE(all.find("target ucs_MPa twice (give each a target.name)"), std::string::npos) << all;
  EXPECT_NE(all.find("parameter cement twice"), std::string::npos) << all;
  all = problems(std::string(kHead) + R"(
[[target]]
protocol = "missing.toml"
result = "ucs_MPa"
value = 9.9
tolerance = 1
)" + kCement);
  EXPECT_NE(all.find("missing.toml"), std::string::npos) << all;
}

// The material file a calibration writes keeps what it did not fit: the file's other keys and
// comments stay, the fitted ones take their new values where they were, a key the file lacked
// goes under its table (or a new one), and the old header gives way to the new.
TEST(MaterialFile, TheFittedKeysAreWrittenIntoTheFileAsItWas) {
  const std::string previous = R"(# Material calibrated by an earlier run
# evaluation 3

[material]
friction = 0.5
density_kg_per_m3 = 2650

[bonds]
# Why the cement is what it is.
tensile_strength_mean_MPa = 18.0  # hand-calibrated
model = "parallel"
)";
  const std::string text = materialText(previous, "# New header\n",
                                        {{"bonds.tensile_strength_mean_MPa", "12.5"},
                                         {"bonds.tensile_strength_std_MPa", "2.5"},
                                         {"grain_bonds.shear_strength_mean_MPa", "30.0"},
                                         {"grain_bonds.tensile_strength_mean_MPa", "31.0"}});
  EXPECT_EQ(text, R"(# New header

[material]
friction = 0.5
density_kg_per_m3 = 2650

[bonds]
tensile_strength_std_MPa = 2.5
# Why the cement is what it is.
tensile_strength_mean_MPa = 12.5
model = "parallel"

[grain_bonds]
tensile_strength_mean_MPa = 31.0
shear_strength_mean_MPa = 30.0
)");
  // No file yet: the header and the keys.
  EXPECT_EQ(materialText("", "# h\n", {{"bonds.modulus_GPa", "4.0"}}),
            "# h\n\n[bonds]\nmodulus_GPa = 4.0\n");
  // A key given dotted at the top cannot be placed: refused, not written twice.
  EXPECT_THROW(materialText("bonds.modulus_GPa = 3.0\n", "# h\n", {{"bonds.modulus_GPa", "4.0"}}),
               std::invalid_argument);
  EXPECT_TRUE(isMaterialKey("grain_bonds.modulus_GPa"));
  EXPECT_TRUE(isMaterialKey("material.friction"));
  EXPECT_FALSE(isMaterialKey("numerics.threads"));
  EXPECT_FALSE(isMaterialKey("sample.count"));
}

}  // namespace
