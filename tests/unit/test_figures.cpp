// Report figures read only what their rig records: each rig's figures are built on a run
// holding every series and result the rig declares (rigs/<rig>/outputs.cpp), and every name
// they ask for must be declared, every parameter a key of the rig. A figure asking for a
// series no rig writes fails here, not silently in a user's report.

#include <gtest/gtest.h>

#include <string>

#include "reports/figures/figures.hpp"
#include "rigs/registry.hpp"

namespace rocklab::reports {
namespace {

// The declared names with each '#' a number (1 or 2); names with a '*' stand for several
// recorded names and are left out.
std::vector<std::string> instances(std::string_view pattern) {
  if (pattern.find('*') != std::string_view::npos) return {};
  std::vector<std::string> out;
  for (const char* n : {"1", "2"}) {
    std::string s(pattern);
    for (std::size_t k = s.find('#'); k != std::string::npos; k = s.find('#')) s.replace(k, 1, n);
    if (out.empty() || out.back() != s) out.push_back(s);
  }
  return out;
}

// A run of `rig` with every declared series and result under every declared prefix, and the
// parameters of a minimal protocol with `overrides`.
RunData syntheticRun(const rigs::RigEntry& rig, const protocol::Schema& schema,
                     const std::vector<std::pair<std::string, std::string>>& overrides) {
  RunData r;
  r.id = 1;
  r.rig = std::string(rig.name);
  r.protocol = "synthetic";
  const rigs::Outputs& o = rig.outputs();
  double value = 1.0;
  for (const std::string& p : o.prefixes()) {
    for (const std::string& prefix : instances(p)) {
      for (const rigs::OutputDecl& d : o.of(rigs::OutputKind::Series)) {
        for (const std::string& base : instances(d.name)) {
          SeriesData& s = r.series[prefix + base];
          for (int k = 0; k < 10; ++k) {
            s.step.push_back(100 * k);
            s.value.push_back(0.1 * k * value);
          }
        }
      }
      for (const rigs::OutputDecl& d : o.of(rigs::OutputKind::Result)) {
        for (const std::string& base : instances(d.name)) r.results[prefix + base] = {value, "-"};
      }
      value += 1.0;  // tests of a sweep at distinct confinements
    }
  }
  std::string text = "[protocol]\nname = \"t\"\nrig = \"" + r.rig + "\"\n[sample]\ncount = 10\n";
  if (r.rig == "ultrasonic") text += "[wave]\nfrequency_kHz = 100\n";
  protocol::Settings s = protocol::parseProtocol("synthetic.toml", text, schema);
  for (const auto& [key, v] : overrides) s.apply({{key, v}});
  for (const auto& row : s.table()) r.params.emplace_back(row.key, row.value, row.unit);
  return r;
}

void checkReads(const rigs::RigEntry& rig, const protocol::Schema& schema, const Reads& reads,
                const std::string& variant) {
  const rigs::Outputs& o = rig.outputs();
  for (const std::string& name : reads.series) {
    EXPECT_TRUE(o.declares(rigs::OutputKind::Series, name))
        << rig.name << " figures" << variant << " read the series '" << name
        << "', which the rig does not record";
  }
  for (const std::string& name : reads.results) {
    EXPECT_TRUE(o.declares(rigs::OutputKind::Result, name))
        << rig.name << " figures" << variant << " read the result '" << name << "'";
  }
  for (const std::string& key : reads.params) {
    EXPECT_NE(schema.find(key), nullptr)
        << rig.name << " figures" << variant << " read the parameter '" << key << "'";
  }
}

TEST(Figures, ReadOnlyWhatTheirRigRecords) {
  const Paper paper = loadPaper(ROCKLAB_SOURCE_DIR "/data/paper.toml");
  for (const FigureEntry& entry : figureTable()) {
    const rigs::RigEntry& rig = rigs::findRig(entry.rig, "figure table");
    const protocol::Schema schema = rigs::schemaOf(rig);
    // With the defaults, then with each value of the choices the figures branch on.
    Reads first;
    RunData r = syntheticRun(rig, schema, {});
    r.reads = &first;
    EXPECT_FALSE(entry.build({&r}, paper).empty()) << entry.rig << ": no figure from a full run";
    checkReads(rig, schema, first, "");
    for (const std::string& key : first.params) {
      const protocol::ParamDecl* d = schema.find(key);
      if (!d) continue;
      std::vector<std::string> values = d->choices;
      if (key == "protocol.dimension") values = {"2", "3"};
      for (const std::string& v : values) {
        Reads reads;
        RunData variant = syntheticRun(rig, schema, {{key, v}});
        variant.reads = &reads;
        entry.build({&variant}, paper);
        checkReads(rig, schema, reads, " with " + key + " = " + v);
      }
    }
  }
}

}  // namespace
}  // namespace rocklab::reports
