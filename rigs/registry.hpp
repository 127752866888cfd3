#pragma once
// The rigs a protocol can name: one table row per rig. A row declares the rig's own
// protocol keys, checks them across keys, and runs the protocol.

#include <string>
#include <string_view>
#include <vector>

#include "lab/protocol/params.hpp"
#include "rigs/common/experiment.hpp"

namespace rocklab::rigs {

struct RigEntry {
  std::string_view name;
  std::string_view doc;
  void (*declare)(protocol::Schema&);
  void (*validate)(const protocol::Settings&);
  void (*run)(const protocol::Settings&, Recorder&, RunControl&);
};

const std::vector<RigEntry>& rigTable();
// Throws protocol::ProtocolError listing the rigs when `name` is none of them.
const RigEntry& findRig(std::string_view name, const std::string& file);
// The whole schema of a rig's protocols: the shared sections and the rig's own.
protocol::Schema schemaOf(const RigEntry& rig);
// Reads and checks a protocol file completely (keys, types, ranges, cross-key rules).
struct CheckedProtocol {
  const RigEntry* rig;
  protocol::Settings settings;
};
CheckedProtocol checkProtocol(const std::string& path);
// The checks across keys again, after values were replaced (a study's settings).
void validateProtocol(const RigEntry& rig, const protocol::Settings& s);

}  // namespace rocklab::rigs
