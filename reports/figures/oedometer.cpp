// The oedometer's figures: the paper's Figure 1 (axial stress and cumulative broken bonds
// against axial strain) and Figure 2 (lateral against axial stress), every run and branch
// (virgin, cored) overlaid, with the formation state the paper gives.

#include "reports/figures/figures.hpp"

namespace rocklab::reports {

namespace {

// The loading branches a run recorded: plain, or virgin and cored with coring.
std::vector<std::pair<std::string, std::string>> branches(const RunData& r) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const char* prefix : {"", "virgin.", "cored."}) {
    if (r.find(std::string(prefix) + "axial_strain")) {
      std::string name = prefix;
      if (!name.empty()) name = " (" + name.substr(0, name.size() - 1) + ")";
      out.emplace_back(prefix, r.label() + name);
    }
  }
  return out;
}

Series paperPoint(const Paper& paper, const char* label, double x, const char* ykey) {
  Series s;
  s.label = label;
  s.markers = true;
  if (const PaperNumber* y = paper.byKey(ykey)) {
    s.x.push_back(x);
    s.y.push_back(y->value);
  }
  return s;
}

}  // namespace

std::vector<Figure> oedometerFigures(const std::vector<const RunData*>& runs, const Paper& paper) {
  Figure f1;
  f1.id = "oedometer-figure1";
  f1.title = "Uniaxial compaction from the formation state (cf. Li & Holt, Figure 1)";
  f1.caption =
      "Axial stress (top) and cumulative number of broken bonds (bottom) against axial strain "
      "since cementing. The diamond is the paper's formation state (30 MPa axial).";
  Panel stress{"axial strain (-)", "axial stress (MPa)", {}};
  Panel broken{"axial strain (-)", "broken bonds (cumulative)", {}};
  Figure f2;
  f2.id = "oedometer-figure2";
  f2.title = "Stress path in uniaxial strain (cf. Li & Holt, Figure 2)";
  f2.caption =
      "Lateral against axial stress. The diamond is the paper's formation state (30 MPa axial, "
      "15 MPa lateral); the slope is the stress path increment.";
  Panel path{"axial stress (MPa)", "lateral stress (MPa)", {}};
  for (const RunData* r : runs) {
    for (const auto& [prefix, label] : branches(*r)) {
      Series s{label, {}, {}, false};
      pair(*r, prefix + "axial_strain", prefix + "axial_stress_MPa", s.x, s.y);
      stress.series.push_back(s);
      Series b{label, {}, {}, false};
      pair(*r, prefix + "axial_strain", prefix + "broken_bonds_total", b.x, b.y);
      broken.series.push_back(b);
      Series p{label, {}, {}, false};
      pair(*r, prefix + "axial_stress_MPa", prefix + "lateral_stress_MPa", p.x, p.y);
      path.series.push_back(p);
    }
  }
  if (stress.series.empty()) return {};
  stress.series.push_back(
      paperPoint(paper, "paper: formation state", 0.0, "formation_axial_stress"));
  Series formation = paperPoint(paper, "paper: formation state", 0.0, "formation_lateral_stress");
  if (const PaperNumber* ax = paper.byKey("formation_axial_stress"); ax && !formation.x.empty()) {
    formation.x[0] = ax->value;
  }
  path.series.push_back(formation);
  f1.panels = {stress, broken};
  f2.panels = {path};
  return {f1, f2};
}

}  // namespace rocklab::reports
