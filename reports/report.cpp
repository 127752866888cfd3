#include "reports/report.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include "lab/core/frame.hpp"
#include "lab/notebook/notebook.hpp"
#include "reports/chart.hpp"
#include "reports/figures/figures.hpp"
#include "reports/html.hpp"
#include "reports/key_results.hpp"
#include "reports/paper.hpp"
#include "reports/run_data.hpp"
#include "reports/snapshot.hpp"
#include "reports/vtk_export.hpp"

namespace rocklab::reports {

namespace fs = std::filesystem;

namespace {

// One colour field over the particles of a frame.
FieldValues field(const std::string& which, const Frame& f, const Frame& first, const RunData& r,
                  const SnapshotRow& snap) {
  FieldValues v;
  v.values.assign(f.size(), 0.0);
  if (snap.stage.rfind("wave-", 0) == 0) {
    // A wave front (Figure 17): each particle's velocity along the wave's polarisation, signed,
    // whatever field the report draws elsewhere. pz moves along the axis (the last), px and
    // szx along x, sxy along y.
    const std::string wave = snap.stage.substr(5);
    const int axis = wave == "pz" ? f.dimension - 1 : (wave == "sxy" ? 1 : 0);
    v.label = "velocity along " + std::string(1, "xyz"[axis]) + " (mm/s)";
    std::vector<double> magnitude;
    for (std::size_t i = 0; i < f.size(); ++i) {
      v.values[i] = 1e3 * f.vel[i][axis];
      magnitude.push_back(std::abs(v.values[i]));
    }
    // Symmetric (the sign is the pulse's phase), to the 98th percentile: a loose grain
    // rattling in its pore would wash the front out.
    std::sort(magnitude.begin(), magnitude.end());
    const double peak = magnitude.empty()
                            ? 0.0
                            : magnitude[static_cast<std::size_t>(0.98 * (magnitude.size() - 1))];
    v.lo = -peak, v.hi = peak > 0.0 ? peak : 1.0;
    return v;
  }
  if (which == "velocity") {
    v.label = "speed (mm/s)";
    for (std::size_t i = 0; i < f.size(); ++i) {
      const auto& u = f.vel[i];
      v.values[i] = 1e3 * std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    }
  } else if (which == "grain") {
    // Neighbouring grains in well-separated colours: ids spread by the golden ratio.
    v.label = "grain (id, shuffled)";
    for (std::size_t i = 0; i < f.size(); ++i) {
      if (i < f.cluster.size() && f.cluster[i] != 0xffffffffu) {
        v.values[i] = std::fmod(0.618033988749895 * f.cluster[i], 1.0);
      }
    }
  } else if (which == "broken_bonds") {
    v.label = "broken bonds per particle";
    std::unordered_map<std::int64_t, double> count;
    for (const notebook::EventRecord& e : r.breaks) {
      if (e.stage != snap.stage || e.step > snap.step) continue;
      count[e.particle_a] += 1.0;
      count[e.particle_b] += 1.0;
    }
    for (std::size_t i = 0; i < f.size(); ++i) {
      auto it = count.find(f.slot[i]);
      if (it != count.end()) v.values[i] = it->second;
    }
  } else {
    v.label = "displacement (mm)";
    std::unordered_map<std::uint32_t, std::size_t> ref;
    for (std::size_t i = 0; i < first.size(); ++i) ref[first.slot[i]] = i;
    for (std::size_t i = 0; i < f.size(); ++i) {
      auto it = ref.find(f.slot[i]);
      if (it == ref.end()) continue;
      double d2 = 0.0;
      for (int d = 0; d < 3; ++d) {
        const double u = f.pos[i][d] - first.pos[it->second][d];
        d2 += u * u;
      }
      v.values[i] = 1e3 * std::sqrt(d2);
    }
  }
  // Colour range to the 99th percentile, so a few outliers do not wash the field out.
  std::vector<double> sorted = v.values;
  std::sort(sorted.begin(), sorted.end());
  v.lo = sorted.empty() ? 0.0 : sorted.front();
  v.hi = sorted.empty() ? 1.0 : sorted[static_cast<std::size_t>(0.99 * (sorted.size() - 1))];
  if (!(v.hi > v.lo)) v.hi = v.lo + 1.0;
  return v;
}

std::vector<BreakMark> breaksUpTo(const RunData& r, const SnapshotRow& snap) {
  std::vector<BreakMark> out;
  for (const notebook::EventRecord& e : r.breaks) {
    if (e.stage != snap.stage || e.step > snap.step) continue;
    out.push_back({{e.x, e.y, e.z}, e.mode == "tensile", e.granular == "intra"});
  }
  return out;
}

}  // namespace

namespace {

// The runs at a glance.
void runsTable(std::ostream& body, const std::vector<RunData>& runs) {
  body << "<h2>Runs</h2>\n<table><tr><th>run</th><th>protocol</th><th>rig</th><th>status</th>"
          "<th>started (UTC)</th><th>wall time (s)</th><th>code version</th><th>build</th></tr>\n";
  for (const RunData& r : runs) {
    body << "<tr><td>" << r.id << "</td><td>" << html(r.protocol) << "</td><td>" << html(r.rig)
         << "</td><td class=\"status-" << r.status << "\">" << r.status
         << (r.reason.empty() ? "" : ": " + html(r.reason)) << "</td><td>" << html(r.started)
         << "</td><td class=\"n\">" << num(r.wall_seconds, 4) << "</td><td><code>"
         << html(r.code_version) << "</code></td><td>" << html(r.build_type) << "</td></tr>\n";
  }
  body << "</table>\n";
}

// What each protocol is for: its key results (reports/key_results.hpp).
void keyResultsTable(std::ostream& body, const std::vector<RunData>& runs) {
  body << "<h2>Key results</h2>\n<table><tr><th>run</th><th>key result</th><th>value</th>"
          "<th>unit</th><th>meaning</th></tr>\n";
  for (const RunData& r : runs) {
    for (const KeyValue& k : keyResults(r)) {
      body << "<tr><td>" << r.id << "</td><td>" << html(k.name) << "</td><td class=\"n\">"
           << (k.value ? num(*k.value) : "not recorded") << "</td><td>" << html(k.unit)
           << "</td><td>" << html(k.doc) << "</td></tr>\n";
    }
  }
  body << "</table>\n";
}

// Each rig's figures, the runs of that rig overlaid.
void figures(std::ostream& body, const std::vector<RunData>& runs, const Paper& paper,
             const std::string& out, ReportSummary& summary) {
  body << "<h2>Figures</h2>\n";
  std::size_t count = 0;
  for (const FigureEntry& entry : figureTable()) {
    std::vector<const RunData*> of_rig;
    for (const RunData& r : runs) {
      if (r.rig == entry.rig) of_rig.push_back(&r);
    }
    if (of_rig.empty()) continue;
    for (const Figure& f : entry.build(of_rig, paper)) {
      writeFigure(f, out, body, summary);
      ++count;
    }
  }
  if (count == 0) body << "<p>No figures for these runs' rigs.</p>\n";
}

// One state frame of a run rendered off screen: the cutaway view, and in 3D the section.
void snapshotFigures(std::ostream& body, const RunData& r, const SnapshotRow& snap, const Frame& f,
                     const Frame& first, const std::string& colouring, const std::string& out,
                     ReportSummary& summary) {
  const FieldValues v = field(colouring, f, first, r, snap);
  const auto marks = breaksUpTo(r, snap);
  const std::string stem =
      "run" + std::to_string(r.id) + "-" + snap.stage + "-" + std::to_string(snap.step);
  const std::string what =
      snap.stage + ", " + snap.label + " (step " + std::to_string(snap.step) + ")";
  renderView(f, v, marks, r.label() + ": " + what, out + "/" + stem + "-view.png");
  summary.files.push_back(stem + "-view.png");
  body << "<figure><img src=\"" << stem << "-view.png\" alt=\"" << html(what) << "\"><figcaption>"
       << html(what) << ": "
       << (f.dimension == 3 ? "the half behind the mid-plane, its cut face showing the "
                              "interior; "
                            : "")
       << html(v.label) << ", " << marks.size() << " broken bonds of this stage marked "
       << (f.dimension == 3 ? "near the mid-plane" : "") << ".</figcaption></figure>\n";
  if (f.dimension != 3) return;
  renderSlice(f, v, marks, r.label() + ": " + what, out + "/" + stem + "-slice.png");
  summary.files.push_back(stem + "-slice.png");
  body << "<figure><img src=\"" << stem << "-slice.png\" alt=\"" << html(what)
       << " section\"><figcaption>" << html(what)
       << ": the section by the mid-plane.</figcaption></figure>\n";
}

// Snapshots rendered off screen from the state frames the runs saved.
void snapshots(std::ostream& body, const std::vector<RunData>& runs, const ReportOptions& o,
               ReportSummary& summary) {
  body << "<h2>Snapshots</h2>\n";
  for (const RunData& r : runs) {
    if (r.snapshots.empty()) continue;
    const Frame first = readFrame(r.snapshots.front().path);
    body << "<h3>" << html(r.label()) << "</h3>\n<div class=\"snap\">\n";
    for (const SnapshotRow& snap : r.snapshots) {
      const Frame f = snap.path == r.snapshots.front().path ? first : readFrame(snap.path);
      snapshotFigures(body, r, snap, f, first, o.field, o.out, summary);
    }
    body << "</div>\n";
  }
}

// The paper's numbers beside the runs'.
void paperNumbers(std::ostream& body, const std::vector<RunData>& runs, const Paper& paper) {
  body << "<h2>The paper's numbers</h2>\n<p>From <code>data/paper.toml</code>; a run's value "
          "stands beside each number it has.</p>\n<table><tr><th>number</th><th>paper</th>"
          "<th>unit</th><th>source</th>";
  for (const RunData& r : runs) body << "<th>run " << r.id << "</th>";
  body << "</tr>\n";
  for (const PaperNumber& n : paper.numbers) {
    std::ostringstream cells;
    bool any = false;
    for (const RunData& r : runs) {
      std::string v;
      if (!n.param.empty()) v = html(r.param(n.param));
      if (!n.result.empty()) {
        auto it = r.results.find(n.result);
        if (it != r.results.end()) v = num(it->second.value);
      }
      any = any || !v.empty();
      cells << "<td class=\"n\">" << v << "</td>";
    }
    if (!any) continue;  // numbers of other rigs
    body << "<tr><td>" << html(n.key)
         << (n.note.empty() ? "" : " <small>(" + html(n.note) + ")</small>")
         << "</td><td class=\"n\">" << num(n.value) << "</td><td>" << html(n.unit) << "</td><td>"
         << html(n.source) << "</td>" << cells.str() << "</tr>\n";
  }
  body << "</table>\n";
}

// One run in detail: its messages, results, time per stage and parameters.
void runDetails(std::ostream& body, const RunData& r, const Paper& paper) {
  body << "<h3>" << html(r.label()) << "</h3>\n<p>Protocol file <code>" << html(r.protocol_file)
       << "</code>.</p>\n";
  for (const auto& [level, text] : r.messages) {
    body << "<p class=\"" << (level == "warning" ? "status-failed" : "") << "\">" << html(level)
         << ": " << html(text) << "</p>\n";
  }
  body << "<details open><summary>Results</summary><table><tr><th>result</th><th>value</th>"
          "<th>unit</th><th>paper</th></tr>\n";
  for (const auto& [name, q] : r.results) {
    const PaperNumber* p = paper.byResult(name);
    body << "<tr><td>" << html(name) << "</td><td class=\"n\">" << num(q.value) << "</td><td>"
         << html(q.unit) << "</td><td class=\"n\">" << (p ? num(p->value) : "") << "</td></tr>\n";
  }
  body << "</table></details>\n";
  double total = 0.0;
  for (const auto& t : r.timings) total += std::get<1>(t);
  body << "<details open><summary>Time per stage</summary><table><tr><th>stage</th>"
          "<th>seconds</th><th>calls</th><th>share</th></tr>\n";
  for (const auto& [stage, seconds, calls] : r.timings) {
    body << "<tr><td>" << html(stage) << "</td><td class=\"n\">" << num(seconds, 4)
         << "</td><td class=\"n\">" << calls << "</td><td class=\"n\">"
         << num(total > 0 ? 100.0 * seconds / total : 0.0, 3) << "%</td></tr>\n";
  }
  body << "</table></details>\n";
  body << "<details><summary>Parameters</summary><table><tr><th>key</th><th>value</th>"
          "<th>unit</th><th>paper</th></tr>\n";
  for (const auto& [key, value, unit] : r.params) {
    const PaperNumber* p = paper.byParam(key);
    body << "<tr><td>" << html(key) << "</td><td>" << html(value) << "</td><td>" << html(unit)
         << "</td><td class=\"n\">" << (p ? num(p->value) : "") << "</td></tr>\n";
  }
  body << "</table></details>\n";
}

}  // namespace

void writeFigure(const Figure& f, const std::string& out, std::ostream& body,
                 ReportSummary& summary) {
  renderFigure(f, out);
  summary.files.push_back(f.id + ".png");
  summary.files.push_back(f.id + ".csv");
  body << "<figure><img src=\"" << f.id << ".png\" alt=\"" << html(f.title) << "\"><figcaption><b>"
       << html(f.title) << ".</b> " << html(f.caption) << " Data: <a href=\"" << f.id << ".csv\">"
       << f.id << ".csv</a>.</figcaption></figure>\n";
}

ReportSummary writeReport(const ReportOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  if (o.runs.empty()) throw std::invalid_argument("report: name at least one run");
  if (!fs::exists(o.lab)) throw std::invalid_argument("no lab notebook at '" + o.lab + "'");
  if (o.field != "displacement" && o.field != "velocity" && o.field != "broken_bonds" &&
      o.field != "grain") {
    throw std::invalid_argument(
        "report: --field must be displacement, velocity, broken_bonds or grain");
  }
  fs::create_directories(o.out);
  notebook::Notebook nb(o.lab);
  std::vector<RunData> runs;
  for (std::int64_t id : o.runs) runs.push_back(loadRun(nb, id));
  const Paper paper = loadPaper(o.data_dir + "/paper.toml");
  ReportSummary summary;

  std::ostringstream body;
  body << "<h1>rocklab report</h1>\n<p>Lab notebook <code>" << html(o.lab) << "</code>, runs ";
  for (std::size_t k = 0; k < runs.size(); ++k) body << (k ? ", " : "") << runs[k].id;
  body << ".</p>\n";
  runsTable(body, runs);
  keyResultsTable(body, runs);
  figures(body, runs, paper, o.out, summary);
  if (o.snapshots) snapshots(body, runs, o, summary);
  paperNumbers(body, runs, paper);
  body << "<h2>Run details</h2>\n";
  for (const RunData& r : runs) runDetails(body, r, paper);

  std::ofstream index(o.out + "/index.html");
  index << page("rocklab report", body.str());
  if (!index) throw std::runtime_error("cannot write '" + o.out + "/index.html'");
  summary.files.push_back("index.html");
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return summary;
}

std::string exportRun(const std::string& lab, std::int64_t run, const std::string& dir) {
  if (!fs::exists(lab)) throw std::invalid_argument("no lab notebook at '" + lab + "'");
  notebook::Notebook nb(lab);
  const RunData r = loadRun(nb, run);
  if (r.snapshots.empty()) {
    throw std::invalid_argument("run " + std::to_string(run) +
                                " saved no state frames (output.snapshots = false?)");
  }
  fs::create_directories(dir);
  const Frame first = readFrame(r.snapshots.front().path);
  std::vector<PvdEntry> entries;
  for (const SnapshotRow& snap : r.snapshots) {
    const Frame f = readFrame(snap.path);
    const std::string stem =
        "run" + std::to_string(run) + "-" + snap.stage + "-" + std::to_string(snap.step);
    const auto written = writeFrameVtk(f, &first, dir, stem);
    entries.insert(entries.end(), written.begin(), written.end());
  }
  const std::string pvd = dir + "/run" + std::to_string(run) + ".pvd";
  writePvd(pvd, entries);
  return pvd;
}

}  // namespace rocklab::reports
