#pragma once
// A campaign: one protocol run at several seeds and at the points of sweeps over any of its
// keys (lab/campaign/README.md). The file is TOML, checked like a protocol: every problem
// with its file:line. Each point x seed is a task, run as its own process (a local pool or a
// Slurm job array) into its own notebook shard, merged into the lab when it ends.

#include <cstdint>
#include <string>
#include <vector>

#include "lab/protocol/params.hpp"

namespace rocklab::campaign {

// How sweeps over several keys make points: every combination of their values (the first
// key varying slowest), or their k-th values together (the lists of one length).
enum class Combine { Product, Zip };

// What `--scheduler slurm` passes to sbatch.
struct SlurmOptions {
  std::string partition, time, account;
  int cpus_per_task = 0;             // 0: the runs' threads
  std::vector<std::string> options;  // passed through as they are (e.g. "--mem=2G")
};

struct Point {
  int index = 0;
  std::vector<protocol::Override> settings;  // the sweeps' values of this point
  std::string label() const;                 // "loading.confining_stress_MPa=5" or "base"
};

// What the paper says of a result the campaign measures (a [[paper]] table): the catalogue
// (`rocklab campaign catalogue`) sets each point's ensemble beside it.
struct PaperClaim {
  std::string result;  // a key result of the protocol's rig ("band_angle_deg", "stage1.vp_z")
  std::string number;  // the paper's number: a [[number]] key of data/paper.toml, or empty
  std::string says;    // what the paper says, where it gives no number
  // The fraction of seeds whose result is in [low, high], where the paper's claim is about
  // each sample ("a band nearly normal to sigma_1"), not about the mean.
  bool fraction = false;
  double low = 0.0, high = 0.0;
  // The points the claim is about, by some of their swept values (`point = {KEY = VALUE}`):
  // one sample of Figure 14 loaded along the flow, the other across it. Empty: every point.
  std::vector<protocol::Override> point;
  std::string at;  // file:line of the table, for the catalogue's problems
  bool concerns(const Point& p) const;
};

struct Task {
  int index = 0;  // its number in the campaign (the Slurm array index)
  int point = 0;
  std::int64_t seed = 0;
};

struct Campaign {
  std::string file;      // the campaign file, as given
  std::string text;      // its text
  std::string name;      // campaign.name
  std::string protocol;  // the protocol's path, resolved against the campaign file's folder
  std::vector<std::int64_t> seeds;
  int threads = 1;                        // each run's numerics.threads
  std::vector<protocol::Override> fixed;  // [set]: keys every run takes
  std::vector<Point> points;
  SlurmOptions slurm;
  std::vector<PaperClaim> paper;

  // Every point x seed, the point varying slowest.
  std::vector<Task> tasks() const;
  // A task's overrides of its protocol: the fixed keys, its point's, its seed. Each is
  // named "campaign NAME" in the run's effective protocol (so that its hash, which tells a
  // task already done, does not change when the campaign file gains a line), or by its
  // file:line for the problems `campaign check` reports.
  std::vector<protocol::Override> overrides(const Task& t, bool with_lines = false) const;
};

// Reads a campaign file; throws protocol::ProtocolError with every problem (file:line) in it.
// The seeds are `campaign.seeds`: a list, or a count N (the protocol's seed and the N - 1
// after it, so that its single run is one of them).
Campaign readCampaign(const std::string& path);

}  // namespace rocklab::campaign
