// Campaigns end to end: every point x seed run once as its own process and merged into the
// lab with each point's statistics; a campaign run again does nothing; a task killed is
// listed and, on request, resumed from its checkpoint; a run of a campaign is the run the
// same settings make by hand, bit for bit.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <regex>
#include <sstream>
#include <thread>

#include "lab/campaign/statistics.hpp"
#include "tests/e2e/protocol_support.hpp"

namespace rocklab::testing {
namespace {

namespace fs = std::filesystem;

// A run's results, but for the wall times.
std::vector<std::string> resultsOf(const std::string& lab, std::int64_t run) {
  return rows(lab, "SELECT name, value FROM results WHERE name NOT LIKE '%seconds' AND run_id = " +
                       std::to_string(run) + " ORDER BY name");
}

TEST(Campaigns, EveryPointAndSeedRunsOnceIntoTheLabWithItsStatistics) {
  Lab lab("campaign"), by_hand("campaign-by-hand");
  const std::string file = campaignFile(lab.path, "friction", R"(seeds = 2
[set]
"sample.count" = 200
[sweep]
"material.friction" = [0.3, 0.5]
)");
  std::string out;
  ASSERT_EQ(runRocklab("campaign check " + file, &out), 0) << out;
  EXPECT_NE(out.find("2 points x 2 seeds = 4 runs"), std::string::npos) << out;
  ASSERT_EQ(runRocklab("campaign run " + file + " --jobs 2 --lab " + lab.path, &out), 0) << out;
  EXPECT_EQ(rows(lab.path, "SELECT count(*) FROM runs WHERE status = 'completed'"),
            std::vector<std::string>{"4|"});
  // Off a terminal, each task's end is a line of the log: which task, how it ended, the count.
  {
    const std::regex ended(
        "campaign friction: task [0-3] \\(point [01], seed [0-9]+\\) completed after [^;]+; "
        "[1-4]/4 done, [01] running, 0 failed(, [^,]+ left)?");
    std::istringstream lines(out);
    std::size_t n = 0;
    for (std::string line; std::getline(lines, line);) n += std::regex_match(line, ended);
    EXPECT_EQ(n, 4u) << out;
  }
  // Each task's run noted once, from its own process and shard.
  EXPECT_EQ(rows(lab.path, "SELECT count(DISTINCT run_id) FROM campaign_points"),
            std::vector<std::string>{"4|"});
  EXPECT_EQ(rows(lab.path,
                 "SELECT group_concat(task_id) FROM (SELECT task_id FROM run_origins "
                 "WHERE scheduler = 'local' ORDER BY task_id)"),
            std::vector<std::string>{"0,1,2,3|"});
  EXPECT_TRUE(rows(lab.path,
                   "SELECT 1 FROM runs r JOIN run_origins o ON o.run_id = r.id "
                   "GROUP BY r.pid HAVING count(*) > 1")
                  .empty())
      << "two tasks ran in one process";
  // The statistics of each point are those of its runs' results.
  EXPECT_EQ(rows(lab.path,
                 "SELECT count(*) FROM campaign_statistics s WHERE s.n = 2 AND abs(s.mean - "
                 "(SELECT avg(r.value) FROM results r JOIN campaign_points p ON p.run_id = "
                 "r.run_id WHERE p.point = s.point AND r.name = s.name)) > 1e-12 * abs(s.mean)"),
            std::vector<std::string>{"0|"});
  EXPECT_EQ(rows(lab.path,
                 "SELECT count(*) > 10 FROM campaign_statistics WHERE n = 2 AND "
                 "ci95_low < mean AND mean < ci95_high OR std = 0"),
            std::vector<std::string>{"1|"});
  ASSERT_EQ(runRocklab("campaign show " + file + " --lab " + lab.path, &out), 0) << out;
  EXPECT_NE(out.find("point 1 (material.friction=0.5): 2/2 runs completed"), std::string::npos)
      << out;
  EXPECT_NE(out.find("mean_stress_peak_MPa"), std::string::npos) << out;
  // A key result a rule evaluates from the runs' series has its statistics too.
  EXPECT_EQ(rows(lab.path,
                 "SELECT count(*) FROM campaign_statistics WHERE n = 2 AND name = "
                 "'broken_bond_fraction_at_peak'"),
            std::vector<std::string>{"2|"});
  // Two runs warned alike but for their numbers: one kind of warning, counted over the runs.
  {
    nb::Notebook notebook(lab.path);
    notebook.db().exec(
        "INSERT INTO messages (run_id, step, time_s, level, text) VALUES "
        "(1, 0, 0, 'warning', 'the walls strayed 1.5% from their target: lower the rate'), "
        "(2, 0, 0, 'warning', 'the walls strayed 2.25e-1% from their target; lower the rate')");
  }
  // The report: the key results per point, and each figure over the seeds with its spread.
  const std::string report = lab.path + ".report";
  ASSERT_EQ(runRocklab("campaign report " + file + " --lab " + lab.path + " --out " + report, &out),
            0)
      << out;
  std::ifstream page_in(report + "/index.html");
  const std::string page(std::istreambuf_iterator<char>(page_in), {});
  EXPECT_NE(page.find("Point 1: <code>material.friction=0.5</code>, 2 completed runs"),
            std::string::npos);
  EXPECT_NE(page.find("Over 2 seeds (runs "), std::string::npos);
  EXPECT_NE(page.find("<li>the walls strayed #% from their target: 2 of 4 runs</li>"),
            std::string::npos);
  std::ifstream csv_in(report + "/key-results.csv");
  const std::string csv(std::istreambuf_iterator<char>(csv_in), {});
  EXPECT_NE(csv.find("\n1,material.friction=0.5,broken_bond_fraction_at_peak,-,2,"),
            std::string::npos)
      << csv;
  // Over one numeric key, each key result against it: each point's mean and interval, as
  // the statistics hold them.
  std::ifstream sweep_in(report + "/sweep.csv");
  const std::string sweep(std::istreambuf_iterator<char>(sweep_in), {});
  for (const std::string friction : {"0.3", "0.5"}) {
    const auto stat = rows(lab.path,
                           "SELECT mean, ci95_low, ci95_high FROM campaign_statistics s JOIN "
                           "campaign_points p ON p.campaign_id = s.campaign_id AND p.point = "
                           "s.point WHERE p.settings = 'material.friction=" +
                               friction + "' AND s.name = 'secant_bulk_modulus_MPa' LIMIT 1");
    ASSERT_EQ(stat.size(), 1u);
    std::smatch m;
    ASSERT_TRUE(std::regex_search(
        sweep, m, std::regex("\n3,mean  95% CI," + friction + ",([^,]+),([^,]+),([^,\n]+)")))
        << sweep;
    double mean = 0, low = 0, high = 0;
    ASSERT_EQ(std::sscanf(stat[0].c_str(), "%lf|%lf|%lf", &mean, &low, &high), 3) << stat[0];
    EXPECT_NEAR(std::stod(m[1].str()), mean, 1e-8 * std::abs(mean));
    EXPECT_NEAR(std::stod(m[2].str()), low, 1e-8 * std::abs(mean));
    EXPECT_NEAR(std::stod(m[3].str()), high, 1e-8 * std::abs(mean));
  }
  // Last against the sweep, what a run of each point cost: the mean core time of its runs.
  {
    const auto cost = rows(lab.path,
                           "SELECT avg(r.wall_seconds * max(r.threads, 1)) FROM runs r JOIN "
                           "campaign_points p ON p.run_id = r.id WHERE p.point = 1");
    ASSERT_EQ(cost.size(), 1u);
    int last = 0;
    std::istringstream lines(sweep);
    for (std::string line; std::getline(lines, line);) {
      if (!line.empty() && std::isdigit(static_cast<unsigned char>(line[0])))
        last = std::max(last, std::stoi(line));
    }
    std::smatch m;
    ASSERT_TRUE(std::regex_search(
        sweep, m,
        std::regex("\n" + std::to_string(last) + ",mean  95% CI,0.5,([^,]+),[^,]+,[^,\n]+")))
        << sweep;
    EXPECT_NEAR(std::stod(m[1].str()), std::stod(cost[0]), 1e-6 * std::stod(cost[0]));
  }
  // What a mean costs: for each point and key result, the seeds whose 95% interval is +-5% of
  // the mean at the point's scatter (the least n with t(0.975, n - 1) cv / sqrt(n) <= 0.05).
  {
    const auto stat = rows(lab.path,
                           "SELECT std / abs(mean) FROM campaign_statistics s JOIN "
                           "campaign_points p ON p.campaign_id = s.campaign_id AND p.point = "
                           "s.point WHERE p.point = 1 AND s.name = 'secant_bulk_modulus_MPa' "
                           "LIMIT 1");
    ASSERT_EQ(stat.size(), 1u);
    const double cv = std::stod(stat[0]);
    std::size_t n = 2;
    while (campaign::studentT975(double(n - 1)) * cv / std::sqrt(double(n)) > 0.05) ++n;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(
        page, m,
        std::regex("<tr><td>1 <code>material.friction=0.5</code></td><td class=\"n\">[0-9]+</td>"
                   "<td>secant_bulk_modulus_MPa</td><td class=\"n\">[^<]+</td><td "
                   "class=\"n\">([0-9]+)</td>")))
        << page;
    EXPECT_EQ(m[1].str(), std::to_string(n));
  }
  // The points compared: each point's curves, as its own figure drew them, in one figure.
  std::size_t compared = 0;
  for (const auto& e : fs::directory_iterator(report)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("compared-", 0) != 0 || e.path().extension() != ".csv") continue;
    ++compared;
    std::ifstream in(e.path());
    const std::string both(std::istreambuf_iterator<char>(in), {});
    std::ifstream point_in(report + "/point1-" + name.substr(9));
    ASSERT_TRUE(point_in) << name;
    std::string header, row;
    std::getline(point_in, header);
    ASSERT_TRUE(std::getline(point_in, row)) << name;
    // panel,series,x,y,...: the same row, its series named with its point (and its own name
    // when the point draws several), or as it was when every point draws it alike.
    const auto comma = row.find(',');
    const auto next = row.find(',', comma + 1);
    const std::string panel = row.substr(0, comma + 1),
                      series = row.substr(comma + 1, next - comma - 1), rest = row.substr(next);
    const bool found =
        both.find("\n" + panel + "point 1" + rest + "\n") != std::string::npos ||
        both.find("\n" + panel + "point 1: " + series + rest + "\n") != std::string::npos ||
        both.find("\n" + row + "\n") != std::string::npos;
    EXPECT_TRUE(found) << name << ": " << row;
    EXPECT_NE(both.find(",point 0"), std::string::npos) << name;
  }
  EXPECT_GE(compared, 1u);
  EXPECT_NE(page.find("<h2>The points compared</h2>"), std::string::npos);
  EXPECT_NE(page.find("point 0, material.friction=0.3; point 1, material.friction=0.5."),
            std::string::npos);
  std::size_t figures = 0, banded = 0;
  for (const auto& e : fs::directory_iterator(report)) {
    if (e.path().extension() != ".csv" || e.path().filename() == "key-results.csv" ||
        e.path().filename() == "sweep.csv") {
      continue;
    }
    ++figures;
    std::ifstream in(e.path());
    std::string header, row;
    std::getline(in, header);
    // A curve's row with its band: panel,series,x,y,low,high all given.
    while (std::getline(in, row)) {
      if (std::regex_match(row, std::regex("[0-9]+,[^,]*,[^,]+,[^,]+,[^,]+,[^,]+"))) {
        ++banded;
        break;
      }
    }
  }
  EXPECT_GE(figures, 2u);
  EXPECT_GE(banded, 2u);
  fs::remove_all(report);
  // The shards are merged and gone.
  EXPECT_FALSE(fs::exists(lab.path + ".campaigns/friction/task-0.sqlite"));
  // Run again: nothing to do.
  ASSERT_EQ(runRocklab("campaign run " + file + " --quiet --lab " + lab.path, &out), 0) << out;
  EXPECT_NE(out.find("0 of 4 runs to do"), std::string::npos) << out;
  EXPECT_EQ(rows(lab.path, "SELECT count(*) FROM runs"), std::vector<std::string>{"4|"});
  // The protocol worded otherwise (a comment, a key given at its default, another path) is the
  // same protocol: nothing to do.
  {
    std::ifstream in(sourceDir() + "/protocols/hydrostatic-quick.toml");
    const std::string text(std::istreambuf_iterator<char>(in), {});
    std::ofstream(lab.path + ".worded.toml")
        << "# worded otherwise\n"
        << text << "\n[output]\nsnapshots = true  # its default\n";
    std::ifstream c_in(file);
    std::string campaign(std::istreambuf_iterator<char>(c_in), {});
    const std::string shipped = sourceDir() + "/protocols/hydrostatic-quick.toml";
    campaign.replace(campaign.find(shipped), shipped.size(), lab.path + ".worded.toml");
    std::ofstream(file) << campaign;
  }
  ASSERT_EQ(runRocklab("campaign run " + file + " --quiet --lab " + lab.path, &out), 0) << out;
  EXPECT_NE(out.find("0 of 4 runs to do"), std::string::npos) << out;
  // Runs a notebook noted by the hash of their text (before runs were known by their
  // settings) are found by the text it kept.
  {
    nb::Notebook notebook(lab.path);
    notebook.db().exec("UPDATE runs SET protocol_hash = 'of-the-text-' || id");
  }
  ASSERT_EQ(runRocklab("campaign run " + file + " --quiet --lab " + lab.path, &out), 0) << out;
  EXPECT_NE(out.find("0 of 4 runs to do"), std::string::npos) << out;
  fs::remove(lab.path + ".worded.toml");
  // A task's run is the run of the same settings by hand.
  const std::string seed =
      rows(lab.path, "SELECT seed FROM campaign_points WHERE point = 1 ORDER BY seed DESC")[0];
  ASSERT_EQ(runRocklab("run " + sourceDir() +
                           "/protocols/hydrostatic-quick.toml --quiet --set sample.count=200 "
                           "--set material.friction=0.5 --set protocol.seed=" +
                           seed.substr(0, seed.size() - 1) + " --lab " + by_hand.path,
                       &out),
            0)
      << out;
  const std::string task_run =
      rows(lab.path, "SELECT run_id FROM campaign_points WHERE point = 1 ORDER BY seed DESC")[0];
  EXPECT_EQ(resultsOf(lab.path, std::stoll(task_run)), resultsOf(by_hand.path, 1));
  // The lab merged into another, twice: the runs once.
  Lab other("campaign-merged");
  ASSERT_EQ(runRocklab("notebook merge " + lab.path + " --lab " + other.path, &out), 0) << out;
  ASSERT_EQ(runRocklab("notebook merge " + lab.path + " --lab " + other.path, &out), 0) << out;
  EXPECT_NE(out.find("0 runs merged into " + other.path + ", 4 there already"), std::string::npos)
      << out;
  EXPECT_EQ(rows(other.path, "SELECT count(*) FROM runs"), std::vector<std::string>{"4|"});
  // Over two numeric keys the sweep figure draws one curve per value of one against the
  // other (the later on a tie): the friction's points at 200 particles are those above.
  {
    const std::string both = campaignFile(lab.path, "friction-size", R"(seeds = 2
[sweep]
"material.friction" = [0.3, 0.5]
"sample.count" = [150, 200]
)");
    ASSERT_EQ(runRocklab("campaign run " + both + " --jobs 2 --quiet --lab " + lab.path, &out), 0)
        << out;
    EXPECT_NE(out.find("4 of 8 runs to do"), std::string::npos) << out;
    const std::string two = lab.path + ".report-two";
    ASSERT_EQ(runRocklab("campaign report " + both + " --lab " + lab.path + " --out " + two, &out),
              0)
        << out;
    std::ifstream in(two + "/sweep.csv");
    const std::string curves(std::istreambuf_iterator<char>(in), {});
    for (const char* friction : {"0.3", "0.5"}) {
      for (const char* count : {"150", "200"}) {
        EXPECT_NE(curves.find(std::string(",material.friction=") + friction + "," + count + ","),
                  std::string::npos)
            << curves;
      }
    }
    const auto stat = rows(lab.path,
                           "SELECT s.mean FROM campaign_statistics s JOIN campaigns c ON c.id = "
                           "s.campaign_id WHERE c.name = 'friction' AND s.point = 1 AND s.name = "
                           "'secant_bulk_modulus_MPa'");
    ASSERT_EQ(stat.size(), 1u);
    std::smatch m;
    ASSERT_TRUE(std::regex_search(curves, m, std::regex("\n3,material.friction=0.5,200,([^,]+),")))
        << curves;
    EXPECT_NEAR(std::stod(m[1].str()), std::stod(stat[0]), 1e-8 * std::abs(std::stod(stat[0])));
    fs::remove_all(two);
    fs::remove(both);
  }
  fs::remove(file);
  removeLabFiles(lab);
  removeLabFiles(by_hand);
  removeLabFiles(other);
}

// A task killed (SIGKILL, as a lost node would) is listed with its reason; the campaign run
// again with --rerun-failed resumes it from its checkpoint, to the run an uninterrupted
// campaign makes.
TEST(Campaigns, AKilledTaskIsListedAndResumedFromItsCheckpointOnRequest) {
  Lab lab("campaign-killed"), reference("campaign-reference");
  const std::string body = kCheckpointedCampaign;
  const std::string file = campaignFile(lab.path, "killed", body);
  const std::string shard = lab.path + ".campaigns/killed/task-0.sqlite";
  const pid_t campaign = fork();
  if (campaign == 0) {
    std::freopen("/dev/null", "w", stderr);
    execl(ROCKLAB_BINARY, ROCKLAB_BINARY, "campaign", "run", file.c_str(), "--jobs", "1", "--quiet",
          "--lab", lab.path.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  // The first task's process, once its loading reaches its shard.
  pid_t task = 0;
  for (int k = 0; k < 1200 && task == 0; ++k) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    try {
      if (rows(shard, "SELECT 1 FROM series WHERE name LIKE 'loading.%' LIMIT 1").size() == 1) {
        task = static_cast<pid_t>(std::stol(rows(shard, "SELECT pid FROM runs")[0]));
      }
    } catch (const std::exception&) {  // not there yet
    }
  }
  ASSERT_GT(task, 0) << "the first task never reached its loading";
  std::this_thread::sleep_for(std::chrono::milliseconds(700));
  kill(task, SIGKILL);
  int status = 0;
  waitpid(campaign, &status, 0);
  EXPECT_EQ(WEXITSTATUS(status), 1) << "a campaign with a failed task ends with 1";
  std::string out;
  ASSERT_EQ(runRocklab("campaign show " + file + " --lab " + lab.path, &out), 0) << out;
  EXPECT_NE(out.find("task 0 (base, seed 3): run 1 failed: the process ended"), std::string::npos)
      << out;
  EXPECT_TRUE(fs::exists(shard)) << "the failed task's shard is kept for its resumption";
  const auto killed_uuid = rows(lab.path, "SELECT uuid FROM runs WHERE status = 'failed'");
  ASSERT_EQ(killed_uuid.size(), 1u);
  ASSERT_EQ(runRocklab("campaign run " + file + " --rerun-failed --quiet --lab " + lab.path, &out),
            0)
      << out;
  EXPECT_EQ(rows(lab.path, "SELECT count(*) FROM runs WHERE status = 'completed'"),
            std::vector<std::string>{"2|"});
  EXPECT_EQ(rows(lab.path, "SELECT count(*) FROM runs"), std::vector<std::string>{"2|"});
  // Resumed, not run anew: the completed run is the killed one (its uuid), continued.
  EXPECT_EQ(rows(lab.path,
                 "SELECT r.uuid FROM runs r JOIN campaign_points p ON p.run_id = r.id "
                 "WHERE p.seed = 3 AND r.status = 'completed'"),
            killed_uuid);
  // The killed task against the same task never killed.
  const std::string reference_file =
      campaignFile(reference.path, "killed", std::regex_replace(body, std::regex("3, 4"), "3"));
  ASSERT_EQ(runRocklab("campaign run " + reference_file + " --quiet --lab " + reference.path, &out),
            0)
      << out;
  for (const char* sql :
       {"SELECT r.name, r.value FROM results r JOIN campaign_points p ON p.run_id = r.run_id "
        "WHERE p.seed = 3 AND r.name NOT LIKE '%seconds' ORDER BY r.name",
        "SELECT m.text FROM messages m JOIN campaign_points p ON p.run_id = m.run_id WHERE "
        "p.seed = 3 AND m.text LIKE 'final state hash%'"}) {
    const auto resumed = rows(lab.path, sql);
    EXPECT_FALSE(resumed.empty()) << sql;
    EXPECT_EQ(resumed, rows(reference.path, sql)) << sql;
  }
  fs::remove(file);
  fs::remove(reference_file);
  removeLabFiles(lab);
  removeLabFiles(reference);
}

// The catalogue: each [[paper]] claim against the campaign's ensemble, the mean and the
// fraction of seeds computed again here from the notebook's rows.
TEST(Campaigns, TheCatalogueSetsTheEnsembleBesideThePaper) {
  Lab lab("catalogue");
  const std::string file = lab.path + ".flow.toml";
  const std::string claims = R"([campaign]
name = "flow"
protocol = ")" + sourceDir() +
                             R"(/protocols/permeameter-plane-strain-2d-quick.toml"
seeds = 3
[[paper]]
result = "k_over_kozeny_carman_final"
number = "kozeny_carman_agreement_2d"
[[paper]]
result = "k_over_k0_final"
says = "falls with stress"
within = [0.0, 0.775]
)";
  std::ofstream(file) << claims;
  const std::string out = lab.path + ".catalogue.md";
  nb::Notebook n(lab.path);  // a lab where the campaign has not run yet
  std::string text;
  ASSERT_EQ(runRocklab("campaign catalogue " + file + " --lab " + lab.path, &text), 0) << text;
  EXPECT_NE(text.find("| `flow` | `k_over_k0_final` | falls with stress | not run | 0 |"),
            std::string::npos)
      << text;
  ASSERT_EQ(runRocklab("campaign run " + file + " --jobs 2 --quiet --lab " + lab.path, &text), 0)
      << text;
  ASSERT_EQ(
      runRocklab("campaign catalogue " + file + " --lab " + lab.path + " --out " + out, &text), 0)
      << text;
  std::ifstream in(out);
  const std::string md((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // The row of the mean: the paper's number with its source, the ensemble's mean of the
  // three runs' k / k_KC, and where the paper's 1 falls.
  const double k_kc = std::stod(
      scalar(n,
             "SELECT avg(r.value / (SELECT s.value FROM series s WHERE s.run_id = r.run_id AND "
             "s.name = 'kozeny_carman_over_k0' ORDER BY s.step DESC LIMIT 1)) FROM results r "
             "WHERE r.name = 'k_over_k0_final'"));
  std::smatch m;
  ASSERT_TRUE(std::regex_search(
      md, m,
      std::regex(
          R"(\| `k_over_kozeny_carman_final` \| 1 \(Section 3\.5\.4, text \(Figure 13\)\) \| )"
          R"(([0-9.]+) &plusmn; ([0-9.e-]+) \| 3 \| (inside the interval|outside: [^|]+) \|)")))
      << md;
  EXPECT_NEAR(std::stod(m[1].str()), k_kc, 5e-4 * k_kc);
  const double half = std::stod(m[2].str());
  EXPECT_EQ(m[3].str() == "inside the interval", std::abs(k_kc - 1.0) <= half) << m[3].str();
  // The row of the fraction: the seeds at or under 0.775, counted here.
  const std::string k =
      scalar(n, "SELECT count(*) FROM results WHERE name = 'k_over_k0_final' AND value <= 0.775");
  EXPECT_NE(md.find("| " + k + " of 3 seeds in [0, 0.775]: "), std::string::npos) << md;
  // A claim on a number the paper does not have: refused, the catalogue left as it was.
  std::ofstream(file) << claims << "[[paper]]\nresult = \"porosity_initial\"\nnumber = \"none\"\n";
  EXPECT_EQ(
      runRocklab("campaign catalogue " + file + " --lab " + lab.path + " --out " + out, &text), 2);
  EXPECT_NE(text.find("flow.toml:12: paper.number = \"none\" is not a [[number]]"),
            std::string::npos)
      << text;
  std::ifstream again(out);
  EXPECT_EQ(std::string((std::istreambuf_iterator<char>(again)), std::istreambuf_iterator<char>()),
            md);
  fs::remove(file);
  fs::remove(out);
  removeLabFiles(lab);
}

// The campaigns that ship with the protocols are valid, every point of them.
TEST(Campaigns, ShippedCampaignsCheck) {
  int checked = 0;
  for (const auto& f : fs::directory_iterator(sourceDir() + "/protocols/campaigns")) {
    if (f.path().extension() != ".toml") continue;
    std::string out;
    EXPECT_EQ(runRocklab("campaign check " + f.path().string(), &out), 0) << out;
    // The paper's ensembles (*-seeds.toml) at 5 seeds at least, the model studies at 3.
    std::smatch m;
    ASSERT_TRUE(std::regex_search(out, m, std::regex(R"(x (\d+) seeds)"))) << out;
    const bool paper = f.path().stem().string().ends_with("-seeds");
    EXPECT_GE(std::stoi(m[1].str()), paper ? 5 : 3) << out;
    ++checked;
  }
  EXPECT_GE(checked, 5);
}

}  // namespace
}  // namespace rocklab::testing
