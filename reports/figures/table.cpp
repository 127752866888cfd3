#include "reports/figures/figures.hpp"

namespace rocklab::reports {

const std::vector<FigureEntry>& figureTable() {
  static const std::vector<FigureEntry> table = {
      {"oedometer", oedometerFigures},
      {"hydrostatic", hydrostaticFigures},
      {"biaxial", biaxialFigures},
  };
  return table;
}

}  // namespace rocklab::reports
