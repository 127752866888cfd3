#include "reports/study.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "lab/campaign/statistics.hpp"
#include "reports/chart.hpp"
#include "reports/html.hpp"
#include "reports/key_results.hpp"
#include "reports/run_data.hpp"

namespace rocklab::reports {

namespace {

// The keys whose values differ between the runs: what the study varied, and the seed of a
// study over seeds; the run's own bookkeeping (threads) does not change results. Every run's
// keys count: a run of an older rocklab may lack a key the others vary.
std::vector<std::string> variedKeys(const std::vector<RunData>& runs) {
  std::vector<std::string> keys;
  for (const RunData& run : runs) {
    for (const auto& [key, value, unit] : run.params) {
      if (key == "numerics.threads" || std::ranges::find(keys, key) != keys.end()) continue;
      for (const RunData& r : runs) {
        if (r.param(key) != value) {
          keys.push_back(key);
          break;
        }
      }
    }
  }
  return keys;
}

// The keys that make a setting: the varied ones but the seed, whose runs are its ensemble.
std::vector<std::string> withoutSeed(std::vector<std::string> keys) {
  keys.erase(std::remove(keys.begin(), keys.end(), "protocol.seed"), keys.end());
  return keys;
}

std::string settingOf(const RunData& r, const std::vector<std::string>& varied) {
  std::string s;
  for (const std::string& k : varied) s += (s.empty() ? "" : ", ") + k + " = " + r.param(k);
  return s.empty() ? "as the protocol" : s;
}

// The setting's values against the finest's, seed by seed (the seeds both ran): their
// differences' mean lies outside its 95% t interval of zero (Student's paired test).
bool pairedShift(const std::map<std::string, double>& finest,
                 const std::map<std::string, double>& mine) {
  std::vector<double> d;
  for (const auto& [seed, v] : mine) {
    const auto f = finest.find(seed);
    if (f != finest.end()) d.push_back(v - f->second);
  }
  if (d.size() < 2) return false;
  const campaign::Summary m = campaign::summarize(d);
  return m.low > 0.0 || m.high < 0.0;
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
  const bool seeds = s.seeds > 1;
  f.caption =
      "Each setting of the study: its wall time against its error, the largest relative "
      "deviation of a key result from the finest setting (run " +
      std::to_string(s.points.front().run) + ")" +
      (seeds ? " beyond the seed scatter: over " + std::to_string(s.seeds) +
                   " seeds per setting, a deviation inside Welch's 95% interval of the "
                   "difference of the means counts as none unless the paired differences of "
                   "each seed's runs resolve it, and times are means"
             : "") +
      ". The line joins the Pareto front: the settings no faster one matches in accuracy. The "
      "flat line is the tolerance.";
  Panel p{"wall time (s)",
          seeds ? "largest deviation beyond the seed scatter or shifted (%)"
                : "largest deviation of a key result (%)",
          {}};
  Series all{"settings", {}, {}, true}, front{"Pareto front", {}, {}, false},
      tol{"tolerance " + num(100.0 * s.tolerance, 3) + "%", {}, {}, false};
  std::vector<const StudyPoint*> sorted;
  for (const StudyPoint& q : s.points) {
    if (!std::isfinite(q.loss)) continue;
    all.x.push_back(q.wall_seconds), all.y.push_back(100.0 * q.loss);
    sorted.push_back(&q);
  }
  std::sort(sorted.begin(), sorted.end(), [](const StudyPoint* a, const StudyPoint* b) {
    return a->wall_seconds < b->wall_seconds;
  });
  for (const StudyPoint* q : sorted) {
    if (q->pareto) front.x.push_back(q->wall_seconds), front.y.push_back(100.0 * q->loss);
  }
  if (!all.x.empty()) {
    tol.x = {*std::min_element(all.x.begin(), all.x.end()),
             *std::max_element(all.x.begin(), all.x.end())};
    tol.y = {100.0 * s.tolerance, 100.0 * s.tolerance};
  }
  p.series = {all, front, tol};
  f.panels = {p};
  if (!seeds) return f;
  // The second panel: what a mean of the same precision costs. A setting may keep the
  // means and still widen the seeds' scatter (a new draw of the sample per seed).
  f.caption +=
      " Below: the largest ratio of a key result's standard deviation over the seeds "
      "to the finest setting's; a mean as precise as the finest's needs its square "
      "times the seeds.";
  Panel q{"wall time (s)", "largest seed scatter / the finest's", {}};
  Series ratio{"settings", {}, {}, true}, one{"as the finest", {}, {}, false};
  for (const StudyPoint& point : s.points) {
    if (!std::isfinite(point.scatter)) continue;
    ratio.x.push_back(point.wall_seconds), ratio.y.push_back(point.scatter);
  }
  if (!ratio.x.empty()) {
    one.x = {*std::min_element(ratio.x.begin(), ratio.x.end()),
             *std::max_element(ratio.x.begin(), ratio.x.end())};
    one.y = {1.0, 1.0};
  }
  q.series = {ratio, one};
  f.panels.push_back(q);
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
  s.varied = withoutSeed(variedKeys(runs));
  const std::vector<KeyValue> ref = keyResults(runs.front());
  if (ref.empty()) {
    throw std::invalid_argument("study: protocol '" + s.protocol +
                                "' names no key results (protocol.key_results): nothing to "
                                "compare");
  }
  for (const KeyValue& k : ref) s.key_names.push_back(k.name), s.key_units.push_back(k.unit);
  // Settings in order of their first run; a setting's runs differ only in their seed.
  std::vector<std::vector<const RunData*>> settings;
  for (const RunData& r : runs) {
    auto same = std::find_if(settings.begin(), settings.end(), [&](const auto& g) {
      return settingOf(*g.front(), s.varied) == settingOf(r, s.varied);
    });
    if (same == settings.end()) {
      settings.push_back({&r});
    } else {
      same->push_back(&r);
    }
  }
  std::vector<std::vector<campaign::Summary>> summaries;  // per setting, per key result
  // Per setting, per key result: the value of each seed's run.
  std::vector<std::vector<std::map<std::string, double>>> by_seed;
  for (const auto& group : settings) {
    StudyPoint q;
    q.run = group.front()->id, q.setting = settingOf(*group.front(), s.varied);
    q.status = "completed";
    std::vector<std::vector<double>> values(s.key_names.size());
    by_seed.emplace_back(s.key_names.size());
    bool complete = true;
    for (const RunData* r : group) {
      q.runs.push_back(r->id);
      q.wall_seconds += r->wall_seconds / static_cast<double>(group.size());
      if (r->status != "completed" && q.status == "completed") q.status = r->status;
      const std::vector<KeyValue> keys = keyResults(*r);
      for (std::size_t k = 0; k < keys.size(); ++k) {
        if (keys[k].value) {
          values[k].push_back(*keys[k].value);
          by_seed.back()[k][r->param("protocol.seed")] = *keys[k].value;
        } else {
          complete = false;
        }
      }
    }
    s.seeds = std::max(s.seeds, group.size());
    summaries.emplace_back();
    for (const auto& v : values) {
      summaries.back().push_back(campaign::summarize(v));
      const campaign::Summary& m = summaries.back().back();
      q.values.push_back(m.n ? std::optional<double>(m.mean) : std::nullopt);
      q.spread.push_back(m.n > 1 ? std::optional<double>(m.std) : std::nullopt);
    }
    for (std::size_t k = 0; k < s.key_names.size(); ++k) {
      const campaign::Summary& mine = summaries.back()[k];
      const campaign::Summary& finest = summaries.front()[k];
      std::optional<double> dev;
      bool inside = false;
      if (mine.n && finest.n) {
        const double d = std::abs(mine.mean - finest.mean);
        dev = finest.mean != 0.0 ? d / std::abs(finest.mean) : d;
        const campaign::Difference diff = campaign::compareMeans(finest, mine);
        inside = summaries.size() > 1 && diff.known && !diff.resolved();
      }
      const bool shifted =
          settings.size() > 1 && pairedShift(by_seed.front()[k], by_seed.back()[k]);
      if (mine.n > 1 && finest.n > 1 && finest.std > 0.0) {
        q.scatter = std::isnan(q.scatter) ? mine.std / finest.std
                                          : std::max(q.scatter, mine.std / finest.std);
      }
      q.deviation.push_back(dev);
      q.within_scatter.push_back(inside);
      q.paired_shift.push_back(shifted);
      q.error = dev ? std::max(q.error, *dev) : INFINITY;
      q.loss = dev ? std::max(q.loss, inside && !shifted ? 0.0 : *dev) : INFINITY;
    }
    if (q.status != "completed" || !complete) q.error = q.loss = INFINITY;
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
    if (!std::isfinite(q.loss)) continue;
    q.pareto = q.loss < best;
    best = std::min(best, q.loss);
    if (!found && q.loss <= tolerance) s.cheapest = static_cast<int>(k), found = true;
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
  if (s.seeds > 1) {
    o << ", " << 100.0 * c.loss << "% beyond the scatter of " << s.seeds
      << " seeds or shifted seed by seed";
    if (std::isfinite(c.scatter)) o << ", seed scatter " << c.scatter << " times the finest's";
  }
  return o.str();
}

namespace {

std::string runIds(const StudyPoint& q) {
  std::string ids;
  for (std::int64_t id : q.runs) ids += (ids.empty() ? "" : " ") + std::to_string(id);
  return ids;
}

void writeStudyCsv(const Study& s, const std::string& path) {
  std::ofstream csv(path);
  csv.precision(10);
  csv << "runs,setting,status,wall_seconds,error,loss,scatter_ratio,pareto";
  for (const std::string& k : s.key_names) {
    csv << "," << k << "," << k << "_std," << k << "_deviation," << k << "_within_scatter," << k
        << "_paired_shift";
  }
  csv << "\n";
  for (const StudyPoint& q : s.points) {
    std::string setting = q.setting;
    std::replace(setting.begin(), setting.end(), ',', ';');
    csv << runIds(q) << "," << setting << "," << q.status << "," << q.wall_seconds << "," << q.error
        << "," << q.loss << ",";
    if (std::isfinite(q.scatter)) csv << q.scatter;
    csv << "," << q.pareto;
    for (std::size_t k = 0; k < s.key_names.size(); ++k) {
      csv << ",";
      if (q.values[k]) csv << *q.values[k];
      csv << ",";
      if (q.spread[k]) csv << *q.spread[k];
      csv << ",";
      if (q.deviation[k]) csv << *q.deviation[k];
      csv << "," << q.within_scatter[k] << "," << q.paired_shift[k];
    }
    csv << "\n";
  }
  if (!csv) throw std::runtime_error("cannot write '" + path + "'");
}

}  // namespace

void writeStudyReport(const Study& s, const std::string& out) {
  std::filesystem::create_directories(out);
  const Figure chart = costAccuracyChart(s);
  renderFigure(chart, out);
  writeStudyCsv(s, out + "/study.csv");
  const bool seeds = s.seeds > 1;

  std::ostringstream b;
  b << "<h1>Accuracy study: " << html(s.protocol) << "</h1>\n<p>Lab notebook <code>" << html(s.lab)
    << "</code>; varied: ";
  for (std::size_t k = 0; k < s.varied.size(); ++k) {
    b << (k ? ", " : "") << "<code>" << html(s.varied[k]) << "</code>";
  }
  if (s.varied.empty()) b << "nothing (repeats of one setting)";
  b << ". The finest setting is run"
    << (seeds ? "s " + runIds(s.points.front()) : " ") +
           (seeds ? "" : std::to_string(s.points.front().run))
    << "; a setting's error is the largest relative deviation of a key result from it.</p>\n";
  if (seeds) {
    b << "<p>Each setting ran at " << s.seeds
      << " seeds; its key results are the means over them, shown with their standard "
         "deviation. A deviation inside the seed scatter &mdash; Welch's 95% interval of the "
         "difference of the two means contains zero &mdash; is not a loss of accuracy: the "
         "seeds cannot tell the two settings apart, and such a deviation is marked "
         "<em>inside the scatter</em> and counts as none in the setting's loss, which ranks "
         "the settings and picks the cheapest &mdash; unless it is <em>shifted seed by "
         "seed</em>: a seed draws the same sample in every setting, and the mean of the "
         "differences from the finest's run of the same seed lies outside its 95% t interval "
         "of zero (Student's paired test). Such a setting makes another material out of the "
         "same draws, and its deviation counts.</p>\n";
  }
  const StudyPoint& c = s.points[s.cheapest];
  b << "<p><strong>Cheapest within " << num(100.0 * s.tolerance, 3) << "%:</strong> run " << c.run
    << " (" << html(c.setting) << "), " << num(c.wall_seconds, 4) << " s against "
    << num(s.points.front().wall_seconds, 4) << " s for the finest ("
    << num(s.points.front().wall_seconds / std::max(c.wall_seconds, 1e-9), 3)
    << "&times; faster), largest deviation " << percent(c.error);
  if (seeds) b << ", " << percent(c.loss) << " beyond the seed scatter or shifted seed by seed";
  if (std::isfinite(c.scatter))
    b << ", seed scatter " << num(c.scatter, 3) << " times the finest's";
  b << ".</p>\n";
  b << "<figure><img src=\"cost-accuracy.png\" alt=\"cost-accuracy chart\"><figcaption>"
    << html(chart.caption) << " Data: <a href=\"cost-accuracy.csv\">cost-accuracy.csv</a>, "
    << "<a href=\"study.csv\">study.csv</a>.</figcaption></figure>\n";
  b << "<h2>Settings</h2>\n<table><tr><th>run" << (seeds ? "s" : "")
    << "</th><th>setting</th><th>status</th><th>wall time (s)</th><th>error</th>"
    << (seeds ? "<th>loss</th><th>scatter / finest's</th>" : "") << "<th>Pareto</th>";
  for (std::size_t k = 0; k < s.key_names.size(); ++k) {
    b << "<th>" << html(s.key_names[k])
      << (s.key_units[k].empty() || s.key_units[k] == "-" ? "" : " (" + html(s.key_units[k]) + ")")
      << "</th>";
  }
  b << "</tr>\n";
  for (const StudyPoint& q : s.points) {
    b << "<tr><td>" << runIds(q) << "</td><td>" << html(q.setting) << "</td><td class=\"status-"
      << q.status << "\">" << q.status << "</td><td class=\"n\">" << num(q.wall_seconds, 4)
      << "</td><td class=\"n\">" << percent(q.error) << "</td>"
      << (seeds ? "<td class=\"n\">" + percent(q.loss) + "</td><td class=\"n\">" +
                      (std::isfinite(q.scatter) ? num(q.scatter, 3) : "&ndash;") + "</td>"
                : "")
      << "<td>" << (q.pareto ? "yes" : "") << "</td>";
    for (std::size_t k = 0; k < s.key_names.size(); ++k) {
      b << "<td class=\"n\">" << (q.values[k] ? num(*q.values[k], 4) : "&ndash;");
      if (q.spread[k]) b << " &plusmn; " << num(*q.spread[k], 2);
      if (q.deviation[k] && q.run != s.points.front().run) {
        b << " (" << percent(*q.deviation[k]) << (q.within_scatter[k] ? ", inside the scatter" : "")
          << (q.paired_shift[k] ? ", shifted seed by seed" : "") << ")";
      }
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
