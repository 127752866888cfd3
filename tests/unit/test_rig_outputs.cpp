// A rig's outputs, declared once: names matched with their prefixes and patterns, a recorder
// that refuses what is not declared, protocols naming key results checked against the rig's.

#include <gtest/gtest.h>

#include <map>

#include "rigs/common/checked_recorder.hpp"
#include "rigs/registry.hpp"

namespace rocklab::rigs {
namespace {

TEST(RigOutputs, NamesArePrefixesAndBasesTheRigDeclares) {
  const Outputs& oedometer = *rigOutputs("oedometer");
  EXPECT_TRUE(oedometer.declares(OutputKind::Series, "axial_stress_MPa"));
  EXPECT_TRUE(oedometer.declares(OutputKind::Series, "formation.axial_stress_MPa"));
  EXPECT_TRUE(oedometer.declares(OutputKind::Series, "cored.phase"));
  EXPECT_TRUE(oedometer.declares(OutputKind::Result, "virgin.cycle12_modulus_ratio"));
  EXPECT_FALSE(oedometer.declares(OutputKind::Result, "virgin.cycle_modulus_ratio"));  // no number
  EXPECT_FALSE(oedometer.declares(OutputKind::Series, "axial_stres_MPa"));
  EXPECT_FALSE(oedometer.declares(OutputKind::Series, "test1.axial_stress_MPa"));  // envelope's
  EXPECT_TRUE(oedometer.declares(OutputKind::Event, "bond_break"));
  EXPECT_FALSE(oedometer.declares(OutputKind::Event, "pore_pressure"));
  const Outputs& envelope = *rigOutputs("envelope");
  EXPECT_TRUE(envelope.declares(OutputKind::Series, "test3.confinement.porosity"));
  EXPECT_TRUE(envelope.declares(OutputKind::Result, "test10.band_angle_deg"));
  EXPECT_NE(envelope.keyResult("test2.ucs_MPa"), nullptr);
  EXPECT_EQ(envelope.keyResult("test2.ucs_GPa"), nullptr);
  const Outputs& permeameter = *rigOutputs("permeameter");
  EXPECT_TRUE(permeameter.declares(OutputKind::Result, "solver_implicit_cg_seconds"));
  EXPECT_TRUE(permeameter.declares(OutputKind::Series, "flow.porosity"));
  EXPECT_EQ(rigOutputs("no such rig"), nullptr);
}

TEST(RigOutputs, EveryRigOfTheTableDeclaresItsOutputs) {
  for (const RigEntry& rig : rigTable()) {
    ASSERT_NE(rigOutputs(rig.name), nullptr) << rig.name;
    EXPECT_FALSE(rig.outputs().keyResults().empty()) << rig.name;
  }
}

struct Discard : Recorder {
  int series_count = 0;
  void series(std::string_view, std::uint64_t, double, double) override { ++series_count; }
  void event(const EventRecord&) override {}
  void result(std::string_view, double, std::string_view) override {}
  void message(std::uint64_t, double, std::string_view, std::string_view) override {}
  void stageTiming(std::string_view, double, std::uint64_t) override {}
  void snapshot(std::string_view, std::string_view, const Frame&) override {}
  void wave(const WaveRecord&) override {}
};

TEST(RigOutputs, TheRecorderRefusesWhatTheRigDoesNotDeclare) {
  Discard inner;
  CheckedRecorder rec(inner, *rigOutputs("hydrostatic"), "hydrostatic");
  rec.series("loading.porosity", 1, 0.0, 0.4);
  rec.series("loading.porosity", 2, 0.0, 0.4);
  EXPECT_EQ(inner.series_count, 2);
  try {
    rec.series("loading.porosity_typo", 3, 0.0, 0.4);
    FAIL() << "no error";
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("'loading.porosity_typo'"), std::string::npos);
  }
  EXPECT_THROW(rec.result("k_over_k0_final", 1.0, ""), std::logic_error);  // the permeameter's
  EventRecord pore;
  pore.kind = "pore_pressure";
  EXPECT_THROW(rec.event(pore), std::logic_error);
}

TEST(RigOutputs, AProtocolNamingAnUndeclaredKeyResultIsRefusedAtItsLine) {
  const RigEntry& rig = findRig("biaxial", "test");
  const protocol::Schema schema = schemaOf(rig);
  const std::string head = "[protocol]\nname = \"t\"\nrig = \"biaxial\"\n";
  const auto good = protocol::parseProtocol(
      "q.toml", head + "key_results = [\"ucs_MPa\"]\n[sample]\ncount = 10\n", schema);
  EXPECT_NO_THROW(validateProtocol(rig, good));
  const auto bad = protocol::parseProtocol(
      "p.toml", head + "key_results = [\"ucs_MPa\", \"ucs_GPa\"]\n[sample]\ncount = 10\n", schema);
  try {
    validateProtocol(rig, bad);
    FAIL() << "no error";
  } catch (const protocol::ProtocolError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("p.toml:4: protocol.key_results: 'ucs_GPa' is not a key result of the "
                     "biaxial rig: one of peak_deviatoric_stress_MPa, ucs_MPa"),
              std::string::npos)
        << m;
    EXPECT_EQ(m.find("'ucs_MPa'"), std::string::npos) << m;
  }
}

TEST(RigOutputs, ProtocolKeysOfAllRigsComeFromOneDeclarationEach) {
  // The keys several rigs share are declared once: the same unit, range and doc in each. (A
  // choice such as loading.mode names each rig's own modes.)
  std::map<std::string, const protocol::ParamDecl*> seen;
  std::vector<protocol::Schema> schemas;
  for (const RigEntry& rig : rigTable()) schemas.push_back(schemaOf(rig));
  for (const protocol::Schema& s : schemas) {
    for (const protocol::ParamDecl& d : s.all()) {
      auto [it, fresh] = seen.emplace(d.key, &d);
      if (fresh || d.kind == protocol::Kind::Choice) continue;
      EXPECT_EQ(it->second->unit.name, d.unit.name) << d.key;
      EXPECT_EQ(it->second->rangeText(), d.rangeText()) << d.key;
      EXPECT_EQ(it->second->doc, d.doc) << d.key;
    }
  }
  EXPECT_GT(seen.count("loading.confining_stress_MPa"), 0u);
}

}  // namespace
}  // namespace rocklab::rigs
