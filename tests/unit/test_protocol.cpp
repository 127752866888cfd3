// Protocol parsing: every problem named with file, line, key, allowed range and unit.

#include <gtest/gtest.h>

#include "lab/protocol/params.hpp"

namespace rocklab::protocol {
namespace {

Schema schema() {
  Schema s;
  s.text("protocol.name", std::nullopt, "protocol name");
  s.text("protocol.rig", std::nullopt, "rig");
  range(s.real("formation.axial_stress_MPa", "MPa", 1e6, std::nullopt, "axial stress"), 0, true,
        500, false);
  range(s.real("numerics.local_damping", "-", 1, 0.7, "PFC local damping"), 0, false, 1, true);
  range(s.integer("sample.count", 2000, "particles"), 2, false, 1e8, false);
  s.choice("bonds.negative_strength", {"skip", "resample"}, "skip", "draws <= 0");
  s.flag("output.quiet", false, "no progress");
  range(s.realList("loading.cycle_at_axial_strain", "-", 1, std::vector<double>{}, "cycles"), 0,
        true, 1, true);
  s.textList("protocol.key_results", std::vector<std::string>{}, "key results");
  return s;
}

const char* kGood = R"(
[protocol]
name = "t"
rig = "oedometer"

[formation]
axial_stress_MPa = 30

[loading]
cycle_at_axial_strain = [0.002, 0.02]
)";

TEST(Protocol, ParsesValuesDefaultsAndUnits) {
  const Schema sc = schema();
  const Settings s = parseProtocol("p.toml", kGood, sc);
  EXPECT_DOUBLE_EQ(s.real("formation.axial_stress_MPa"), 30.0);
  EXPECT_DOUBLE_EQ(s.si("formation.axial_stress_MPa"), 30e6);
  EXPECT_DOUBLE_EQ(s.real("numerics.local_damping"), 0.7);  // default
  EXPECT_EQ(s.integer("sample.count"), 2000);
  EXPECT_EQ(s.text("bonds.negative_strength"), "skip");
  EXPECT_EQ(s.list("loading.cycle_at_axial_strain").size(), 2u);
  EXPECT_TRUE(s.given("formation.axial_stress_MPa"));
  EXPECT_FALSE(s.given("sample.count"));
  EXPECT_EQ(s.where("formation.axial_stress_MPa"), "p.toml:7");
  const auto table = s.table();
  ASSERT_EQ(table.size(), sc.all().size());
  EXPECT_EQ(table[2].key, "formation.axial_stress_MPa");
  EXPECT_EQ(table[2].value, "30");
  EXPECT_EQ(table[2].unit, "MPa");
  EXPECT_EQ(rigOf("p.toml", kGood), "oedometer");
}

std::string errors(const std::string& text) {
  const Schema sc = schema();
  try {
    parseProtocol("bad.toml", text, sc);
  } catch (const ProtocolError& e) {
    return e.what();
  }
  return "";
}

TEST(Protocol, EveryProblemIsNamedWithFileLineKeyRangeAndUnit) {
  const std::string e = errors(R"([protocol]
name = "t"
rig = "oedometer"
[formation]
axial_stress_MPa = -3
[numerics]
local_damping = "high"
local_dampin = 0.5
[sample]
count = 2.5
[bonds]
negative_strength = "clip"
)");
  EXPECT_NE(e.find("bad.toml:5: formation.axial_stress_MPa = -3 is outside the allowed range (0, "
                   "500] (MPa)"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("bad.toml:7: 'numerics.local_damping' (-) expects a number"), std::string::npos)
      << e;
  EXPECT_NE(e.find("bad.toml:8: unknown key 'numerics.local_dampin'; did you mean "
                   "'numerics.local_damping'?"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("bad.toml:10: 'sample.count' (-) expects an integer"), std::string::npos) << e;
  EXPECT_NE(e.find("bad.toml:12: bonds.negative_strength = \"clip\" is not allowed: one of: skip, "
                   "resample"),
            std::string::npos)
      << e;
}

TEST(Protocol, MissingRequiredKeysAndSyntaxErrors) {
  std::string e = errors("[protocol]\nname = \"t\"\nrig = \"oedometer\"\n");
  EXPECT_NE(e.find("missing required key 'formation.axial_stress_MPa' (MPa)"), std::string::npos)
      << e;
  e = errors("[protocol\nname = 1");
  EXPECT_NE(e.find("bad.toml: not valid TOML"), std::string::npos) << e;
  e = errors(std::string(kGood) + "\n[loading]\n");  // a table defined twice
  EXPECT_NE(e.find("not valid TOML"), std::string::npos) << e;
  EXPECT_THROW(rigOf("x.toml", "[protocol]\nname = \"t\"\n"), ProtocolError);
}

TEST(Protocol, HelpListsKeysWithUnitsDefaultsAndRanges) {
  const std::string h = schema().help();
  EXPECT_NE(h.find("numerics.local_damping (-) = 0.7  [0, 1)"), std::string::npos) << h;
  EXPECT_NE(h.find("formation.axial_stress_MPa (MPa)  (required)  (0, 500]"), std::string::npos)
      << h;
}

TEST(Protocol, ListsOfNamesAreReadAndShown) {
  const Schema sc = schema();
  const Settings s = parseProtocol("p.toml", kGood, sc);  // no key_results: the default
  EXPECT_TRUE(s.texts("protocol.key_results").empty());
  const std::string text = R"(
[protocol]
name = "t"
rig = "oedometer"
key_results = ["ucs_MPa", "test2.band_angle_deg"]
[formation]
axial_stress_MPa = 30
)";
  const Settings t = parseProtocol("p.toml", text, sc);
  EXPECT_EQ(t.texts("protocol.key_results"),
            (std::vector<std::string>{"ucs_MPa", "test2.band_angle_deg"}));
  bool shown = false;
  for (const ParamRow& r : t.table()) {
    if (r.key == "protocol.key_results") {
      EXPECT_EQ(r.value, "[\"ucs_MPa\", \"test2.band_angle_deg\"]");
      shown = true;
    }
  }
  EXPECT_TRUE(shown);
  std::string e;
  try {
    parseProtocol("p.toml",
                  "[protocol]\nname = \"t\"\nrig = \"o\"\nkey_results = [1, 2]\n"
                  "[formation]\naxial_stress_MPa = 3\n",
                  sc);
  } catch (const ProtocolError& x) {
    e = x.what();
  }
  EXPECT_NE(e.find("p.toml:4: 'protocol.key_results' expects a list of strings"), std::string::npos)
      << e;
}

TEST(Protocol, CommandLineValuesAreReadAsTheKeysKindAndChecked) {
  const Schema sc = schema();
  Settings s = parseProtocol("p.toml", kGood, sc);
  s.overrideText("numerics.local_damping", "0.35");
  EXPECT_DOUBLE_EQ(s.real("numerics.local_damping"), 0.35);
  s.overrideText("sample.count", "500");
  EXPECT_EQ(s.integer("sample.count"), 500);
  s.overrideText("bonds.negative_strength", "resample");
  EXPECT_EQ(s.text("bonds.negative_strength"), "resample");
  s.overrideText("output.quiet", "true");
  EXPECT_TRUE(s.flag("output.quiet"));
  auto error = [&](const std::string& key, const std::string& text) {
    try {
      s.overrideText(key, text);
    } catch (const ProtocolError& x) {
      return std::string(x.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error("numerics.local_damping", "1.5").find("outside the allowed range [0, 1)"),
            std::string::npos);
  EXPECT_NE(error("numerics.local_damping", "fast").find("expects a number (-)"),
            std::string::npos);
  EXPECT_NE(error("sample.count", "2.5").find("expects an integer"), std::string::npos);
  EXPECT_NE(error("bonds.negative_strength", "drop").find("one of: skip, resample"),
            std::string::npos);
  EXPECT_NE(error("loading.cycle_at_axial_strain", "0.1").find("cannot be varied"),
            std::string::npos);
  EXPECT_NE(error("numerics.damping", "0.1").find("not a key"), std::string::npos);
  EXPECT_DOUBLE_EQ(s.real("numerics.local_damping"), 0.35);  // a refused value changes nothing
}

}  // namespace
}  // namespace rocklab::protocol
