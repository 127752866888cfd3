#pragma once
// Runs of one notebook copied into another (`rocklab notebook merge`, and the campaigns'
// shards collected into the lab): every row a run has in any table, and its files, under
// new ids, with where it came from kept in `run_origins`. A run is known by its uuid, so a
// merge done twice copies nothing the second time.

#include <cstdint>
#include <string>
#include <vector>

#include "lab/notebook/notebook.hpp"

namespace rocklab::notebook {

// Where the runs of a merged notebook were made (kept in run_origins beside the notebook's
// path): "local" or "slurm", the scheduler's job and task ids ("" and -1 when none).
struct Provenance {
  std::string scheduler = "local";
  std::string job_id;
  std::int64_t task_id = -1;
};

struct MergeOutcome {
  std::vector<std::int64_t> runs;         // the new ids, in the order of the source's ids
  std::size_t already = 0;                // runs the target had already (the same uuid)
  std::vector<std::int64_t> source_runs;  // the source ids of `runs`
};

// Copies every run of the notebook at `source` into `into` in one transaction; the files
// are copied before it commits and removed again if it fails. A run still running in the
// source is refused. The source is first brought up to this rocklab's schema (as opening
// it with rocklab would), then only read.
MergeOutcome mergeNotebook(Notebook& into, const std::string& source, const Provenance& origin);

// What a notebook is on disk besides its file's name: its journal and its runs' files.
inline constexpr const char* kNotebookParts[] = {"", "-wal", "-shm", ".files"};
// Removes a (closed) notebook and its files, as a merged shard is.
void removeNotebook(const std::string& path);

}  // namespace rocklab::notebook
