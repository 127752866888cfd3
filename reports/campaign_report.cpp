#include "reports/campaign_report.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include "lab/campaign/statistics.hpp"
#include "lab/notebook/notebook.hpp"
#include "reports/ensemble.hpp"
#include "reports/figures/figures.hpp"
#include "reports/html.hpp"
#include "reports/key_results.hpp"
#include "reports/paper.hpp"
#include "reports/run_data.hpp"

namespace rocklab::reports {

namespace fs = std::filesystem;

namespace {

struct TaskRow {
  int point = 0;
  std::int64_t seed = 0, run = 0;
  std::string settings, status, reason;
  double core_seconds = 0.0;       // its run's wall time times its threads
  std::set<std::string> warnings;  // the kinds its run warned of (each message's words before ':')
};

struct StatisticRow {
  std::int64_t n = 0;
  double mean = 0.0, std = 0.0;
  std::optional<double> low, high;
  std::string unit;
};

struct CampaignData {
  std::int64_t id = 0;
  std::string name, file, text, protocol;
  std::vector<TaskRow> tasks;
  std::map<int, std::string> points;  // point -> its settings
  std::map<std::pair<int, std::string>, StatisticRow> statistics;
};

// A warning's kind: its words before the first ':' or ';', each number written '#' ("the
// confining stress strayed #% from its target during loading"), so that runs count together.
std::string warningKind(const std::string& text) {
  const std::string head = text.substr(0, text.find_first_of(":;"));
  std::string kind;
  for (std::size_t k = 0; k < head.size(); ++k) {
    if (!std::isdigit(static_cast<unsigned char>(head[k]))) {
      kind += head[k];
      continue;
    }
    while (k + 1 < head.size() && (std::isdigit(static_cast<unsigned char>(head[k + 1])) ||
                                   head[k + 1] == '.' || head[k + 1] == 'e' || head[k + 1] == '-'))
      ++k;
    kind += '#';
  }
  return kind;
}

CampaignData loadCampaign(notebook::Notebook& nb, const std::string& name) {
  CampaignData c;
  auto& db = nb.db();
  auto q = db.prepare("SELECT id, name, file, text, protocol FROM campaigns WHERE name = ?");
  q.bind(1, name);
  if (!q.step())
    throw std::invalid_argument("campaign '" + name + "' has not run in this notebook");
  c.id = q.integer(0), c.name = q.text(1), c.file = q.text(2), c.text = q.text(3);
  c.protocol = q.text(4);
  auto t = db.prepare(
      "SELECT p.point, p.seed, p.settings, coalesce(p.run_id, 0), coalesce(r.status, ''), "
      "coalesce(r.reason, ''), coalesce(r.wall_seconds * max(r.threads, 1), 0) FROM "
      "campaign_points p LEFT JOIN runs r ON r.id = p.run_id "
      "WHERE p.campaign_id = ? ORDER BY p.point, p.seed");
  t.bind(1, c.id);
  while (t.step()) {
    TaskRow row{static_cast<int>(t.integer(0)),
                t.integer(1),
                t.integer(3),
                t.text(2),
                t.text(4),
                t.text(5),
                t.real(6)};
    c.points[row.point] = row.settings;
    c.tasks.push_back(std::move(row));
  }
  auto w = db.prepare("SELECT text FROM messages WHERE run_id = ? AND level = 'warning'");
  for (TaskRow& row : c.tasks) {
    if (!row.run) continue;
    w.bind(1, row.run);
    while (w.step()) row.warnings.insert(warningKind(w.text(0)));
    w.reset();
  }
  auto s = db.prepare(
      "SELECT point, name, n, mean, std, ci95_low, ci95_high, unit FROM campaign_statistics "
      "WHERE campaign_id = ?");
  s.bind(1, c.id);
  while (s.step()) {
    StatisticRow row{s.integer(2), s.real(3), s.real(4), std::nullopt, std::nullopt, s.text(7)};
    if (!s.isNull(5)) row.low = s.real(5), row.high = s.real(6);
    c.statistics[{static_cast<int>(s.integer(0)), s.text(1)}] = row;
  }
  return c;
}

std::string interval(const StatisticRow& s) {
  if (!s.low) return "&ndash;";
  std::ostringstream o;
  o << "[" << num(*s.low) << ", " << num(*s.high) << "]";
  return o.str();
}

// The tasks, and what their runs warned of: an ensemble whose every run warned that its
// loading was not quasi-static measures the rate as much as the rock.
void tasksTable(std::ostream& body, const CampaignData& c) {
  body << "<h2>Tasks</h2>\n";
  std::map<std::string, int> kinds;
  int with_run = 0;
  for (const TaskRow& t : c.tasks) {
    with_run += t.run > 0;
    for (const std::string& k : t.warnings) ++kinds[k];
  }
  if (!kinds.empty()) {
    body << "<p>Warnings of the runs:</p>\n<ul>\n";
    for (const auto& [kind, runs] : kinds) {
      body << "<li>" << html(kind) << ": " << runs << " of " << with_run << " runs</li>\n";
    }
    body << "</ul>\n";
  }
  body << "<table><tr><th>point</th><th>settings</th><th>seed</th><th>run</th><th>status</th>"
          "<th>warnings</th></tr>\n";
  for (const TaskRow& t : c.tasks) {
    std::string warned;
    for (const std::string& k : t.warnings) warned += (warned.empty() ? "" : "; ") + k;
    body << "<tr><td>" << t.point << "</td><td><code>" << html(t.settings) << "</code></td><td>"
         << t.seed << "</td><td>" << (t.run ? std::to_string(t.run) : "&ndash;")
         << "</td><td class=\"status-" << html(t.status) << "\">"
         << (t.status.empty() ? "not run" : html(t.status))
         << (t.reason.empty() ? "" : ": " + html(t.reason)) << "</td><td>" << html(warned)
         << "</td></tr>\n";
  }
  body << "</table>\n";
}

// Each point's key results over its seeds, as `campaign show` prints them; also as CSV.
void keyResultsTable(std::ostream& body, const CampaignData& c,
                     const std::vector<std::string>& keys, const std::string& out,
                     ReportSummary& summary) {
  std::ofstream csv(out + "/key-results.csv");
  csv.precision(10);
  csv << "point,settings,key_result,unit,n,mean,std,ci95_low,ci95_high\n";
  body << "<h2>Key results</h2>\n<p>Per point over its completed runs: the mean, the sample "
          "standard deviation (the scatter of one sample) and the 95% confidence interval of "
          "the mean (Student t). Data: <a href=\"key-results.csv\">key-results.csv</a>.</p>\n"
          "<table><tr><th>point</th><th>key result</th><th>n</th><th>mean</th><th>std</th>"
          "<th>95% CI</th><th>unit</th></tr>\n";
  for (const auto& [point, settings] : c.points) {
    for (const std::string& key : keys) {
      auto it = c.statistics.find({point, key});
      body << "<tr><td>" << point << " <code>" << html(settings) << "</code></td><td>" << html(key)
           << "</td>";
      if (it == c.statistics.end()) {
        body << "<td class=\"n\">0</td><td colspan=\"4\">not recorded</td></tr>\n";
        continue;
      }
      const StatisticRow& s = it->second;
      body << "<td class=\"n\">" << s.n << "</td><td class=\"n\">" << num(s.mean)
           << "</td><td class=\"n\">" << num(s.std, 3) << "</td><td class=\"n\">" << interval(s)
           << "</td><td>" << html(s.unit) << "</td></tr>\n";
      std::string quoted = settings;
      for (char& ch : quoted) {
        if (ch == ',' || ch == '"') ch = ';';
      }
      csv << point << "," << quoted << "," << key << "," << s.unit << "," << s.n << "," << s.mean
          << "," << s.std << ",";
      if (s.low)
        csv << *s.low << "," << *s.high;
      else
        csv << ",";
      csv << "\n";
    }
  }
  body << "</table>\n";
  if (!csv) throw std::runtime_error("cannot write '" + out + "/key-results.csv'");
  summary.files.push_back("key-results.csv");
}

// The core time of each point's completed runs (wall time times threads), in seconds.
std::map<int, campaign::Summary> coreSeconds(const CampaignData& c) {
  std::map<int, std::vector<double>> at;
  for (const TaskRow& t : c.tasks) {
    if (t.status == "completed") at[t.point].push_back(t.core_seconds);
  }
  std::map<int, campaign::Summary> out;
  for (const auto& [point, values] : at) out[point] = campaign::summarize(values);
  return out;
}

// The seeds whose mean has a 95% interval within `fraction` of it, for a result of this
// relative scatter (std / |mean|, as one point's seeds estimate it): the least n >= 2 with
// t(0.975, n - 1) cv / sqrt(n) <= fraction. 0 past 100,000.
std::size_t seedsFor(double cv, double fraction) {
  for (std::size_t n = 2; n <= 100000; ++n) {
    if (campaign::studentT975(static_cast<double>(n - 1)) * cv / std::sqrt(double(n)) <= fraction)
      return n;
  }
  return 0;
}

// What a mean costs at each point: a size study's smaller sample is quicker per run but may
// scatter more, so it needs more seeds for the same interval. For each point and key result,
// the scatter of one sample, the seeds for a 95% interval of +-5% of the mean, and the core
// time they take at the point's mean run.
void costTable(std::ostream& body, const CampaignData& c, const std::vector<std::string>& keys) {
  const auto cost = coreSeconds(c);
  if (cost.empty()) return;
  body << "<h2>What a mean costs</h2>\n<p>Each point's core time per run (wall time times "
          "threads, mean over its completed runs), and for each key result the scatter of one "
          "sample (standard deviation over the mean), the seeds whose mean has a 95% interval "
          "of &plusmn;5% of the mean at that scatter (Student t), and their core time. The "
          "scatter is estimated from this campaign's seeds, so the seeds needed are as "
          "uncertain as it.</p>\n<table><tr><th>point</th><th>core time per run (s)</th>"
          "<th>key result</th><th>scatter</th><th>seeds for &plusmn;5%</th><th>their core "
          "time (h)</th></tr>\n";
  for (const auto& [point, settings] : c.points) {
    const auto run = cost.find(point);
    if (run == cost.end()) continue;
    for (const std::string& key : keys) {
      const auto it = c.statistics.find({point, key});
      if (it == c.statistics.end() || it->second.n < 2 || it->second.mean == 0.0) continue;
      const double cv = it->second.std / std::abs(it->second.mean);
      const std::size_t n = seedsFor(cv, 0.05);
      body << "<tr><td>" << point << " <code>" << html(settings) << "</code></td><td class=\"n\">"
           << std::lround(run->second.mean) << "</td><td>" << html(key) << "</td><td class=\"n\">"
           << num(cv, 2) << "</td><td class=\"n\">" << (n ? std::to_string(n) : "&gt; 100000")
           << "</td><td class=\"n\">"
           << (n ? num(double(n) * run->second.mean / 3600.0, 2) : "&ndash;") << "</td></tr>\n";
    }
  }
  body << "</table>\n";
}

// A point's settings ("k1=v1, k2=v2") as numbers, in the campaign's order of the keys; none
// when a value is not a number.
using Numbers = std::vector<std::pair<std::string, double>>;
std::optional<Numbers> numericSettings(const std::string& settings) {
  Numbers out;
  std::size_t from = 0;
  while (from < settings.size()) {
    std::size_t to = settings.find(", ", from);
    if (to == std::string::npos) to = settings.size();
    const std::string one = settings.substr(from, to - from);
    const auto eq = one.find('=');
    if (eq == std::string::npos) return std::nullopt;
    char* end = nullptr;
    const double x = std::strtod(one.c_str() + eq + 1, &end);
    if (end == one.c_str() + eq + 1 || *end != '\0') return std::nullopt;
    out.emplace_back(one.substr(0, eq), x);
    from = to + 2;
  }
  return out;
}

// The curves of a sweep figure: one per value of the second swept key (one in all over a
// single key), each its points in the order of the key along x.
struct SweepCurves {
  std::string x_key;
  bool log_x = false;
  std::vector<std::pair<std::string, std::vector<std::pair<double, int>>>> curves;
};

// Over one numeric key, or two (a size study at several rates, a rate check at several
// sizes): x is the key with the more values (the later on a tie), one curve per value of the
// other. None when the points sweep other keys or values that are not numbers.
std::optional<SweepCurves> sweepCurves(const CampaignData& c) {
  std::vector<std::pair<Numbers, int>> points;
  for (const auto& [point, settings] : c.points) {
    auto values = numericSettings(settings);
    if (!values || values->empty() || values->size() > 2) return std::nullopt;
    if (!points.empty()) {
      const Numbers& first = points.front().first;
      if (values->size() != first.size()) return std::nullopt;
      for (std::size_t k = 0; k < first.size(); ++k) {
        if ((*values)[k].first != first[k].first) return std::nullopt;
      }
    }
    points.emplace_back(std::move(*values), point);
  }
  if (points.size() < 2) return std::nullopt;
  const std::size_t keys = points.front().first.size();
  const auto distinct = [&](std::size_t k) {
    std::set<double> v;
    for (const auto& [values, point] : points) v.insert(values[k].second);
    return v;
  };
  const std::size_t x = keys == 2 && distinct(0).size() > distinct(1).size() ? 0 : keys - 1;
  SweepCurves s;
  s.x_key = points.front().first[x].first;
  const std::set<double> xs = distinct(x);
  // A rate halved at each point spans decades: its points are evenly apart on a log axis.
  s.log_x = *xs.begin() > 0.0 && *xs.rbegin() / *xs.begin() > 10.0;
  std::map<double, std::vector<std::pair<double, int>>> by_group;  // the other key's value
  for (const auto& [values, point] : points) {
    by_group[keys == 2 ? values[1 - x].second : 0.0].emplace_back(values[x].second, point);
  }
  for (auto& [g, at] : by_group) {
    std::sort(at.begin(), at.end());
    std::ostringstream label;
    if (keys == 2) {
      label << points.front().first[1 - x].first << "=" << g;
    } else {
      label << "mean, 95% CI";
    }
    s.curves.emplace_back(label.str(), std::move(at));
  }
  return s;
}

// A campaign over one or two numeric keys (a size study over sample.count, a rate study): each
// key result's mean with its 95% interval against the key, so that a reader sees where a
// result converges and where a smaller sample sits on the curve, and last what a run of each
// point costs. None for other campaigns.
std::optional<Figure> sweepFigure(const CampaignData& c, const std::vector<std::string>& keys) {
  const auto sweep = sweepCurves(c);
  if (!sweep) return std::nullopt;
  Figure f;
  f.id = "sweep";
  f.title = "Key results against " + sweep->x_key;
  f.caption =
      "Each point's mean over its seeds with its 95% confidence interval (Student t), "
      "against " +
      sweep->x_key + (sweep->log_x ? " (log scale)" : "") +
      (sweep->curves.size() > 1 ? ", one curve per value of the other swept key" : "") +
      "; last, what a run of each point costs in core time.";
  const auto cost = coreSeconds(c);
  const auto panel = [&](const std::string& y_label, const auto& at_point) {
    Panel p{sweep->x_key, y_label, {}, sweep->log_x};
    for (const auto& [label, at] : sweep->curves) {
      Series s;
      s.label = label;
      s.markers = sweep->curves.size() == 1;
      for (const auto& [x, point] : at) {
        const std::optional<std::array<double, 3>> v = at_point(point);
        if (!v) continue;
        s.x.push_back(x);
        s.y.push_back((*v)[0]);
        s.low.push_back((*v)[1]);
        s.high.push_back((*v)[2]);
      }
      if (!s.x.empty()) p.series.push_back(std::move(s));
    }
    if (!p.series.empty()) f.panels.push_back(std::move(p));
  };
  for (const std::string& key : keys) {
    std::string unit;
    panel(key, [&](int point) -> std::optional<std::array<double, 3>> {
      const auto it = c.statistics.find({point, key});
      if (it == c.statistics.end()) return std::nullopt;
      const StatisticRow& r = it->second;
      unit = r.unit;
      return std::array<double, 3>{r.mean, r.low.value_or(r.mean), r.high.value_or(r.mean)};
    });
    if (!f.panels.empty() && f.panels.back().y_label == key && !unit.empty() && unit != "-")
      f.panels.back().y_label += " (" + unit + ")";
  }
  if (f.panels.empty()) return std::nullopt;
  panel("core time per run (s)", [&](int point) -> std::optional<std::array<double, 3>> {
    const auto it = cost.find(point);
    if (it == cost.end()) return std::nullopt;
    const campaign::Summary& r = it->second;
    return std::array<double, 3>{r.mean, r.n > 1 ? r.low : r.mean, r.n > 1 ? r.high : r.mean};
  });
  return f;
}

// A point's figures: each run's built alone and combined, with the rig's own ensemble
// figures in place of those of the same id.
std::vector<Figure> pointFigures(const std::vector<const RunData*>& runs, const Paper& paper) {
  const FigureEntry* entry = nullptr;
  for (const FigureEntry& e : figureTable()) {
    if (e.rig == runs.front()->rig) entry = &e;
  }
  if (!entry) return {};
  std::vector<RunFigures> per_run;
  for (const RunData* r : runs) per_run.push_back({r->id, entry->build({r}, paper)});
  std::vector<Figure> out = combineFigures(per_run);
  if (!entry->ensemble) return out;
  for (Figure& own : entry->ensemble(runs, paper)) {
    bool replaced = false;
    for (Figure& f : out) {
      if (f.id == own.id) f = own, replaced = true;
    }
    if (!replaced) out.push_back(std::move(own));
  }
  return out;
}

// A point's figures in the report: its number, its swept values, its figures over the seeds.
struct PointFigures {
  int point = 0;
  std::string settings;
  std::vector<Figure> figures;
};

// Every point's curves of one figure drawn together (what the swept keys do to a curve, for
// example formation porosity to Figures 1 and 2): each point's series over its seeds, with
// its band, labelled "point N" (the caption says each point's values: a legend of them would
// hide the curves). A series every point draws alike (the paper's values) is drawn once, with
// its own label. None where a point lacks the figure or draws other panels.
std::optional<Figure> comparedFigure(const std::string& id,
                                     const std::vector<PointFigures>& points) {
  std::vector<const Figure*> members;
  for (const PointFigures& pf : points) {
    const auto it = std::find_if(pf.figures.begin(), pf.figures.end(),
                                 [&](const Figure& f) { return f.id == id; });
    if (it == pf.figures.end()) return std::nullopt;
    members.push_back(&*it);
  }
  const Figure& first = *members.front();
  for (const Figure* m : members) {
    if (m->panels.size() != first.panels.size()) return std::nullopt;
  }
  Figure f;
  f.id = "compared-" + id;
  f.title = first.title + ": the points compared";
  f.caption =
      "The points' figures above drawn together, each curve a point's mean over its seeds "
      "with its band:";
  for (const PointFigures& pf : points) {
    f.caption += (&pf == &points.front() ? " " : "; ") + std::string("point ") +
                 std::to_string(pf.point) + ", " + pf.settings;
  }
  f.caption += ".";
  auto same = [](const Series& a, const Series& b) {
    return a.label == b.label && a.x == b.x && a.y == b.y;
  };
  for (std::size_t p = 0; p < first.panels.size(); ++p) {
    Panel panel{first.panels[p].x_label, first.panels[p].y_label, {}};
    // Drawn alike by every point: once.
    std::vector<const Series*> shared;
    for (const Series& s : first.panels[p].series) {
      const bool everywhere = std::all_of(members.begin(), members.end(), [&](const Figure* m) {
        const auto& list = m->panels[p].series;
        return std::any_of(list.begin(), list.end(), [&](const Series& x) { return same(x, s); });
      });
      if (everywhere) shared.push_back(&s);
    }
    for (std::size_t k = 0; k < members.size(); ++k) {
      std::vector<const Series*> own;
      for (const Series& s : members[k]->panels[p].series) {
        if (std::none_of(shared.begin(), shared.end(),
                         [&](const Series* x) { return same(*x, s); }))
          own.push_back(&s);
      }
      for (const Series* s : own) {
        panel.series.push_back(*s);
        panel.series.back().label = "point " + std::to_string(points[k].point) +
                                    (own.size() > 1 && !s->label.empty() ? ": " + s->label : "");
      }
    }
    for (const Series* s : shared) panel.series.push_back(*s);
    f.panels.push_back(std::move(panel));
  }
  return f;
}

}  // namespace

ReportSummary writeCampaignReport(const CampaignReportOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!fs::exists(o.lab)) throw std::invalid_argument("no lab notebook at '" + o.lab + "'");
  notebook::Notebook nb(o.lab);
  const CampaignData c = loadCampaign(nb, o.campaign);
  std::map<int, std::vector<RunData>> runs;  // per point, its completed runs
  for (const TaskRow& t : c.tasks) {
    if (t.status == "completed") runs[t.point].push_back(loadRun(nb, t.run));
  }
  if (runs.empty()) {
    throw std::invalid_argument("campaign '" + c.name + "' has no completed run in '" + o.lab +
                                "' yet");
  }
  fs::create_directories(o.out);
  const Paper paper = loadPaper(o.data_dir + "/paper.toml");
  ReportSummary summary;
  const RunData& any = runs.begin()->second.front();

  std::ostringstream body;
  body << "<h1>Campaign " << html(c.name) << "</h1>\n<p>Protocol <code>" << html(c.protocol)
       << "</code> (" << html(any.rig) << "), " << c.points.size() << " points, " << c.tasks.size()
       << " tasks; lab notebook <code>" << html(o.lab)
       << "</code>.</p>\n<details><summary>Campaign file <code>" << html(c.file)
       << "</code></summary><pre>" << html(c.text) << "</pre></details>\n";
  tasksTable(body, c);
  keyResultsTable(body, c, keyResultNames(any), o.out, summary);
  if (const auto sweep = sweepFigure(c, keyResultNames(any))) {
    body << "<h2>Against the sweep</h2>\n";
    writeFigure(*sweep, o.out, body, summary);
  }
  costTable(body, c, keyResultNames(any));
  body << "<h2>Figures</h2>\n";
  std::vector<PointFigures> by_point;
  for (const auto& [point, point_runs] : runs) {
    body << "<h3>Point " << point << ": <code>" << html(c.points.at(point)) << "</code>, "
         << point_runs.size() << " completed runs</h3>\n";
    std::vector<const RunData*> ptrs;
    for (const RunData& r : point_runs) ptrs.push_back(&r);
    by_point.push_back({point, c.points.at(point), pointFigures(ptrs, paper)});
    for (Figure f : by_point.back().figures) {
      f.id = "point" + std::to_string(point) + "-" + f.id;
      writeFigure(f, o.out, body, summary);
    }
  }
  // Past the palette's eight colours the curves could not be told apart.
  if (by_point.size() > 1 && by_point.size() <= 8) {
    body << "<h2>The points compared</h2>\n";
    for (const Figure& f : by_point.front().figures) {
      if (const auto compared = comparedFigure(f.id, by_point)) {
        writeFigure(*compared, o.out, body, summary);
      }
    }
  }
  std::ofstream index(o.out + "/index.html");
  index << page("rocklab campaign " + c.name, body.str());
  if (!index) throw std::runtime_error("cannot write '" + o.out + "/index.html'");
  summary.files.push_back("index.html");
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return summary;
}

}  // namespace rocklab::reports
