#include "rigs/common/release.hpp"

#include "lab/core/errors.hpp"
#include "rigs/common/formation.hpp"
#include "rigs/common/measurements.hpp"

namespace rocklab::rigs::unconfined {

template <int D>
Specimen<D> formAndUnload(const SpecimenSettings& s, const Release& release, Recorder& rec,
                          RunControl& control) {
  Specimen<D> sp = buildSpecimen<D>(s, control);
  rec.result("particles", static_cast<double>(sp.sim->particles().size()), "");
  formAndCement(sp, rec, control);
  servoTo(sp, release.unload_to, release.unload_to, release.unload_rate, "unloading", rec, control);
  recordBreaks(sp, rec, "unloading");
  return sp;
}

template <int D>
void clearSides(Specimen<D>& sp) {
  auto& frame = *sp.frame;
  auto& sim = *sp.sim;
  using Axis = typename LoadingFrame<D>::Axis;
  for (int a = 0; a < D; ++a) frame.set(a, Axis{});
  for (int a = 0; a < D - 1; ++a) {
    const double away = frame.length(a);
    frame.place(a, sim.wall(2 * a).point[a] - away, sim.wall(2 * a + 1).point[a] + away);
  }
}

namespace {

// The relaxation's loop state: the steps it has run.
struct Relaxing {
  std::uint64_t done = 0;
  template <class Archive>
  void visit(Archive& ar) {
    ar("done", done);
  }
};

}  // namespace

template <int D>
void relax(Specimen<D>& sp, std::int64_t max_steps, Recorder& rec, RunControl& control) {
  auto& sim = *sp.sim;
  Relaxing st;
  Journal::Unit unit = control.unit("relaxation");
  if (unit.done(st, sp)) return;
  unit.resume(st, sp);
  const double limit = sp.settings.formation.unbalanced_force_ratio;
  for (; st.done < static_cast<std::uint64_t>(max_steps); ++st.done) {
    unit.tick(st, sp);
    sp.frame->step();
    if (st.done % 100 == 99 && sim.unbalancedForceRatio() < limit) {
      ++st.done;
      break;
    }
  }
  rec.result("relaxation_steps", static_cast<double>(st.done), "");
  rec.result("relaxation_unbalanced_force_ratio", sim.unbalancedForceRatio(), "");
  recordBreaks(sp, rec, "relaxation");  // the breaks the release made are the relaxation's
  unit.finish(st, sp);
}

template <int D>
bool PeakWatch::see(const Specimen<D>& sp, double load, double strain) {
  if (!(load > peak)) return false;
  peak = load;
  peak_strain = strain;
  breaks_at_peak = sp.sim->bondBreaks().size();
  tensile_at_peak = sp.broken(BondBreakMode::Tensile);
  shear_at_peak = sp.broken(BondBreakMode::Shear);
  return true;
}

bool PeakWatch::ends(double load, double strain, std::size_t breaks, const Loading& rule) const {
  if (strain >= rule.axial_strain_max) return true;
  const bool cracked = peak > 0.0 && breaks >= breaks_at_peak + 10;
  return rule.stop_after_drop > 0.0 && strain >= rule.stop_after_drop_min_strain && cracked &&
         load < (1.0 - rule.stop_after_drop) * peak && strain > peak_strain;
}

bool PeakWatch::recordDue(std::uint64_t stage_step, std::uint64_t step, std::uint64_t every,
                          bool new_peak, bool done) const {
  const bool at_peak = new_peak && step >= last_record + std::max<std::uint64_t>(every / 10, 1);
  return stage_step % every == 0 || done || at_peak;
}

template <int D>
void PeakWatch::record(Specimen<D>& sp, Recorder& rec, const std::string& stage) {
  const auto& sim = *sp.sim;
  last_record = sim.steps();
  auto put = [&](const std::string& name, double v) {
    rec.series(name, sim.steps(), sim.time(), v);
  };
  const double tensile = static_cast<double>(sp.broken(BondBreakMode::Tensile));
  const double shear = static_cast<double>(sp.broken(BondBreakMode::Shear));
  put("broken_bonds_tensile", tensile);
  put("broken_bonds_shear", shear);
  put("broken_bonds_total", tensile + shear);
  put("unbalanced_force_ratio", sim.unbalancedForceRatio());
  unbalanced_sum += sim.unbalancedForceRatio();
  ++records;
  recordBreaks(sp, rec, stage);
}

template <int D>
void recordLoadingResults(const Specimen<D>& sp, const PeakWatch& w, std::uint64_t start_step,
                          double inertial_at_peak, Recorder& rec) {
  const auto& sim = *sp.sim;
  rec.result("broken_bonds_at_peak", static_cast<double>(w.tensile_at_peak + w.shear_at_peak), "");
  rec.result("broken_bonds_tensile_at_peak", static_cast<double>(w.tensile_at_peak), "");
  rec.result("broken_bonds_shear_at_peak", static_cast<double>(w.shear_at_peak), "");
  rec.result(
      "broken_bonds_total",
      static_cast<double>(sp.broken(BondBreakMode::Tensile) + sp.broken(BondBreakMode::Shear)), "");
  rec.result("loading_steps", static_cast<double>(sim.steps() - start_step), "");
  rec.result("mean_unbalanced_force_ratio", w.meanUnbalanced(), "");
  rec.result("inertial_number_at_peak", inertial_at_peak, "");
  warnIfNotQuasiStatic(sp, rec, "loading", w.meanUnbalanced(), inertial_at_peak);
}

void validate(const SpecimenSettings& specimen, const Release& release, const Loading& loading) {
  if (specimen.sample.kind == SampleKind::Clumps) {
    throw InvalidParameter("", "sample.kind",
                           "clumps can be neither cut nor glued (a rigid grain would be cut "
                           "through or held by some of its pebbles): use spheres or grains");
  }
  if (loading.axial_strain_max <= loading.stop_after_drop_min_strain) {
    throw InvalidParameter("", "loading.axial_strain_max",
                           "must exceed loading.stop_after_drop_min_strain: the test must get "
                           "past the strain where a drop may end it");
  }
  const FormationSettings& f = specimen.formation;
  if (release.unload_to > std::min(f.axial_stress, f.lateral_stress)) {
    throw InvalidParameter("", "release.unload_to_MPa",
                           "must not exceed the formation stresses: the sample is unloaded to it");
  }
}

template bool PeakWatch::see<2>(const Specimen<2>&, double, double);
template bool PeakWatch::see<3>(const Specimen<3>&, double, double);
template void PeakWatch::record<2>(Specimen<2>&, Recorder&, const std::string&);
template void PeakWatch::record<3>(Specimen<3>&, Recorder&, const std::string&);
template void recordLoadingResults<2>(const Specimen<2>&, const PeakWatch&, std::uint64_t, double,
                                      Recorder&);
template void recordLoadingResults<3>(const Specimen<3>&, const PeakWatch&, std::uint64_t, double,
                                      Recorder&);
template Specimen<2> formAndUnload<2>(const SpecimenSettings&, const Release&, Recorder&,
                                      RunControl&);
template Specimen<3> formAndUnload<3>(const SpecimenSettings&, const Release&, Recorder&,
                                      RunControl&);
template void clearSides<2>(Specimen<2>&);
template void clearSides<3>(Specimen<3>&);
template void relax<2>(Specimen<2>&, std::int64_t, Recorder&, RunControl&);
template void relax<3>(Specimen<3>&, std::int64_t, Recorder&, RunControl&);

}  // namespace rocklab::rigs::unconfined
