#include "rigs/registry.hpp"

#include "rigs/biaxial/biaxial.hpp"
#include "rigs/biaxial/envelope.hpp"
#include "rigs/hydrostatic/hydrostatic.hpp"
#include "rigs/oedometer/oedometer.hpp"
#include "rigs/permeameter/permeameter.hpp"
#include "rigs/tensile/brazilian.hpp"
#include "rigs/tensile/direct.hpp"
#include "rigs/ucs/ucs.hpp"
#include "rigs/ultrasonic/ultrasonic.hpp"

namespace rocklab::rigs {

const std::vector<RigEntry>& rigTable() {
  static const std::vector<RigEntry> table = {
      rigEntry<oedometer::Settings, oedometer::run>(
          "oedometer",
          "uniaxial strain: lateral walls fixed, axial strain rate or stress ramp, cycles, "
          "coring"),
      rigEntry<biaxial::Settings, biaxial::run>(
          "biaxial",
          "biaxial frame (2D) / triaxial cell (3D): confinement held by servo walls, axial "
          "strain rate through the peak; zero confinement: the UCS between walls at zero stress"),
      rigEntry<envelope::Settings, envelope::run>(
          "envelope",
          "failure envelope: one formed sample, a biaxial / triaxial test at each confinement "
          "of a sweep; critical points, Mohr-Coulomb line and end cap"),
      rigEntry<hydrostatic::Settings, hydrostatic::run>(
          "hydrostatic", "all walls servo-controlled to one stress, ramped up and optionally down"),
      rigEntry<permeameter::Settings, permeameter::run>(
          "permeameter",
          "permeameter: pore fluid driven through the sample between fixed end pressures, "
          "steady flow every n steps, Darcy permeability under hydrostatic or biaxial / "
          "triaxial loading"),
      rigEntry<ultrasonic::Settings, ultrasonic::run>(
          "ultrasonic",
          "ultrasonic bench: P and S waves (pz, px, szx, sxy) through copies of a sample at "
          "stages of hydrostatic, uniaxial-strain or triaxial loading; FFT-picked velocities, "
          "dynamic and static moduli"),
      rigEntry<brazilian::Settings, brazilian::run>(
          "brazilian",
          "Brazilian test: a disk (2D) or cylinder (3D) cut from the formed, cemented sample, "
          "loaded along its diameter between flat platens; sigma_t = 2 F / (pi D t) and the "
          "fracture"),
      rigEntry<direct_tension::Settings, direct_tension::run>(
          "direct_tension",
          "direct tension: the formed, cemented sample out of its box, its end layers glued to "
          "the platens and pulled apart; tensile strength and modulus in tension"),
      rigEntry<ucs::Settings, ucs::run>(
          "ucs",
          "unconfined compression: the formed, cemented sample (a prism, or a cylinder cut from "
          "it) between platens with free sides; UCS, Young's modulus and Poisson's ratio at half "
          "the peak, crack damage stress"),
  };
  return table;
}

const RigEntry& findRig(std::string_view name, const std::string& file) {
  std::string known;
  for (const RigEntry& r : rigTable()) {
    if (r.name == name) return r;
    known += (known.empty() ? "" : ", ") + std::string(r.name);
  }
  throw protocol::ProtocolError(
      {file + ": protocol.rig = \"" + std::string(name) + "\" is not a rig: one of " + known});
}

protocol::Schema schemaOf(const RigEntry& rig) {
  std::vector<std::string> names;
  for (const RigEntry& r : rigTable()) names.emplace_back(r.name);
  protocol::Schema s;
  rig.declare(s);
  s.setChoices("protocol.rig", names);
  s.setRig(std::string(rig.name));
  for (const RigEntry& other : rigTable()) {
    if (other.name == rig.name) continue;
    protocol::Schema theirs;
    other.declare(theirs);
    for (const protocol::ParamDecl& d : theirs.all()) {
      if (!s.find(d.key)) s.addForeign(d.key, std::string(other.name));
    }
  }
  return s;
}

namespace {

// Every name in protocol.key_results must be one of the rig's key results.
void checkKeyResults(const RigEntry& rig, const protocol::Settings& s) {
  const std::string key = "protocol.key_results";
  std::vector<std::string> problems;
  for (const std::string& name : s.texts(key)) {
    if (rig.outputs().keyResult(name)) continue;
    std::string known;
    for (const OutputDecl& d : rig.outputs().keyResults()) {
      known += (known.empty() ? "" : ", ") + std::string(d.name);
    }
    problems.push_back(s.where(key) + ": " + key + ": '" + name + "' is not a key result of the " +
                       std::string(rig.name) + " rig: one of " + known + " (`rocklab keys " +
                       std::string(rig.name) + "` says what each is)");
  }
  if (!problems.empty()) throw protocol::ProtocolError(problems);
}

}  // namespace

CheckedProtocol checkProtocol(const std::string& path,
                              const std::vector<protocol::Override>& overrides) {
  return checkProtocolText(path, protocol::readFile(path), overrides);
}

CheckedProtocol checkProtocolText(const std::string& path, const std::string& text,
                                  const std::vector<protocol::Override>& overrides) {
  std::string rig_name;
  for (const auto& o : overrides) {
    if (o.key == "protocol.rig") rig_name = o.value;  // the schema depends on it
  }
  if (rig_name.empty()) rig_name = protocol::rigOf(path, text);
  const RigEntry& rig = findRig(rig_name, path);
  CheckedProtocol c{&rig, protocol::parseProtocol(path, text, schemaOf(rig), overrides)};
  validateProtocol(rig, c.settings);
  return c;
}

std::vector<std::string> unusedKeys(const protocol::Settings& s) {
  std::vector<std::string> out;
  const std::string& kind = s.text("sample.kind");
  for (const notebook::ParamRow& row : s.table()) {
    const std::string& key = row.key;
    if (!s.given(key)) continue;
    const bool of_file = key.starts_with("sample.file") || key == "sample.format";
    const bool of_generator = key.starts_with("grains.") || key.starts_with("clumps.") ||
                              (key.starts_with("sample.") && !of_file && key != "sample.kind" &&
                               key != "sample.thickness_m");
    if (kind == "file" && of_generator) {
      out.push_back(s.where(key) + ": " + key +
                    " is not used: the sample is read from sample.file (kind = file)");
    } else if (kind != "file" && of_file) {
      out.push_back(s.where(key) + ": " + key + " is not used: sample.kind is " + kind +
                    ", not file");
    }
  }
  return out;
}

void validateProtocol(const RigEntry& rig, const protocol::Settings& s) {
  rig.check(s);
  checkKeyResults(rig, s);
}

}  // namespace rocklab::rigs
