#pragma once
// `rocklab report` and `rocklab export`: figure reports from the notebook, and VTK files
// for ParaView from the runs' state frames.

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "reports/chart.hpp"

namespace rocklab::reports {

struct ReportOptions {
  std::string lab = "lab.sqlite";
  std::vector<std::int64_t> runs;
  std::string out;
  std::string field = "displacement";  // snapshot colouring: displacement, velocity, broken_bonds
  std::string data_dir;                // holds paper.toml
  bool snapshots = true;
};

struct ReportSummary {
  std::vector<std::string> files;  // every file written, relative to `out`
  double seconds = 0.0;
};

// Renders a figure into `out` (PNG and CSV, noted in `summary`) and writes its HTML block,
// caption and link to its data, into `body`.
void writeFigure(const Figure& f, const std::string& out, std::ostream& body,
                 ReportSummary& summary);

// Writes out/index.html with the figures (PNG + CSV), snapshots and tables.
ReportSummary writeReport(const ReportOptions& o);

// Writes every frame of a run as VTK XML PolyData and a .pvd time series into `dir`;
// returns the .pvd path.
std::string exportRun(const std::string& lab, std::int64_t run, const std::string& dir);

}  // namespace rocklab::reports
