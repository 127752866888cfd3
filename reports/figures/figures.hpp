#pragma once
// The figures each rig contributes to a report: one table row per rig (figures/table.cpp).
// A rig's figure code reads run data and returns chart specifications; the report core
// renders them. Adding a rig's figures is one file and one row.

#include <string_view>
#include <vector>

#include "reports/chart.hpp"
#include "reports/paper.hpp"
#include "reports/run_data.hpp"

namespace rocklab::reports {

using FigureBuilder = std::vector<Figure> (*)(const std::vector<const RunData*>& runs,
                                              const Paper& paper);

struct FigureEntry {
  std::string_view rig;
  FigureBuilder build;
};

const std::vector<FigureEntry>& figureTable();

std::vector<Figure> oedometerFigures(const std::vector<const RunData*>& runs, const Paper& paper);
std::vector<Figure> hydrostaticFigures(const std::vector<const RunData*>& runs, const Paper& paper);
std::vector<Figure> biaxialFigures(const std::vector<const RunData*>& runs, const Paper& paper);
std::vector<Figure> envelopeFigures(const std::vector<const RunData*>& runs, const Paper& paper);
std::vector<Figure> permeameterFigures(const std::vector<const RunData*>& runs, const Paper& paper);
std::vector<Figure> ultrasonicFigures(const std::vector<const RunData*>& runs, const Paper& paper);

}  // namespace rocklab::reports
