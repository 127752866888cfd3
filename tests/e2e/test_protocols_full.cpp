// The long end-to-end runs (label full, `make test-full`): the quick twins of the 2D
// superparticle protocols under confinement, each the full protocol on 500 grains of the
// calibrated material, its loading density-scaled once the grains are at rest: a million
// loading steps and more each, the envelope sweep six of them. The rigs themselves run end to
// end in the default run, on a sample from a file (Protocols.EveryRigRunsOnASampleFromAFile).
// And the regression guard at all of each reference's seeds.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>

#include "tests/e2e/protocol_support.hpp"

namespace {

using namespace rocklab::testing;

// Figure 4 on the quick twin (500 grains of the calibrated material, its loading
// density-scaled once the confined grains are at rest): at 4 MPa the sample dilates to its
// peak and localises in a band inclined to sigma_1, the cement breaking mainly in tension.
// Measured over seeds 1-5, scaled and unscaled (campaigns/fewer-steps-shear-band-at-rest-2d.toml):
// tensile against shear breaks 163-523 against 106-215; the band at 22.25-53.25 deg (the
// scaled mean 36.5, sd 11.3; the paper: about 35), so one seed is held to 15-60 deg, where a
// compaction band would be beyond 70; its contrast 2.9-5.6. The rise of the shear breaks and
// the crushing from 4 to 18 MPa on one sample is the envelope sweep's
// (EnvelopeSweepGivesMohrCoulombLineAndCap).
TEST(QuickProtocols, LowConfinementLocalisesInAnInclinedBand) {
  Lab lab("shear-band");
  nb::Notebook n = runQuick(lab, "biaxial-shear-band-quick");
  EXPECT_EQ(scalar(n, "SELECT status FROM runs"), "completed");
  EXPECT_LT(result(n, "confining_stress_error_max"), 0.01);  // the servo's bound
  EXPECT_GT(result(n, "broken_bonds_tensile"), result(n, "broken_bonds_shear"));
  EXPECT_EQ(result(n, "critical_is_compaction"), 0.0);
  EXPECT_EQ(result(n, "band_is_compaction"), 0.0);
  EXPECT_GT(result(n, "band_angle_deg"), 15.0);
  EXPECT_LT(result(n, "band_angle_deg"), 60.0);
  EXPECT_GT(result(n, "band_contrast"), 2.5);  // a band, not diffuse strain
}

// Figure 5 on the compaction band's quick twin (500 grains of the calibrated material, its
// loading density-scaled once the confined grains are at rest, run to 2.5% strain). Measured over
// the reference's seeds 1-8: every critical point the onset of compactive yield and every band
// sought in the compaction field; the band at 48.5-89.75 deg (mean 76.9, sd 12.7; within 20
// deg of normal to sigma_1 at 7 of 8 seeds, so that share is the ensemble's result,
// campaigns/compaction-band-seeds.toml, not one seed's), its contrast 3.9-5.4; 108-147 of the
// 500 grains crushed; more cement bonds broken in shear than in tension on every seed, where
// at 4 MPa tension wins (LowConfinementLocalisesInAnInclinedBand).
TEST(QuickProtocols, HighConfinementCompactsInASteepBand) {
  Lab lab("compaction-band");
  nb::Notebook high = runQuick(lab, "biaxial-compaction-band-quick");
  EXPECT_EQ(scalar(high, "SELECT status FROM runs"), "completed");
  EXPECT_LT(result(high, "confining_stress_error_max"), 0.01);
  EXPECT_GT(result(high, "crushed_grains"), 0.1 * result(high, "grains"));
  EXPECT_GT(result(high, "broken_bonds_shear"), result(high, "broken_bonds_tensile"));
  EXPECT_GT(result(high, "volumetric_strain_at_peak"), 0.005);  // compaction, positive
  EXPECT_EQ(result(high, "critical_is_compaction"), 1.0);
  EXPECT_EQ(result(high, "band_in_compaction_field"), 1.0);
  EXPECT_GT(result(high, "band_angle_deg"), 45.0);  // steep: the 4 MPa bands average 36.5 deg
  EXPECT_GT(result(high, "band_contrast"), 3.0);    // a band, not diffuse compaction
  // The band of each twentieth of the strain range after the critical point is recorded. A
  // compaction band migrates along the sample (Olsson 1999; Baud et al. 2004): sharp in its
  // own strain window, smeared over the whole range. So the windows' bands are on average
  // more contrasted than the whole range's (measured at seeds 1-8: window means 3.2-3.9 against
  // range contrasts 2.3-2.9); a band that stayed in place would gather its strain in one zone
  // over the whole range and be sharpest there.
  const std::vector<double> window_contrast = seriesValues(high, "band_window_contrast");
  ASSERT_GE(window_contrast.size(), 5u);
  EXPECT_EQ(seriesValues(high, "band_window_angle_deg").size(), window_contrast.size());
  double window_mean = 0.0;
  for (double c : window_contrast) window_mean += c / static_cast<double>(window_contrast.size());
  EXPECT_GT(window_mean, result(high, "band_range_contrast"));
  // Every break is an event with its kind: intragranular breaks are the crushing.
  EXPECT_EQ(std::stod(scalar(high,
                             "SELECT count(*) FROM events WHERE granular = 'intra' AND "
                             "stage = 'loading'")),
            result(high, "broken_grain_bonds_tensile") + result(high, "broken_grain_bonds_shear"));
}

// Li & Holt Figure 6 from one sweep on the envelope's quick twin (500 grains of the calibrated
// material, six tests at 0-18 MPa on copies of one formed sample, each loading density-scaled
// once the confined grains are at rest): the Mohr-Coulomb line through the dilatant critical
// points and an end cap at high confinement. Measured over the reference's seeds 1-8: the
// friction angle 15.7-21.5 deg (mean 18.3, sd 2.2), the line's intercept 2-26% above the
// sweep's UCS test (7.0-9.7 MPa against 5.5-9.3); the critical point of the 18 MPa test
// compactive at every seed, of the 0 MPa test dilatant; the band at 4 MPa at 23-51.75 deg, at
// 18 MPa at 48.5-89.75 deg in the compaction field; shear breaks 0.22-0.41 of the cement's at
// 4 MPa, 0.54-0.63 at 18; 2-10 grains crushed at 0 MPa, 108-147 at 18; peak q 11.5-14.4 MPa at
// 4 MPa, 18.7-22.3 at 18. One run takes 15-21 minutes on one thread.
TEST(QuickProtocols, EnvelopeSweepGivesMohrCoulombLineAndCap) {
  Lab lab("envelope");
  nb::Notebook n = runQuick(lab, "triaxial-envelope-quick");
  EXPECT_EQ(scalar(n, "SELECT status FROM runs"), "completed");
  EXPECT_EQ(result(n, "tests"), 6.0);
  // Every test on a copy of the one formed sample: one formation, six confinements.
  EXPECT_EQ(std::stod(scalar(n,
                             "SELECT count(*) FROM results WHERE name LIKE "
                             "'test%.confining_stress_MPa'")),
            6.0);
  // Low confinement dilates at its peak, the highest compacts: the cap exists.
  EXPECT_EQ(result(n, "test1.critical_is_compaction"), 0.0);
  EXPECT_EQ(result(n, "test6.critical_is_compaction"), 1.0);
  EXPECT_GE(result(n, "envelope_points_compactive"), 1.0);
  EXPECT_GE(result(n, "envelope_points_dilatant"), 2.0);
  // The friction angle within about three standard deviations of the seeds' mean, and an
  // intercept near the sweep's own UCS test (within 35%: the line is a fit through scattered
  // peaks).
  EXPECT_GT(result(n, "friction_angle_deg"), 10.0);
  EXPECT_LT(result(n, "friction_angle_deg"), 30.0);
  EXPECT_NEAR(result(n, "mohr_coulomb_ucs_MPa"), result(n, "test1.ucs_MPa"),
              0.35 * result(n, "test1.ucs_MPa"));
  // The bands of Figures 4 and 5 in the sweep, held to the single tests' ranges
  // (LowConfinementLocalisesInAnInclinedBand, HighConfinementCompactsInASteepBand): inclined at
  // 4 MPa, steep and in the compaction field at 18 MPa.
  EXPECT_EQ(result(n, "test3.band_is_compaction"), 0.0);
  EXPECT_GT(result(n, "test3.band_angle_deg"), 15.0);
  EXPECT_LT(result(n, "test3.band_angle_deg"), 60.0);
  EXPECT_GT(result(n, "test6.band_angle_deg"), 45.0);
  EXPECT_EQ(result(n, "test6.band_in_compaction_field"), 1.0);
  // The cap: below the Mohr-Coulomb line at the highest confinement.
  const double phi = result(n, "friction_angle_deg") * M_PI / 180.0;
  const double N = (1 + std::sin(phi)) / (1 - std::sin(phi));
  EXPECT_LT(result(n, "test6.critical_deviatoric_stress_MPa"),
            (N - 1) * 18.0 + result(n, "mohr_coulomb_ucs_MPa"));
  // Figures 4 and 5 in the sweep: at low confinement the cement breaks mainly in tension, at
  // 18 MPa the share of shear breaks is far larger and grains crush.
  auto shear_share = [&](const std::string& test) {
    const double shear = result(n, test + ".broken_bonds_shear");
    return shear / (shear + result(n, test + ".broken_bonds_tensile"));
  };
  EXPECT_GT(result(n, "test3.broken_bonds_tensile"), result(n, "test3.broken_bonds_shear"));
  EXPECT_GT(shear_share("test6"), shear_share("test3") + 0.1);
  EXPECT_GT(result(n, "test6.crushed_grains"),
            2 * std::max(1.0, result(n, "test1.crushed_grains")));
  EXPECT_GT(result(n, "test6.peak_deviatoric_stress_MPa"),
            result(n, "test3.peak_deviatoric_stress_MPa"));
}

// The regression guard at every seed of each reference (issue 30). The default run holds each
// quick protocol at its own seed, where a key result is guarded only if one seed's interval,
// t(0.995, n - 1) s sqrt(1/n + 1) for a reference of n seeds, stays within 15% of the mean; a
// result that scatters more is named there as not guarded. Here the mean of all n seeds is held
// to the reference's, within t(0.995, n - 1) s sqrt(2/n): 1.75 s at 8 seeds, so results
// scattering up to 8.6% of their mean are guarded (16.6% at 20 seeds); one that scatters more
// still is not, and its reference file says so. Each protocol is a test of its own
// (--gtest_filter picks one), its seeds run one after the other on one thread: all of them take
// about as long as `make references` on one core, the envelope's alone 8 runs of 15-20 minutes.
std::vector<std::string> referencedProtocols() {
  std::vector<std::string> names;
  for (const auto& f : std::filesystem::directory_iterator(sourceDir() + "/tests/reference")) {
    if (f.path().extension() == ".toml") names.push_back(f.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

class GuardAtEverySeed : public ::testing::TestWithParam<std::string> {};

TEST_P(GuardAtEverySeed, HoldsTheMeanOfTheReferencesSeeds) {
  const std::string protocol = GetParam();
  const std::string reference = sourceDir() + "/tests/reference/" + protocol + ".toml";
  std::ifstream in(reference);
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  std::smatch m;
  ASSERT_TRUE(std::regex_search(text, m, std::regex(R"(\nseeds = \[([0-9, ]+)\])"))) << reference;
  const std::string seeds = m[1].str();
  Lab lab("guard-" + protocol);
  std::string out;
  const std::regex number("[0-9]+");
  for (std::sregex_iterator it(seeds.begin(), seeds.end(), number), end; it != end; ++it) {
    EXPECT_EQ(runRocklab("run " + sourceDir() + "/protocols/" + protocol +
                             ".toml --set protocol.seed=" + it->str() +
                             " --quiet --threads 1 --lab " + lab.path,
                         &out),
              0)
        << out;
  }
  EXPECT_EQ(runRocklab("regress check " + reference + " --lab " + lab.path, &out), 0) << out;
  removeLabFiles(lab);
}

INSTANTIATE_TEST_SUITE_P(QuickProtocols, GuardAtEverySeed,
                         ::testing::ValuesIn(referencedProtocols()), [](const auto& info) {
                           std::string name = info.param;
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

// Li & Holt section 4.1: the dynamic moduli from the velocities were "identical" to the
// static ones of small stress cycles in the elastic range. On the full-size sample (8,000
// spheres, 20 across, a P wavelength of 11 grains) at 0.5 and 2 MPa, before its cement
// breaks: rho vp_z^2 against the constrained modulus of a 1e-4 strain cycle, the strain
// the interior's. Measured over seeds 3, 4 and 5: 0.993, 0.952, 1.006 at 0.5 MPa and 1.059,
// 1.003, 1.055 at 2 MPa (sd 0.03), so one seed is held within 10%, about three of its
// standard deviations. On the quick twin's 1,500 spheres the P velocity is resolved to 10%
// only and the ratio reads 0.84 +- 0.05 over 8 seeds: this test would fail there.
TEST(FullProtocols, DynamicAndStaticModuliAgreeInTheElasticRange) {
  Lab lab("dynamic-static");
  std::string out;
  ASSERT_EQ(runRocklab("run " + sourceDir() +
                           "/protocols/ultrasonic-hydrostatic.toml --quiet --threads 2 "
                           "--set 'loading.stages_MPa=[0.5, 2.0]' --lab " +
                           lab.path,
                       &out),
            0)
      << out;
  const std::vector<std::string> stages = rows(
      lab.path,
      "SELECT s.value / d.value, e.value / v.value FROM series s JOIN series d ON d.run_id = "
      "s.run_id AND d.step = s.step AND d.name = 'modulus_z_dynamic_MPa' JOIN series v ON "
      "v.run_id = s.run_id AND v.step = s.step AND v.name = 'vp_z' JOIN series e ON e.run_id = "
      "s.run_id AND e.step = s.step AND e.name = 'vp_z_error' WHERE s.name = "
      "'modulus_z_static_MPa' ORDER BY s.step");
  ASSERT_EQ(stages.size(), 2u);
  for (const std::string& row : stages) {
    double ratio = 0.0, error = 0.0;
    ASSERT_EQ(std::sscanf(row.c_str(), "%lf|%lf", &ratio, &error), 2) << row;
    EXPECT_LT(error, 0.02) << "the P velocity resolved to 2%: " << row;
    EXPECT_NEAR(ratio, 1.0, 0.1) << "static over dynamic modulus: " << row;
  }
  removeLabFiles(lab);
}

}  // namespace
