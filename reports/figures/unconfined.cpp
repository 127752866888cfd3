// The figures of the tests on a specimen out of its box (the tensile tests and the
// unconfined compression): the load against the deformation with the bond breaks as they
// accumulate, and the fracture (where the bonds broke in the loading plane, by mode), every
// run overlaid.

#include "reports/figures/figures.hpp"

namespace rocklab::reports {

namespace {

// The load (top) and the breaks by mode (bottom) against the series `x`.
Figure loadAndBreaks(const std::vector<const RunData*>& runs, const std::string& id,
                     const std::string& title, const std::string& caption, const std::string& x,
                     const std::string& x_label, const std::string& load_label) {
  Figure f{id, title, caption, {}};
  Panel load{x_label, load_label, {}};
  Panel broken{x_label, "broken bonds (cumulative)", {}};
  for (const RunData* r : runs) {
    Series s{r->label(), {}, {}, false};
    pair(*r, x, "tensile_stress_MPa", s.x, s.y);
    if (!s.x.empty()) load.series.push_back(s);
    for (const char* mode : {"tensile", "shear"}) {
      Series b{r->label() + " " + mode, {}, {}, false};
      pair(*r, x, std::string("broken_bonds_") + mode, b.x, b.y);
      if (!b.x.empty()) broken.series.push_back(b);
    }
  }
  if (!load.series.empty()) f.panels = {load, broken};
  return f;
}

// Where the cement broke during the loading, in the loading plane (x across, the load along
// the vertical axis), by mode.
Figure fracture(const std::vector<const RunData*>& runs, const std::string& id,
                const std::string& title) {
  Figure f{id,
           title,
           "Where the cement bonds broke during the loading, in the loading plane (x across, the "
           "load along the vertical axis), by mode.",
           {}};
  Panel where{"x (mm)", "along the load (mm)", {}};
  for (const RunData* r : runs) {
    const bool in_3d = r->param("protocol.dimension") == "3";
    for (const char* mode : {"tensile", "shear"}) {
      Series at{r->label() + " " + mode, {}, {}, true};
      for (const notebook::EventRecord& e : r->breaks) {
        if (e.stage != "loading" || e.mode != mode || e.granular != "inter") continue;
        at.x.push_back(e.x * 1e3);
        at.y.push_back((in_3d ? e.z : e.y) * 1e3);
      }
      if (!at.x.empty()) where.series.push_back(at);
    }
  }
  if (!where.series.empty()) f.panels = {where};
  return f;
}

// The axial stress against the three strains a compression test measures (the platens'
// axial, the gauge's lateral and volumetric), and the breaks by mode against the axial strain.
Figure compression(const std::vector<const RunData*>& runs) {
  Figure f{"ucs-stress-strain",
           "Unconfined compression: stress against strains, and breaks",
           "Axial stress against the platens' axial strain and the gauge section's lateral and "
           "volumetric strains, compression positive (top; the peak is the UCS, the volumetric "
           "strain's turn the crack damage stress), and the cement bonds broken since loading "
           "began, by mode, against the axial strain (bottom).",
           {}};
  Panel curves{"strain (-)", "axial stress (MPa)", {}};
  Panel broken{"axial strain (-)", "broken bonds (cumulative)", {}};
  for (const RunData* r : runs) {
    for (const auto& [strain, what] : {std::pair{"axial_strain", "axial"},
                                       {"lateral_strain", "lateral"},
                                       {"volumetric_strain", "volumetric"}}) {
      Series s{r->label() + " " + what, {}, {}, false};
      pair(*r, strain, "axial_stress_MPa", s.x, s.y);
      if (!s.x.empty()) curves.series.push_back(s);
    }
    for (const char* mode : {"tensile", "shear"}) {
      Series b{r->label() + " " + mode, {}, {}, false};
      pair(*r, "axial_strain", std::string("broken_bonds_") + mode, b.x, b.y);
      if (!b.x.empty()) broken.series.push_back(b);
    }
  }
  if (!curves.series.empty()) f.panels = {curves, broken};
  return f;
}

std::vector<Figure> nonEmpty(std::vector<Figure> figures) {
  std::erase_if(figures, [](const Figure& f) { return f.panels.empty(); });
  return figures;
}

}  // namespace

std::vector<Figure> brazilianFigures(const std::vector<const RunData*>& runs, const Paper&) {
  return nonEmpty(
      {loadAndBreaks(runs, "brazilian-loading",
                     "Brazilian test: load and breaks against platen closure",
                     "Nominal tensile stress at the centre 2F / (pi D t) (top; its peak is "
                     "sigma_t) and the cement bonds broken since loading began, by mode "
                     "(bottom), against the closure of the platens.",
                     "platen_closure_mm", "platen closure (mm)", "2F / (pi D t) (MPa)"),
       fracture(runs, "brazilian-fracture", "Brazilian test: the fracture")});
}

std::vector<Figure> directTensionFigures(const std::vector<const RunData*>& runs, const Paper&) {
  return nonEmpty(
      {loadAndBreaks(runs, "direct-tension-loading",
                     "Direct tension: stress and breaks against strain",
                     "Pull force over the cross-section (top; its peak is the tensile strength, "
                     "its slope from 10% to 50% of it the modulus in tension) and the cement "
                     "bonds broken since loading began, by mode (bottom), against the extension "
                     "between the glued layers.",
                     "axial_strain", "axial strain (-)", "tensile stress (MPa)"),
       fracture(runs, "direct-tension-fracture", "Direct tension: the fracture")});
}

std::vector<Figure> ucsFigures(const std::vector<const RunData*>& runs, const Paper&) {
  return nonEmpty(
      {compression(runs), fracture(runs, "ucs-fracture", "Unconfined compression: the fracture")});
}

}  // namespace rocklab::reports
