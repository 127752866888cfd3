// The permeameter's figures (Li & Holt section 3.5): the steady pore-pressure field before
// loading (Figure 11), k/k0 against porosity beside Kozeny-Carman (Figures 12 and 13), k/k0
// under loading, along and normal to it when both were measured (Figure 14), and
// what each flow solver cost on the same network.

#include <algorithm>
#include <cmath>
#include <sstream>

#include "reports/figures/figures.hpp"

namespace rocklab::reports {

namespace {

std::string fixed(double v, int digits) {
  std::ostringstream o;
  o.setf(std::ios::fixed);
  o.precision(digits);
  o << v;
  return o.str();
}

bool biaxialLoading(const RunData& r) {
  return r.param("loading.mode") == "biaxial";
}

// Figure 11: the pores' centroids coloured by pressure band (five bands of the drop), in
// the plane of the flow (3D: a slab two mean diameters thick through the middle), and the
// pressure against height with Darcy's straight line.
Figure pressureField(const RunData& r) {
  const bool three_d = r.param("protocol.dimension") == "3";
  const bool normal = r.param("flow.direction") == "normal";
  std::vector<const notebook::EventRecord*> pores;
  double lo = 1e300, hi = -1e300, mid_lo = 1e300, mid_hi = -1e300;
  for (const notebook::EventRecord& p : r.pores) {
    if (p.stage != "initial") continue;
    pores.push_back(&p);
    lo = std::min(lo, p.value), hi = std::max(hi, p.value);
    mid_lo = std::min(mid_lo, p.y), mid_hi = std::max(mid_hi, p.y);
  }
  Figure f;
  f.id = "pressure-field-run" + std::to_string(r.id);
  f.title = "Steady pore pressure before loading, " + r.label();
  f.caption =
      "Each pore at its centroid, coloured by its pressure's fifth of the drop (top; 3D: the "
      "pores of a slab 2 mm thick through the middle of the sample, in the x-z plane), and "
      "every pore's pressure against its position along the flow (bottom): the pressure "
      "falls linearly from inlet to outlet, as Darcy's law says (cf. Figure 11).";
  const std::string along = three_d ? (normal ? "x" : "z") : (normal ? "x" : "y");
  Panel map{"x (mm)", (three_d ? "z" : "y") + std::string(" (mm)"), {}};
  Panel profile{along + " (mm)", "pore pressure (kPa)", {}};
  const double span = std::max(hi - lo, 1e-30);
  for (int band = 0; band < 5; ++band) {
    Series s{fixed((lo + span * band / 5) / 1e3, 1) + "-" +
                 fixed((lo + span * (band + 1) / 5) / 1e3, 1) + " kPa",
             {},
             {},
             true};
    map.series.push_back(s);
  }
  Series all{"pores", {}, {}, true};
  const double slab_mid = 0.5 * (mid_lo + mid_hi);
  for (const notebook::EventRecord* p : pores) {
    const double height = three_d ? (normal ? p->x : p->z) : (normal ? p->x : p->y);
    all.x.push_back(height * 1e3);
    all.y.push_back(p->value / 1e3);
    if (three_d && std::abs(p->y - slab_mid) > 1e-3) continue;
    const int band = std::clamp(static_cast<int>((p->value - lo) / span * 5), 0, 4);
    map.series[band].x.push_back(p->x * 1e3);
    map.series[band].y.push_back((three_d ? p->z : p->y) * 1e3);
  }
  std::erase_if(map.series, [](const Series& s) { return s.x.empty(); });
  profile.series.push_back(all);
  f.panels = {map, profile};
  return f;
}

Figure permeabilityPorosity(const std::vector<const RunData*>& runs) {
  Figure f;
  f.id = "permeability-porosity";
  f.title = "Permeability against porosity, and Kozeny-Carman";
  f.caption =
      "k/k0 of the pore network (lines) and of Kozeny-Carman's equation 8 (dashed in the "
      "legend: KC) on the same porosity, which starts from the sample's measured porosity "
      "or from the protocol's assumed one (2D: 30%, as in the paper) and follows the "
      "volumetric strain (cf. Figures 12 and 13).";
  Panel p{"porosity (-)", "k / k0 (-)", {}};
  for (const RunData* r : runs) {
    Series k{r->label(), {}, {}, false}, kc{r->label() + " KC", {}, {}, false};
    pair(*r, "flow.porosity", "k_over_k0", k.x, k.y);
    pair(*r, "flow.porosity", "kozeny_carman_over_k0", kc.x, kc.y);
    if (!k.x.empty()) p.series.push_back(k), p.series.push_back(kc);
  }
  if (p.series.empty()) return {};
  f.panels = {p};
  return f;
}

// k/k0 of every measured direction, and Kozeny-Carman's, against series `x` of a run.
void permeabilityCurves(const RunData& r, const std::string& x, Panel& p) {
  for (const char* dir : {"along", "normal"}) {
    Series s{r.label() + " flow " + dir, {}, {}, false};
    pair(r, x, std::string("k_over_k0_") + dir, s.x, s.y);
    if (!s.x.empty()) p.series.push_back(s);
  }
  if (!r.find("k_over_k0_along") && !r.find("k_over_k0_normal")) {
    Series s{r.label(), {}, {}, false};
    pair(r, x, "k_over_k0", s.x, s.y);
    if (!s.x.empty()) p.series.push_back(s);
  }
  Series kc{r.label() + " KC", {}, {}, false};
  pair(r, x, "kozeny_carman_over_k0", kc.x, kc.y);
  if (!kc.x.empty()) p.series.push_back(kc);
}

Figure permeabilityLoading(const std::vector<const RunData*>& runs) {
  Figure f;
  f.id = "permeability-loading";
  f.title = "Permeability under loading";
  f.caption =
      "k/k0 beside Kozeny-Carman (KC): against the mean stress under hydrostatic loading; "
      "under biaxial loading against the axial strain and the axial stress (which falls back "
      "after the peak), with the flow along and normal to the loading when both were "
      "measured, above the test's stress-strain curve, which locates failure (cf. Figure "
      "14).";
  Panel stress{"mean stress (MPa)", "k / k0 (-)", {}};
  Panel strain{"axial strain (-)", "k / k0 (-)", {}};
  Panel axial{"axial stress (MPa)", "k / k0 (-)", {}};
  Panel curve{"axial strain (-)", "deviatoric stress (MPa)", {}};
  for (const RunData* r : runs) {
    if (!biaxialLoading(*r)) {
      permeabilityCurves(*r, "flow.mean_stress_MPa", stress);
      continue;
    }
    permeabilityCurves(*r, "flow.axial_strain", strain);
    permeabilityCurves(*r, "flow.axial_stress_MPa", axial);
    Series q{r->label(), {}, {}, false};
    pair(*r, "axial_strain", "deviatoric_stress_MPa", q.x, q.y);
    if (!q.x.empty()) curve.series.push_back(q);
  }
  for (Panel* p : {&stress, &strain, &axial, &curve}) {
    if (!p->series.empty()) f.panels.push_back(*p);
  }
  return f;
}

// Seconds of each solver on the network before loading, and its largest difference from
// the Cholesky solution.
Figure solverCost(const std::vector<const RunData*>& runs) {
  static const char* kSolvers[] = {"implicit_cholesky", "implicit_cg", "explicit_virtual_volume",
                                   "explicit_real_volume"};
  Figure f;
  f.id = "flow-solver-cost";
  f.title = "What each flow solver costs on the same network";
  f.caption =
      "Wall time of one steady-state solve before loading (top) and the largest pore-pressure "
      "difference from the Cholesky solution over the drop (bottom), per solver: 1 sparse "
      "Cholesky (LDL^T), 2 conjugate gradients with incomplete Cholesky, 3 the paper's explicit "
      "scheme with virtual pore volumes (equation 7), 4 with the real volumes at the critical "
      "step (equation 6); one marker series per run.";
  Panel time{"solver (1-4)", "seconds", {}};
  Panel diff{"solver (1-4)", "max |p - p_cholesky| / drop", {}};
  for (const RunData* r : runs) {
    Series t{r->label(), {}, {}, true}, d{r->label(), {}, {}, true};
    for (int i = 0; i < 4; ++i) {
      const std::string key = std::string("solver_") + kSolvers[i];
      const Quantity* s = r->result(key + "_seconds");
      const Quantity* m = r->result(key + "_max_difference");
      if (!s || !m) continue;
      t.x.push_back(i + 1), t.y.push_back(s->value);
      d.x.push_back(i + 1), d.y.push_back(m->value);
    }
    if (!t.x.empty()) time.series.push_back(t), diff.series.push_back(d);
  }
  if (time.series.empty()) return {};
  f.panels = {time, diff};
  return f;
}

}  // namespace

std::vector<Figure> permeameterFigures(const std::vector<const RunData*>& runs, const Paper&) {
  std::vector<Figure> out;
  for (const RunData* r : runs) {
    if (!r->pores.empty()) out.push_back(pressureField(*r));
  }
  for (Figure f : {permeabilityPorosity(runs), permeabilityLoading(runs), solverCost(runs)}) {
    if (!f.panels.empty()) out.push_back(std::move(f));
  }
  return out;
}

}  // namespace rocklab::reports
