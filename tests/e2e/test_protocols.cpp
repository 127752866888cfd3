// The quick protocols end to end: `rocklab run` into a fresh notebook, then what the paper's
// section 1 says must show, read back from the notebook with SQL. Tolerances are stated at
// each check; the measured values they guard are in the comments.

#include <gtest/gtest.h>

#include "tests/e2e/command.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <random>
#include <regex>
#include <thread>

#include "lab/core/packing_io.hpp"
#include "lab/notebook/queries.hpp"
#include "tests/e2e/protocol_support.hpp"

namespace {

using namespace rocklab::testing;

TEST(QuickProtocols, OedometerFormedUnderStressShowsFigures1And2) {
  Lab lab("oedometer");
  nb::Notebook n = runQuick(lab, "oedometer-formed-under-stress-quick");
  EXPECT_EQ(scalar(n, "SELECT status FROM runs"), "completed");

  // Non-linear: the tangent modulus falls as bonds break (measured 3.5 -> 2.0 GPa, ratio
  // 0.58; a linear material gives 1, and 0.8 leaves room for the scatter between seeds).
  EXPECT_LT(result(n, "tangent_modulus_ratio"), 0.8);
  // Bonds break from the start: the first break within the first 1% of the loading
  // (measured at the first record, 0.0001 of 0.04), and a good share by a tenth of it.
  EXPECT_LT(result(n, "axial_strain_at_first_break"), 0.01 * result(n, "axial_strain_final"));
  EXPECT_GT(result(n, "broken_bonds_by_tenth_of_loading"), 0.05 * result(n, "broken_bonds_total"));
  // The stress path steepens: d(lateral)/d(axial) grows (measured 0.11 -> 0.32, x3; ask for
  // x1.5).
  EXPECT_GT(result(n, "stress_path_slope_final"), 1.5 * result(n, "stress_path_slope_initial"));
  // The lateral stress rises slowly at first: below the elastic K0 of the formation state.
  EXPECT_LT(result(n, "stress_path_slope_initial"), 0.25);
  // An early cycle is nearly elastic, a late one markedly plastic (loading tangent over
  // unloading secant: measured 0.91 at 0.05% strain, 0.67 at 2%; 1 is elastic).
  EXPECT_GT(result(n, "cycle1_modulus_ratio"), 0.85);
  EXPECT_LT(result(n, "cycle2_modulus_ratio"), result(n, "cycle1_modulus_ratio") - 0.15);
  // Quasi-static control is measured: well under the warning limits.
  EXPECT_LT(result(n, "mean_unbalanced_force_ratio"), 0.02);
  EXPECT_LT(result(n, "max_inertial_number"), 1e-3);
  EXPECT_EQ(scalar(n, "SELECT count(*) FROM messages WHERE level = 'warning'"), "0");
  // Every break is an event with its mode, position and kind; counts agree with the results.
  EXPECT_EQ(std::stod(scalar(n,
                             "SELECT count(*) FROM events WHERE kind = 'bond_break' AND "
                             "stage = 'loading'")),
            result(n, "broken_bonds_total"));
  EXPECT_EQ(scalar(n, "SELECT count(*) FROM events WHERE mode NOT IN ('tensile', 'shear')"), "0");
  EXPECT_EQ(scalar(n, "SELECT count(DISTINCT granular) FROM events"), "1");
  // The parameters and stage timings are in the notebook.
  EXPECT_EQ(scalar(n, "SELECT unit FROM params WHERE key = 'formation.axial_stress_MPa'"), "MPa");
  EXPECT_NE(scalar(n, "SELECT count(*) FROM stage_timings WHERE stage = 'bonds'"), "0");
  // Formed under stress: the axial stress when cemented is the formation stress.
  EXPECT_NEAR(result(n, "axial_stress_after_formation_MPa"), 30.0, 0.3);
}

TEST(QuickProtocols, CoredSampleIsSofterAtFirstThanTheVirgin) {
  Lab lab("coring");
  nb::Notebook n = runQuick(lab, "oedometer-core-damage-quick");
  // Measured 0.57: coring broke most bonds (released the stress they were cemented under).
  EXPECT_LT(result(n, "cored_to_virgin_initial_modulus_ratio"), 0.8);
  EXPECT_GT(result(n, "broken_bonds_by_coring"), 0.3 * result(n, "bonds_installed"));
  // The cored sample has lost the virgin's non-linearity (ratio 1.04 against 0.57).
  EXPECT_GT(result(n, "cored.tangent_modulus_ratio"),
            result(n, "virgin.tangent_modulus_ratio") + 0.2);
  EXPECT_NE(scalar(n, "SELECT count(*) FROM series WHERE name = 'cored.axial_stress_MPa'"), "0");
  EXPECT_NE(scalar(n, "SELECT count(*) FROM series WHERE name = 'virgin.axial_stress_MPa'"), "0");
  EXPECT_NE(scalar(n, "SELECT count(*) FROM events WHERE stage = 'coring'"), "0");
}

std::string writeProtocol(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("rocklab-" + std::to_string(::getpid()) + "-" + name + ".toml");
  std::FILE* f = std::fopen(path.c_str(), "w");
  std::fputs(text.c_str(), f);
  std::fclose(f);
  return path.string();
}

const char* kSmallSample = R"(
[sample]
count = 400
size_distribution = "uniform"
d_min_mm = 0.8
d_max_mm = 1.2
porosity_initial = 0.42
[formation]
axial_stress_MPa = 10
lateral_stress_MPa = 5
)";

// Li & Holt section 2.3: the superparticle sample's UCS is 9.9 MPa, what its material was
// calibrated to at the paper's 1,500 grains (materials/superparticle-2d.toml). The quick
// sample's 500 grains sit lower, and one of them scatters more: over the reference's 20 seeds
// (tests/reference/biaxial-ucs-quick.toml) 8.52 MPa, 0.86 of the calibration's 9.95 at 1,500
// grains, with a standard deviation of 1.33 MPa. Held to 0.86 x 9.9 within two of those.
TEST(QuickProtocols, SuperparticleSampleHasThePapersUcs) {
  Lab lab("ucs");
  nb::Notebook n = runQuick(lab, "biaxial-ucs-quick");
  EXPECT_EQ(scalar(n, "SELECT status FROM runs"), "completed");
  EXPECT_NEAR(result(n, "ucs_MPa"), 0.86 * 9.9, 2 * 1.33);
  // Grains as generated: irregular, every one below the aspect limit (measured mean 1.26).
  EXPECT_LT(result(n, "grain_aspect_ratio_max"), 1.5);
  EXPECT_GT(result(n, "grain_aspect_ratio_mean"), 1.1);
  // Zero confinement: the lateral walls keep clear (judged against 1 MPa; measured 0.7%).
  EXPECT_LT(result(n, "confining_stress_error_max"), 0.01);
  // Unconfined, the cement fails, mainly in tension, and few grains crush (at 1,500 grains the
  // calibration's runs broke 4 to 6 times as many cement bonds in tension as in shear and
  // crushed 1.1-2.1% of their grains).
  EXPECT_GT(result(n, "broken_bonds_tensile"), 2 * result(n, "broken_bonds_shear"));
  EXPECT_LT(result(n, "crushed_grains"), 0.05 * result(n, "grains"));
}

// Rigid grains from a protocol (sample.kind = clumps): clumps of the grain shapes, cemented
// together, that crush whole into their pebbles at a characteristic stress F / d^2; every
// crushing is a notebook event (measured: 60 clumps at 18 MPa, a few crushed).
TEST(Protocols, ClumpSampleCrushesAndRecordsEachBreak) {
  Lab lab("clumps");
  const std::string file = writeProtocol("clumps", R"([protocol]
name = "clumps"
rig = "biaxial"
dimension = 2
[sample]
kind = "clumps"
count = 60
size_distribution = "phi"
phi_mean = 1.0
phi_std = 0.3
d_min_mm = 0.3
d_max_mm = 0.9
porosity_initial = 0.30
aspect_axial = 2.0
thickness_m = 0.001
[grains]
pebbles_across = 4
[clumps]
break_stress_MPa = 100
[material]
contact_law = "linear"
contact_modulus_GPa = 4.0
friction = 0.5
density_kg_per_m3 = 100000
[bonds]
enabled = true
modulus_GPa = 4.0
tensile_strength_mean_MPa = 33.0
shear_strength_mean_MPa = 33.0
[formation]
axial_stress_MPa = 1.0
lateral_stress_MPa = 1.0
friction = 0.0
[loading]
confining_stress_MPa = 18.0
axial_strain_rate_per_s = 5.0
axial_strain_max = 0.004
)");
  std::string out;
  ASSERT_EQ(
      rocklab::testing::runRocklab("run " + file + " --quiet --threads 1 --lab " + lab.path, &out),
      0)
      << out;
  nb::Notebook n(lab.path);
  EXPECT_EQ(scalar(n, "SELECT status FROM runs"), "completed");
  EXPECT_EQ(result(n, "grains"), 60.0);
  EXPECT_LT(result(n, "grain_aspect_ratio_max"), 1.5);
  EXPECT_GT(result(n, "crushed_grains"), 0.0);
  EXPECT_EQ(std::stod(scalar(n,
                             "SELECT count(*) FROM events WHERE kind = 'clump_break' AND "
                             "stage = 'loading'")),
            result(n, "crushed_grains"));
  // A clump holds its pebbles rigidly: no bonds inside grains, none broken there.
  EXPECT_EQ(scalar(n, "SELECT count(*) FROM results WHERE name = 'grain_bonds_installed'"), "0");
}

// A loading fast for the grains' inertia is flagged in the notebook, not passed off as a
// quasi-static test.
TEST(Protocols, FastLoadingIsFlaggedAsNotQuasiStatic) {
  Lab lab("fast");
  const std::string file = writeProtocol(
      "fast", std::string("[protocol]\nname = \"fast\"\nrig = \"oedometer\"\n") + kSmallSample +
                  "[loading]\naxial_strain_rate_per_s = 3000\naxial_strain_max = 0.01\n");
  std::string out;
  ASSERT_EQ(
      rocklab::testing::runRocklab("run " + file + " --quiet --threads 1 --lab " + lab.path, &out),
      0)
      << out;
  EXPECT_NE(out.find("warning: loading was not quasi-static"), std::string::npos) << out;
  nb::Notebook n(lab.path);
  EXPECT_NE(scalar(n,
                   "SELECT count(*) FROM messages WHERE level = 'warning' AND text LIKE "
                   "'%not quasi-static%'"),
            "0");
  EXPECT_GT(result(n, "max_inertial_number"), 1e-3);
  std::filesystem::remove(file);
}

// The oedometer's adaptive rate: up to rate_boost_max times the set rate while calm, the set
// rate while bonds break and through a cycle (a measurement); refused under stress control,
// which has no strain rate to boost.
TEST(Protocols, OedometerRateBoostsWhileCalmAndNeedsStrainControl) {
  Lab lab("oedometer-boost");
  const std::string head = std::string("[protocol]\nname = \"boost\"\nrig = \"oedometer\"\n") +
                           kSmallSample + "[loading]\nrate_boost_max = 4\n";
  const std::string file =
      writeProtocol("boost", head +
                                 "axial_strain_rate_per_s = 5\naxial_strain_max = 0.01\n"
                                 "cycle_at_axial_strain = [0.005]\n");
  std::string out;
  ASSERT_EQ(
      rocklab::testing::runRocklab("run " + file + " --quiet --threads 1 --lab " + lab.path, &out),
      0)
      << out;
  nb::Notebook n(lab.path);
  const std::string rates = "SELECT %s(value) FROM series WHERE name = 'axial_strain_rate_per_s'";
  auto rate = [&](const char* f) {
    char sql[128];
    std::snprintf(sql, sizeof sql, rates.c_str(), f);
    return std::stod(scalar(n, sql));
  };
  EXPECT_GT(rate("max"), 5.0 * 1.25 * 1.25);  // boosted while calm, 1.25 times per 100 steps
  EXPECT_LE(rate("max"), 20.0);               // at most 4 x 5 /s
  EXPECT_DOUBLE_EQ(rate("min"), -5.0);        // the cycle unloads at the set rate
  EXPECT_NE(scalar(n,
                   "SELECT count(*) FROM series WHERE name = 'axial_strain_rate_per_s' AND "
                   "value = 5"),
            "0");  // back at the set rate while the cement breaks
  const std::string refused = writeProtocol("boost-ramp", head + "control = \"stress_ramp\"\n");
  EXPECT_EQ(rocklab::testing::runRocklab("run " + refused + " --lab " + lab.path + "-ramp", &out),
            2);
  EXPECT_NE(out.find("loading.rate_boost_max: the rate boost needs loading.control = strain_rate"),
            std::string::npos)
      << out;
  std::filesystem::remove(file);
  std::filesystem::remove(refused);
}

// `rocklab run FILE` on one thread into the lab, with KEYS (" --set k=v ..."); its notebook.
nb::Notebook runWith(const std::string& file, const Lab& lab, const std::string& keys) {
  std::string out;
  EXPECT_EQ(rocklab::testing::runRocklab(
                "run " + file + " --quiet --threads 1 --lab " + lab.path + keys, &out),
            0)
      << out;
  return nb::Notebook(lab.path);
}

// The densification's own damping (formation.local_damping) and its end by porosity
// (formation.densified_porosity_change): the densification runs at its damping, what comes
// after at numerics.local_damping again, and a porosity that stops falling ends it.
TEST(Protocols, DensificationHasItsOwnDampingAndEndsWhenItsPorosityStopsFalling) {
  const std::string head = std::string("[protocol]\nname = \"densify\"\nrig = \"oedometer\"\n") +
                           kSmallSample + "[loading]\naxial_strain_max = 0.002\n";
  // Any fall below 5% in 200 steps ends it: at the first window with the walls at stress.
  const std::string stall =
      " --set formation.local_damping=0.3 --set formation.densified_porosity_change=0.05"
      " --set formation.densified_window_steps=200";
  const std::string file = writeProtocol("densify", head);
  auto run = [&](const Lab& lab, const std::string& keys) { return runWith(file, lab, keys); };
  Lab a("densify-a"), b("densify-b"), c("densify-c");
  nb::Notebook na = run(a, stall), nb = run(b, stall + " --set numerics.local_damping=0.3"),
               nc = run(c, "");
  const std::string ended =
      "SELECT count(*) FROM messages WHERE text LIKE 'densification ended by its porosity%'";
  EXPECT_EQ(scalar(na, ended), "1");
  EXPECT_EQ(scalar(nc, ended), "0");
  EXPECT_LT(result(na, "formation_steps"), result(nc, "formation_steps"));
  const std::string path =
      "SELECT group_concat(step || ':' || value, ' ') FROM series WHERE "
      "name = 'densification.porosity'";
  EXPECT_EQ(scalar(na, path), scalar(nb, path));  // the densification at its own damping
  EXPECT_NE(scalar(na, path).substr(0, 40), scalar(nc, path).substr(0, 40));
  const std::string hash = "SELECT text FROM messages WHERE text LIKE 'final state hash%'";
  EXPECT_NE(scalar(na, hash), scalar(nb, hash));  // the loading at numerics.local_damping
  std::filesystem::remove(file);
}

// The formation's own density scaling (formation.density_scaling): at 1 the sample forms as
// it does unscaled whatever numerics.density_scaling gives the loading, bit for bit, and
// that loading then takes fewer steps; at 4 the formation itself is another path.
TEST(Protocols, TheFormationHasItsOwnDensityScaling) {
  const std::string file =
      writeProtocol("scaled", std::string("[protocol]\nname = \"scaled\"\nrig = \"oedometer\"\n") +
                                  kSmallSample + "[loading]\naxial_strain_max = 0.004\n");
  auto run = [&](const Lab& lab, const std::string& keys) { return runWith(file, lab, keys); };
  Lab a("scaled-a"), b("scaled-b"), c("scaled-c");
  nb::Notebook na = run(a, ""), nb = run(b, " --set numerics.density_scaling=4"),
               nc = run(c, " --set formation.density_scaling=4");
  const std::string formed =
      "SELECT group_concat(name || '=' || value, ' ') FROM results WHERE name IN "
      "('formation_steps', 'porosity_after_formation', 'coordination_after_formation')";
  EXPECT_EQ(scalar(na, formed), scalar(nb, formed));
  EXPECT_NE(scalar(na, formed), scalar(nc, formed));
  EXPECT_LT(result(nb, "loading_steps"), 0.75 * result(na, "loading_steps"));
  // the loading unscaled: as many steps as unscaled, to the sample's change of its step
  EXPECT_NEAR(result(nc, "loading_steps") / result(na, "loading_steps"), 1.0, 0.1);
  std::filesystem::remove(file);
}

// The confinement held until the grains are at rest (loading.rest_speed_ratio): the
// loading then starts from the stresses the confinement holds, q at the seating stress. Let
// go as soon as the stresses are on target and the forces in balance, a density-scaled
// sample is still straining from the confinement ramp, and its loading starts about 0.15
// MPa higher (measured at 250 grains: 0.25 against 0.12; at 500 the scaled shear band test
// began 0.45 MPa high). q at zero strain is the intercept of a line through the records of
// the first 0.3 millistrain, where the sample is elastic.
TEST(Protocols, AConfinementHeldUntilAtRestStartsTheLoadingFromItsStresses) {
  Lab lab("at-rest");
  auto run = [&](const std::string& ratio) {
    std::string out;
    EXPECT_EQ(runRocklab("run " + sourceDir() +
                             "/protocols/biaxial-shear-band.toml --quiet --threads 1 --set "
                             "sample.count=250 --set formation.reuse=true --set "
                             "numerics.density_scaling=4 --set loading.axial_strain_max=0.0003 "
                             "--set loading.stop_after_drop=0 --set loading.rest_speed_ratio=" +
                             ratio + " --lab " + lab.path,
                         &out),
              0)
        << out;
  };
  run("0");  // forms the sample, both runs load it
  run("0.1");
  nb::Notebook n(lab.path);
  auto startingQ = [&](int id) {
    const auto t = nb::query(
        n,
        "SELECT e.value, q.value FROM series e JOIN series q ON q.run_id = e.run_id AND q.step "
        "= e.step AND q.name = 'deviatoric_stress_MPa' WHERE e.name = 'axial_strain' AND "
        "e.run_id = " +
            std::to_string(id) + " ORDER BY e.step");
    double se = 0, sq = 0, see = 0, seq = 0;
    const double k = static_cast<double>(t.rows.size());
    for (const auto& row : t.rows) {
      se += row[0].real, sq += row[1].real;
      see += row[0].real * row[0].real, seq += row[0].real * row[1].real;
    }
    EXPECT_GE(k, 10.0);
    const double slope = (k * seq - se * sq) / (k * see - se * se);
    return (sq - slope * se) / k;
  };
  const double seating = std::stod(scalar(
      n, "SELECT value FROM params WHERE run_id = 2 AND key = 'loading.seating_stress_MPa'"));
  // The servo holds each wall within formation.stress_tolerance (1%) of its target: q within
  // 1% of sigma_3 + seating plus 1% of sigma_3 (4 MPa) of the seating stress.
  const double tolerance = 0.01 * (4.0 + seating) + 0.01 * 4.0;
  EXPECT_NEAR(startingQ(2), seating, tolerance);
  EXPECT_GT(startingQ(1), seating + tolerance);  // let go straining: what the hold is for
}

// The same rig with disks (2D), driven by a stress ramp.
TEST(Protocols, DisksUnderAStressRamp) {
  Lab lab("disks");
  const std::string file = writeProtocol(
      "disks", std::string("[protocol]\nname = \"disks\"\nrig = \"oedometer\"\ndimension = 2\n") +
                   kSmallSample +
                   "[loading]\ncontrol = \"stress_ramp\"\naxial_stress_rate_MPa_per_s = 20000\n"
                   "axial_stress_max_MPa = 40\n");
  std::string out;
  ASSERT_EQ(
      rocklab::testing::runRocklab("run " + file + " --quiet --threads 1 --lab " + lab.path, &out),
      0)
      << out;
  nb::Notebook n(lab.path);
  EXPECT_NEAR(result(n, "axial_stress_final_MPa"), 40.0, 0.5);
  EXPECT_GT(result(n, "axial_strain_final"), 0.0);
  EXPECT_GT(result(n, "broken_bonds_total"), 0.0);
  EXPECT_EQ(scalar(n, "SELECT count(*) FROM series WHERE name = 'lateral_stress_x_MPa'"), "0");
  std::filesystem::remove(file);
}

// Simulate only what a scene calls for (house rule 4, README.md): a dry, uncemented sample
// runs contacts and nothing else, and a key for an effect its rig cannot use is refused
// with the rig it belongs to.
TEST(Protocols, ADryUncementedSceneRunsOnlyTheStagesItCallsFor) {
  Lab lab("dry");
  const std::string head = "[protocol]\nname = \"dry\"\nrig = \"hydrostatic\"\n";
  const std::string body = std::string(kSmallSample) +
                           "[bonds]\nenabled = false\n[loading]\nstress_max_MPa = 20\n"
                           "stress_rate_MPa_per_s = 20000\n";
  const std::string file = writeProtocol("dry", head + body);
  std::string out;
  ASSERT_EQ(
      rocklab::testing::runRocklab("run " + file + " --quiet --threads 1 --lab " + lab.path, &out),
      0)
      << out;
  nb::Notebook n(lab.path);
  EXPECT_NE(scalar(n, "SELECT calls FROM stage_timings WHERE stage = 'contacts'"), "");
  EXPECT_EQ(scalar(n,
                   "SELECT count(*) FROM stage_timings WHERE stage IN ('bonds', 'flow', "
                   "'flow_network', 'flow_solve', 'waves', 'static_cycles')"),
            "0");
  EXPECT_EQ(scalar(n, "SELECT count(*) FROM results WHERE name LIKE '%bond%' AND value > 0"), "0");

  const std::string wet = writeProtocol(
      "wet", head + body + "[wave]\nfrequency_kHz = 100\n[flow]\nupdate_every_steps = 10\n");
  Lab refused("refused");
  EXPECT_EQ(rocklab::testing::runRocklab("run " + wet + " --lab " + refused.path, &out), 2);
  EXPECT_NE(out.find("'wave.frequency_kHz' is a key of the ultrasonic rig: the hydrostatic rig "
                     "has no use for it"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("'flow.update_every_steps' is a key of the permeameter rig"),
            std::string::npos)
      << out;
  EXPECT_FALSE(std::filesystem::exists(refused.path));
  std::filesystem::remove(file);
  std::filesystem::remove(wet);
}

TEST(Protocols, InvalidProtocolWritesNothing) {
  Lab lab("invalid");
  const auto bad = std::filesystem::temp_directory_path() /
                   ("rocklab-bad-" + std::to_string(::getpid()) + ".toml");
  {
    std::FILE* f = std::fopen(bad.c_str(), "w");
    std::fputs(
        "[protocol]\nname = \"x\"\nrig = \"oedometer\"\n[sample]\ncount = 100\n"
        "[formation]\naxial_stress_MPa = -30\n",
        f);
    std::fclose(f);
  }
  std::string out;
  EXPECT_EQ(rocklab::testing::runRocklab("run " + bad.string() + " --lab " + lab.path, &out), 2);
  EXPECT_NE(out.find(bad.string() + ":7: formation.axial_stress_MPa = -30 is outside the allowed "
                                    "range (0, 10000] (MPa)"),
            std::string::npos)
      << out;
  EXPECT_FALSE(std::filesystem::exists(lab.path));
  EXPECT_EQ(rocklab::testing::runRocklab("check " + bad.string(), &out), 2);
  std::filesystem::remove(bad);
  EXPECT_EQ(rocklab::testing::runRocklab(
                "check " + sourceDir() + "/protocols/oedometer-formed-under-stress.toml", &out),
            0)
      << out;
}

// A study end to end on the cheapest quick protocol: two settings of the re-triangulation
// threshold at two seeds each, every run in the notebook with its value and seed, compared
// on the key results' means against the seed scatter.
TEST(Protocols, AccuracyStudyRunsTheLadderAndReportsIt) {
  Lab lab("study");
  const std::string out_dir = lab.path + ".study";
  std::string out;
  ASSERT_EQ(rocklab::testing::runRocklab(
                "study accuracy " + sourceDir() +
                    "/protocols/permeameter-hydrostatic-3d-quick.toml --quiet --threads 1"
                    " --vary flow.retriangulate_displacement_radii=0.25,2 --seeds 2"
                    " --tolerance 50 --lab " +
                    lab.path + " --out " + out_dir,
                &out),
            0)
      << out;
  EXPECT_NE(out.find("cheapest within 50%: run "), std::string::npos) << out;
  EXPECT_NE(out.find("beyond the scatter of 2 seeds"), std::string::npos) << out;
  nb::Notebook n(lab.path);
  EXPECT_EQ(scalar(n,
                   "SELECT group_concat(a.value || '@' || b.value, ' ') FROM (SELECT run_id, value "
                   "FROM params WHERE key = 'flow.retriangulate_displacement_radii') a JOIN "
                   "(SELECT run_id, value FROM params WHERE key = 'protocol.seed') b USING "
                   "(run_id) ORDER BY run_id"),
            "0.25@12 0.25@13 2@12 2@13");
  EXPECT_EQ(scalar(n, "SELECT count(*) FROM runs WHERE status = 'completed'"), "4");
  std::ifstream page(out_dir + "/index.html");
  const std::string html((std::istreambuf_iterator<char>(page)), {});
  EXPECT_NE(html.find("flow.retriangulate_displacement_radii = 2"), std::string::npos);
  EXPECT_NE(html.find("k_over_k0_final"), std::string::npos);
  EXPECT_NE(html.find("Each setting ran at 2 seeds"), std::string::npos);
  EXPECT_GT(std::filesystem::file_size(out_dir + "/cost-accuracy.png"), 5000u);
  std::filesystem::remove_all(out_dir);
  std::filesystem::remove_all(lab.path + ".files");
}

// The regression check on runs whose key results are known, at seeds 4 and 5 of a reference
// at seeds 4 to 11: the mean of the checked seeds' values is held to the reference's mean within
// t(0.995, 7) s sqrt(1/8 + 1/m); beyond it (or with a key result a run did not record) the
// check fails and names the key result, and a key result that scatters beyond 15% of its
// mean at the seeds checked is not guarded. A reference without seeds (an older rocklab's)
// or with values that do not match them is refused.
TEST(Protocols, RegressCheckHoldsTheSeedsMeanToTheReferences) {
  Lab lab("regress");
  {
    nb::Notebook n(lab.path);
    for (const auto& [seed, ucs] : {std::pair{4, 9.8}, {5, 10.6}, {20, 1.0}}) {
      nb::RunInfo info;
      info.protocol = "biaxial-ucs-quick";
      info.rig = "biaxial";
      info.seed = seed;
      nb::RunWriter w(n, info, {{"protocol.key_results", "[\"ucs_MPa\"]", ""}});
      w.result("ucs_MPa", ucs, "MPa");
      w.result("test2.ucs_MPa", 7.0, "MPa");
      w.finish(nb::RunStatus::Completed);
    }
  }
  auto check = [&](const std::string& results, const std::string& run = "") {
    const std::string ref = writeProtocol(
        "reference",
        "protocol = \"biaxial-ucs-quick\"\nseeds = [4, 5, 6, 7, 8, 9, 10, 11]\n" + results);
    std::string out;
    const int code =
        rocklab::testing::runRocklab("regress check " + ref + " --lab " + lab.path + run, &out);
    return std::pair{code, out};
  };
  // Mean 10 + shift, standard deviation 0.2: at two seeds +- 0.5533, at one +- 0.7424.
  auto ucs = [](double shift) {
    std::string v = "[results.ucs_MPa]\nunit = \"MPa\"\nvalues = [";
    for (double x : {10.0, 10.2, 9.8, 10.1, 9.9, 10.0, 10.3, 9.7}) {
      v += std::to_string(x + shift) + (x == 9.7 ? "]\n" : ", ");
    }
    return v;
  };
  auto [code, out] = check(ucs(0.7));  // seeds 4 and 5: mean 10.2, 0.5 from 10.7
  EXPECT_EQ(code, 0) << out;
  EXPECT_NE(out.find("at seeds 4 (run 1, completed), 5 (run 2, completed)"), std::string::npos)
      << out;
  EXPECT_NE(out.find("ok   ucs_MPa = 10.2 MPa, reference 10.7 +- 0.5533169 MPa"), std::string::npos)
      << out;
  std::tie(code, out) = check(ucs(0.8));
  EXPECT_EQ(code, 1) << out;
  EXPECT_NE(out.find("FAIL ucs_MPa = 10.2 MPa, reference 10.8 +- 0.5533169 MPa"), std::string::npos)
      << out;
  // One run: its own value, the interval of one seed.
  std::tie(code, out) = check(ucs(0.3), " --run 1");  // 9.8, 0.5 from 10.3
  EXPECT_EQ(code, 0) << out;
  EXPECT_NE(out.find("ucs_MPa = 9.8 MPa, reference 10.3 +- 0.7423525 MPa"), std::string::npos)
      << out;
  std::tie(code, out) = check(ucs(0.7), " --run 3");
  EXPECT_EQ(code, 2) << out;
  EXPECT_NE(out.find("not at a seed of the reference"), std::string::npos) << out;
  // Scattered beyond 15% at two seeds: named, not failed; not recorded: failed.
  std::tie(code, out) = check(
      "[results.ucs_MPa]\nvalues = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]\n"
      "[results.band_angle_deg]\nvalues = [30.0, 30.1, 29.9, 30.0, 30.0, 30.2, 29.8, 30.0]\n");
  EXPECT_EQ(code, 1) << out;
  EXPECT_NE(out.find("--   ucs_MPa = 10.2: not guarded at 2 seeds"), std::string::npos) << out;
  EXPECT_NE(out.find("FAIL band_angle_deg = not recorded"), std::string::npos) << out;
  // A prefixed name, quoted as written or unquoted (TOML's nested tables).
  for (const char* name : {"\"test2.ucs_MPa\"", "test2.ucs_MPa"}) {
    std::tie(code, out) = check(std::string("[results.") + name +
                                "]\nvalues = [9.0, 9.1, 8.9, 9.0, 9.0, 9.1, 8.9, 9.0]\n");
    EXPECT_EQ(code, 1) << out;
    EXPECT_NE(out.find("FAIL test2.ucs_MPa = 7.0"), std::string::npos) << out;
  }
  std::tie(code, out) = check("[results.ucs_MPa]\nvalues = [9.8, 10.6]\n");
  EXPECT_EQ(code, 2) << out;
  EXPECT_NE(out.find("2 values for 8 seeds"), std::string::npos) << out;
  const std::string old = writeProtocol("reference",
                                        "protocol = \"biaxial-ucs-quick\"\n[results.ucs_MPa]\n"
                                        "value = 9.8\ntolerance = 0.5\n");
  EXPECT_EQ(rocklab::testing::runRocklab("regress check " + old + " --lab " + lab.path, &out), 2);
  EXPECT_NE(out.find("an older rocklab"), std::string::npos) << out;
}

// The guard has teeth. The cemented oedometer sample of Figures 1 and 2, run at its own seed
// and checked there (one seed's interval: t(0.995, 7) s sqrt(1/8 + 1)), with one change of
// the physics of a few percent, fails it; with a change of rounding alone (the time step one
// part in ten billion shorter, which sends the sample down another path as another seed
// would, but leaves the material as it was) it passes. Measured on the references of
// tests/reference: the cement 5% weaker (mean 8 -> 7.6 MPa) leaves 5,108 broken bonds where
// the eight seeds give 5,302 +- 109; the grain friction 0.5 -> 0.45 a final lateral stress of
// 33.64 MPa where they give 33.00 +- 0.36.
namespace guard {

struct Checked {
  int code;
  std::string out;
};

// The quick oedometer protocol at its own seed with `sets`, checked against its reference.
Checked checkOedometerWith(const std::string& name, const std::string& sets) {
  Lab lab("guard-" + name);
  std::string out;
  EXPECT_EQ(rocklab::testing::runRocklab("run " + sourceDir() +
                                             "/protocols/oedometer-formed-under-stress-quick.toml" +
                                             sets + " --quiet --threads 1 --lab " + lab.path,
                                         &out),
            0)
      << out;
  const int code = rocklab::testing::runRocklab(
      "regress check " + sourceDir() +
          "/tests/reference/oedometer-formed-under-stress-quick.toml --lab " + lab.path,
      &out);
  removeLabFiles(lab);
  return {code, out};
}

TEST(Protocols, TheGuardFailsACement5PercentWeaker) {
  const auto [code, out] = checkOedometerWith(
      "cement",
      " --set bonds.tensile_strength_mean_MPa=7.6 --set bonds.shear_strength_mean_MPa=7.6");
  EXPECT_EQ(code, 1) << out;
  EXPECT_NE(out.find("FAIL broken_bonds_total"), std::string::npos) << out;
}

TEST(Protocols, TheGuardFailsAGrainFriction10PercentLower) {
  const auto [code, out] = checkOedometerWith("friction", " --set material.friction=0.45");
  EXPECT_EQ(code, 1) << out;
  EXPECT_NE(out.find("FAIL lateral_stress_final_MPa"), std::string::npos) << out;
}

TEST(Protocols, TheGuardPassesAChangeOfRounding) {
  const auto [code, out] =
      checkOedometerWith("rounding", " --set numerics.timestep_safety=0.49999999995");
  EXPECT_EQ(code, 0) << out;
  EXPECT_EQ(out.find("FAIL"), std::string::npos) << out;
}

}  // namespace guard

namespace resume {

// Starts `rocklab ARGS` as a child process.
pid_t start(const std::vector<std::string>& args) {
  const pid_t pid = fork();
  if (pid == 0) {
    std::vector<char*> argv{const_cast<char*>(ROCKLAB_BINARY)};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    std::freopen("/dev/null", "w", stderr);
    execv(ROCKLAB_BINARY, argv.data());
    _exit(127);
  }
  return pid;
}

// Waits until the run has recorded a series named like `series`; false if it ended first.
bool recording(pid_t pid, const std::string& lab, const std::string& series) {
  const std::string started = "SELECT 1 FROM series WHERE name LIKE '" + series + "' LIMIT 1";
  for (;;) {
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) return false;
    try {
      if (rows(lab, started).size() == 1) return true;
    } catch (const std::exception&) {  // the notebook is not there yet
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

// Kills the run with SIGKILL `delay_s` after its loading has begun to reach the notebook (a
// series named like `loading_series`), as a node lost or a wall-clock limit would; false if
// it ended first.
bool killDuringLoading(pid_t pid, const std::string& lab, double delay_s,
                       const std::string& loading_series = "loading.%") {
  if (!recording(pid, lab, loading_series)) return false;
  std::this_thread::sleep_for(std::chrono::duration<double>(delay_s));
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFSIGNALED(status);
}

// `rocklab run` of a quick protocol on one thread, checkpointing every 0.2 s, with `sets`.
std::vector<std::string> checkpointedRun(const std::string& protocol, const std::string& lab,
                                         const std::vector<std::string>& sets) {
  std::vector<std::string> args = {"run",
                                   sourceDir() + "/protocols/" + protocol + ".toml",
                                   "--quiet",
                                   "--threads",
                                   "1",
                                   "--set",
                                   "output.checkpoint_every_s=0.2"};
  for (const auto& s : sets) args.insert(args.end(), {"--set", s});
  args.insert(args.end(), {"--lab", lab});
  return args;
}

std::vector<std::string> quickHydrostatic(const std::string& lab) {
  return checkpointedRun("hydrostatic-quick", lab, {"sample.count=600"});
}

// The same with its loading density-scaled: the masses and the step change after the formation.
std::vector<std::string> scaledHydrostatic(const std::string& lab) {
  return checkpointedRun("hydrostatic-quick", lab,
                         {"sample.count=600", "numerics.density_scaling=4"});
}

// A biaxial test in the permeameter: the fluid's networks and pressures (applied to the
// particles) carried through the checkpoints of the loading loop.
std::vector<std::string> quickPermeameter(const std::string& lab) {
  return checkpointedRun(
      "permeameter-anisotropy-2d-quick", lab,
      {"flow.direction=along", "flow.apply_forces=true", "flow.compare_solvers=false"});
}

double randomDelay(double lo, double hi) {
  std::mt19937 rng(std::random_device{}());
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

// Runs `run(lab)` through, and again killed `lo` to `hi` s into its loading (its first
// series named like `loading_series`); resumes the killed one on two threads and compares it
// with the first. Returns what the resume printed and the number of reference and resumed
// runs that took a formed sample from the lab (formation.reuse).
struct Resumed {
  std::string out;
  int from_formed = 0;
};
template <class Run>
Resumed killedAndResumed(const std::string& name, Run run, double lo, double hi,
                         const std::string& loading_series = "loading.%") {
  Lab reference(name + "-reference"), killed(name + "-killed");
  std::string out;
  start(run(reference.path));
  int status = 0;
  wait(&status);
  EXPECT_EQ(WEXITSTATUS(status), 0);
  const double delay = randomDelay(lo, hi);
  SCOPED_TRACE("killed " + std::to_string(delay) + " s into the loading");
  if (killDuringLoading(start(run(killed.path)), killed.path, delay, loading_series)) {
    EXPECT_EQ(
        rocklab::testing::runRocklab("resume 1 --quiet --threads 2 --lab " + killed.path, &out), 0)
        << out;
    expectSameRun(reference.path, killed.path);
  } else {
    ADD_FAILURE() << "the run ended before it was killed";
  }
  int from_formed = 0;
  for (const Lab* lab : {&reference, &killed}) {
    from_formed += std::stoi(rows(lab->path,
                                  "SELECT count(*) FROM messages WHERE text LIKE "
                                  "'formation.reuse: the sample formed by an earlier run%'")
                                 .at(0));
  }
  return {out, from_formed};
}

}  // namespace resume

// SIGTERM during a run: the run is closed as interrupted, with what it recorded until then.
TEST(Protocols, SigtermLeavesAnInterruptedRunWithItsData) {
  Lab lab("sigterm");
  const pid_t pid =
      resume::start({"run", sourceDir() + "/protocols/oedometer-formed-under-stress-quick.toml",
                     "--quiet", "--threads", "1", "--lab", lab.path});
  ASSERT_TRUE(resume::recording(pid, lab.path, "%"));
  kill(pid, SIGTERM);
  int status = 0;
  waitpid(pid, &status, 0);
  EXPECT_EQ(WEXITSTATUS(status), 130);
  nb::Notebook n(lab.path);
  EXPECT_EQ(scalar(n, "SELECT status || ': ' || reason FROM runs"),
            "interrupted: terminated (SIGTERM)");
  EXPECT_NE(scalar(n, "SELECT count(*) FROM series"), "0");
}

// `regress update --jobs 2` runs the seeds two at a time, each in a process of its own whose
// notebook is merged into the lab: the same reference file as one run after the other (every
// value, bit for bit), the runs in the lab with the shard each came from, no shard left. Run
// again with more seeds, either way, it keeps the runs the lab has and runs the rest. A
// SIGTERM to the update alone reaches its runs: it ends with 130 and writes no reference, its
// runs interrupted in the lab with what they recorded.
TEST(Protocols, RegressUpdateRunsTheSeedsAtOnceToTheSameReference) {
  Lab one("update-one"), two("update-two"), stopped("update-stopped");
  const std::string protocol = writeProtocol(
      "tiny-ucs", "base = \"" + sourceDir() +
                      "/protocols/biaxial-ucs-hand-set.toml\"\n[protocol]\nname = \"tiny-ucs\"\n"
                      "[sample]\ncount = 60\n");
  // The reference file an update at `seeds` seeds (0: no --seeds) writes; what it printed in
  // `out`.
  auto update = [&](const Lab& lab, int seeds, const std::string& jobs, std::string& out) {
    const std::string count = seeds > 0 ? " --seeds " + std::to_string(seeds) : "";
    EXPECT_EQ(
        rocklab::testing::runRocklab("regress update " + protocol + count + " --threads 1 --out " +
                                         lab.path + ".ref --lab " + lab.path + jobs,
                                     &out),
        0)
        << out;
    std::ifstream in(lab.path + ".ref/tiny-ucs.toml");
    return std::string((std::istreambuf_iterator<char>(in)), {});
  };
  std::string out;
  const std::string sequential = update(one, 2, "", out);
  const std::string at_once = update(two, 2, " --jobs 2", out);
  EXPECT_NE(sequential.find("seeds = [1, 2]"), std::string::npos) << sequential;
  EXPECT_EQ(at_once, sequential);
  EXPECT_EQ(rows(two.path, "SELECT seed, status FROM runs ORDER BY seed"),
            (std::vector<std::string>{"1|completed|", "2|completed|"}));
  EXPECT_EQ(rows(two.path,
                 "SELECT count(*) FROM run_origins WHERE notebook LIKE "
                 "'%.regress/tiny-ucs-seed-_.sqlite'"),
            std::vector<std::string>{"2|"});
  EXPECT_FALSE(std::filesystem::exists(two.path + ".regress"));
  // Run again with a third seed, both ways: the seeds the lab has from this build are kept,
  // only the new one runs, to the same file.
  const std::string three = update(one, 3, "", out);
  EXPECT_NE(three.find("seeds = [1, 2, 3]"), std::string::npos) << three;
  for (const Lab* lab : {&one, &two}) {
    if (lab == &two) {
      EXPECT_EQ(update(two, 3, " --jobs 2", out), three);
    }
    for (const char* seed : {"1", "2"}) {
      EXPECT_TRUE(std::regex_search(out, std::regex(std::string("seed ") + seed +
                                                    " is run [12] of the lab, completed by "
                                                    "this build: kept")))
          << out;
    }
    EXPECT_EQ(out.find("seed 3 is run"), std::string::npos) << out;
    EXPECT_EQ(rows(lab->path, "SELECT seed, status FROM runs ORDER BY seed"),
              (std::vector<std::string>{"1|completed|", "2|completed|", "3|completed|"}));
  }
  // Written again without --seeds, a reference keeps its count of seeds (here every one kept).
  EXPECT_EQ(update(one, 0, "", out), three);
  EXPECT_NE(out.find("seed 3 is run 3 of the lab, completed by this build: kept"),
            std::string::npos)
      << out;

  const pid_t pid =
      resume::start({"regress", "update", protocol, "--seeds", "2", "--threads", "1", "--jobs", "2",
                     "--out", stopped.path + ".ref", "--lab", stopped.path});
  ASSERT_TRUE(resume::recording(pid, stopped.path + ".regress/tiny-ucs-seed-1.sqlite", "%"));
  kill(pid, SIGTERM);
  int status = 0;
  waitpid(pid, &status, 0);
  EXPECT_EQ(WEXITSTATUS(status), 130);
  EXPECT_FALSE(std::filesystem::exists(stopped.path + ".ref/tiny-ucs.toml"));
  EXPECT_EQ(rows(stopped.path, "SELECT status FROM runs WHERE seed = 1"),
            std::vector<std::string>{"interrupted|"});
  EXPECT_NE(rows(stopped.path,
                 "SELECT count(*) FROM series s JOIN runs r ON r.id = s.run_id "
                 "WHERE r.seed = 1"),
            std::vector<std::string>{"0|"});
  for (const Lab* lab : {&one, &two, &stopped}) {
    std::filesystem::remove_all(lab->path + ".ref");
    std::filesystem::remove_all(lab->path + ".regress");
  }
  std::filesystem::remove(protocol);
}

// A run killed (SIGKILL) at a random moment of its loading and resumed ends as the run that
// was never killed: the same final state, every record once (the delay after the loading's
// first records is drawn anew each time; it is printed when the test fails).
TEST(Protocols, AKilledRunResumesToTheUninterruptedRunOnceOrTwice) {
  Lab reference("resume-reference"), killed("resume-killed"), twice("resume-twice");
  std::string out;
  ASSERT_EQ(resume::start(resume::quickHydrostatic(reference.path)) > 0, true);
  int status = 0;
  wait(&status);
  ASSERT_EQ(WEXITSTATUS(status), 0);
  std::mt19937 rng(std::random_device{}());
  {
    const double delay = std::uniform_real_distribution<double>(0.0, 2.0)(rng);
    SCOPED_TRACE("killed " + std::to_string(delay) + " s into the loading");
    ASSERT_TRUE(resume::killDuringLoading(resume::start(resume::quickHydrostatic(killed.path)),
                                          killed.path, delay));
    EXPECT_EQ(rows(killed.path, "SELECT status FROM runs"), std::vector<std::string>{"running|"});
    ASSERT_EQ(
        rocklab::testing::runRocklab("resume 1 --quiet --threads 2 --lab " + killed.path, &out), 0)
        << out;
    EXPECT_NE(out.find("resumes from unit"), std::string::npos) << out;
    expectSameRun(reference.path, killed.path);
    // The completed run keeps no checkpoints and cannot be resumed again.
    EXPECT_FALSE(std::filesystem::exists(killed.path + ".files/run-1/checkpoints"));
    EXPECT_EQ(rocklab::testing::runRocklab("resume 1 --lab " + killed.path, &out), 2);
    EXPECT_NE(out.find("completed: nothing to resume"), std::string::npos) << out;
  }
  {
    // Killed twice in one run, the second time while it was resuming.
    const double first = std::uniform_real_distribution<double>(0.0, 1.0)(rng);
    const double second = std::uniform_real_distribution<double>(0.3, 1.5)(rng);
    SCOPED_TRACE("killed " + std::to_string(first) + " s into the loading, then " +
                 std::to_string(second) + " s after resuming");
    ASSERT_TRUE(resume::killDuringLoading(resume::start(resume::quickHydrostatic(twice.path)),
                                          twice.path, first));
    const pid_t again =
        resume::start({"resume", "1", "--quiet", "--threads", "1", "--lab", twice.path});
    std::this_thread::sleep_for(std::chrono::duration<double>(second));
    kill(again, SIGKILL);
    waitpid(again, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the resumed run ended before it was killed";
    ASSERT_EQ(rocklab::testing::runRocklab("resume 1 --quiet --lab " + twice.path, &out), 0) << out;
    expectSameRun(reference.path, twice.path);
  }
  for (const Lab* l : {&reference, &killed, &twice}) {
    std::filesystem::remove_all(l->path + ".files");
  }
}

// A run killed in a density-scaled loading (the sample formed at its physical masses, the
// loading's heavier ones and longer step set after it) resumes to the uninterrupted run.
TEST(Protocols, AKilledDensityScaledLoadingResumesToTheUninterruptedRun) {
  resume::killedAndResumed("resume-scaled", resume::scaledHydrostatic, 0.0, 1.5);
}

// A run started from the lab's formed sample (formation.reuse) and killed in its loading
// resumes to the uninterrupted run: the sample it took is in its own checkpoints.
TEST(Protocols, ARunFromAFormedSampleKilledInItsLoadingResumes) {
  Lab source("resume-formed-source");
  const std::vector<std::string> sets = {"sample.count=600", "formation.reuse=true"};
  resume::start(resume::checkpointedRun("hydrostatic-quick", source.path, sets));
  int status = 0;
  wait(&status);
  ASSERT_EQ(WEXITSTATUS(status), 0);
  auto fromFormed = [&](const std::string& lab) {
    std::filesystem::copy(
        source.path + ".formed", lab + ".formed",
        std::filesystem::copy_options::recursive | std::filesystem::copy_options::skip_existing);
    std::vector<std::string> with = sets;
    with.push_back("loading.unload_to_MPa=8");  // another loading than the source's
    return resume::checkpointedRun("hydrostatic-quick", lab, with);
  };
  EXPECT_EQ(resume::killedAndResumed("resume-formed", fromFormed, 0.0, 1.0).from_formed, 2);
}

// The permeameter killed in its axial loading: the loading loop resumes from its own
// checkpoint, with the pore networks and the pressures on the particles as they were.
TEST(Protocols, APermeameterKilledInItsLoadingResumesToTheUninterruptedRun) {
  // The loading takes about 8 s of the run's 10 (one thread): past 0.5 s it has checkpointed.
  const std::string out = resume::killedAndResumed("resume-flow", resume::quickPermeameter, 0.5,
                                                   3.0, "deviatoric_stress_MPa")
                              .out;
  EXPECT_NE(out.find("(loading), mid"), std::string::npos) << out;
}

// A run whose protocol (a value, not its wording) or code changed since its checkpoint is
// refused with the reason.
TEST(Protocols, ResumeRefusesAChangedProtocol) {
  Lab lab("resume-refused");
  std::string out;
  ASSERT_TRUE(
      resume::killDuringLoading(resume::start(resume::quickHydrostatic(lab.path)), lab.path, 0.0));
  {
    nb::Notebook n(lab.path);
    ASSERT_EQ(scalar(n, "SELECT instr(protocol_text, 'stress_max_MPa = 60.0') > 0 FROM runs"), "1");
    n.db().exec(
        "UPDATE runs SET protocol_text = replace(protocol_text, 'stress_max_MPa = 60.0', "
        "'stress_max_MPa = 61.0') || '\n# edited' WHERE id = 1");
  }
  EXPECT_EQ(rocklab::testing::runRocklab("resume 1 --lab " + lab.path, &out), 2);
  EXPECT_NE(out.find("the protocol changed since the checkpoint"), std::string::npos) << out;
  {
    nb::Notebook n(lab.path);
    n.db().exec("UPDATE runs SET code_version = 'abc123' WHERE id = 1");
  }
  EXPECT_EQ(rocklab::testing::runRocklab("resume 1 --lab " + lab.path, &out), 2);
  EXPECT_NE(out.find("it was made by rocklab abc123"), std::string::npos) << out;
  std::filesystem::remove_all(lab.path + ".files");
}

namespace samples {

// A packing written in the other codes' formats, each as its own tool writes it.
void writeCsvMm(const std::string& path, const rocklab::Packing<3>& p) {
  std::ofstream out(path);
  out.precision(17);
  out << "id,x_mm,y_mm,z_mm,r_mm\n";
  for (std::size_t i = 0; i < p.centers.size(); ++i) {
    out << i << "," << p.centers[i].x() * 1e3 << "," << p.centers[i].y() * 1e3 << ","
        << p.centers[i].z() * 1e3 << "," << p.radii[i] * 1e3 << "\n";
  }
}

void writeLammps(const std::string& path, const rocklab::Packing<3>& p) {
  std::ofstream out(path);
  out.precision(17);
  out << "LIGGGHTS data file\n\n" << p.centers.size() << " atoms\n1 atom types\n\n";
  for (int a = 0; a < 3; ++a) {
    out << p.lo[a] << " " << p.hi[a] << " "
        << "xyz"[a] << "lo "
        << "xyz"[a] << "hi\n";
  }
  out << "\nAtoms # granular\n\n";
  for (std::size_t i = 0; i < p.centers.size(); ++i) {
    out << i + 1 << " 1 " << 2 * p.radii[i] << " 2650 " << p.centers[i].x() << " "
        << p.centers[i].y() << " " << p.centers[i].z() << " 0 0 0\n";
  }
}

void writeYade(const std::string& path, const rocklab::Packing<3>& p) {
  std::ofstream out(path);
  out.precision(17);
  out << "#format x_y_z_r\n";
  for (std::size_t i = 0; i < p.centers.size(); ++i) {
    out << p.centers[i].x() << " " << p.centers[i].y() << " " << p.centers[i].z() << " "
        << p.radii[i] << "\n";
  }
}

void writeVtpLayer(const std::string& path, const rocklab::Packing<2>& p) {
  std::ofstream out(path);
  out.precision(17);
  out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\">\n<PolyData>\n"
      << "<Piece NumberOfPoints=\"" << p.centers.size() << "\">\n<PointData>\n"
      << "<DataArray type=\"Float64\" Name=\"radius\" format=\"ascii\">\n";
  for (double r : p.radii) out << r << "\n";
  out << "</DataArray>\n</PointData>\n<Points>\n"
      << "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const auto& c : p.centers) out << c.x() << " " << c.y() << " 0\n";
  out << "</DataArray>\n</Points>\n</Piece>\n</PolyData>\n</VTKFile>\n";
}

}  // namespace samples

// Every rig runs on a sample the user brings, in every format, formed and cemented like a
// generated one or (formation.enabled = false) as it is; the notebook keeps the file's name,
// hash and a copy, and a rerun reads the copy when the file is gone.
TEST(Protocols, EveryRigRunsOnASampleFromAFile) {
  Lab lab("files");
  const std::string dir = lab.path + ".samples";
  std::filesystem::create_directories(dir);
  std::string out;
  ASSERT_EQ(rocklab::testing::runRocklab("pack --n 500 --porosity 0.42 --d-min-mm 0.8 "
                                         "--d-max-mm 1.2 --seed 3 --out " +
                                             dir + "/s3.txt",
                                         &out),
            0)
      << out;
  ASSERT_EQ(rocklab::testing::runRocklab("pack --lattice hex --spacing-mm 1 --cells 14,9 "
                                         "--perturb-radius 0.1 --out " +
                                             dir + "/h2.txt",
                                         &out),
            0)
      << out;
  const auto s3 = rocklab::readPacking<3>(dir + "/s3.txt");
  const auto h2 = rocklab::readPacking<2>(dir + "/h2.txt");
  samples::writeCsvMm(dir + "/s3.csv", s3);
  samples::writeLammps(dir + "/s3.data", s3);
  samples::writeYade(dir + "/s3.yade", s3);
  samples::writeVtpLayer(dir + "/h2.vtp", h2);
  struct Case {
    std::string protocol, file, extra;
    std::size_t particles;
  };
  const std::vector<Case> cases = {
      {"oedometer-formed-under-stress-quick", "s3.txt", "", s3.radii.size()},
      {"hydrostatic-quick", "s3.csv", "", s3.radii.size()},
      {"hydrostatic-quick", "s3.txt", " --set formation.enabled=false", s3.radii.size()},
      {"permeameter-hydrostatic-3d-quick", "s3.data", "", s3.radii.size()},
      {"ultrasonic-hydrostatic-quick", "s3.yade", "", s3.radii.size()},
      {"biaxial-ucs-quick", "h2.vtp", "", h2.radii.size()},
      {"triaxial-envelope-quick", "h2.txt", "", h2.radii.size()},
  };
  int cemented = 0;
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const Case& c = cases[k];
    ASSERT_EQ(rocklab::testing::runRocklab(
                  "run " + sourceDir() + "/protocols/" + c.protocol +
                      ".toml --quiet --threads 1 --set sample.kind=file --set " +
                      "sample.file=" + dir + "/" + c.file + c.extra + " --lab " + lab.path,
                  &out),
              0)
        << c.protocol << " on " << c.file << ":\n"
        << out;
    nb::Notebook n(lab.path);
    const std::string run = std::to_string(k + 1);
    EXPECT_EQ(scalar(n, "SELECT value FROM results WHERE name = 'particles' AND run_id = " + run),
              std::to_string(c.particles))
        << c.protocol;
    EXPECT_EQ(scalar(n, "SELECT sha256 FROM inputs WHERE key = 'sample.file' AND run_id = " + run),
              nb::fileSha256(dir + "/" + c.file));
    const bool formed = c.extra.empty();
    EXPECT_EQ(std::stod(scalar(n,
                               "SELECT value FROM results WHERE name = 'formation_steps' AND "
                               "run_id = " +
                                   run)) > 0,
              formed)
        << c.protocol;
    // Cemented like a generated sample where the protocol cements (the permeameter's do not).
    if (scalar(n, "SELECT value FROM params WHERE key = 'bonds.enabled' AND run_id = " + run) ==
        "true") {
      ++cemented;
      EXPECT_GT(std::stod(scalar(n,
                                 "SELECT value FROM results WHERE name = 'bonds_installed' "
                                 "AND run_id = " +
                                     run)),
                0)
          << c.protocol;
    }
  }
  EXPECT_EQ(cemented, 6);
  {
    // The generator's keys the protocol gives are named as unused, where they were given.
    nb::Notebook n(lab.path);
    EXPECT_NE(scalar(n,
                     "SELECT text FROM messages WHERE run_id = 1 AND level = 'warning' AND text "
                     "LIKE '%sample.count is not used%'"),
              "")
        << "no warning that sample.count is not read";
  }
  // The file gone, a rerun reads the notebook's copy and finds the same results.
  std::filesystem::remove(dir + "/s3.csv");
  ASSERT_EQ(rocklab::testing::runRocklab("rerun 2 --quiet --threads 1 --lab " + lab.path, &out), 0)
      << out;
  EXPECT_NE(out.find("reading the notebook's copy"), std::string::npos) << out;
  nb::Notebook n(lab.path);
  const std::string next = std::to_string(cases.size() + 1);
  EXPECT_EQ(scalar(n,
                   "SELECT count(*) FROM results a JOIN results b ON a.name = b.name AND "
                   "b.run_id = " +
                       next + " WHERE a.run_id = 2 AND a.value IS NOT b.value"),
            "0");
  EXPECT_NE(scalar(n, "SELECT count(*) FROM results WHERE run_id = " + next), "0");
  // A bad file is refused with its line before anything is written.
  std::ofstream(dir + "/bad.csv") << "x,y,z,r\n0,0,0,1\n0,0,x,1\n";
  EXPECT_EQ(rocklab::testing::runRocklab("run " + sourceDir() +
                                             "/protocols/hydrostatic-quick.toml --quiet --set "
                                             "sample.kind=file --set sample.file=" +
                                             dir + "/bad.csv --lab " + lab.path + ".bad",
                                         &out),
            2);
  EXPECT_NE(out.find("bad.csv:3: column z: 'x' is not a finite number"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(lab.path + ".bad"));
  // A hard case: the lattice of equal disks loaded density-scaled 4 times (biaxial-ucs-quick,
  // run 6), every disk at its bound. It went unstable 11 steps into its loading while the step
  // stayed the one of the contacts alone after the cement stiffened them
  // (DensityScaling.CementingEstimatesTheStepAgainAtOnce). Its UCS is within 2% of the
  // unscaled loading's on the same lattice (measured: +0.6%; the paired density-scaling study
  // at 500 generated grains: +1.6 +- 0.4%).
  const Lab unscaled("files-unscaled");
  ASSERT_EQ(rocklab::testing::runRocklab("run " + sourceDir() +
                                             "/protocols/biaxial-ucs-quick.toml --quiet --threads "
                                             "1 --set numerics.density_scaling=1 --set "
                                             "sample.kind=file --set sample.file=" +
                                             dir + "/h2.vtp --lab " + unscaled.path,
                                         &out),
            0)
      << out;
  nb::Notebook plain(unscaled.path);
  EXPECT_NEAR(std::stod(scalar(n,
                               "SELECT value FROM results WHERE name = 'ucs_MPa' AND run_id = "
                               "6")) /
                  result(plain, "ucs_MPa"),
              1.0, 0.02);
  std::filesystem::remove_all(dir);
  std::filesystem::remove_all(lab.path + ".files");
}

// A key set on the command line is checked like the file's, runs, is kept in the notebook's
// protocol text, and `rerun` repeats the run from that text alone.
TEST(Protocols, SetOverridesAKeyAndRerunRepeatsTheRun) {
  Lab lab("set");
  const std::string protocol = lab.path + ".protocol.toml";
  std::filesystem::copy_file(sourceDir() + "/protocols/hydrostatic-quick.toml", protocol,
                             std::filesystem::copy_options::overwrite_existing);
  std::string out;
  EXPECT_EQ(
      rocklab::testing::runRocklab(
          "run " + protocol + " --quiet --set loading.stress_max_MPa=-3 --lab " + lab.path, &out),
      2);
  EXPECT_NE(out.find("--set loading.stress_max_MPa=-3: loading.stress_max_MPa = -3 is outside "
                     "the allowed range"),
            std::string::npos)
      << out;
  EXPECT_FALSE(std::filesystem::exists(lab.path));  // nothing written
  EXPECT_EQ(rocklab::testing::runRocklab("check " + protocol + " --set sample.count=300", &out), 0)
      << out;
  ASSERT_EQ(rocklab::testing::runRocklab("run " + protocol +
                                             " --quiet --threads 1 --set sample.count=300 --set " +
                                             "loading.stress_max_MPa=30 --lab " + lab.path,
                                         &out),
            0)
      << out;
  std::filesystem::remove(protocol);  // the notebook alone is enough to rerun
  ASSERT_EQ(rocklab::testing::runRocklab("rerun 1 --quiet --threads 2 --lab " + lab.path, &out), 0)
      << out;
  nb::Notebook n(lab.path);
  EXPECT_EQ(scalar(n, "SELECT value FROM params WHERE run_id = 1 AND key = 'sample.count'"), "300");
  EXPECT_EQ(scalar(n, "SELECT value FROM params WHERE run_id = 2 AND key = 'sample.count'"), "300");
  const std::string text = scalar(n, "SELECT protocol_text FROM runs WHERE id = 1");
  EXPECT_NE(text.find("stress_max_MPa = 30.0  # --set loading.stress_max_MPa=30"),
            std::string::npos)
      << text;
  EXPECT_EQ(scalar(n, "SELECT count(DISTINCT protocol_hash) FROM runs"), "1");
  EXPECT_EQ(scalar(n,
                   "SELECT count(*) FROM results a JOIN results b ON a.name = b.name "
                   "AND b.run_id = 2 WHERE a.run_id = 1 AND a.value IS NOT b.value"),
            "0");
  EXPECT_EQ(scalar(n, "SELECT count(*) FROM results WHERE run_id = 2"),
            scalar(n, "SELECT count(*) FROM results WHERE run_id = 1"));
  EXPECT_NE(scalar(n, "SELECT count(*) FROM results WHERE run_id = 1"), "0");
  EXPECT_DOUBLE_EQ(std::stod(scalar(n,
                                    "SELECT max(value) FROM series WHERE run_id = 2 AND name = "
                                    "'loading.axial_stress_MPa'")),
                   std::stod(scalar(n,
                                    "SELECT max(value) FROM series WHERE run_id = 1 AND name = "
                                    "'loading.axial_stress_MPa'")));
}

// The hydrostatic cell's quick protocol, and the notebook commands on its run (one run for
// both: the sample is formed once).
TEST(QuickProtocols, HydrostaticCellRunsAndTheNotebookCommandsQueryIt) {
  Lab lab("queries");
  std::string out;
  {
    nb::Notebook n = runQuick(lab, "hydrostatic-quick");
    EXPECT_NEAR(result(n, "mean_stress_peak_MPa"), 60.0, 0.6);
    EXPECT_LT(result(n, "porosity_at_peak"), result(n, "porosity_after_formation"));
    EXPECT_GT(result(n, "broken_bonds_at_peak"), 0.0);
  }
  EXPECT_EQ(rocklab::testing::runRocklab("notebook runs --lab " + lab.path, &out), 0);
  EXPECT_NE(out.find("hydrostatic-quick"), std::string::npos) << out;
  EXPECT_EQ(rocklab::testing::runRocklab("notebook show 1 --lab " + lab.path, &out), 0);
  EXPECT_NE(out.find("secant_bulk_modulus_MPa"), std::string::npos) << out;
  EXPECT_EQ(rocklab::testing::runRocklab(
                "notebook series 1 loading.porosity --csv --lab " + lab.path, &out),
            0);
  EXPECT_EQ(out.rfind("name,step,time_s,value\nloading.porosity,", 0), 0u) << out.substr(0, 200);
  EXPECT_EQ(rocklab::testing::runRocklab(
                "notebook events 1 --kind bond_break --csv --lab " + lab.path, &out),
            0);
  EXPECT_NE(out.find("bond_break"), std::string::npos);
  EXPECT_EQ(rocklab::testing::runRocklab(
                "notebook sql \"SELECT count(*) AS n FROM runs\" --lab " + lab.path, &out),
            0);
  EXPECT_EQ(out, "n\n1\n");
  EXPECT_NE(
      rocklab::testing::runRocklab("notebook sql \"DROP TABLE runs\" --lab " + lab.path, &out), 0);
  EXPECT_NE(out.find("read-only"), std::string::npos) << out;
  EXPECT_NE(rocklab::testing::runRocklab("notebook show 7 --lab " + lab.path, &out), 0);
  EXPECT_NE(out.find("no run 7"), std::string::npos) << out;
  // Deleting asks for confirmation, then removes the run's rows and files together.
  EXPECT_EQ(rocklab::testing::runRocklab("notebook delete 1 --lab " + lab.path, &out), 2);
  EXPECT_NE(out.find("add --yes"), std::string::npos) << out;
  EXPECT_EQ(rocklab::testing::runRocklab("notebook runs --csv --lab " + lab.path, &out), 0);
  EXPECT_NE(out.find("hydrostatic-quick"), std::string::npos) << out;
  EXPECT_EQ(rocklab::testing::runRocklab("notebook delete 1 --yes --lab " + lab.path, &out), 0)
      << out;
  EXPECT_FALSE(std::filesystem::exists(lab.path + ".files/run-1"));
  EXPECT_EQ(rocklab::testing::runRocklab(
                "notebook sql \"SELECT count(*) AS n FROM series\" --lab " + lab.path, &out),
            0);
  EXPECT_EQ(out, "n\n0\n");
}

}  // namespace

namespace permeameter {

// The largest gap between two series at their common records.
double largestGap(nb::Notebook& n, const std::string& a, const std::string& b) {
  return std::stod(scalar(n,
                          "SELECT max(abs(a.value - b.value)) FROM series a JOIN series b "
                          "ON a.step = b.step AND b.name = '" +
                              b + "' WHERE a.name = '" + a + "'"));
}

// A series at the record where another one peaks (e.g. k/k0 at the peak stress).
double atPeakOf(nb::Notebook& n, const std::string& series, const std::string& peak_of) {
  return std::stod(scalar(n,
                          "SELECT a.value FROM series a JOIN series p ON a.step = p.step AND "
                          "p.name = '" +
                              peak_of + "' WHERE a.name = '" + series +
                              "' ORDER BY p.value DESC LIMIT 1"));
}

// What every permeameter run must show: the steady state balances, and the solvers that
// converged agree with the Cholesky solution to 1e-6 of the drop (measured: 4e-10 CG, 3e-8
// explicit). The explicit scheme with virtual volumes always converges; with the real ones
// it may not within flow.explicit_max_steps (the reason the paper has virtual volumes).
void expectSoundFlow(nb::Notebook& n) {
  EXPECT_EQ(scalar(n, "SELECT status FROM runs"), "completed");
  EXPECT_LT(result(n, "flow_balance_error"), 1e-9);
  EXPECT_EQ(result(n, "solver_explicit_virtual_volume_converged"), 1.0);
  for (const char* s : {"implicit_cg", "explicit_virtual_volume", "explicit_real_volume"}) {
    const std::string key = std::string("solver_") + s;
    if (result(n, key + "_converged") == 1.0) {
      EXPECT_LT(result(n, key + "_max_difference"), 1e-6) << s;
    }
  }
  EXPECT_GT(result(n, "pores"), result(n, "particles"));
  EXPECT_GT(result(n, "pipes"), result(n, "pores"));
}

// Figure 12: alpha calibrated so that k0 is Kozeny-Carman's; under hydrostatic loading k/k0
// falls with the porosity and follows Kozeny-Carman (measured: 0.70 against 0.73 at 40 MPa,
// at most 0.034 apart over the loading; 0.06 allows another seed).
TEST(QuickProtocols, HydrostaticPermeabilityFollowsKozenyCarman3D) {
  Lab lab("permeameter-3d");
  auto n = runQuick(lab, "permeameter-hydrostatic-3d-quick");
  expectSoundFlow(n);
  // The network's k0 is Kozeny-Carman's on another sample too, with the alpha this one
  // calibrated (section 3.5.3: alpha is a property of the network model, not of one
  // packing). Measured with seed 12's alpha on seeds 13-17: k0 / Kozeny-Carman 1.013, 1.002,
  // 1.061, 0.994, 1.021 (mean 1.018, sd 0.026); 10% is about three sd past the mean.
  const double alpha = result(n, "conductance_alpha");
  Lab other("permeameter-3d-other");
  std::string out;
  ASSERT_EQ(rocklab::testing::runRocklab(
                "run " + sourceDir() +
                    "/protocols/permeameter-hydrostatic-3d-quick.toml --quiet --threads 1"
                    " --set protocol.seed=13 --set flow.calibrate_alpha=false"
                    " --set flow.explicit_max_steps=1000 --set flow.conductance_alpha=" +
                    std::to_string(alpha) + " --lab " + other.path,
                &out),
            0)
      << out;
  nb::Notebook m(other.path);
  // It ran on the alpha given (a calibrated alpha would make the ratio 1 by construction).
  ASSERT_EQ(result(m, "conductance_alpha"), std::stod(std::to_string(alpha)));
  EXPECT_NEAR(result(m, "permeability_initial_m2") / result(m, "kozeny_carman_initial_m2"), 1.0,
              0.10);
  EXPECT_LT(result(n, "k_over_k0_final"), 0.85);
  EXPECT_LT(largestGap(n, "k_over_k0", "kozeny_carman_over_k0"), 0.06);
  // The pore pressure field (Figure 11) is in the notebook, every pore before and after.
  EXPECT_EQ(std::stod(scalar(n,
                             "SELECT count(*) FROM events WHERE kind = 'pore_pressure' AND "
                             "stage = 'initial'")),
            result(n, "pores"));
  // The fluid's cost is in the stage timings; the sample is uncemented: no bond stage.
  EXPECT_NE(scalar(n, "SELECT calls FROM stage_timings WHERE stage = 'flow_network'"), "");
  EXPECT_NE(scalar(n, "SELECT calls FROM stage_timings WHERE stage = 'flow_solve'"), "");
  EXPECT_EQ(scalar(n, "SELECT count(*) FROM stage_timings WHERE stage = 'bonds'"), "0");
}

// Figure 13: plane strain, equal loading in x and y, Kozeny-Carman from an assumed 30%
// (measured: k/k0 0.77 at 40 MPa, at most 0.022 from Kozeny-Carman over the loading).
TEST(QuickProtocols, PlaneStrainPermeabilityFollowsKozenyCarman2D) {
  Lab lab("permeameter-2d");
  auto n = runQuick(lab, "permeameter-plane-strain-2d-quick");
  expectSoundFlow(n);
  // The Kozeny-Carman curve is equation 8 on the paper's assumed 30%, carried by the
  // sample's volume: phi = 1 - 0.7 V0 / V, recomputed here from the volumetric strain.
  const std::vector<double> strain = seriesValues(n, "flow.volumetric_strain");
  const std::vector<double> kc = seriesValues(n, "kozeny_carman_over_k0");
  ASSERT_EQ(strain.size(), kc.size());
  ASSERT_GT(strain.back(), 0.01);  // the loading compacts the sample (measured 3.1%)
  for (std::size_t i = 0; i < kc.size(); ++i) {
    const double phi = 1.0 - 0.7 / (1.0 - strain[i]);
    EXPECT_NEAR(kc[i], std::pow(phi / 0.3, 3) * std::pow(0.7 / (1.0 - phi), 2), 1e-9) << i;
  }
  EXPECT_LT(result(n, "k_over_k0_final"), 0.9);
  EXPECT_LT(largestGap(n, "k_over_k0", "kozeny_carman_over_k0"), 0.06);
}

// Figure 14 on one test: before failure the flow across the loading loses permeability and
// the flow along it keeps it; after failure the flow along the loading gains much more than
// the flow across (measured: 0.970 and 0.999 at the peak; 1.07 and 1.29 at 3% strain;
// Kozeny-Carman 0.98 and 1.09: it sees neither difference).
TEST(QuickProtocols, PermeabilityAnisotropyUnderBiaxialLoading2D) {
  Lab lab("permeameter-anisotropy");
  auto n = runQuick(lab, "permeameter-anisotropy-2d-quick");
  EXPECT_EQ(scalar(n, "SELECT status FROM runs"), "completed");
  const double normal_at_peak = atPeakOf(n, "k_over_k0_normal", "flow.axial_stress_MPa");
  const double along_at_peak = atPeakOf(n, "k_over_k0_along", "flow.axial_stress_MPa");
  EXPECT_LT(normal_at_peak, 0.99);
  EXPECT_LT(normal_at_peak, along_at_peak - 0.01);
  EXPECT_GT(result(n, "k_over_k0_final_along"), 1.15);
  EXPECT_GT(result(n, "k_over_k0_final_along") - 1.0,
            2.0 * (result(n, "k_over_k0_final_normal") - 1.0));
}

// The explicit scheme refuses a step above its critical one (equation 6): the run stops
// with the key and the critical step, and is marked failed.
TEST(Protocols, ExplicitFlowStepAboveCriticalIsRefused) {
  Lab lab("permeameter-step");
  const std::string path = sourceDir() + "/protocols/permeameter-plane-strain-2d-quick.toml";
  std::string out;
  EXPECT_EQ(rocklab::testing::runRocklab(
                "run " + path +
                    " --set flow.solver=explicit --set flow.virtual_volume=false"
                    " --set flow.explicit_timestep_s=1.0 --quiet --threads 1 --lab " +
                    lab.path,
                &out),
            1)
      << out;
  EXPECT_NE(out.find("flow.explicit_timestep_s"), std::string::npos) << out;
  EXPECT_NE(out.find("critical step"), std::string::npos) << out;
  nb::Notebook n(lab.path);
  EXPECT_EQ(scalar(n, "SELECT status FROM runs"), "failed");
}

}  // namespace permeameter

// Li & Holt Figure 18a: in a Hertzian pack (cement in parallel) the velocities rise with
// the hydrostatic stress and stay nearly isotropic. Measured on the quick sample, 0.5 ->
// 8 MPa: vp_z 1622 -> 1841, vp_x 1535 -> 1744, vs_zx 1081 -> 1266, vs_xy 1037 -> 1217 m/s;
// at 8 MPa vp_x / vp_z 0.95, vs_xy / vs_zx 0.96. 42 of the 48 cross-correlation picks pass
// the quality gate on this small (11 grains across), noisy sample.
TEST(QuickProtocols, UltrasonicVelocitiesRiseWithHydrostaticStress) {
  Lab lab("ultrasonic-hydrostatic");
  auto n = runQuick(lab, "ultrasonic-hydrostatic-quick");
  EXPECT_EQ(scalar(n, "SELECT status FROM runs"), "completed");
  // Three stages of four waves, four receivers each, every trace and pick in the notebook.
  EXPECT_EQ(scalar(n, "SELECT count(*) FROM waves"), "12");
  EXPECT_EQ(scalar(n, "SELECT count(*) FROM traces WHERE length(samples) > 800"), "48");
  EXPECT_GE(std::stoi(scalar(n, "SELECT count(*) FROM picks WHERE method = 'xcorr'")), 36);
  EXPECT_EQ(scalar(n, "SELECT count(*) FROM picks WHERE method = 'first_break'"), "48");
  for (const char* v : {"vp_z", "vp_x", "vs_zx", "vs_xy"}) {
    const std::vector<double> x = seriesValues(n, v);
    ASSERT_EQ(x.size(), 3u) << v;
    EXPECT_GT(x.back(), 1.03 * x.front()) << v;
    // At most Hertz's rise, v ~ sigma^(1/6) (effective medium, fixed coordination: K, G ~
    // sigma^(1/3)); the cement in parallel flattens it (measured: 0.046 for vp_z).
    EXPECT_LT(std::log(x.back() / x.front()) / std::log(8.0 / 0.5), 1.0 / 6.0) << v;
  }
  EXPECT_NEAR(result(n, "vp_x") / result(n, "vp_z"), 1.0, 0.15);
  EXPECT_NEAR(result(n, "vs_xy") / result(n, "vs_zx"), 1.0, 0.15);
  // S slower than P, as in any solid (measured vs/vp 0.71).
  EXPECT_LT(result(n, "vs_zx"), 0.8 * result(n, "vp_z"));
  // Static moduli are measured at every stage and stiffen with the stress too.
  const std::vector<double> m = seriesValues(n, "modulus_z_static_MPa");
  ASSERT_EQ(m.size(), 3u);
  EXPECT_GT(m.back(), m.front());
  EXPECT_GE(result(n, "wavelength_min_diameters"), 4.0);
  // The report draws the bench's figures with their data, and the wave fronts (Figure 17).
  const std::string rep = lab.path + "-report";
  std::string out;
  ASSERT_EQ(rocklab::testing::runRocklab("report 1 --lab " + lab.path + " --out " + rep, &out), 0)
      << out;
  for (const char* id : {"ultrasonic-velocities-run1", "ultrasonic-moduli-run1",
                         "ultrasonic-traces-run1", "ultrasonic-spectra-run1"}) {
    EXPECT_TRUE(std::filesystem::exists(rep + "/" + id + ".png")) << id;
    std::ifstream csv(rep + "/" + id + ".csv");
    std::string line;
    int rows = 0;
    while (std::getline(csv, line)) ++rows;
    EXPECT_GT(rows, 10) << id;
  }
  int fronts = 0;
  for (const auto& e : std::filesystem::directory_iterator(rep)) {
    fronts += e.path().filename().string().rfind("run1-wave-", 0) == 0;
  }
  EXPECT_GE(fronts, 4);  // frames of each wave at the last stage
  std::filesystem::remove_all(rep);
  std::filesystem::remove_all(lab.path + ".files");
  EXPECT_EQ(scalar(n, "SELECT calls FROM stage_timings WHERE stage = 'waves'"), "12");
}

// Li & Holt Figure 18b: in uniaxial strain the weakly cemented sample fails at a few
// millistrain with little lateral stress; after failure the velocities across the axis drop
// more than those along it. Measured on the quick sample (stages at 1-5 millistrain): bonds
// break from 2 millistrain (106 by then, 1,784 by 5) at 5.1-8.1 MPa axial and 0.33-1.85 MPa
// lateral; from 1 to 5 millistrain vp_x falls 28% and vs_xy 26%, vp_z 3% and vs_zx 13%.
TEST(QuickProtocols, UltrasonicAnisotropyAfterFailureIsLargestInUniaxialStrain) {
  Lab lab("ultrasonic-uniaxial");
  auto n = runQuick(lab, "ultrasonic-uniaxial-strain-quick");
  EXPECT_EQ(scalar(n, "SELECT status FROM runs"), "completed");
  const std::vector<double> broken = seriesValues(n, "stage.broken_bonds_total");
  const std::vector<double> axial = seriesValues(n, "stage.axial_stress_MPa");
  const std::vector<double> lateral = seriesValues(n, "stage.lateral_stress_MPa");
  const std::vector<double> pz = seriesValues(n, "vp_z"), px = seriesValues(n, "vp_x");
  const std::vector<double> szx = seriesValues(n, "vs_zx"), sxy = seriesValues(n, "vs_xy");
  ASSERT_EQ(broken.size(), 6u);  // stages at 1-6 millistrain
  for (const auto* v : {&pz, &px, &szx, &sxy}) ASSERT_EQ(v->size(), 6u);
  EXPECT_LT(broken[0], 50.0);             // intact at 1 millistrain (measured 1)
  EXPECT_GT(broken[5], 1000.0);           // failed by 6 (measured 1,263)
  EXPECT_LT(lateral[5], 0.3 * axial[5]);  // little lateral stress (the paper: 0.4 of 6 MPa)
  // Figure 18b, from 1 to 6 millistrain (measured): vp_x falls 24% while vp_z rises 7.5%
  // (its axial contacts stiffen under the growing axial stress; from its peak it falls 1%).
  EXPECT_LT(px[5] / px[0], 0.85);
  EXPECT_LT(px[5] / px[0], pz[5] / pz[0] - 0.2);
  // The S wave across the axis (along x, moving along y) falls more than the one along it,
  // 21% against 10% (measured). A crack along the axis softens shear in the planes through
  // the axis (szx) at most half as much as across it (sxy; README, "Waves").
  EXPECT_LT(sxy[5] / sxy[0], szx[5] / szx[0] - 0.07);
  // The cause the paper gives (section 4.2): the cement fails by orientation. The bonds
  // across the axis break, opening cracks along it, which the waves across the axis cross;
  // those along the axis are held shut by the axial stress, which also raises their shear
  // strength (bonds.friction_angle_deg), and bend without breaking (bonds.moment_factor).
  // By 6 millistrain (measured) 52% of the bonds within 30 degrees of the plane normal to
  // the axis have broken, 1.3% of those within 30 degrees of the axis (the full sample:
  // 48.5% and 1.7%).
  const std::vector<double> lateral_broken = seriesValues(n, "stage.broken_fraction_lateral_bonds");
  const std::vector<double> axial_broken = seriesValues(n, "stage.broken_fraction_axial_bonds");
  ASSERT_EQ(lateral_broken.size(), 6u);
  ASSERT_EQ(axial_broken.size(), 6u);
  EXPECT_LT(lateral_broken[0], 0.02);
  EXPECT_GT(lateral_broken[5], 0.4);
  EXPECT_GT(lateral_broken[5], 5.0 * axial_broken[5]);
  // The bonds between break in between (measured 13%): they carry szx's stiffness.
  const std::vector<double> inclined_broken =
      seriesValues(n, "stage.broken_fraction_inclined_bonds");
  ASSERT_EQ(inclined_broken.size(), 6u);
  for (const auto* f : {&lateral_broken, &axial_broken, &inclined_broken}) {
    for (double v : *f) EXPECT_GE(v, 0.0);  // each bond counted in its class at the start
  }
  EXPECT_GT(inclined_broken[5], axial_broken[5]);
  EXPECT_LT(inclined_broken[5], lateral_broken[5]);

  // Figure 18c: under 2.85 MPa confinement the same strain leaves less anisotropy (the
  // confinement keeps the cracks across the axis closed): from 3 to 5 millistrain the drop of
  // vp_x below vp_z's is smaller at every stage than in uniaxial strain, and a millistrain or
  // two after that sample's failure (4 millistrain) it is a fraction of it. Over seeds 1-5 that
  // fraction is 0.36-0.67 (mean 0.52, sd 0.14; 0.665 at this protocol's seed 3, 0.0634 against
  // 0.0954), so one seed is held below 0.85, 2.4 sd above the mean. Later the lateral stress of
  // uniaxial strain climbs toward the confinement (2.2 MPa at 6 millistrain) and the two tests
  // converge: at 6 millistrain the triaxial drop passes the other at seeds 1 and 2. The
  // triaxial sample fails too, and vp_x falls.
  Lab tri_lab("ultrasonic-triaxial");
  auto t = runQuick(tri_lab, "ultrasonic-triaxial-quick");
  EXPECT_EQ(scalar(t, "SELECT status FROM runs"), "completed");
  const std::vector<double> tz = seriesValues(t, "vp_z"), tx = seriesValues(t, "vp_x");
  ASSERT_EQ(tz.size(), 6u);
  ASSERT_EQ(tx.size(), 6u);
  EXPECT_GT(seriesValues(t, "stage.broken_bonds_total")[5], 1000.0);  // measured 1,261
  EXPECT_LT(tx[5] / tx[0], 0.9);
  auto anisotropy = [](const std::vector<double>& z, const std::vector<double>& x, std::size_t k) {
    return z[k] / z[0] - x[k] / x[0];
  };
  for (std::size_t k = 2; k < 5; ++k) {
    EXPECT_LT(anisotropy(tz, tx, k), anisotropy(pz, px, k)) << "stage " << k + 1;
  }
  EXPECT_GT(anisotropy(pz, px, 3), 0.08);
  EXPECT_LT(anisotropy(tz, tx, 3), 0.85 * anisotropy(pz, px, 3));
}
