// Protocol parsing: every problem named with file, line, key, allowed range and unit.

#include <gtest/gtest.h>

#include <unistd.h>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "lab/protocol/declare.hpp"

namespace rocklab::protocol {
namespace {

enum class Negative { Skip, Resample };

// A settings struct as the rigs write them (lab/core/fields.hpp): keys in several sections.
struct Sample {
  std::string name, rig;
  double axial_stress = 0.0;  // Pa, required
  double local_damping = 0.7;
  std::int64_t count = 2000;
  Negative negative = Negative::Skip;
  bool quiet = false;
  std::vector<double> cycles;
  std::vector<std::string> key_results;
  std::string file;

  template <class F>
  void fields(F& f) {
    static constexpr Choice<Negative> kNegative[] = {{"skip", Negative::Skip},
                                                     {"resample", Negative::Resample}};
    auto p = f.at("protocol.");
    p(name, {"name", units::text, {}, "protocol name", true});
    p(rig, {"rig", units::text, {}, "rig", true});
    f.at("formation.")(axial_stress, {"axial_stress_MPa", units::MPa, Range::leftOpen(0, 500),
                                      "axial stress", true});
    f.at("numerics.")(local_damping,
                      {"local_damping", units::none, Range::rightOpen(0, 1), "PFC local damping"});
    f.at("sample.")(count, {"count", units::none, Range::closed(2, 1e8), "particles"});
    f.at("sample.")(file, {"file", units::path, {}, "a packing"});
    f.at("bonds.")(negative, {"negative_strength", units::text, {}, "draws <= 0"}, kNegative);
    f.at("output.")(quiet, {"quiet", units::text, {}, "no progress"});
    f.at("loading.")(cycles, {"cycle_at_axial_strain", units::none, Range::open(0, 1), "cycles"});
    p(key_results, {"key_results", units::text, {}, "key results"});
  }
};

Schema schema() {
  Schema s;
  declare<Sample>(s);
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
  EXPECT_DOUBLE_EQ(read<Sample>(s).axial_stress, 30e6);
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
  for (const notebook::ParamRow& r : t.table()) {
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
  s.apply({parseOverride("numerics.local_damping=0.35"), parseOverride("sample.count = 500"),
           parseOverride("bonds.negative_strength=resample"), parseOverride("output.quiet=true"),
           parseOverride("loading.cycle_at_axial_strain=[0.001, 0.01, 0.03]")});
  EXPECT_DOUBLE_EQ(s.real("numerics.local_damping"), 0.35);
  EXPECT_EQ(s.integer("sample.count"), 500);
  EXPECT_EQ(s.text("bonds.negative_strength"), "resample");  // bare text for a text key
  EXPECT_TRUE(s.flag("output.quiet"));
  EXPECT_EQ(s.list("loading.cycle_at_axial_strain").size(), 3u);
  EXPECT_EQ(s.where("sample.count"), "--set sample.count=500");
  auto error = [&](const std::string& key, const std::string& text) {
    try {
      s.apply({{key, text, "--vary"}});
    } catch (const ProtocolError& x) {
      return std::string(x.what());
    }
    return std::string("no error");
  };
  // The same messages as for the file's keys, at the override instead of a line.
  EXPECT_EQ(error("numerics.local_damping", "1.5"),
            "--vary numerics.local_damping=1.5: numerics.local_damping = 1.5 is outside the "
            "allowed range [0, 1) (-)");
  EXPECT_NE(error("numerics.local_damping", "fast").find("is not a value"), std::string::npos);
  EXPECT_NE(error("numerics.local_damping", "\"fast\"").find("expects a number"),
            std::string::npos);
  EXPECT_NE(error("sample.count", "2.5").find("expects an integer"), std::string::npos);
  EXPECT_NE(error("bonds.negative_strength", "drop").find("one of: skip, resample"),
            std::string::npos);
  EXPECT_NE(error("numerics.damping", "0.1").find("unknown key 'numerics.damping'"),
            std::string::npos);
  EXPECT_DOUBLE_EQ(s.real("numerics.local_damping"), 0.35);  // a refused value changes nothing
  EXPECT_THROW(parseOverride("numerics.local_damping"), ProtocolError);
}

TEST(Protocol, OverridesAtParseTimeAreCheckedWithTheFileAndMayGiveRequiredKeys) {
  const Schema sc = schema();
  const std::string text = "[protocol]\nname = \"t\"\nrig = \"oedometer\"\n";
  try {
    parseProtocol("p.toml", text, sc);
    ADD_FAILURE() << "a required key was missing";
  } catch (const ProtocolError&) {
  }
  const Settings s =
      parseProtocol("p.toml", text, sc, {parseOverride("formation.axial_stress_MPa=12")});
  EXPECT_DOUBLE_EQ(s.real("formation.axial_stress_MPa"), 12.0);
  try {
    parseProtocol("p.toml", kGood + std::string("sample.count = 0.5\n"), sc,
                  {parseOverride("formation.axial_stress_MPa=-1")});
    ADD_FAILURE() << "no error";
  } catch (const ProtocolError& e) {
    ASSERT_EQ(e.problems().size(), 2u) << e.what();
    EXPECT_EQ(e.problems()[0].rfind("p.toml:11: unknown key 'loading.sample.count'", 0), 0u)
        << e.what();
    EXPECT_EQ(e.problems()[1].rfind("--set formation.axial_stress_MPa=-1: ", 0), 0u) << e.what();
  }
}

// The effective text reads back to the same settings, whether the override replaces a line
// of the file, goes under an existing table or into a new one, or cannot be written in.
TEST(Protocol, EffectiveTextReadsBackToTheSettingsWithTheOverridesMarked) {
  const Schema sc = schema();
  EXPECT_EQ(parseProtocol("p.toml", kGood, sc).effectiveText(), kGood);
  const std::vector<Override> o = {parseOverride("formation.axial_stress_MPa=12.5"),
                                   parseOverride("loading.cycle_at_axial_strain=[0.1]"),
                                   parseOverride("numerics.local_damping=0.1234567890123"),
                                   parseOverride("bonds.negative_strength=resample")};
  const Settings s = parseProtocol("p.toml", kGood, sc, o);
  const std::string effective = s.effectiveText();
  EXPECT_NE(effective.find("axial_stress_MPa = 12.5  # --set formation.axial_stress_MPa=12.5 "
                           "(the file had: 30)"),
            std::string::npos)
      << effective;
  EXPECT_NE(effective.find("[numerics]\nlocal_damping = 0.1234567890123  # --set"),
            std::string::npos)
      << effective;
  const Settings back = parseProtocol("p.toml", effective, sc);
  const auto back_table = back.table();
  for (const auto& row : s.table()) {
    const auto it = std::find_if(back_table.begin(), back_table.end(),
                                 [&](const auto& r) { return r.key == row.key; });
    ASSERT_NE(it, back_table.end()) << row.key;
    EXPECT_EQ(it->value, row.value) << row.key;
  }
  EXPECT_EQ(back.real("numerics.local_damping"), 0.1234567890123);  // every bit
  // A run's choice that leaves the results as they are (--threads) stays out of the text:
  // the protocol's hash does not depend on it.
  Settings chosen = s;
  chosen.runChoice("numerics.local_damping", 0.5);
  EXPECT_EQ(chosen.real("numerics.local_damping"), 0.5);
  EXPECT_EQ(chosen.effectiveText(), effective);
  // A multi-line list cannot be replaced in place: every key is written out instead.
  const std::string multi = std::string(kGood) + "[sample]\ncount = 300\n";
  const std::string spread = std::string("[protocol]\nname = \"t\"\nrig = \"oedometer\"\n") +
                             "[formation]\naxial_stress_MPa = 30\n[loading]\n" +
                             "cycle_at_axial_strain = [\n  0.002,\n  0.02,\n]\n";
  const Settings m =
      parseProtocol("p.toml", spread, sc, {parseOverride("loading.cycle_at_axial_strain=[0.5]")});
  const Settings mb = parseProtocol("p.toml", m.effectiveText(), sc);
  EXPECT_EQ(mb.list("loading.cycle_at_axial_strain"), std::vector<double>{0.5});
  EXPECT_DOUBLE_EQ(mb.real("formation.axial_stress_MPa"), 30.0);
  const Settings c = parseProtocol("p.toml", multi, sc, {parseOverride("sample.count=7")});
  EXPECT_EQ(parseProtocol("p.toml", c.effectiveText(), sc).integer("sample.count"), 7);
}

// A folder with a protocol that includes a material file, written for one test.
class Included : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("rocklab-include-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_ / "materials");
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    const auto path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }
  // The protocol as run, parsed alone as `file`, gives the same settings.
  static void expectReadsBack(const std::string& file, const Settings& s) {
    const Settings back = parseProtocol(file, s.effectiveText(), schema());
    ASSERT_EQ(back.table().size(), s.table().size());
    for (std::size_t k = 0; k < s.table().size(); ++k) {
      EXPECT_EQ(back.table()[k].value, s.table()[k].value) << s.table()[k].key;
    }
  }
  // The problems of `text` written as `name` and parsed, joined; "" when there are none.
  std::string problems(const std::string& name, const std::string& text) {
    const std::string file = write(name, text);
    try {
      parseProtocol(file, text, schema());
    } catch (const ProtocolError& e) {
      return std::string(e.what());
    }
    return std::string();
  }
  std::filesystem::path dir_;
};

constexpr const char* kMaterial = "[numerics]\nlocal_damping = 0.25\n\n[sample]\ncount = 64\n";

TEST_F(Included, AMaterialFilesKeysJoinTheProtocolsCheckedAtTheirOwnLines) {
  const Schema sc = schema();
  write("materials/soft.toml", kMaterial);
  const std::string text = "include = \"materials/soft.toml\"\n" + std::string(kGood);
  const std::string file = write("p.toml", text);
  const Settings s = parseProtocol(file, text, sc);
  EXPECT_DOUBLE_EQ(s.real("numerics.local_damping"), 0.25);
  EXPECT_EQ(s.integer("sample.count"), 64);
  EXPECT_DOUBLE_EQ(s.real("formation.axial_stress_MPa"), 30.0);
  const std::string material = (dir_ / "materials/soft.toml").string();
  EXPECT_EQ(s.where("sample.count"), material + ":5");
  EXPECT_EQ(s.where("formation.axial_stress_MPa"), file + ":8");
  ASSERT_EQ(s.includes(), std::vector<std::string>{material});

  // The protocol as run stands alone: the material's keys written in, so a changed material
  // file changes the run's text (and hash), and parsing the text alone gives these settings.
  const std::string effective = s.effectiveText();
  EXPECT_EQ(effective.find("include ="), std::string::npos) << effective;
  EXPECT_NE(effective.find("count = 64  # " + material), std::string::npos) << effective;
  expectReadsBack(file, s);
  write("materials/soft.toml", "[sample]\ncount = 65\n");
  EXPECT_NE(parseProtocol(file, text, sc).effectiveText(), effective);

  // --set overrides an included key like any other.
  const Settings o = parseProtocol(file, text, sc, {parseOverride("sample.count=9")});
  EXPECT_EQ(o.integer("sample.count"), 9);
  EXPECT_EQ(parseProtocol(file, o.effectiveText(), sc).integer("sample.count"), 9);
}

// The protocol as run names its file by one path however it was spelled (from the repository,
// or from another folder by another path).
TEST_F(Included, TheProtocolAsRunDoesNotDependOnHowItsPathWasSpelled) {
  const Schema sc = schema();
  const std::string file = write("p.toml", kGood);
  std::filesystem::create_directories(dir_ / "sub");
  const std::string other = (dir_ / "sub" / ".." / "." / "p.toml").string();
  const std::vector<Override> o = {parseOverride("sample.count=9")};
  const std::string text = parseProtocol(file, kGood, sc, o).effectiveText();
  EXPECT_EQ(parseProtocol(other, kGood, sc, o).effectiveText(), text);
  EXPECT_NE(text.find("# The protocol as run: " + file + " with"), std::string::npos) << text;
}

TEST_F(Included, AKeyIsGivenOnceAndABadIncludeIsNamedAtItsLine) {
  auto problems = [&](const std::string& text) { return Included::problems("p.toml", text); };
  const std::string p = (dir_ / "p.toml").string();
  write("materials/soft.toml", kMaterial);
  // Given in both: named at the material's line with the protocol's place.
  std::string e = problems("include = [\"materials/soft.toml\"]\n" + std::string(kGood) +
                           "\n[sample]\ncount = 3\n");
  EXPECT_NE(e.find((dir_ / "materials/soft.toml").string() +
                   ":5: sample.count is given again: " + p + ":14 gives it too"),
            std::string::npos)
      << e;
  // A key out of range in the material file: its own file and line.
  write("materials/bad.toml", "[sample]\n\ncount = 1\n");
  e = problems("include = \"materials/bad.toml\"\n" + std::string(kGood));
  EXPECT_NE(e.find((dir_ / "materials/bad.toml").string() +
                   ":3: sample.count = 1 is outside the allowed range [2, 100000000]"),
            std::string::npos)
      << e;
  e = problems("include = \"materials/none.toml\"\n" + std::string(kGood));
  EXPECT_NE(e.find(p + ":1: include: cannot read " + (dir_ / "materials/none.toml").string()),
            std::string::npos)
      << e;
  e = problems("include = 3\n" + std::string(kGood));
  EXPECT_NE(e.find(p + ":1: include expects a file or a list of files"), std::string::npos) << e;
  write("materials/nested.toml", "include = \"soft.toml\"\n");
  e = problems("include = \"materials/nested.toml\"\n" + std::string(kGood));
  EXPECT_NE(e.find("may hold a material's keys only"), std::string::npos) << e;
  write("materials/broken.toml", "[sample\n");
  e = problems("include = \"materials/broken.toml\"\n" + std::string(kGood));
  EXPECT_NE(
      e.find(p + ":1: include: " + (dir_ / "materials/broken.toml").string() + ": not valid TOML"),
      std::string::npos)
      << e;
}

// A variant of a protocol (a quick twin) names it as its base and gives only what differs:
// the base's keys, its includes' and its relative paths as the base reads them.
TEST_F(Included, AVariantGivesOnlyWhatDiffersFromItsBase) {
  const Schema sc = schema();
  const std::string material = write("materials/soft.toml", kMaterial);
  const std::string full =
      write("full.toml", "include = \"materials/soft.toml\"\n" + std::string(kGood) +
                             "[sample]\nfile = \"data/p.txt\"\n");
  std::filesystem::create_directories(dir_ / "quick");
  const std::string text =
      "base = \"../full.toml\"\n[protocol]\nname = \"t-quick\"\n[sample]\ncount = 9\n";
  const std::string file = write("quick/q.toml", text);
  EXPECT_EQ(rigOf(file, text), "oedometer");
  const Settings s = parseProtocol(file, text, sc);
  EXPECT_EQ(s.text("protocol.name"), "t-quick");
  EXPECT_EQ(s.integer("sample.count"), 9);
  EXPECT_DOUBLE_EQ(s.real("numerics.local_damping"), 0.25);
  EXPECT_DOUBLE_EQ(s.real("formation.axial_stress_MPa"), 30.0);
  EXPECT_EQ(s.where("numerics.local_damping"), material + ":2");
  EXPECT_EQ(s.where("formation.axial_stress_MPa"), full + ":8");
  EXPECT_EQ(s.where("sample.count"), file + ":5");
  EXPECT_EQ(std::filesystem::weakly_canonical(s.path("sample.file")), dir_ / "data/p.txt");
  EXPECT_EQ(s.base(), full);
  EXPECT_EQ(s.includes(), std::vector<std::string>{material});
  // Named from its own folder (a path without a folder).
  const auto here = std::filesystem::current_path();
  std::filesystem::current_path(dir_ / "quick");
  EXPECT_EQ(parseProtocol("q.toml", text, sc).integer("sample.count"), 9);
  std::filesystem::current_path(here);
  // The same run as the base with the differences set on the command line (from the base's
  // folder: the identity writes a path as given).
  const std::string beside = "base = \"full.toml\"\n" + text.substr(text.find('\n') + 1);
  EXPECT_EQ(parseProtocol(write("q.toml", beside), beside, sc).identity(),
            parseProtocol(full, readFile(full), sc,
                          {parseOverride("protocol.name=t-quick"), parseOverride("sample.count=9")})
                .identity());
  // The protocol as run stands alone, and the base's edits change it.
  const std::string effective = s.effectiveText();
  EXPECT_EQ(effective.find("base ="), std::string::npos) << effective;
  EXPECT_NE(effective.find(" with base " + full), std::string::npos) << effective;
  expectReadsBack(file, s);
  write("full.toml", "include = \"materials/soft.toml\"\n" + std::string(kGood) +
                         "[sample]\nfile = \"data/q.txt\"\n");
  EXPECT_NE(parseProtocol(file, text, sc).effectiveText(), effective);

  auto problems = [&](const std::string& t) { return Included::problems("quick/q.toml", t); };
  // Within the variant a key is still given once; its base's problems at their own lines.
  EXPECT_NE(
      problems("include = \"../materials/soft.toml\"\n" + text).find("sample.count is given again"),
      std::string::npos);
  write("bad.toml", "[protocol]\nname = \"b\"\nrig = \"oedometer\"\n[sample]\ncount = 1\n");
  std::string e = problems("base = \"../bad.toml\"\n");
  EXPECT_NE(e.find(file + ":1: base: " + (dir_ / "bad.toml").string() +
                   ":5: sample.count = 1 is outside the allowed range"),
            std::string::npos)
      << e;
  e = problems("base = \"../none.toml\"\n");
  EXPECT_NE(e.find(file + ":1: base: " + (dir_ / "none.toml").string() + ": cannot read"),
            std::string::npos)
      << e;
  e = problems("base = 3\n");
  EXPECT_NE(e.find(file + ":1: base expects the file of the protocol this one varies"),
            std::string::npos)
      << e;
  write("a.toml", "base = \"b.toml\"\n");
  write("b.toml", "base = \"a.toml\"\n");
  e = problems("base = \"../a.toml\"\n");
  EXPECT_NE(e.find("a cycle of bases"), std::string::npos) << e;
}

// A section of two fields and a rule across them, as a rig's loading.
struct Ramp {
  double from = 1.0 * kMPa, to = 2.5 * kMPa;  // Pa
  double angle = 0.0;                         // rad
  double grain = 0.6 * kmm;                   // m

  template <class F>
  void fields(F& f) {
    f(from, {"from_MPa", units::MPa, Range::closed(0, 100), "start"});
    f(to, {"to_MPa", units::MPa, Range::closed(0, 100), "end"});
    f(angle, {"angle_deg", units::deg, Range::closed(0, 85), "an angle"});
    f(grain, {"grain_mm", units::mm, Range::leftOpen(0, 10), "a size"});
  }
  void validate() const {
    if (to <= from) throw InvalidParameter("", "to_MPa", "must exceed from_MPa");
  }
};

struct TwoRamps {
  Ramp up;
  Ramp down{3.0 * kMPa, 4.0 * kMPa};  // a second use of the declaration, its own defaults
  template <class F>
  void fields(F& f) {
    f.section("up.", up);
    f.section("down.", down);
  }
};

bool sameBits(double a, double b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

TEST(Declarations, StructsAreReadInSiWithTheLibrarysDefaultsBitForBit) {
  Schema sc;
  declare<TwoRamps>(sc);
  EXPECT_EQ(sc.find("down.from_MPa")->unit.name, "MPa");
  EXPECT_EQ(std::get<double>(*sc.find("down.from_MPa")->fallback), 3.0);  // its own default
  EXPECT_EQ(std::get<double>(*sc.find("up.grain_mm")->fallback), 0.6);
  const Settings s = parseProtocol("p.toml", "[up]\nto_MPa = 7.5\nangle_deg = 30\n", sc);
  const TwoRamps r = read<TwoRamps>(s);
  EXPECT_TRUE(sameBits(r.up.to, 7.5 * kMPa));
  EXPECT_TRUE(sameBits(r.up.angle, 30.0 * std::numbers::pi / 180.0));  // degrees to radians
  const TwoRamps defaults;
  EXPECT_TRUE(sameBits(r.up.from, defaults.up.from));
  EXPECT_TRUE(sameBits(r.up.grain, defaults.up.grain));
  EXPECT_TRUE(sameBits(r.down.from, defaults.down.from));
  EXPECT_TRUE(sameBits(r.down.to, defaults.down.to));
}

TEST(Declarations, ADefaultItsUnitCannotCarryBackExactlyIsRefused) {
  // Dividing by 1e6 and multiplying back is not the identity for every double: find one.
  double v = 0.123456789;
  while (sameBits(units::MPa.toSi(units::MPa.fromSi(v)), v)) v = std::nextafter(v, 1.0);
  Ramp odd;
  odd.from = v;
  Schema sc;
  EXPECT_THROW(declare(sc, odd), std::logic_error);
}

TEST(Declarations, RulesAcrossFieldsNameTheFileLineAndKey) {
  Schema sc;
  declare<TwoRamps>(sc);
  const Settings s = parseProtocol("p.toml", "[down]\nfrom_MPa = 5\nto_MPa = 4\n", sc);
  try {
    read<TwoRamps>(s);
    FAIL() << "no error";
  } catch (const ProtocolError& e) {
    EXPECT_STREQ(e.what(), "p.toml:3: down.to_MPa: must exceed from_MPa");
  }
  // The core checks the same declaration, naming the key with its section and unit.
  TwoRamps bad;
  bad.up.angle = 1.6;  // rad: above 85 degrees
  try {
    checkFields(bad, "ramps");
    FAIL() << "no error";
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.key(), "up.angle_deg");
    EXPECT_EQ(e.unit(), "deg");
    EXPECT_NE(std::string(e.what()).find("ramps: up.angle_deg = 91.6"), std::string::npos)
        << e.what();
  }
  bad = TwoRamps{};
  bad.down.to = bad.down.from;
  try {
    checkFields(bad, "ramps");
    FAIL() << "no error";
  } catch (const InvalidParameter& e) {
    EXPECT_EQ(e.key(), "down.to_MPa");
  }
}

}  // namespace
// A run is known by its settings, not by how its text says them: a comment, a key given at
// its default, a material moved to an included file, the file's path, the threads chosen at
// run time leave its identity as it is; a value changed does not.
TEST_F(Included, TheIdentityIsTheSettingsNotTheirWording) {
  const Schema sc = schema();
  const std::string file = write("p.toml", kGood);
  const std::string base = parseProtocol(file, kGood, sc).identity();
  EXPECT_NE(base.find("formation.axial_stress_MPa = 30"), std::string::npos) << base;
  EXPECT_EQ(base.find("numerics.local_damping"), std::string::npos) << base;  // its default
  const std::string worded = std::string("# a comment\n") + kGood +
                             "\n[numerics]\nlocal_damping = 0.7  # the default, given\n";
  EXPECT_EQ(parseProtocol(write("q.toml", worded), worded, sc).identity(), base);
  write("materials/f.toml", "[formation]\naxial_stress_MPa = 30\n");
  std::string moved = kGood;
  moved.erase(moved.find("axial_stress_MPa = 30\n"), 22);
  moved = "include = \"materials/f.toml\"\n" + moved;
  EXPECT_EQ(parseProtocol(write("r.toml", moved), moved, sc).identity(), base);
  Settings chosen = parseProtocol(file, kGood, sc);  // a run's choice, as --threads is
  chosen.runChoice("numerics.local_damping", 0.5);
  EXPECT_EQ(chosen.identity(), base);
  EXPECT_NE(
      parseProtocol(file, kGood, sc, {parseOverride("formation.axial_stress_MPa=31")}).identity(),
      base);
}

}  // namespace rocklab::protocol
