#pragma once
// `rocklab regress`: the regression guard. A reference file holds a protocol's key results at
// several seeds. A run is as reproducible as its seed, but only to the bit: anything that
// changes the rounding (a reordered sum, another compiler) sends a granular sample down
// another path, and a seed then draws a sample about as different as another seed's. So a
// check holds the mean of its seeds' values to the reference's mean within the sample's
// scatter over both (Student's t, 99.5%), which narrows as more seeds are checked; a key result
// that scatters too much for the seeds a check has is named and not guarded.

#include <cstdint>
#include <string>
#include <vector>

namespace rocklab::cli {

// Compares the key results of the runs at the reference's seeds with the reference file: 0
// within tolerance, 1 not (or a run did not complete), 2 bad input. run 0: every seed of the
// reference that the notebook has a run of the protocol at (its newest at each); else that
// run alone.
int regressCheck(const std::string& reference, const std::string& lab, std::int64_t run);

struct RegressUpdateOptions {
  std::vector<std::string> protocols;
  std::string out = "tests/reference";
  std::string lab = "lab.sqlite";
  int seeds = 0;  // 0: as many as the protocol's reference in `out` has, 8 for a new one
  int threads = 0;
  int jobs = 1;  // runs at once, each a process of its own (1: in this one)
};
// Runs each protocol at `seeds` seeds (its own and the next ones) and writes
// out/<protocol name>.toml. A result that scatters too much to guard at 8 seeds is guarded at
// more: its reference written once at those keeps them when written again.
int regressUpdate(const RegressUpdateOptions& o);

}  // namespace rocklab::cli
