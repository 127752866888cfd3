// The biaxial frame's and triaxial cell's figure: deviatoric stress, volumetric strain and
// cumulative broken bonds (cement and inside grains) against axial strain, one curve per
// run, labelled with its confinement (cf. Li & Holt, section 2.3), with the paper's UCS.

#include "reports/figures/figures.hpp"

#include <sstream>

namespace rocklab::reports {

std::vector<Figure> biaxialFigures(const std::vector<const RunData*>& runs, const Paper& paper) {
  Figure f;
  f.id = "biaxial-stress-strain";
  f.title = "Biaxial / triaxial tests: stress, volume change and damage against axial strain";
  f.caption =
      "Deviatoric stress (top), volumetric strain, compaction positive (middle), and cumulative "
      "broken bonds between grains (cement) and inside grains (crushing) (bottom) against "
      "axial strain since the start of loading; one curve per run, labelled with its "
      "confining stress. The paper's UCS is the marker at zero strain.";
  Panel stress{"axial strain (-)", "deviatoric stress (MPa)", {}};
  Panel volume{"axial strain (-)", "volumetric strain (-)", {}};
  Panel broken{"axial strain (-)", "broken bonds (cumulative)", {}};
  for (const RunData* r : runs) {
    std::ostringstream label;
    label << r->label();
    if (auto it = r->results.find("confining_stress_MPa"); it != r->results.end()) {
      label << ", sigma3 = " << it->second.value << " MPa";
    }
    Series q{label.str(), {}, {}, false};
    pair(*r, "axial_strain", "deviatoric_stress_MPa", q.x, q.y);
    if (q.x.empty()) continue;
    stress.series.push_back(q);
    Series v{label.str(), {}, {}, false};
    pair(*r, "axial_strain", "volumetric_strain", v.x, v.y);
    volume.series.push_back(v);
    Series cement{label.str() + ": cement", {}, {}, false};
    pair(*r, "axial_strain", "broken_bonds_total", cement.x, cement.y);
    broken.series.push_back(cement);
    Series tensile{label.str() + ": in grains", {}, {}, false};
    Series shear{"", {}, {}, false};
    pair(*r, "axial_strain", "broken_grain_bonds_tensile", tensile.x, tensile.y);
    pair(*r, "axial_strain", "broken_grain_bonds_shear", shear.x, shear.y);
    if (!tensile.x.empty() && shear.y.size() == tensile.y.size()) {
      for (std::size_t k = 0; k < tensile.y.size(); ++k) tensile.y[k] += shear.y[k];
      broken.series.push_back(tensile);
    }
  }
  if (stress.series.empty()) return {};
  if (const PaperNumber* ucs = paper.byKey("ucs")) {
    stress.series.push_back({"paper: UCS", {0.0}, {ucs->value}, true});
  }
  f.panels = {stress, volume, broken};
  return {f};
}

}  // namespace rocklab::reports
