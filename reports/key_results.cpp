#include "reports/key_results.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "rigs/common/outputs.hpp"

namespace rocklab::reports {

namespace {

using Value = std::optional<double>;

Value recorded(const RunData& r, const KeyResultRule& d, const std::string& prefix,
               const std::string& base) {
  auto it = r.results.find(prefix + (d.source.empty() ? base : d.source));
  if (it == r.results.end() || !std::isfinite(it->second.value)) return std::nullopt;
  return it->second.value;
}

// A count of broken bonds (the definition's source, prefixed) over the bonds the sample was
// cemented with: intensive, so that samples of different sizes compare (a resolution study).
Value brokenFraction(const RunData& r, const KeyResultRule& d, const std::string& prefix,
                     const std::string& base) {
  auto installed = r.results.find("bonds_installed");
  if (installed == r.results.end() || !(installed->second.value > 0.0)) return std::nullopt;
  const Value broken = recorded(r, d, prefix, base);
  if (!broken) return std::nullopt;
  return *broken / installed->second.value;
}

// y where x first reaches `at`, interpolated linearly between the two records around it.
Value seriesAt(const RunData& r, const KeyResultRule& d, const std::string& prefix,
               const std::string&) {
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
Value slopeAt(const RunData& r, const KeyResultRule& d, const std::string& prefix,
              const std::string&) {
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
Value secantAtHalfPeak(const RunData& r, const KeyResultRule& d, const std::string& prefix,
                       const std::string&) {
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
Value atFractionOfPeak(const RunData& r, const KeyResultRule& d, const std::string& prefix,
                       const std::string&) {
  std::vector<double> x, y;
  pair(r, prefix + d.x_series, prefix + d.source, x, y);
  if (x.empty()) return std::nullopt;
  KeyResultRule fixed = d;
  fixed.at = d.at * *std::max_element(x.begin(), x.end());
  return seriesAt(r, fixed, prefix, "");
}

// y at the record where x peaks (k/k0 at the peak axial stress of a test through failure:
// before it, what the stress did to the permeability; after it, what the failure did).
Value atPeakOf(const RunData& r, const KeyResultRule& d, const std::string& prefix,
               const std::string&) {
  std::vector<double> x, y;
  pair(r, prefix + d.x_series, prefix + d.source, x, y);
  if (x.empty()) return std::nullopt;
  return y[static_cast<std::size_t>(std::max_element(x.begin(), x.end()) - x.begin())];
}

// An ultrasonic value at stage N ("stage3.vp_z": the series' value at the Nth stage's step),
// or at the last stage when unprefixed (the rig records those as results).
Value atStage(const RunData& r, const KeyResultRule& d, const std::string& prefix,
              const std::string& base) {
  if (prefix.empty()) return recorded(r, d, prefix, base);
  if (prefix.rfind("stage", 0) != 0) return std::nullopt;
  std::size_t n = 0;
  try {
    n = std::stoul(prefix.substr(5));
  } catch (const std::exception&) {
    return std::nullopt;
  }
  const SeriesData* stages = r.find("stage.density_kg_per_m3");
  const SeriesData* s = r.find(d.source.empty() ? base : d.source);
  if (!stages || !s || n < 1 || n > stages->step.size()) return std::nullopt;
  const std::uint64_t step = stages->step[n - 1];
  for (std::size_t k = 0; k < s->step.size(); ++k) {
    if (s->step[k] == step) return s->value[k];
  }
  return std::nullopt;  // the pulse drowned at that stage: no velocity was recorded
}

// The measured k / k0 at the end over Kozeny-Carman's (equation 8) from the same porosity
// change: 1 where the network follows Kozeny-Carman, as the paper finds (Figures 12-13).
Value overKozenyCarman(const RunData& r, const KeyResultRule& d, const std::string& prefix,
                       const std::string&) {
  const Value k = recorded(r, d, prefix, "");
  const SeriesData* kc = r.find(prefix + "kozeny_carman_over_k0");
  if (!k || !kc || kc->value.empty() || !(kc->value.back() > 0.0)) return std::nullopt;
  return *k / kc->value.back();
}

// The static constrained modulus over the dynamic one (rho vp_z^2) at a stage: 1 where the
// small stress cycle stays elastic, as the paper checked (section 4.1).
Value staticOverDynamic(const RunData& r, const KeyResultRule& d, const std::string& prefix,
                        const std::string&) {
  KeyResultRule part = d;  // its source: the static modulus
  const Value s = atStage(r, part, prefix, part.source);
  part.source = "modulus_z_dynamic_MPa";
  const Value m = atStage(r, part, prefix, part.source);
  if (!s || !m || !(*m > 0.0)) return std::nullopt;
  return *s / *m;
}

KeyResultRule rec(std::string name) {
  return {std::move(name), recorded, "", "", 0.0, 0.0};
}

KeyResultRule stage(std::string name) {
  return {std::move(name), atStage, "", "", 0.0, 0.0};
}

// The biaxial frame's / triaxial cell's test, also each test of an envelope sweep.
std::vector<KeyResultRule> biaxialRules() {
  return {
      rec("peak_deviatoric_stress_MPa"),
      rec("ucs_MPa"),
      rec("axial_strain_at_peak"),
      rec("volumetric_strain_at_peak"),
      {"deviatoric_stress_at_1pct_strain_MPa", seriesAt, "deviatoric_stress_MPa", "axial_strain",
       0.01, 0.0},
      {"tangent_modulus_at_1pct_strain_MPa", slopeAt, "deviatoric_stress_MPa", "axial_strain", 0.01,
       0.0025},
      {"secant_modulus_50_MPa", secantAtHalfPeak, "deviatoric_stress_MPa", "axial_strain", 0.0,
       0.0},
      rec("critical_deviatoric_stress_MPa"),
      rec("band_angle_deg"),
      rec("broken_bonds_total"),
      {"broken_bond_fraction", brokenFraction, "broken_bonds_total", "", 0.0, 0.0},
      rec("crushed_grains"),
  };
}

std::vector<KeyResultRule> envelopeRules() {
  std::vector<KeyResultRule> d = {rec("friction_angle_deg"), rec("mohr_coulomb_ucs_MPa")};
  for (KeyResultRule& b : biaxialRules()) d.push_back(std::move(b));
  return d;
}

std::vector<KeyResultRule> oedometerRules() {
  return {
      rec("tangent_modulus_initial_MPa"),
      rec("tangent_modulus_final_MPa"),
      rec("tangent_modulus_ratio"),
      rec("axial_stress_final_MPa"),
      rec("lateral_stress_final_MPa"),
      rec("stress_path_slope_final"),
      {"axial_stress_at_1pct_strain_MPa", seriesAt, "axial_stress_MPa", "axial_strain", 0.01, 0.0},
      rec("broken_bonds_total"),
      {"broken_bond_fraction", brokenFraction, "broken_bonds_total", "", 0.0, 0.0},
      rec("cycle#_modulus_ratio"),
      rec("cored_to_virgin_initial_modulus_ratio"),
      rec("broken_bonds_by_coring"),
      rec("porosity_after_formation"),
  };
}

std::vector<KeyResultRule> hydrostaticRules() {
  return {
      rec("mean_stress_peak_MPa"),
      rec("volumetric_strain_at_peak"),
      rec("secant_bulk_modulus_MPa"),
      rec("porosity_at_peak"),
      rec("volumetric_strain_after_unloading"),
      rec("broken_bonds_at_peak"),
      {"broken_bond_fraction_at_peak", brokenFraction, "broken_bonds_at_peak", "", 0.0, 0.0},
  };
}

// The permeameter's own, and in its biaxial mode the biaxial test's.
std::vector<KeyResultRule> permeameterRules() {
  std::vector<KeyResultRule> d = {
      rec("permeability_initial_m2"),
      rec("k_over_k0_final"),
      rec("k_over_k0_final_along"),
      rec("k_over_k0_final_normal"),
      {"k_over_kozeny_carman_final", overKozenyCarman, "k_over_k0_final", "", 0.0, 0.0},
      {"k_over_k0_at_half_peak_stress", atFractionOfPeak, "k_over_k0", "flow.mean_stress_MPa", 0.5,
       0.0},
      {"k_over_k0_at_peak_stress", atPeakOf, "k_over_k0", "flow.axial_stress_MPa", 0.0, 0.0},
      {"k_over_k0_at_peak_stress_along", atPeakOf, "k_over_k0_along", "flow.axial_stress_MPa", 0.0,
       0.0},
      {"k_over_k0_at_peak_stress_normal", atPeakOf, "k_over_k0_normal", "flow.axial_stress_MPa",
       0.0, 0.0},
      rec("porosity_initial"),
      rec("mean_stress_peak_MPa"),
      rec("flow_balance_error"),
  };
  for (KeyResultRule& b : biaxialRules()) d.push_back(std::move(b));
  return d;
}

std::vector<KeyResultRule> ultrasonicRules() {
  return {
      stage("vp_z"),
      stage("vp_x"),
      stage("vs_zx"),
      stage("vs_xy"),
      stage("modulus_z_dynamic_MPa"),
      stage("shear_modulus_zx_dynamic_MPa"),
      stage("modulus_z_static_MPa"),
      {"static_over_dynamic_modulus", staticOverDynamic, "modulus_z_static_MPa", "", 0.0, 0.0},
  };
}

std::vector<KeyResultRule> brazilianRules() {
  return {
      rec("tensile_strength_MPa"),    rec("peak_force_N"),
      rec("broken_bonds_at_peak"),    rec("fracture_angle_to_loading_deg"),
      rec("fracture_through_centre"),
  };
}

std::vector<KeyResultRule> directTensionRules() {
  return {
      rec("tensile_strength_MPa"),  rec("tensile_modulus_MPa"),
      rec("axial_strain_at_peak"),  rec("broken_bonds_at_peak"),
      rec("fracture_height_ratio"), rec("fracture_angle_to_loading_deg"),
  };
}

std::vector<KeyResultRule> ucsRules() {
  return {
      rec("ucs_MPa"),
      rec("young_modulus_secant_50_MPa"),
      rec("young_modulus_tangent_50_MPa"),
      rec("poisson_ratio_secant_50"),
      rec("poisson_ratio_tangent_50"),
      rec("crack_damage_stress_MPa"),
      rec("crack_damage_ratio"),
      rec("axial_strain_at_peak"),
      rec("broken_bonds_at_peak"),
  };
}

struct RigRules {
  std::string_view rig;
  std::vector<KeyResultRule> rules;
};

const std::vector<RigRules>& table() {
  static const std::vector<RigRules> t = {
      {"oedometer", oedometerRules()},
      {"biaxial", biaxialRules()},
      {"envelope", envelopeRules()},
      {"hydrostatic", hydrostaticRules()},
      {"permeameter", permeameterRules()},
      {"ultrasonic", ultrasonicRules()},
      {"brazilian", brazilianRules()},
      {"direct_tension", directTensionRules()},
      {"ucs", ucsRules()},
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

const std::vector<KeyResultRule>& keyResultRules(std::string_view rig) {
  static const std::vector<KeyResultRule> none;
  for (const RigRules& r : table()) {
    if (r.rig == rig) return r.rules;
  }
  return none;
}

const KeyResultRule* findKeyResultRule(std::string_view rig, const std::string& name) {
  const std::string base = splitPrefix(name).second;
  for (const KeyResultRule& d : keyResultRules(rig)) {
    if (rigs::outputNameMatches(d.name, base)) return &d;
  }
  return nullptr;
}

std::vector<std::string> keyResultNames(const RunData& run) {
  return parseTextList(run.param("protocol.key_results"));
}

std::optional<double> evaluateKeyResult(const RunData& run, const std::string& name) {
  const KeyResultRule* d = findKeyResultRule(run.rig, name);
  if (!d) return std::nullopt;
  const auto [prefix, base] = splitPrefix(name);
  return d->evaluate(run, *d, prefix, base);
}

std::vector<KeyValue> keyResults(const RunData& run) {
  std::vector<KeyValue> out;
  const rigs::Outputs* outputs = rigs::rigOutputs(run.rig);
  for (const std::string& name : keyResultNames(run)) {
    const rigs::OutputDecl* d = outputs ? outputs->keyResult(name) : nullptr;
    if (!d || !findKeyResultRule(run.rig, name)) {
      out.push_back({name, "", "not a key result of the " + run.rig + " rig", std::nullopt});
      continue;
    }
    out.push_back({name, std::string(d->unit), std::string(d->doc), evaluateKeyResult(run, name)});
  }
  return out;
}

}  // namespace rocklab::reports
