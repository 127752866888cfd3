#include "rigs/biaxial/envelope.hpp"

#include <algorithm>
#include <sstream>

#include "rigs/common/formation.hpp"
#include "rigs/common/measurements.hpp"

namespace rocklab::rigs::envelope {

void Settings::validate() const {
  const std::string key = "envelope.confining_stresses_MPa";
  if (confining_stresses.size() < 2) {
    throw InvalidParameter("", key, "needs at least two confinements for an envelope");
  }
  for (std::size_t i = 1; i < confining_stresses.size(); ++i) {
    if (confining_stresses[i] <= confining_stresses[i - 1]) {
      throw InvalidParameter("", key, "must rise strictly");
    }
  }
}

namespace {

template <int D>
void runDimension(const Settings& s, Recorder& rec, RunControl& control) {
  Specimen<D> formed = buildSpecimen<D>(s.specimen, control);
  biaxial::recordSample(formed, rec);
  formAndCement(formed, rec, control);
  const std::vector<double>& sweep = s.confining_stresses;
  std::vector<EnvelopePoint> points;
  std::vector<std::unique_ptr<Simulation<D>>> done;  // kept for the stage timings
  double highest_dilatant = -1.0, lowest_compactive = -1.0;
  for (std::size_t k = 0; k < sweep.size(); ++k) {
    Specimen<D> sp = formed.branch();
    const std::string branch = "test" + std::to_string(k + 1);
    const biaxial::TestOutcome t =
        biaxial::confineAndLoad(sp, s.test, s.analysis, sweep[k], branch, rec, control);
    done.push_back(std::move(sp.sim));
    if (!t.critical.found) continue;
    points.push_back({t.sigma3, t.sigma3 + t.critical.q, t.critical.compactive});
    if (t.critical.compactive) {
      if (lowest_compactive < 0.0) lowest_compactive = t.sigma3;
    } else {
      highest_dilatant = std::max(highest_dilatant, t.sigma3);
    }
  }
  rec.result("tests", static_cast<double>(sweep.size()), "");
  const auto compactive = std::count_if(points.begin(), points.end(),
                                        [](const EnvelopePoint& p) { return p.compactive; });
  rec.result("envelope_points_dilatant", static_cast<double>(points.size() - compactive), "");
  rec.result("envelope_points_compactive", static_cast<double>(compactive), "");
  const MohrCoulomb mc = fitMohrCoulomb(points);
  if (mc.fitted) {
    rec.result("friction_angle_deg", mc.friction_angle_deg, "deg");
    rec.result("mohr_coulomb_ucs_MPa", mc.ucs / 1e6, "MPa");
    rec.result("mohr_coulomb_rms_residual_MPa", mc.rms_residual / 1e6, "MPa");
  } else {
    rec.message(formed.sim->steps(), formed.sim->time(), "warning",
                "no Mohr-Coulomb line: it needs dilatant critical points at two confinements "
                "or more, with sigma_1 rising with sigma_3");
  }
  if (lowest_compactive >= 0.0) {
    // The cap begins between the last dilatant and the first compactive confinement.
    rec.result("cap_confining_stress_MPa",
               (highest_dilatant >= 0.0 ? 0.5 * (highest_dilatant + lowest_compactive)
                                        : lowest_compactive) /
                   1e6,
               "MPa");
  }
  std::vector<const Simulation<D>*> sims{formed.sim.get()};
  for (const auto& sim : done) sims.push_back(sim.get());
  recordTimings<D>(rec, sims);
}

}  // namespace

void run(const Settings& s, Recorder& rec, RunControl& control) {
  byDimension(s.specimen.protocol.dimension,
              [&](auto dim) { runDimension<dim.value>(s, rec, control); });
}

}  // namespace rocklab::rigs::envelope
