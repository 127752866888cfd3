#pragma once
// What accuracy costs in time: runs of one protocol over a ladder of numerical settings,
// each compared with the finest (the first run) on the protocol's key results, and the
// study's report: the cost-accuracy chart with its Pareto front, the table, and the cheapest
// setting within the user's tolerance.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace rocklab::reports {

struct StudyPoint {
  std::int64_t run = 0;
  std::string setting;  // the varied keys' values, "numerics.timestep_safety = 0.3"
  std::string status;
  double wall_seconds = 0.0;
  std::vector<std::optional<double>> values;     // per key result
  std::vector<std::optional<double>> deviation;  // relative to the finest, per key result
  double error = 0.0;   // the largest deviation; infinite when a run failed or missed a value
  bool pareto = false;  // no faster run is as accurate
};

struct Study {
  std::string protocol, lab;
  std::vector<std::string> varied;                // the keys whose values differ between runs
  std::vector<std::string> key_names, key_units;  // the protocol's key results
  std::vector<StudyPoint> points;                 // points[0] is the finest: the reference
  double tolerance = 0.05;                        // relative
  int cheapest = 0;                               // index of the fastest point within the tolerance
};

// Reads the runs from the notebook (the first is the reference) and compares them. The runs
// must be of one protocol. A deviation is relative to the reference's value, or absolute
// where the reference is zero.
Study evaluateStudy(const std::string& lab, const std::vector<std::int64_t>& runs,
                    double tolerance);

// Writes out/index.html, out/cost-accuracy.png and .csv, and out/study.csv (one row per run).
void writeStudyReport(const Study& s, const std::string& out);

// The cheapest setting as one line, for the terminal.
std::string studySummary(const Study& s);

}  // namespace rocklab::reports
