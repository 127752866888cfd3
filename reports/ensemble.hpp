#pragma once
// An ensemble's figures: the figures of each of its runs (the same protocol at several
// seeds) combined into one set, each series the mean over the runs with a spread of one
// standard deviation: a band about a curve, error bars through points.

#include <cstdint>
#include <string>
#include <vector>

#include "reports/chart.hpp"

namespace rocklab::reports {

// The run a set of figures was built from: its id, which their texts name ("run 12",
// "-run12") and which the ensemble's drop.
struct RunFigures {
  std::int64_t run = 0;
  std::vector<Figure> figures;
};

// Combines the figures of the runs, in the first run's order. Series are matched by their
// place (or, when the runs' panels hold different series, by label), curves averaged on a
// common abscissa branch by branch (a loading, an unloading: the abscissa's monotonic runs),
// points point by point. Numbers that differ between the runs' labels become "mean +- std".
// A figure whose runs differ in shape (other branches, abscissa ranges that do not meet,
// other point counts) has the runs' series overlaid instead, its caption saying so.
std::vector<Figure> combineFigures(const std::vector<RunFigures>& runs);

// A text with its mention of a run removed: "run 12 " and "-run12".
std::string withoutRun(const std::string& text, std::int64_t run);

}  // namespace rocklab::reports
