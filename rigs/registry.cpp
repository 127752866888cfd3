#include "rigs/registry.hpp"

#include "rigs/biaxial/biaxial.hpp"
#include "rigs/biaxial/envelope.hpp"
#include "rigs/common/specimen.hpp"
#include "rigs/hydrostatic/hydrostatic.hpp"
#include "rigs/oedometer/oedometer.hpp"
#include "rigs/permeameter/permeameter.hpp"
#include "rigs/ultrasonic/ultrasonic.hpp"

namespace rocklab::rigs {

const std::vector<RigEntry>& rigTable() {
  static const std::vector<RigEntry> table = {
      {"oedometer",
       "uniaxial strain: lateral walls fixed, axial strain rate or stress ramp, cycles, coring",
       oedometer::declare, oedometer::validate, oedometer::run},
      {"biaxial",
       "biaxial frame (2D) / triaxial cell (3D): confinement held by servo walls, axial strain "
       "rate through the peak; zero confinement is the UCS test",
       biaxial::declare, biaxial::validate, biaxial::run},
      {"envelope",
       "failure envelope: one formed sample, a biaxial / triaxial test at each confinement of a "
       "sweep; critical points, Mohr-Coulomb line and end cap",
       envelope::declare, envelope::validate, envelope::run},
      {"hydrostatic", "all walls servo-controlled to one stress, ramped up and optionally down",
       hydrostatic::declare, hydrostatic::validate, hydrostatic::run},
      {"permeameter",
       "permeameter: pore fluid driven through the sample between fixed end pressures, steady "
       "flow every n steps, Darcy permeability under hydrostatic or biaxial / triaxial loading",
       permeameter::declare, permeameter::validate, permeameter::run},
      {"ultrasonic",
       "ultrasonic bench: P and S waves (pz, px, szx, sxy) through copies of a sample at stages "
       "of hydrostatic, uniaxial-strain or triaxial loading; FFT-picked velocities, dynamic "
       "and static moduli",
       ultrasonic::declare, ultrasonic::validate, ultrasonic::run},
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
  declareCommon(s, names);
  rig.declare(s);
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

CheckedProtocol checkProtocol(const std::string& path) {
  const std::string text = protocol::readFile(path);
  const RigEntry& rig = findRig(protocol::rigOf(path, text), path);
  CheckedProtocol c{&rig, protocol::parseProtocol(path, text, schemaOf(rig))};
  validateProtocol(rig, c.settings);
  return c;
}

void validateProtocol(const RigEntry& rig, const protocol::Settings& s) {
  validateCommon(s);
  rig.validate(s);
}

}  // namespace rocklab::rigs
