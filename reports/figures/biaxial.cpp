// The biaxial frame's and triaxial cell's figures: deviatoric stress, volumetric strain and
// cumulative broken bonds (cement and inside grains) against axial strain, one curve per
// test, labelled with its confinement (cf. Li & Holt, section 2.3); and for a confinement
// sweep, the failure envelope with the Mohr-Coulomb line and the end cap (Figure 6).

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <sstream>

#include "lab/campaign/statistics.hpp"
#include "reports/figures/figures.hpp"

namespace rocklab::reports {

namespace {

// One loading test inside a run: the biaxial rig's single test (no prefix) or each test of
// an envelope sweep ("test1.", ...), found by its confinement result.
struct Test {
  const RunData* run;
  std::string prefix, label;
  double sigma3 = 0.0;  // MPa
};

std::vector<Test> testsOf(const RunData& r) {
  std::vector<Test> out;
  const std::string key = "confining_stress_MPa";
  for (const auto& [name, q] : r.results) {
    if (name.size() < key.size() || name.compare(name.size() - key.size(), key.size(), key) != 0)
      continue;
    const std::string prefix = name.substr(0, name.size() - key.size());
    if (!prefix.empty() && prefix.back() != '.') continue;
    std::ostringstream label;  // short: the legend sits on the chart
    label << "run " << r.id << (prefix.empty() ? "" : " " + prefix.substr(0, prefix.size() - 1))
          << ", sigma3 = " << q.value << " MPa";
    out.push_back({&r, prefix, label.str(), q.value});
  }
  std::sort(out.begin(), out.end(),
            [](const Test& a, const Test& b) { return a.sigma3 < b.sigma3; });
  return out;
}

Figure stressStrain(const std::vector<Test>& tests, const Paper& paper, const std::string& id) {
  Figure f;
  f.id = id;
  f.title = "Biaxial / triaxial tests: stress, volume change and damage against axial strain";
  f.caption =
      "Deviatoric stress (top), volumetric strain, compaction positive (middle), and cumulative "
      "broken bonds between grains (cement) and inside grains (crushing) (bottom) against "
      "axial strain since the start of loading; one curve per test, labelled with its "
      "confining stress. The paper's UCS is the marker at zero strain.";
  Panel stress{"axial strain (-)", "deviatoric stress (MPa)", {}};
  Panel volume{"axial strain (-)", "volumetric strain (-)", {}};
  Panel broken{"axial strain (-)", "broken bonds (cumulative)", {}};
  for (const Test& t : tests) {
    const RunData& r = *t.run;
    const std::string ea = t.prefix + "axial_strain";
    Series q{t.label, {}, {}, false};
    pair(r, ea, t.prefix + "deviatoric_stress_MPa", q.x, q.y);
    if (q.x.empty()) continue;
    stress.series.push_back(q);
    Series v{t.label, {}, {}, false};
    pair(r, ea, t.prefix + "volumetric_strain", v.x, v.y);
    volume.series.push_back(v);
    Series cement{t.label + ": cement", {}, {}, false};
    pair(r, ea, t.prefix + "broken_bonds_total", cement.x, cement.y);
    broken.series.push_back(cement);
    Series grains{t.label + ": in grains", {}, {}, false};
    Series shear{"", {}, {}, false};
    pair(r, ea, t.prefix + "broken_grain_bonds_tensile", grains.x, grains.y);
    pair(r, ea, t.prefix + "broken_grain_bonds_shear", shear.x, shear.y);
    if (!grains.x.empty() && shear.y.size() == grains.y.size()) {
      for (std::size_t k = 0; k < grains.y.size(); ++k) grains.y[k] += shear.y[k];
      broken.series.push_back(grains);
    }
  }
  if (stress.series.empty()) return f;
  if (const PaperNumber* ucs = paper.byKey("ucs")) {
    stress.series.push_back({"paper: UCS", {0.0}, {ucs->value}, true});
  }
  f.panels = {stress, volume, broken};
  return f;
}

// The Mohr-Coulomb line of a fit in the (p, q) plane at the confinements s3 (Li & Holt,
// equation 1: sigma_1 = N sigma_3 + UCS, N = tan^2(45 + phi/2)): q at each s3.
std::vector<double> mohrCoulombQ(double phi_deg, double ucs, const std::vector<double>& s3) {
  const double s = std::sin(phi_deg * std::numbers::pi / 180.0);
  const double N = (1.0 + s) / (1.0 - s);
  std::vector<double> q;
  for (double x : s3) q.push_back((N - 1.0) * x + ucs);
  return q;
}

// Figure 6: the critical points in the (p, q) plane, p = mean stress; the Mohr-Coulomb
// line sigma_1 = N sigma_3 + UCS of the run's fit drawn through the same plane, and the
// cap joining the compactive points (from the last dilatant one).
Figure failureEnvelope(const RunData& r, const std::vector<Test>& tests) {
  Figure f;
  f.id = "failure-envelope-run" + std::to_string(r.id);
  f.title = "Failure envelope, run " + std::to_string(r.id) + " " + r.protocol;
  f.caption =
      "Critical points of each test in the mean stress - deviatoric stress plane (Li & Holt, "
      "Figure 6): the dilatant peak where the sample turns to dilate, the onset of "
      "shear-enhanced compaction where it compacts beyond its elastic trend. The line is the "
      "Mohr-Coulomb fit of the dilatant points (equation 1, friction angle and UCS in the "
      "legend); the cap joins the compactive points.";
  const int dim = r.param("protocol.dimension") == "2" ? 2 : 3;
  Series dilatant{"dilatant critical points (peak)", {}, {}, true};
  Series compactive{"compactive critical points (onset of compaction)", {}, {}, true};
  Series cap{"end cap", {}, {}, false};
  double last_dilatant_p = NAN, last_dilatant_q = NAN, sigma3_max = 0.0;
  for (const Test& t : tests) {
    sigma3_max = std::max(sigma3_max, t.sigma3);
    const Quantity* q = r.result(t.prefix + "critical_deviatoric_stress_MPa");
    const Quantity* p = r.result(t.prefix + "critical_mean_stress_MPa");
    const Quantity* c = r.result(t.prefix + "critical_is_compaction");
    if (!q || !p || !c) continue;
    if (c->value > 0.5) {
      if (cap.x.empty() && std::isfinite(last_dilatant_p)) {
        cap.x.push_back(last_dilatant_p);
        cap.y.push_back(last_dilatant_q);
      }
      compactive.x.push_back(p->value);
      compactive.y.push_back(q->value);
      cap.x.push_back(p->value);
      cap.y.push_back(q->value);
    } else {
      dilatant.x.push_back(p->value);
      dilatant.y.push_back(q->value);
      last_dilatant_p = p->value, last_dilatant_q = q->value;
    }
  }
  Panel pq{"mean stress p (MPa)", "deviatoric stress q (MPa)", {}};
  const Quantity* phi = r.result("friction_angle_deg");
  const Quantity* ucs = r.result("mohr_coulomb_ucs_MPa");
  if (phi && ucs) {
    std::ostringstream label;
    label.precision(3);
    label << "Mohr-Coulomb: phi = " << phi->value << " deg, UCS = " << ucs->value << " MPa";
    Series line{label.str(), {}, {}, false};
    std::vector<double> s3;
    for (int k = 0; k <= 20; ++k) s3.push_back(sigma3_max * 1.1 * k / 20.0);
    const std::vector<double> q = mohrCoulombQ(phi->value, ucs->value, s3);
    for (std::size_t k = 0; k < s3.size(); ++k) {
      line.x.push_back(s3[k] + q[k] / dim);
      line.y.push_back(q[k]);
    }
    pq.series.push_back(line);
  }
  for (Series* s : {&dilatant, &compactive, &cap}) {
    if (!s->x.empty()) pq.series.push_back(*s);
  }
  if (dilatant.x.empty() && compactive.x.empty()) return f;
  f.panels = {pq};
  return f;
}

std::vector<Figure> loadingFigures(const std::vector<const RunData*>& runs, const Paper& paper,
                                   const std::string& id) {
  std::vector<Test> all;
  std::vector<Figure> out;
  for (const RunData* r : runs) {
    const std::vector<Test> tests = testsOf(*r);
    all.insert(all.end(), tests.begin(), tests.end());
    if (r->rig == "envelope" && tests.size() > 1) {  // a sweep's Mohr-Coulomb fit
      Figure e = failureEnvelope(*r, tests);
      if (!e.panels.empty()) out.push_back(e);
    }
  }
  Figure f = stressStrain(all, paper, id);
  if (!f.panels.empty()) out.insert(out.begin(), f);
  return out;
}

// A point of Figure 6 over seeds: test K's critical point in every run.
struct CriticalPoints {
  std::vector<double> p, q;
  int compactive = 0;
};

std::string withInterval(const campaign::Summary& m, const char* unit) {
  std::ostringstream o;
  o.precision(3);
  o << m.mean;
  if (m.n > 1) o << " [" << m.low << ", " << m.high << "]";
  o << " " << unit;
  return o.str();
}

}  // namespace

// Figure 6 over an ensemble: each test's critical point averaged over the seeds with a bar
// of one standard deviation in q, classed compactive where most seeds found it so; the
// Mohr-Coulomb line of each seed's fit averaged with its band, and the fit's friction angle
// and UCS as means with their 95% intervals.
std::vector<Figure> envelopeEnsembleFigures(const std::vector<const RunData*>& seeds,
                                            const Paper&) {
  if (seeds.empty()) return {};
  std::map<std::string, CriticalPoints> by_test;
  std::vector<std::string> order;
  std::vector<double> phis, ucss;
  double sigma3_max = 0.0;
  for (const RunData* r : seeds) {
    for (const Test& t : testsOf(*r)) {
      sigma3_max = std::max(sigma3_max, t.sigma3);
      const Quantity* q = r->result(t.prefix + "critical_deviatoric_stress_MPa");
      const Quantity* p = r->result(t.prefix + "critical_mean_stress_MPa");
      const Quantity* c = r->result(t.prefix + "critical_is_compaction");
      if (!q || !p || !c) continue;
      if (!by_test.count(t.prefix)) order.push_back(t.prefix);
      CriticalPoints& points = by_test[t.prefix];
      points.p.push_back(p->value);
      points.q.push_back(q->value);
      points.compactive += c->value > 0.5;
    }
    const Quantity* phi = r->result("friction_angle_deg");
    const Quantity* ucs = r->result("mohr_coulomb_ucs_MPa");
    if (phi && ucs) phis.push_back(phi->value), ucss.push_back(ucs->value);
  }
  if (order.empty()) return {};
  const RunData& first = *seeds.front();
  const int dim = first.param("protocol.dimension") == "2" ? 2 : 3;
  Figure f;
  f.id = "failure-envelope";
  f.title = "Failure envelope over " + std::to_string(seeds.size()) + " seeds, " + first.protocol;
  f.caption =
      "Critical points of each test in the mean stress - deviatoric stress plane (Li & Holt, "
      "Figure 6), each the mean over the seeds with a bar of one standard deviation in q; a "
      "test's point is compactive (the onset of shear-enhanced compaction) where most seeds "
      "found it so, dilatant (the peak) otherwise. The line is the mean of the seeds' "
      "Mohr-Coulomb fits of their dilatant points, its band one standard deviation; its "
      "legend gives the fits' friction angle and UCS as means with their 95% confidence "
      "intervals (Student t).";
  Series dilatant{"dilatant critical points (peak)", {}, {}, true};
  Series compactive{"compactive critical points (onset of compaction)", {}, {}, true};
  for (const std::string& prefix : order) {
    const CriticalPoints& c = by_test[prefix];
    const campaign::Summary p = campaign::summarize(c.p), q = campaign::summarize(c.q);
    Series& s = 2 * c.compactive > static_cast<int>(c.p.size()) ? compactive : dilatant;
    s.x.push_back(p.mean);
    s.y.push_back(q.mean);
    s.low.push_back(q.mean - q.std);
    s.high.push_back(q.mean + q.std);
  }
  Panel pq{"mean stress p (MPa)", "deviatoric stress q (MPa)", {}};
  if (!phis.empty()) {
    std::vector<double> s3;
    for (int k = 0; k <= 20; ++k) s3.push_back(sigma3_max * 1.1 * k / 20.0);
    std::vector<std::vector<double>> lines;
    for (std::size_t k = 0; k < phis.size(); ++k)
      lines.push_back(mohrCoulombQ(phis[k], ucss[k], s3));
    Series line{"Mohr-Coulomb, " + std::to_string(phis.size()) +
                    " fits: phi = " + withInterval(campaign::summarize(phis), "deg") +
                    ", UCS = " + withInterval(campaign::summarize(ucss), "MPa"),
                {},
                {},
                false};
    for (std::size_t i = 0; i < s3.size(); ++i) {
      std::vector<double> at;
      for (const auto& l : lines) at.push_back(l[i]);
      const campaign::Summary q = campaign::summarize(at);
      line.x.push_back(s3[i] + q.mean / dim);
      line.y.push_back(q.mean);
      line.low.push_back(q.mean - q.std);
      line.high.push_back(q.mean + q.std);
    }
    pq.series.push_back(line);
  }
  for (Series* s : {&dilatant, &compactive}) {
    if (!s->x.empty()) pq.series.push_back(*s);
  }
  f.panels = {pq};
  return {f};
}

std::vector<Figure> biaxialFigures(const std::vector<const RunData*>& runs, const Paper& paper) {
  return loadingFigures(runs, paper, "biaxial-stress-strain");
}

std::vector<Figure> envelopeFigures(const std::vector<const RunData*>& runs, const Paper& paper) {
  return loadingFigures(runs, paper, "envelope-stress-strain");
}

}  // namespace rocklab::reports
