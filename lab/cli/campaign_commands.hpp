#pragma once
// `rocklab campaign`: a protocol over seeds and sweeps (lab/campaign/campaign.hpp), each
// point x seed a task run as its own process into its own notebook shard, on a local pool
// or as a Slurm job array, the shards merged into the lab. And `rocklab notebook merge`.

#include <string>
#include <vector>

namespace rocklab::cli {

struct CampaignOptions {
  std::string file;
  std::string lab = "lab.sqlite";
  int jobs = 0;  // local pool: tasks at once (0: the cores over each run's threads)
  bool quiet = false;
  bool rerun_failed = false;
  std::string scheduler = "local";  // or "slurm"
  bool wait = false;                // slurm: wait for the tasks and collect them here
  int task = -1;                    // `campaign task`: which one
  std::string shard_dir;            // `campaign task`: where its shard goes
  std::string scratch;              // `campaign task`: local storage to run in, if any
  std::string out;                  // `campaign report`: its folder
  std::string data_dir;             // `campaign report`: the folder holding paper.toml
};

int campaignCheck(const CampaignOptions& o);
// Runs what is not done yet; 0 when every task has completed.
int campaignRun(const CampaignOptions& o);
// One task into its shard (what the pool's processes and the Slurm array's tasks run).
int campaignTask(const CampaignOptions& o);
// Merges the campaign's shards into the lab and updates its statistics.
int campaignCollect(const CampaignOptions& o);
int campaignShow(const CampaignOptions& o);
// The campaign's report (reports/campaign_report.hpp) from the lab.
int campaignReport(const CampaignOptions& o);
// Merges the runs of each `sources` notebook into `into` (twice is the same as once).
int notebookMerge(const std::string& into, const std::vector<std::string>& sources);

}  // namespace rocklab::cli
