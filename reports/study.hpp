#pragma once
// What accuracy costs in time: runs of one protocol over a ladder of numerical settings,
// each compared with the finest (the first run) on the protocol's key results, and the
// study's report: the cost-accuracy chart with its Pareto front, the table, and the cheapest
// setting within the user's tolerance.

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace rocklab::reports {

// One setting of a study: its runs, one per seed.
struct StudyPoint {
  std::int64_t run = 0;            // its first run
  std::vector<std::int64_t> runs;  // all of them, in order of seed
  std::string setting;             // the varied keys' values, "numerics.timestep_safety = 0.3"
  std::string status;              // completed, or the first status of a run that did not
  double wall_seconds = 0.0;       // the mean over its runs
  // Per key result: the mean over the runs, their standard deviation (with 2 seeds or more),
  // and the mean's deviation from the finest setting's, relative.
  std::vector<std::optional<double>> values, spread, deviation;
  // Per key result: the deviation lies inside the seed scatter, Welch's 95% interval of the
  // difference of the two means (lab/campaign/statistics.hpp); never with one seed.
  std::vector<bool> within_scatter;
  // Per key result: the setting shifts it seed by seed. The same seed draws the same sample,
  // so the differences from the finest's run of each seed cancel the sample's own scatter:
  // shifted when their mean's 95% t interval excludes zero (two shared seeds or more). A
  // shift inside the unpaired scatter is still one material made into another.
  std::vector<bool> paired_shift;
  double error = 0.0;  // the largest deviation; infinite when a run failed or missed a value
  // The largest deviation beyond the seed scatter or shifted seed by seed: the accuracy the
  // setting loses (with one seed, the error).
  double loss = 0.0;
  // The largest ratio of a key result's seed scatter (standard deviation) to the finest
  // setting's: a setting that widens it needs ratio^2 times the seeds for a mean as precise
  // (NaN with one seed).
  double scatter = NAN;
  bool pareto = false;  // no faster setting loses as little
};

struct Study {
  std::string protocol, lab;
  std::vector<std::string> varied;                // the keys whose values differ between runs
  std::vector<std::string> key_names, key_units;  // the protocol's key results
  std::vector<StudyPoint> points;                 // points[0] is the finest: the reference
  std::size_t seeds = 1;                          // runs per setting (its largest count)
  double tolerance = 0.05;                        // relative
  int cheapest = 0;                               // the fastest point losing within the tolerance
};

// Reads the runs from the notebook and compares them. The runs must be of one protocol; runs
// that differ only in their seed are one setting, its key results their means; the first
// setting is the reference. A deviation is relative to the reference's value, or absolute
// where the reference is zero.
Study evaluateStudy(const std::string& lab, const std::vector<std::int64_t>& runs,
                    double tolerance);

// Writes out/index.html, out/cost-accuracy.png and .csv, and out/study.csv (one row per run).
void writeStudyReport(const Study& s, const std::string& out);

// The cheapest setting as one line, for the terminal.
std::string studySummary(const Study& s);

}  // namespace rocklab::reports
