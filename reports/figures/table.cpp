#include "reports/figures/figures.hpp"

namespace rocklab::reports {

const std::vector<FigureEntry>& figureTable() {
  static const std::vector<FigureEntry> table = {
      {"oedometer", oedometerFigures},
      {"hydrostatic", hydrostaticFigures},
      {"biaxial", biaxialFigures},
      {"envelope", envelopeFigures, envelopeEnsembleFigures},
      {"permeameter", permeameterFigures},
      {"ultrasonic", ultrasonicFigures},
      {"brazilian", brazilianFigures},
      {"direct_tension", directTensionFigures},
      {"ucs", ucsFigures},
  };
  return table;
}

}  // namespace rocklab::reports
