#pragma once
// The lab commands: run and check protocols, list a rig's keys, query the notebook.

#include <cstdint>
#include <string>
#include <vector>

namespace rocklab::cli {

struct RunOptions {
  std::string protocol;
  std::string lab = "lab.sqlite";
  bool quiet = false;
  int threads = 0;  // 0: as the protocol says
};

// Returns the process exit code: 0 completed, 1 failed, 2 invalid protocol, 130 interrupted.
int runProtocol(const RunOptions& o);
int checkProtocol(const std::string& path);
int listKeys(const std::string& rig);

struct NotebookOptions {
  std::string lab = "lab.sqlite";
  bool csv = false;
  std::string what;  // runs, show, series, events, sql
  std::int64_t run = 0;
  std::vector<std::string> names;  // series names
  std::string kind;                // event kind
  std::string sql;
};
int notebookCommand(const NotebookOptions& o);

}  // namespace rocklab::cli
