#pragma once
// The rigs a protocol can name: one table row per rig. A rig is a settings struct (its
// protocol keys, declared once: lab/core/fields.hpp), a run function taking it, and its
// outputs (rigs/common/outputs.hpp); the row makes the schema, the checks and the run of its
// protocols from them.

#include <string>
#include <string_view>
#include <vector>

#include "lab/protocol/declare.hpp"
#include "rigs/common/experiment.hpp"
#include "rigs/common/outputs.hpp"

namespace rocklab::rigs {

struct RigEntry {
  std::string_view name;
  std::string_view doc;
  void (*declare)(protocol::Schema&);
  // Reads the settings into the rig's struct, which checks its rules across keys (throws
  // protocol::ProtocolError).
  void (*check)(const protocol::Settings&);
  void (*run)(const protocol::Settings&, Recorder&, RunControl&);
  const Outputs& outputs() const { return *rigOutputs(name); }
};

// A row for a rig whose settings are `S` and whose run is `Run`.
template <class S, void (*Run)(const S&, Recorder&, RunControl&)>
RigEntry rigEntry(std::string_view name, std::string_view doc) {
  return {name, doc, [](protocol::Schema& s) { protocol::declare<S>(s); },
          [](const protocol::Settings& s) { (void)protocol::read<S>(s); },
          [](const protocol::Settings& s, Recorder& rec, RunControl& control) {
            Run(protocol::read<S>(s), rec, control);
          }};
}

const std::vector<RigEntry>& rigTable();
// Throws protocol::ProtocolError listing the rigs when `name` is none of them.
const RigEntry& findRig(std::string_view name, const std::string& file);
// The whole schema of a rig's protocols: the shared sections and the rig's own.
protocol::Schema schemaOf(const RigEntry& rig);
// Reads and checks a protocol file completely (keys, types, ranges, rules across keys, the
// key results it names).
struct CheckedProtocol {
  const RigEntry* rig;
  protocol::Settings settings;
};
// Overrides (`--set KEY=VALUE`) are checked with the file's keys, as if the file gave them.
CheckedProtocol checkProtocol(const std::string& path,
                              const std::vector<protocol::Override>& overrides = {});
// The same for a protocol's text kept elsewhere (the notebook's, for `rocklab rerun`),
// read as if it were the file `path`.
CheckedProtocol checkProtocolText(const std::string& path, const std::string& text,
                                  const std::vector<protocol::Override>& overrides = {});
// The checks across keys again, after values were replaced (a study's settings).
void validateProtocol(const RigEntry& rig, const protocol::Settings& s);
// The keys a protocol gives that its run does not read (the generator's keys of a sample
// read from a file), each as a warning naming where it was given.
std::vector<std::string> unusedKeys(const protocol::Settings& s);

}  // namespace rocklab::rigs
