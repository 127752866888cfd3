// The hydrostatic cell's figure: stress and broken bonds against volumetric strain, loading
// and unloading, every run overlaid.

#include "reports/figures/figures.hpp"

namespace rocklab::reports {

std::vector<Figure> hydrostaticFigures(const std::vector<const RunData*>& runs, const Paper&) {
  Figure f;
  f.id = "hydrostatic-compaction";
  f.title = "Hydrostatic loading and unloading";
  f.caption =
      "Mean stress (top) and cumulative broken bonds (bottom) against volumetric strain since "
      "cementing, for the loading to the peak and the unloading.";
  Panel stress{"volumetric strain (-)", "stress (MPa)", {}};
  Panel broken{"volumetric strain (-)", "broken bonds (cumulative)", {}};
  for (const RunData* r : runs) {
    for (const char* stage : {"loading.", "unloading."}) {
      const std::string label =
          r->label() + " " + std::string(stage).substr(0, std::string(stage).size() - 1);
      Series s{label, {}, {}, false};
      pair(*r, std::string(stage) + "volumetric_strain", std::string(stage) + "axial_stress_MPa",
           s.x, s.y);
      if (!s.x.empty()) stress.series.push_back(s);
      Series b{label, {}, {}, false};
      pair(*r, std::string(stage) + "volumetric_strain", std::string(stage) + "broken_bonds_total",
           b.x, b.y);
      if (!b.x.empty()) broken.series.push_back(b);
    }
  }
  if (stress.series.empty()) return {};
  f.panels = {stress, broken};
  return {f};
}

}  // namespace rocklab::reports
