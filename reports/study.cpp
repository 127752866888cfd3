#include "reports/study.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "reports/chart.hpp"
#include "reports/html.hpp"
#include "reports/key_results.hpp"
#include "reports/run_data.hpp"

namespace rocklab::reports {

namespace {

// The keys whose values differ between the runs: what the study varied. The seed of a study
// over seeds counts; the run's own bookkeeping (threads) does not change results.
std::vector<std::string> variedKeys(const std::vector<RunData>& runs) {
  std::vector<std::string> keys;
  for (const auto& [key, value, unit] : runs.front().params) {
    if (key == "numerics.threads") continue;
    for (const RunData& r : runs) {
      if (r.param(key) != value) {
        keys.push_back(key);
        break;
      }
    }
  }
  return keys;
}

std::string settingOf(const RunData& r, const std::vector<std::string>& varied) {
  std::string s;
  for (const std::string& k : varied) s += (s.empty() ? "" : ", ") + k + " = " + r.param(k);
  return s.empty() ? "as the protocol" : s;
}

std::string percent(double v) {
  if (!std::isfinite(v)) return "&ndash;";
  return num(100.0 * v, 3) + "%";
}

Figure costAccuracyChart(const Study& s) {
  Figure f;
  f.id = "cost-accuracy";
  std::string varied;
  for (const std::string& k : s.varied) varied += (varied.empty() ? "" : ", ") + k;
  f.title = s.protocol + ": what accuracy costs" + (varied.empty() ? "" : " (" + varied + ")");
  f.caption =
      "Each run of the study: its wall time against its error, the largest relative deviation "
      "of a key result from the finest setting (run " +
      std::to_string(s.points.front().run) +
      "). The line joins the Pareto front: the runs no faster run matches in accuracy. The "
      "flat line is the tolerance.";
  Panel p{"wall time (s)", "largest deviation of a key result (%)", {}};
  Series all{"settings", {}, {}, true}, front{"Pareto front", {}, {}, false},
      tol{"tolerance " + num(100.0 * s.tolerance, 3) + "%", {}, {}, false};
  std::vector<const StudyPoint*> sorted;
  for (const StudyPoint& q : s.points) {
    if (!std::isfinite(q.error)) continue;
    all.x.push_back(q.wall_seconds), all.y.push_back(100.0 * q.error);
    sorted.push_back(&q);
  }
  std::sort(sorted.begin(), sorted.end(), [](const StudyPoint* a, const StudyPoint* b) {
    return a->wall_seconds < b->wall_seconds;
  });
  for (const StudyPoint* q : sorted) {
    if (q->pareto) front.x.push_back(q->wall_seconds), front.y.push_back(100.0 * q->error);
  }
  if (!all.x.empty()) {
    tol.x = {*std::min_element(all.x.begin(), all.x.end()),
             *std::max_element(all.x.begin(), all.x.end())};
    tol.y = {100.0 * s.tolerance, 100.0 * s.tolerance};
  }
  p.series = {all, front, tol};
  f.panels = {p};
  return f;
}

}  // namespace

Study evaluateStudy(const std::string& lab, const std::vector<std::int64_t>& ids,
                    double tolerance) {
  if (ids.empty()) throw std::invalid_argument("study: no runs");
  if (!std::filesystem::exists(lab))
    throw std::invalid_argument("no lab notebook at '" + lab + "'");
  notebook::Notebook nb(lab);
  std::vector<RunData> runs;
  for (std::int64_t id : ids) runs.push_back(loadRun(nb, id));
  Study s;
  s.lab = lab;
  s.tolerance = tolerance;
  s.protocol = runs.front().protocol;
  for (const RunData& r : runs) {
    if (r.protocol != s.protocol) {
      throw std::invalid_argument("study: run " + std::to_string(r.id) + " is of protocol '" +
                                  r.protocol + "', not '" + s.protocol + "'");
    }
  }
  s.varied = variedKeys(runs);
  const std::vector<KeyValue> ref = keyResults(runs.front());
  if (ref.empty()) {
    throw std::invalid_argument("study: protocol '" + s.protocol +
                                "' names no key results (protocol.key_results): nothing to "
                                "compare");
  }
  for (const KeyValue& k : ref) s.key_names.push_back(k.name), s.key_units.push_back(k.unit);
  for (const RunData& r : runs) {
    StudyPoint q;
    q.run = r.id, q.setting = settingOf(r, s.varied), q.status = r.status;
    q.wall_seconds = r.wall_seconds;
    const std::vector<KeyValue> keys = keyResults(r);
    for (std::size_t k = 0; k < keys.size(); ++k) {
      q.values.push_back(keys[k].value);
      std::optional<double> dev;
      if (keys[k].value && ref[k].value) {
        const double d = std::abs(*keys[k].value - *ref[k].value);
        dev = *ref[k].value != 0.0 ? d / std::abs(*ref[k].value) : d;
      }
      q.deviation.push_back(dev);
      q.error = dev ? std::max(q.error, *dev) : INFINITY;
    }
    if (r.status != "completed") q.error = INFINITY;
    s.points.push_back(std::move(q));
  }
  // The Pareto front: scanning from the fastest, a run is on it when it is more accurate than
  // every faster run.
  std::vector<std::size_t> order(s.points.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return s.points[a].wall_seconds < s.points[b].wall_seconds;
  });
  double best = INFINITY;
  bool found = false;
  for (std::size_t k : order) {
    StudyPoint& q = s.points[k];
    if (!std::isfinite(q.error)) continue;
    q.pareto = q.error < best;
    best = std::min(best, q.error);
    if (!found && q.error <= tolerance) s.cheapest = static_cast<int>(k), found = true;
  }
  return s;
}

std::string studySummary(const Study& s) {
  const StudyPoint& c = s.points[s.cheapest];
  std::ostringstream o;
  o.precision(3);
  o << "cheapest within " << 100.0 * s.tolerance << "%: run " << c.run << " (" << c.setting << "), "
    << c.wall_seconds << " s against " << s.points.front().wall_seconds
    << " s for the finest, largest deviation " << 100.0 * c.error << "%";
  return o.str();
}

void writeStudyReport(const Study& s, const std::string& out) {
  std::filesystem::create_directories(out);
  const Figure chart = costAccuracyChart(s);
  renderFigure(chart, out);

  std::ofstream csv(out + "/study.csv");
  csv.precision(10);
  csv << "run,setting,status,wall_seconds,error,pareto";
  for (const std::string& k : s.key_names) csv << "," << k << "," << k << "_deviation";
  csv << "\n";
  for (const StudyPoint& q : s.points) {
    std::string setting = q.setting;
    std::replace(setting.begin(), setting.end(), ',', ';');
    csv << q.run << "," << setting << "," << q.status << "," << q.wall_seconds << "," << q.error
        << "," << q.pareto;
    for (std::size_t k = 0; k < s.key_names.size(); ++k) {
      csv << ",";
      if (q.values[k]) csv << *q.values[k];
      csv << ",";
      if (q.deviation[k]) csv << *q.deviation[k];
    }
    csv << "\n";
  }
  if (!csv) throw std::runtime_error("cannot write '" + out + "/study.csv'");

  std::ostringstream b;
  b << "<h1>Accuracy study: " << html(s.protocol) << "</h1>\n<p>Lab notebook <code>" << html(s.lab)
    << "</code>; varied: ";
  for (std::size_t k = 0; k < s.varied.size(); ++k) {
    b << (k ? ", " : "") << "<code>" << html(s.varied[k]) << "</code>";
  }
  if (s.varied.empty()) b << "nothing (repeats of one setting)";
  b << ". The finest setting is run " << s.points.front().run
    << "; a run's error is the largest relative deviation of a key result from it.</p>\n";
  const StudyPoint& c = s.points[s.cheapest];
  b << "<p><strong>Cheapest within " << num(100.0 * s.tolerance, 3) << "%:</strong> run " << c.run
    << " (" << html(c.setting) << "), " << num(c.wall_seconds, 4) << " s against "
    << num(s.points.front().wall_seconds, 4) << " s for the finest ("
    << num(s.points.front().wall_seconds / std::max(c.wall_seconds, 1e-9), 3)
    << "&times; faster), largest deviation " << percent(c.error) << ".</p>\n";
  b << "<figure><img src=\"cost-accuracy.png\" alt=\"cost-accuracy chart\"><figcaption>"
    << html(chart.caption) << " Data: <a href=\"cost-accuracy.csv\">cost-accuracy.csv</a>, "
    << "<a href=\"study.csv\">study.csv</a>.</figcaption></figure>\n";
  b << "<h2>Runs</h2>\n<table><tr><th>run</th><th>setting</th><th>status</th>"
       "<th>wall time (s)</th><th>error</th><th>Pareto</th>";
  for (std::size_t k = 0; k < s.key_names.size(); ++k) {
    b << "<th>" << html(s.key_names[k])
      << (s.key_units[k].empty() || s.key_units[k] == "-" ? "" : " (" + html(s.key_units[k]) + ")")
      << "</th>";
  }
  b << "</tr>\n";
  for (const StudyPoint& q : s.points) {
    b << "<tr><td>" << q.run << "</td><td>" << html(q.setting) << "</td><td class=\"status-"
      << q.status << "\">" << q.status << "</td><td class=\"n\">" << num(q.wall_seconds, 4)
      << "</td><td class=\"n\">" << percent(q.error) << "</td><td>" << (q.pareto ? "yes" : "")
      << "</td>";
    for (std::size_t k = 0; k < s.key_names.size(); ++k) {
      b << "<td class=\"n\">" << (q.values[k] ? num(*q.values[k], 4) : "&ndash;");
      if (q.deviation[k] && q.run != s.points.front().run)
        b << " (" << percent(*q.deviation[k]) << ")";
      b << "</td>";
    }
    b << "</tr>\n";
  }
  b << "</table>\n";
  std::ofstream index(out + "/index.html");
  index << page("rocklab study: " + s.protocol, b.str());
  if (!index) throw std::runtime_error("cannot write '" + out + "/index.html'");
}

}  // namespace rocklab::reports
