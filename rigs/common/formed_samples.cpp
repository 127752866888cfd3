#include "rigs/common/formed_samples.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "lab/core/archive.hpp"
#include "lab/protocol/declare.hpp"

namespace rocklab::rigs {

namespace {

namespace fs = std::filesystem;

constexpr const char* kFormat = "rocklab formed sample 1";

// The keys of the shared sections that act only after the formation, or not on the physics.
bool afterFormation(const std::string& key) {
  static const std::set<std::string> keys = {
      "protocol.name",
      "protocol.description",
      "protocol.key_results",
      "numerics.density_scaling",
      "formation.reuse",
      "output.checkpoint_every_s",
      "grain_bonds.tensile_strength_mean_MPa",
      "grain_bonds.tensile_strength_std_MPa",
      "grain_bonds.shear_strength_mean_MPa",
      "grain_bonds.shear_strength_std_MPa",
  };
  return key.starts_with("bonds.") || keys.count(key) > 0;
}

}  // namespace

std::string formedSamplesDir(const std::string& lab) {
  return fs::absolute(lab).string() + ".formed";
}

std::string formationIdentity(const protocol::Settings& settings) {
  protocol::Schema schema;
  protocol::SchemaBuilder builder(schema);
  SpecimenSettings shared;
  shared.fields(builder);
  std::set<std::string> keys;
  for (const protocol::ParamDecl& d : schema.all()) {
    if (!afterFormation(d.key)) keys.insert(d.key);
  }
  std::string out = "rig = " + settings.text("protocol.rig") + "\n";
  std::istringstream lines(settings.identity());
  for (std::string line; std::getline(lines, line);) {
    if (keys.count(line.substr(0, line.find(" = "))) > 0) out += line + "\n";
  }
  return out;
}

void FormationRecords::replay(Recorder& rec) const {
  for (const Series& s : series) rec.series(s.name, s.step, s.time, s.value);
  for (const Message& m : messages) rec.message(m.step, m.time, m.level, m.text);
}

void FormationCapture::series(std::string_view name, std::uint64_t step, double time,
                              double value) {
  records_.series.push_back({std::string(name), step, time, value});
  inner_.series(name, step, time, value);
}
void FormationCapture::event(const EventRecord& e) {
  complete_ = false;
  inner_.event(e);
}
void FormationCapture::result(std::string_view name, double value, std::string_view unit) {
  complete_ = false;
  inner_.result(name, value, unit);
}
void FormationCapture::message(std::uint64_t step, double time, std::string_view level,
                               std::string_view text) {
  records_.messages.push_back({step, time, std::string(level), std::string(text)});
  inner_.message(step, time, level, text);
}
void FormationCapture::stageTiming(std::string_view stage, double seconds, std::uint64_t calls) {
  complete_ = false;
  inner_.stageTiming(stage, seconds, calls);
}
void FormationCapture::snapshot(std::string_view stage, std::string_view label,
                                const Frame& frame) {
  complete_ = false;
  inner_.snapshot(stage, label, frame);
}
void FormationCapture::wave(const WaveRecord& w) {
  complete_ = false;
  inner_.wave(w);
}

template <int D>
std::string keepFormed(const FormedSamples& store, const Specimen<D>& sp,
                       std::uint64_t densification_steps, std::uint64_t formation_steps,
                       const FormationCapture& capture) {
  const auto& sim = *sp.sim;
  std::vector<double> tensile, cohesion;
  if (sp.grain_kind) {
    if (sim.bondKinds()[*sp.grain_kind].model != BondModel::Parallel) {
      return "the grains' bonds are flat joints, whose strengths cannot be drawn again";
    }
    if (sp.grain_bonds.skipped_nonpositive > 0) {
      return "grain strength draws <= 0 left bonds out (grain_bonds.negative_strength = skip): "
             "another run's draws would name other bonds";
    }
    if (sim.brokenBonds(*sp.grain_kind, BondBreakMode::Tensile) +
            sim.brokenBonds(*sp.grain_kind, BondBreakMode::Shear) >
        0) {
      return "intragranular bonds broke while it formed: it depends on the grains' strengths";
    }
    const auto* peaks = sim.bondPeaks();
    if (!peaks) return "the grain bonds' peak stresses were not kept through the formation";
    tensile = peaks->tensile, cohesion = peaks->cohesion;
  }
  if (!capture.complete()) return "the formation recorded more than its series and messages";
  ArchiveWriter w;
  w("format", std::string(kFormat));
  w("key", store.key);
  const_cast<Specimen<D>&>(sp).journal(w);  // writing reads the specimen only
  w("densification_steps", densification_steps);
  w("formation_steps", formation_steps);
  w("peak_tensile", tensile);
  w("peak_cohesion", cohesion);
  w("records", capture.records());
  std::error_code ec;
  fs::create_directories(store.dir, ec);
  // Named by host and process: tasks on other nodes of a cluster write to the same folder.
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  const std::string tmp =
      store.file() + ".tmp-" + std::string(host) + "-" + std::to_string(getpid());
  {
    std::ofstream out(tmp, std::ios::binary);
    out.write(w.bytes().data(), static_cast<std::streamsize>(w.bytes().size()));
    if (!out.flush()) {
      fs::remove(tmp, ec);
      return "cannot write " + tmp;
    }
  }
  fs::rename(tmp, store.file(), ec);  // whole or not at all, also with runs writing the same
  if (ec) {
    fs::remove(tmp, ec);
    return "cannot write " + store.file();
  }
  return {};
}

template <int D>
std::optional<Specimen<D>> reuseFormed(const FormedSamples& store, const SpecimenSettings& s,
                                       std::string& why) {
  if (!s.formation.enabled) {
    why = "formation.enabled = false: there is no formation to reuse";
    return std::nullopt;
  }
  std::ifstream in(store.file(), std::ios::binary);
  if (!in) {
    why = "no sample of this formation in " + store.dir + " yet: this run forms it";
    return std::nullopt;
  }
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  Specimen<D> sp;
  FormedOrigin origin;
  std::vector<double> tensile, cohesion;
  try {
    ArchiveReader r(bytes.data(), bytes.size());
    std::string format, key;
    r("format", format);
    r("key", key);
    if (format != kFormat || key != store.key) {
      why = store.file() + " is not this formation's sample: it forms anew";
      return std::nullopt;
    }
    sp.journal(r);
    r("densification_steps", origin.densification_steps);
    r("formation_steps", origin.formation_steps);
    r("peak_tensile", tensile);
    r("peak_cohesion", cohesion);
    r("records", origin.records);
    if (!r.atEnd()) throw CheckpointError("it goes on past its last field");
  } catch (const std::exception& e) {  // a damaged file may also fail to allocate
    why = store.file() + " cannot be read (" + e.what() + "): this run forms it anew";
    return std::nullopt;
  }
  sp.settings = s;
  auto& sim = *sp.sim;
  sim.setThreads(s.simulation.threads);  // the run's, not the forming run's
  // The stream as the run's own build left it: its grain strengths drawn in bond order.
  sim.rng().reseed(bondStream(s));
  if (sp.grain_kind) {
    BondKind k = s.grain_bonds;
    k.name = "grain";
    k.intragranular = true;
    const std::optional<std::size_t> redrawn = sim.redrawStrengths(*sp.grain_kind, k);
    if (!redrawn) {
      why = "a grain strength drawn <= 0 would leave a bond out of this run's grains";
      return std::nullopt;
    }
    sp.grain_bonds.redrawn = *redrawn;
    const BondStore<D>& B = sim.bonds();
    if (tensile.size() != B.size() || cohesion.size() != B.size()) {
      why = store.file() + " holds no peak stress for each bond: this run forms it anew";
      return std::nullopt;
    }
    // Held at every step iff stronger than the peak. A frictional bond's peak is its shear
    // stress less its strength's frictional part as the pass rounded c + sigma_n tan(phi);
    // the margin, relative to the larger of the stress and the strength, covers that
    // rounding (the frictional part is at most the shear stress the bond carried).
    constexpr double kMargin = 1e-12;
    auto above = [&](double strength, double peak) {
      return strength > peak + kMargin * std::max(std::abs(peak), std::abs(strength));
    };
    for (std::size_t b = 0; b < B.size(); ++b) {
      if (B.kind[b] != *sp.grain_kind) continue;
      const bool holds = above(B.tensile[b], tensile[b]) && above(B.shear[b], cohesion[b]);
      if (!holds) {
        why = "grain bond " + std::to_string(b) +
              " of this run is weaker than a stress it carried while the sample formed: its "
              "formation would differ, so it forms anew";
        return std::nullopt;
      }
    }
  }
  origin.file = store.file();
  sp.formed_from = std::move(origin);
  sp.formed_note.clear();  // the forming run's
  return sp;
}

#define ROCKLAB_FORMED(D)                                                                     \
  template std::string keepFormed<D>(const FormedSamples&, const Specimen<D>&, std::uint64_t, \
                                     std::uint64_t, const FormationCapture&);                 \
  template std::optional<Specimen<D>> reuseFormed<D>(const FormedSamples&,                    \
                                                     const SpecimenSettings&, std::string&);
ROCKLAB_FORMED(2)
ROCKLAB_FORMED(3)
#undef ROCKLAB_FORMED

}  // namespace rocklab::rigs
