#pragma once
// The lab commands: run and check protocols, list a rig's keys, query the notebook.

#include <cstdint>
#include <string>
#include <vector>

#include "rigs/registry.hpp"

namespace rocklab::cli {

struct RunOptions {
  std::string protocol;
  std::string lab = "lab.sqlite";
  bool quiet = false;
  int threads = 0;                // 0: as the protocol says
  std::vector<std::string> sets;  // "KEY=VALUE" from --set, in order
  std::string formed_dir;         // formed samples (formation.reuse); empty: beside the lab
};

// Returns the process exit code: 0 completed, 1 failed, 2 invalid protocol, 130 interrupted.
int runProtocol(const RunOptions& o);
int checkProtocol(const std::string& path, const std::vector<std::string>& sets,
                  bool print = false);
// `rocklab rerun`: a run of the notebook run again from its effective protocol text alone,
// into the same notebook as a new run.
int rerunProtocol(std::int64_t run, const RunOptions& o);
// `rocklab resume`: a run that was killed, interrupted or failed continued from its last
// checkpoint in the same notebook row, to the state an uninterrupted run ends in.
int resumeRun(std::int64_t run, const RunOptions& o);
// The --set arguments as overrides; throws protocol::ProtocolError for one without '='.
std::vector<protocol::Override> overridesOf(const std::vector<std::string>& sets);

// Writes a file whole or not at all (a rename over the old one); throws when it cannot.
void writeWhole(const std::string& path, const std::string& text);

struct RunOutcome {
  int code = 0;  // as runProtocol's
  std::int64_t run = 0;
};
// Runs checked settings into the notebook `lab` as one run, or (resume_run > 0) continues
// that run of the notebook from its last checkpoint.
// Formed samples (formation.reuse) are kept in `formed_dir`, by default beside `lab`
// (rigs::formedSamplesDir).
RunOutcome runSettings(const rigs::RigEntry& rig, const protocol::Settings& settings,
                       const std::string& protocol_file, const std::string& lab, bool quiet,
                       std::int64_t resume_run = 0, const std::string& formed_dir = {});
int listKeys(const std::string& rig);

struct NotebookOptions {
  std::string lab = "lab.sqlite";
  bool csv = false;
  std::string what;  // runs, show, series, events, sql, delete
  std::int64_t run = 0;
  std::vector<std::int64_t> runs;  // delete
  bool yes = false;                // delete: confirmed
  std::vector<std::string> names;  // series names
  std::string kind;                // event kind
  std::string sql;
};
int notebookCommand(const NotebookOptions& o);

}  // namespace rocklab::cli
