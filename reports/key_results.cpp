#include "reports/key_results.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace rocklab::reports {

namespace {

using Value = std::optional<double>;

Value recorded(const RunData& r, const KeyResultDef& d, const std::string& prefix) {
  auto it = r.results.find(prefix + d.source);
  if (it == r.results.end() || !std::isfinite(it->second.value)) return std::nullopt;
  return it->second.value;
}

// A count of broken bonds (the definition's source, prefixed) over the bonds the sample was
// cemented with: intensive, so that samples of different sizes compare (a resolution study).
Value brokenFraction(const RunData& r, const KeyResultDef& d, const std::string& prefix) {
  auto installed = r.results.find("bonds_installed");
  if (installed == r.results.end() || !(installed->second.value > 0.0)) return std::nullopt;
  const Value broken = recorded(r, d, prefix);
  if (!broken) return std::nullopt;
  return *broken / installed->second.value;
}

// y where x first reaches `at`, interpolated linearly between the two records around it.
Value seriesAt(const RunData& r, const KeyResultDef& d, const std::string& prefix) {
  std::vector<double> x, y;
  pair(r, prefix + d.x_series, prefix + d.source, x, y);
  for (std::size_t k = 1; k < x.size(); ++k) {
    if (x[k] >= d.at && x[k - 1] < d.at) {
      const double f = (d.at - x[k - 1]) / (x[k] - x[k - 1]);
      return y[k - 1] + f * (y[k] - y[k - 1]);
    }
  }
  return std::nullopt;
}

// The tangent dy/dx at x = `at`: the least-squares slope of the records within
// +-half_window of it (a local fit, not a two-point difference, so that the records' noise
// does not set the value).
Value slopeAt(const RunData& r, const KeyResultDef& d, const std::string& prefix) {
  std::vector<double> x, y;
  pair(r, prefix + d.x_series, prefix + d.source, x, y);
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    if (std::abs(x[k] - d.at) > d.half_window) continue;
    n += 1, sx += x[k], sy += y[k], sxx += x[k] * x[k], sxy += x[k] * y[k];
  }
  const double den = n * sxx - sx * sx;
  if (n < 3 || den <= 0.0) return std::nullopt;
  return (n * sxy - sx * sy) / den;
}

// The secant modulus at half the peak of y (E50 of rock mechanics, ISRM): y50 / x50, with
// x50 where y first reaches half its peak.
Value secantAtHalfPeak(const RunData& r, const KeyResultDef& d, const std::string& prefix) {
  std::vector<double> x, y;
  pair(r, prefix + d.x_series, prefix + d.source, x, y);
  if (y.empty()) return std::nullopt;
  const double half = 0.5 * *std::max_element(y.begin(), y.end());
  for (std::size_t k = 1; k < x.size(); ++k) {
    if (y[k] >= half && y[k - 1] < half) {
      const double x50 = x[k - 1] + (half - y[k - 1]) / (y[k] - y[k - 1]) * (x[k] - x[k - 1]);
      if (x50 > 0.0) return half / x50;
    }
  }
  return std::nullopt;
}

// y where x first reaches the fraction `at` of its own largest value (k/k0 at half the
// peak mean stress, whatever the stress path's peak).
Value atFractionOfPeak(const RunData& r, const KeyResultDef& d, const std::string& prefix) {
  std::vector<double> x, y;
  pair(r, prefix + d.x_series, prefix + d.source, x, y);
  if (x.empty()) return std::nullopt;
  KeyResultDef fixed = d;
  fixed.at = d.at * *std::max_element(x.begin(), x.end());
  return seriesAt(r, fixed, prefix);
}

// An ultrasonic value at stage N ("stage3.vp_z": the series' value at the Nth stage's step),
// or at the last stage when unprefixed (the rig records those as results).
Value atStage(const RunData& r, const KeyResultDef& d, const std::string& prefix) {
  if (prefix.empty()) return recorded(r, d, prefix);
  if (prefix.rfind("stage", 0) != 0) return std::nullopt;
  std::size_t n = 0;
  try {
    n = std::stoul(prefix.substr(5));
  } catch (const std::exception&) {
    return std::nullopt;
  }
  const SeriesData* stages = r.find("stage.density_kg_per_m3");
  const SeriesData* s = r.find(d.source);
  if (!stages || !s || n < 1 || n > stages->step.size()) return std::nullopt;
  const std::uint64_t step = stages->step[n - 1];
  for (std::size_t k = 0; k < s->step.size(); ++k) {
    if (s->step[k] == step) return s->value[k];
  }
  return std::nullopt;  // the pulse drowned at that stage: no velocity was recorded
}

KeyResultDef rec(std::string name, std::string unit, std::string doc) {
  return {name, std::move(unit), std::move(doc), recorded, name, "", 0.0, 0.0};
}

KeyResultDef stage(std::string name, std::string unit, std::string doc) {
  return {name, std::move(unit), std::move(doc), atStage, name, "", 0.0, 0.0};
}

// The biaxial frame's / triaxial cell's test, also each test of an envelope sweep.
std::vector<KeyResultDef> biaxialDefs() {
  return {
      rec("peak_deviatoric_stress_MPa", "MPa", "peak deviatoric stress of the loading"),
      rec("ucs_MPa", "MPa", "uniaxial compressive strength (zero confinement only)"),
      rec("axial_strain_at_peak", "-", "axial strain since loading began, at the peak"),
      rec("volumetric_strain_at_peak", "-", "volumetric strain at the peak, compaction positive"),
      {"deviatoric_stress_at_1pct_strain_MPa", "MPa",
       "deviatoric stress when the axial strain reaches 1%", seriesAt, "deviatoric_stress_MPa",
       "axial_strain", 0.01, 0.0},
      {"tangent_modulus_at_1pct_strain_MPa", "MPa",
       "tangent of deviatoric stress against axial strain at 1% (fit over 0.75-1.25%)", slopeAt,
       "deviatoric_stress_MPa", "axial_strain", 0.01, 0.0025},
      {"secant_modulus_50_MPa", "MPa", "secant modulus at half the peak deviatoric stress (E50)",
       secantAtHalfPeak, "deviatoric_stress_MPa", "axial_strain", 0.0, 0.0},
      rec("critical_deviatoric_stress_MPa", "MPa",
          "deviatoric stress at the critical point (peak or onset of compactive yield)"),
      rec("band_angle_deg", "deg", "angle between the localisation band and sigma_1"),
      rec("broken_bonds_total", "-", "cement bonds broken during the loading, both modes"),
      {"broken_bond_fraction", "-",
       "cement bonds broken during the loading over those installed (compares sample sizes)",
       brokenFraction, "broken_bonds_total", "", 0.0, 0.0},
      rec("crushed_grains", "-", "grains crushed during the loading"),
  };
}

std::vector<KeyResultDef> envelopeDefs() {
  std::vector<KeyResultDef> d = {
      rec("friction_angle_deg", "deg", "Mohr-Coulomb friction angle of the dilatant peaks"),
      rec("mohr_coulomb_ucs_MPa", "MPa", "Mohr-Coulomb line's intercept: its UCS"),
  };
  for (KeyResultDef& b : biaxialDefs()) {
    b.doc += " (of one test: testN.NAME)";
    d.push_back(std::move(b));
  }
  return d;
}

std::vector<KeyResultDef> oedometerDefs() {
  return {
      rec("tangent_modulus_initial_MPa", "MPa", "oedometric tangent modulus at the start"),
      rec("tangent_modulus_final_MPa", "MPa", "oedometric tangent modulus at the end"),
      rec("tangent_modulus_ratio", "-", "final over initial tangent modulus"),
      rec("axial_stress_final_MPa", "MPa", "axial stress at the end of loading"),
      rec("lateral_stress_final_MPa", "MPa", "lateral stress at the end of loading"),
      rec("stress_path_slope_final", "-", "d(lateral)/d(axial) stress at the end"),
      {"axial_stress_at_1pct_strain_MPa", "MPa", "axial stress when the axial strain reaches 1%",
       seriesAt, "axial_stress_MPa", "axial_strain", 0.01, 0.0},
      rec("broken_bonds_total", "-", "cement bonds broken during the loading"),
      {"broken_bond_fraction", "-",
       "cement bonds broken during the loading over those installed (compares sample sizes)",
       brokenFraction, "broken_bonds_total", "", 0.0, 0.0},
      rec("cycle1_modulus_ratio", "-", "first cycle: loading tangent over unloading secant"),
      rec("cycle2_modulus_ratio", "-", "second cycle: loading tangent over unloading secant"),
      rec("cored_to_virgin_initial_modulus_ratio", "-",
          "initial modulus of the cored sample over the virgin's"),
      rec("broken_bonds_by_coring", "-", "bonds broken by unloading the core"),
  };
}

std::vector<KeyResultDef> hydrostaticDefs() {
  return {
      rec("mean_stress_peak_MPa", "MPa", "mean stress at the peak of the ramp"),
      rec("volumetric_strain_at_peak", "-", "volumetric strain at the peak"),
      rec("secant_bulk_modulus_MPa", "MPa", "secant bulk modulus from cementing to the peak"),
      rec("porosity_at_peak", "-", "porosity at the peak"),
      rec("volumetric_strain_after_unloading", "-", "volumetric strain left after unloading"),
      rec("broken_bonds_at_peak", "-", "cement bonds broken by the peak"),
      {"broken_bond_fraction_at_peak", "-",
       "cement bonds broken by the peak over those installed (compares sample sizes)",
       brokenFraction, "broken_bonds_at_peak", "", 0.0, 0.0},
  };
}

std::vector<KeyResultDef> permeameterDefs() {
  return {
      rec("permeability_initial_m2", "m^2", "Darcy permeability before loading"),
      rec("k_over_k0_final", "-", "permeability at the end over the initial"),
      rec("k_over_k0_final_along", "-", "the same, flow along the axis (both directions measured)"),
      rec("k_over_k0_final_normal", "-",
          "the same, flow across the axis (both directions measured)"),
      {"k_over_k0_at_half_peak_stress", "-",
       "permeability over the initial when the mean stress first reaches half its peak",
       atFractionOfPeak, "k_over_k0", "flow.mean_stress_MPa", 0.5, 0.0},
      rec("porosity_initial", "-", "porosity before loading"),
      rec("mean_stress_peak_MPa", "MPa", "mean stress at the end of hydrostatic loading"),
      rec("peak_deviatoric_stress_MPa", "MPa", "peak deviatoric stress of biaxial loading"),
      rec("flow_balance_error", "-", "|outflow - inflow| / inflow of the first steady solve"),
  };
}

std::vector<KeyResultDef> ultrasonicDefs() {
  const std::string at = " (at the last stage; stageN.NAME at stage N)";
  return {
      stage("vp_z", "m/s", "P-wave velocity along the axis" + at),
      stage("vp_x", "m/s", "P-wave velocity across the axis" + at),
      stage("vs_zx", "m/s", "S-wave along the axis, polarised across" + at),
      stage("vs_xy", "m/s", "S-wave across the axis, polarised across" + at),
      stage("modulus_z_dynamic_MPa", "MPa", "rho vp_z^2" + at),
      stage("shear_modulus_zx_dynamic_MPa", "MPa", "rho vs_zx^2" + at),
      stage("modulus_z_static_MPa", "MPa", "static constrained modulus along the axis" + at),
  };
}

struct RigDefs {
  std::string_view rig;
  std::vector<KeyResultDef> defs;
};

const std::vector<RigDefs>& table() {
  static const std::vector<RigDefs> t = {
      {"oedometer", oedometerDefs()},     {"biaxial", biaxialDefs()},
      {"envelope", envelopeDefs()},       {"hydrostatic", hydrostaticDefs()},
      {"permeameter", permeameterDefs()}, {"ultrasonic", ultrasonicDefs()},
  };
  return t;
}

// "test2.ucs_MPa" -> {"test2.", "ucs_MPa"}; a prefix is one word ending in a dot.
std::pair<std::string, std::string> splitPrefix(const std::string& name) {
  const auto dot = name.find('.');
  if (dot == std::string::npos) return {"", name};
  return {name.substr(0, dot + 1), name.substr(dot + 1)};
}

std::vector<std::string> parseTextList(const std::string& text) {
  std::vector<std::string> out;
  std::string cur;
  bool quoted = false;
  for (char c : text) {
    if (c == '"') {
      if (quoted) out.push_back(cur);
      quoted = !quoted;
      cur.clear();
    } else if (quoted) {
      cur += c;
    }
  }
  return out;
}

}  // namespace

const std::vector<KeyResultDef>& keyResultDefs(std::string_view rig) {
  static const std::vector<KeyResultDef> none;
  for (const RigDefs& r : table()) {
    if (r.rig == rig) return r.defs;
  }
  return none;
}

const KeyResultDef* findKeyResult(std::string_view rig, const std::string& name) {
  const std::string base = splitPrefix(name).second;
  for (const KeyResultDef& d : keyResultDefs(rig)) {
    if (d.name == base) return &d;
  }
  return nullptr;
}

void checkKeyResults(std::string_view rig, const protocol::Settings& s) {
  std::vector<std::string> problems;
  for (const std::string& name : s.texts("protocol.key_results")) {
    if (findKeyResult(rig, name)) continue;
    std::string known;
    for (const KeyResultDef& d : keyResultDefs(rig)) known += (known.empty() ? "" : ", ") + d.name;
    problems.push_back(s.where("protocol.key_results") + ": protocol.key_results: '" + name +
                       "' is not a key result of the " + std::string(rig) + " rig: one of " +
                       known + " (`rocklab keys " + std::string(rig) + "` says what each is)");
  }
  if (!problems.empty()) throw protocol::ProtocolError(problems);
}

std::string keyResultHelp(std::string_view rig) {
  std::ostringstream s;
  for (const KeyResultDef& d : keyResultDefs(rig)) {
    s << "  " << d.name << (d.unit == "-" ? "" : " (" + d.unit + ")") << "\n      " << d.doc
      << "\n";
  }
  return s.str();
}

std::vector<std::string> keyResultNames(const RunData& run) {
  return parseTextList(run.param("protocol.key_results"));
}

std::optional<double> evaluateKeyResult(const RunData& run, const std::string& name) {
  const KeyResultDef* d = findKeyResult(run.rig, name);
  if (!d) return std::nullopt;
  return d->evaluate(run, *d, splitPrefix(name).first);
}

std::vector<KeyValue> keyResults(const RunData& run) {
  std::vector<KeyValue> out;
  for (const std::string& name : keyResultNames(run)) {
    const KeyResultDef* d = findKeyResult(run.rig, name);
    if (!d) {
      out.push_back({name, "", "not a key result of the " + run.rig + " rig", std::nullopt});
      continue;
    }
    out.push_back({name, d->unit, d->doc, evaluateKeyResult(run, name)});
  }
  return out;
}

}  // namespace rocklab::reports
