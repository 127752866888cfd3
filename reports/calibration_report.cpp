#include "reports/calibration_report.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "lab/calibration/ledger.hpp"
#include "lab/calibration/optimizer.hpp"
#include "reports/html.hpp"

namespace rocklab::reports {

namespace {

namespace fs = std::filesystem;
using calibration::Calibration;
using calibration::Evaluation;

std::string meanCi(const calibration::TargetValue& v) {
  if (v.n == 0) return "&ndash;";
  std::string s = num(v.mean, 4);
  if (std::isfinite(v.high)) s += " &plusmn; " + num((v.high - v.low) / 2.0, 2);
  return s + " (n " + std::to_string(v.n) + ")";
}

// Each evaluation's runs: their wall time summed, from the campaigns the calibration made.
std::vector<double> wallSeconds(notebook::Notebook& lab, const Calibration& c,
                                const std::vector<Evaluation>& all) {
  std::vector<double> out(all.size(), 0.0);
  auto q = lab.db().prepare(
      "SELECT coalesce(sum(r.wall_seconds), 0) FROM campaign_points p JOIN campaigns k ON k.id "
      "= p.campaign_id JOIN runs r ON r.id = p.run_id WHERE k.name = ? AND p.point = ?");
  for (std::size_t k = 0; k < all.size(); ++k) {
    const Evaluation& e = all[k];
    int position = 0;  // the evaluation's point in its batch's campaigns
    for (const Evaluation& x : all) position += x.batch == e.batch && x.index < e.index;
    for (std::size_t x = 0; x < c.experiments.size(); ++x) {
      const int ex = static_cast<int>(x);
      const bool swept = !c.overrides(ex, e.values, "").empty();
      q.bind(1, e.kind == "check" ? calibration::checkCampaignName(c, ex)
                                  : calibration::batchCampaignName(c, e.batch, ex));
      q.bind(2, swept ? position : 0);
      if (q.step()) out[k] += q.real(0);
      q.reset();
    }
  }
  return out;
}

Figure targetsFigure(const Calibration& c, const std::vector<Evaluation>& all) {
  Figure f{"targets",
           "Targets against the evaluations",
           "Each evaluation's seed mean with its 95% interval, the target and its tolerance. "
           "Evaluations that did not complete are left out.",
           {}};
  for (std::size_t t = 0; t < c.targets.size(); ++t) {
    const calibration::Target& g = c.targets[t];
    Panel p{"evaluation", g.name + " (" + g.unit + ")", {}};
    Series means{"seed mean, 95% interval", {}, {}, true, {}, {}};
    Series check{"check on fresh seeds", {}, {}, true, {}, {}};
    for (const Evaluation& e : all) {
      const calibration::TargetValue& v = e.targets[t];
      if (v.n == 0) continue;
      Series& s = e.kind == "check" ? check : means;
      s.x.push_back(e.index);
      s.y.push_back(v.mean);
      s.low.push_back(std::isfinite(v.low) ? v.low : v.mean);
      s.high.push_back(std::isfinite(v.high) ? v.high : v.mean);
    }
    const double last = all.empty() ? 1.0 : static_cast<double>(all.back().index);
    p.series.push_back({"target", {0.0, last}, {g.value, g.value}, false, {}, {}});
    p.series.push_back({"target + tolerance",
                        {0.0, last},
                        {g.value + g.tolerance, g.value + g.tolerance},
                        false,
                        {},
                        {}});
    p.series.push_back({"target - tolerance",
                        {0.0, last},
                        {g.value - g.tolerance, g.value - g.tolerance},
                        false,
                        {},
                        {}});
    p.series.push_back(std::move(means));
    if (!check.x.empty()) p.series.push_back(std::move(check));
    f.panels.push_back(std::move(p));
  }
  // On a log scale: the misfit falls by decades; 0 (log10 1) is the edge of the tolerance
  // for a single target.
  Panel m{"evaluation", "log10 misfit (sum of squared errors in tolerances)", {}};
  Series each{"evaluation", {}, {}, true, {}, {}}, best{"best so far", {}, {}, false, {}, {}};
  double least = INFINITY;
  for (const Evaluation& e : all) {
    if (!e.counts() || e.status != "evaluated") continue;
    each.x.push_back(e.index);
    const double floor = 1e-6;  // a misfit of 0 drawn at the plot's floor
    each.y.push_back(std::log10(std::max(floor, e.misfit)));
    least = std::min(least, e.misfit);
    best.x.push_back(e.index);
    best.y.push_back(std::log10(std::max(floor, least)));
  }
  m.series = {each, best};
  f.panels.push_back(std::move(m));
  return f;
}

Figure parametersFigure(const Calibration& c, const std::vector<Evaluation>& all) {
  Figure f{"parameters",
           "The parameters the evaluations tried",
           "Each evaluation's value of each free parameter, between its bounds.",
           {}};
  for (std::size_t k = 0; k < c.parameters.size(); ++k) {
    const calibration::Parameter& p = c.parameters[k];
    Panel panel{"evaluation", p.name + " (" + p.unit + ")", {}};
    Series s{"evaluation", {}, {}, true, {}, {}};
    for (const Evaluation& e : all) {
      if (!e.counts()) continue;
      s.x.push_back(e.index);
      s.y.push_back(e.values[k]);
    }
    panel.series.push_back(std::move(s));
    f.panels.push_back(std::move(panel));
  }
  return f;
}

void surrogateTables(std::ostream& body, const Calibration& c, const std::vector<Evaluation>& all,
                     int best) {
  const auto done = calibration::evaluatedPoints(c, all);
  body << "<h2>What the surrogates say</h2>\n";
  if (done.size() < 3) {
    body << "<p>Fewer than 3 evaluations completed: no surrogate is fitted.</p>\n";
    return;
  }
  const calibration::Surrogate s(done);
  const auto spread = calibration::parameterSpread(s);
  body << "<p>One Gaussian process per target, fitted to the " << done.size()
       << " evaluations (Matern 5/2, one length per parameter). The parameters within "
          "tolerance: weighted by each point's chance of meeting every target, and the range "
          "of the points more likely within than not.</p>\n<table><tr><th>parameter</th>"
          "<th>unit</th><th>bounds</th><th>best evaluation</th><th>weighted mean</th>"
          "<th>weighted &plusmn; 1 sd</th><th>range within tolerance</th></tr>\n";
  for (std::size_t k = 0; k < c.parameters.size(); ++k) {
    const calibration::Parameter& p = c.parameters[k];
    const calibration::Spread& w = spread[k];
    body << "<tr><td>" << html(p.name) << "</td><td>" << html(p.unit) << "</td><td>[" << num(p.low)
         << ", " << num(p.high) << "] " << (p.log ? "log" : "linear") << "</td><td class=\"n\">"
         << (best >= 0 ? num(all[static_cast<std::size_t>(best)].values[k], 4) : "&ndash;")
         << "</td>";
    if (w.any) {
      body << "<td class=\"n\">" << num(p.fromUnit(w.mean), 4) << "</td><td class=\"n\">["
           << num(p.fromUnit(std::max(0.0, w.mean - w.std)), 4) << ", "
           << num(p.fromUnit(std::min(1.0, w.mean + w.std)), 4) << "]</td><td class=\"n\">["
           << num(p.fromUnit(w.low), 4) << ", " << num(p.fromUnit(w.high), 4) << "]</td></tr>\n";
    } else {
      body << "<td colspan=\"3\">no point is more likely within tolerance than not</td></tr>\n";
    }
  }
  body << "</table>\n";
  const auto sens = calibration::sensitivity(s);
  body << "<p>Sensitivity: the share of each target's variance over the bounds that one "
          "parameter alone explains (first-order Sobol index of the surrogate's mean), and the "
          "surrogate's length for the parameter (in the bounds' range: a long one, the target "
          "hardly depends on it).</p>\n<table><tr><th>target</th>";
  for (const auto& p : c.parameters) body << "<th>" << html(p.name) << "</th>";
  body << "</tr>\n";
  for (std::size_t t = 0; t < c.targets.size(); ++t) {
    body << "<tr><td>" << html(c.targets[t].name) << "</td>";
    const auto& h = s.process(t).hyperparameters();
    for (std::size_t k = 0; k < c.parameters.size(); ++k) {
      body << "<td class=\"n\">" << num(sens[t][k], 2) << " (length " << num(h.length[k], 2)
           << ")</td>";
    }
    body << "</tr>\n";
  }
  body << "</table>\n";
}

}  // namespace

ReportSummary writeCalibrationReport(const CalibrationReportOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const Calibration& c = o.calibration;
  if (!fs::exists(o.lab)) throw std::invalid_argument("no lab notebook at '" + o.lab + "'");
  notebook::Notebook lab(o.lab);
  const std::int64_t id = calibration::Ledger::find(lab, c.name);
  if (id == 0) {
    throw std::invalid_argument("calibration " + c.name + " has not run in '" + o.lab + "'");
  }
  const calibration::Ledger ledger(lab, c, id);
  const std::vector<Evaluation> all = ledger.load();
  const int best = calibration::bestEvaluation(all);
  const std::vector<double> wall = wallSeconds(lab, c, all);
  fs::create_directories(o.out);
  ReportSummary summary;
  std::ostringstream body;
  double total = 0.0;
  int counted = 0;
  for (std::size_t k = 0; k < all.size(); ++k) total += wall[k], counted += all[k].counts();
  body << "<h1>Calibration " << html(c.name) << "</h1>\n<p>Status <b>" << html(ledger.status())
       << "</b>" << (ledger.reason().empty() ? "" : ": " + html(ledger.reason())) << ". " << counted
       << " evaluations of at most " << c.budget << ", each over "
       << c.experiments.front().seeds.size() << " seeds of " << c.experiments.size()
       << " protocols; the runs took " << num(total / 3600.0, 3)
       << " h of wall time in all. Lab notebook <code>" << html(o.lab) << "</code>.</p>\n";
  body << "<h2>Targets</h2>\n<table><tr><th>target</th><th>protocol</th><th>result</th>"
          "<th>value &plusmn; tolerance</th><th>source</th><th>best evaluation</th>"
          "<th>check on fresh seeds</th></tr>\n";
  const Evaluation* check = nullptr;
  for (const Evaluation& e : all) {
    if (e.kind == "check" && e.status == "evaluated") check = &e;
  }
  for (std::size_t t = 0; t < c.targets.size(); ++t) {
    const calibration::Target& g = c.targets[t];
    body << "<tr><td>" << html(g.name) << "</td><td><code>"
         << html(fs::path(c.experiments[g.experiment].protocol).filename().string())
         << "</code></td><td>" << html(g.result) << "</td><td class=\"n\">" << num(g.value)
         << " &plusmn; " << num(g.tolerance, 3) << " " << html(g.unit) << "</td><td>"
         << html(g.source) << "</td><td class=\"n\">"
         << (best >= 0 ? meanCi(all[static_cast<std::size_t>(best)].targets[t]) : "&ndash;")
         << "</td><td class=\"n\">" << (check ? meanCi(check->targets[t]) : "&ndash;")
         << "</td></tr>\n";
  }
  body << "</table>\n";
  writeFigure(targetsFigure(c, all), o.out, body, summary);
  writeFigure(parametersFigure(c, all), o.out, body, summary);
  surrogateTables(body, c, all, best);

  body << "<h2>Evaluations</h2>\n<table><tr><th>#</th><th>batch</th><th>kind</th>";
  std::ofstream csv(o.out + "/evaluations.csv");
  csv << "evaluation,batch,kind,status";
  for (const auto& p : c.parameters) {
    body << "<th>" << html(p.name) << "</th>";
    csv << "," << p.name;
  }
  for (const auto& g : c.targets) {
    body << "<th>" << html(g.name) << "</th>";
    csv << "," << g.name << "_n," << g.name << "_mean," << g.name << "_ci95_low," << g.name
        << "_ci95_high";
  }
  body << "<th>misfit</th><th>within</th><th>runs' wall time (s)</th></tr>\n";
  csv << ",misfit,within_tolerance,wall_seconds\n";
  for (std::size_t k = 0; k < all.size(); ++k) {
    const Evaluation& e = all[k];
    body << "<tr><td class=\"n\">" << e.index << "</td><td class=\"n\">" << e.batch << "</td><td>"
         << html(e.kind) << (e.status == "evaluated" ? "" : " (" + e.status + ")") << "</td>";
    csv << e.index << "," << e.batch << "," << e.kind << "," << e.status;
    for (double v : e.values) {
      body << "<td class=\"n\">" << num(v, 4) << "</td>";
      csv << "," << v;
    }
    for (const auto& v : e.targets) {
      body << "<td class=\"n\">" << meanCi(v) << "</td>";
      csv << "," << v.n << "," << v.mean << "," << v.low << "," << v.high;
    }
    body << "<td class=\"n\">" << num(e.misfit, 3) << "</td><td>" << (e.within ? "yes" : "")
         << "</td><td class=\"n\">" << num(wall[k], 4) << "</td></tr>\n";
    csv << "," << e.misfit << "," << e.within << "," << wall[k] << "\n";
  }
  body << "</table>\n<details><summary>Calibration file <code>" << html(c.file)
       << "</code></summary><pre>" << html(c.text) << "</pre></details>\n";
  if (!csv) throw std::runtime_error("cannot write '" + o.out + "/evaluations.csv'");
  summary.files.push_back("evaluations.csv");
  std::ofstream index(o.out + "/index.html");
  index << page("rocklab calibration " + c.name, body.str());
  if (!index) throw std::runtime_error("cannot write '" + o.out + "/index.html'");
  summary.files.push_back("index.html");
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return summary;
}

}  // namespace rocklab::reports
