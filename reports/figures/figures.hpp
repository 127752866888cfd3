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
  FigureBuilder build;  // the runs overlaid
  // For the runs of one protocol at several seeds (a campaign point): the figures that a
  // mean of each run's would misstate, which replace those of the same id (reports/ensemble.hpp
  // combines the others). May be null.
  FigureBuilder ensemble = nullptr;
};

const std::vector<FigureEntry>& figureTable();

std::vector<Figure> oedometerFigures(const std::vector<const RunData*>& runs, const Paper& paper);
std::vector<Figure> hydrostaticFigures(const std::vector<const RunData*>& runs, const Paper& paper);
std::vector<Figure> biaxialFigures(const std::vector<const RunData*>& runs, const Paper& paper);
std::vector<Figure> envelopeFigures(const std::vector<const RunData*>& runs, const Paper& paper);
std::vector<Figure> envelopeEnsembleFigures(const std::vector<const RunData*>& seeds,
                                            const Paper& paper);
std::vector<Figure> permeameterFigures(const std::vector<const RunData*>& runs, const Paper& paper);
std::vector<Figure> ultrasonicFigures(const std::vector<const RunData*>& runs, const Paper& paper);
std::vector<Figure> brazilianFigures(const std::vector<const RunData*>& runs, const Paper& paper);
std::vector<Figure> directTensionFigures(const std::vector<const RunData*>& runs,
                                         const Paper& paper);
std::vector<Figure> ucsFigures(const std::vector<const RunData*>& runs, const Paper& paper);

}  // namespace rocklab::reports
