// Observers never change the run (house rule 3, README.md): recording a specimen's state, its bond
// breaks and the fluid's readings twice, once or not at all leaves the same state, bit for
// bit, and a break is recorded once however often the recorder looks.

#include <gtest/gtest.h>

#include "rigs/common/formation.hpp"
#include "rigs/common/measurements.hpp"
#include "rigs/permeameter/permeameter.hpp"

namespace rocklab::rigs {
namespace {

struct Memory : Recorder {
  std::vector<EventRecord> events;
  std::size_t series_count = 0;
  void series(std::string_view, std::uint64_t, double, double) override { ++series_count; }
  void event(const EventRecord& e) override { events.push_back(e); }
  void result(std::string_view, double, std::string_view) override {}
  void message(std::uint64_t, double, std::string_view, std::string_view) override {}
  void stageTiming(std::string_view, double, std::uint64_t) override {}
  void snapshot(std::string_view, std::string_view, const Frame&) override {}
  void wave(const WaveRecord&) override {}
};

// A small 2D sample of weak cement, formed at 1 MPa: loading it breaks bonds at once.
SpecimenSettings weakSample() {
  SpecimenSettings s;
  s.protocol.dimension = 2;
  s.protocol.seed = 3;
  s.sample.packing.count = 150;
  s.sample.packing.sizes = SizeDistribution::uniform(0.8e-3, 1.2e-3);
  s.formation.axial_stress = s.formation.lateral_stress = 1.0 * kMPa;
  s.cement.kind.tensile_mean = s.cement.kind.shear_mean = 1.0 * kMPa;
  s.cement.kind.tensile_std = s.cement.kind.shear_std = 0.3 * kMPa;
  s.output.snapshots = false;
  return s;
}

// Loads the formed sample axially, recording its state `records` times every 200 steps.
std::uint64_t loadAndRecord(int records, Memory& rec) {
  RunControl control(false, nullptr);
  Specimen<2> sp = buildSpecimen<2>(weakSample(), control);
  formAndCement(sp, rec, control);
  rec.series_count = 0;  // the loading's
  using Axis = LoadingFrame<2>::Axis;
  sp.frame->set(1, Axis{LoadingFrame<2>::Mode::StrainRate, 5.0});
  for (int s = 1; s <= 4000; ++s) {
    sp.frame->step();
    if (s % 200 != 0) continue;
    for (int k = 0; k < records; ++k) recordState(sp, rec, "", "loading", 5.0);
  }
  EXPECT_GT(sp.sim->bondBreaks().size(), 10u) << "the test needs bonds to break";
  return sp.sim->stateHash();
}

TEST(Observers, RecordingTwiceOrNotAtAllLeavesTheStateAndTheBreaksAsThey) {
  Memory never, once, twice;
  const std::uint64_t h0 = loadAndRecord(0, never), h1 = loadAndRecord(1, once),
                      h2 = loadAndRecord(2, twice);
  EXPECT_EQ(h0, h1);
  EXPECT_EQ(h1, h2);
  EXPECT_EQ(twice.series_count, 2 * once.series_count);
  // Every break once, in the same order, however often the recorder read the log.
  ASSERT_EQ(once.events.size(), twice.events.size());
  for (std::size_t k = 0; k < once.events.size(); ++k) {
    EXPECT_EQ(once.events[k].step, twice.events[k].step);
    EXPECT_EQ(once.events[k].particle_a, twice.events[k].particle_a);
  }
}

// The permeameter's fluid is a stage of the run: solved and applied every n steps whether
// its recorder records each update twice, once or never (records < 0: no fluid at all).
std::uint64_t flowAndRecord(int records) {
  RunControl control(false, nullptr);
  Memory rec;
  SpecimenSettings s = weakSample();
  s.cement.enabled = false;
  Specimen<2> sp = buildSpecimen<2>(s, control);
  formAndCement(sp, rec, control);
  permeameter::FlowStage<2> flow(flow::FlowSettings{}, permeameter::FlowDirection::Along);
  const permeameter::Measurement m;
  Memory series;
  permeameter::FlowRecorder<2> recorder(sp, m, series);
  recorder.startKozenyCarman();
  flow.start(*sp.sim);
  flow.takeInitialPermeability(*sp.sim);
  if (records >= 0) {
    sp.frame->couple(
        [&] {
          if (!flow.update(*sp.sim)) return;
          for (int k = 0; k < records; ++k) recorder.state(flow);
        },
        100);
  }
  servoTo(sp, 2.0 * kMPa, 2.0 * kMPa, 2e3 * kMPa, "loading", rec, control);
  EXPECT_EQ(flow.updates() > 2u, records >= 0);
  EXPECT_EQ(series.series_count > 0, records > 0);
  return sp.sim->stateHash();
}

TEST(Observers, RecordingTheFluidTwiceOrNotAtAllLeavesTheState) {
  const std::uint64_t h0 = flowAndRecord(0);
  EXPECT_EQ(h0, flowAndRecord(1));
  EXPECT_EQ(h0, flowAndRecord(2));
  EXPECT_NE(h0, flowAndRecord(-1));  // the fluid's pressures did act
}

}  // namespace
}  // namespace rocklab::rigs
