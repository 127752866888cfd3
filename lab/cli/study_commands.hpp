#pragma once
// `rocklab study accuracy`: a protocol over a ladder of numerical settings, and what its key
// results lose against the time saved.

#include <cstdint>
#include <string>
#include <vector>

namespace rocklab::cli {

struct StudyOptions {
  std::string protocol;
  std::vector<std::string> vary;  // "KEY=v1,v2,...", the finest value first
  std::vector<std::string> sets;  // "KEY=VALUE" from --set, for every setting
  std::string lab = "lab.sqlite";
  std::string out;
  double tolerance_percent = 5.0;
  int seeds = 1;    // runs per setting: the protocol's seed and the ones after it
  int threads = 0;  // 0: as the protocol says
  bool quiet = false;
  bool dry_run = false;  // check every setting and list them, run nothing
};
// Exit code: 0 done (failed runs are marked in the report), 2 invalid input (nothing run),
// 130 interrupted.
int studyAccuracy(const StudyOptions& o);

// Writes the report of a study from its runs in the notebook (the first is the finest).
int studyReport(const std::vector<std::int64_t>& runs, const std::string& lab,
                const std::string& out, double tolerance_percent);

}  // namespace rocklab::cli
