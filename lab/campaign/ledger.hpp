#pragma once
// What the lab notebook keeps of a campaign (tables campaigns, campaign_points and
// campaign_statistics, lab/notebook/README.md): which run each task made, and each point's
// statistics over its seeds. A task is known by the hash of the protocol it runs (its
// settings, protocol::Settings::identity: the protocol with the point's keys and the seed),
// so a campaign run again finds the tasks already done, whatever became of the campaign
// file, and whatever the protocol file says in other words (a comment, an included file).

#include <cstdint>
#include <string>
#include <vector>

#include "lab/campaign/campaign.hpp"
#include "lab/notebook/notebook.hpp"

namespace rocklab::campaign {

// A task's protocol as its run will keep it (rigs::checkProtocol with its overrides): its
// hash tells the run in the notebook. Throws protocol::ProtocolError.
std::string taskProtocolHash(const Campaign& c, const Task& t);

struct TaskState {
  Task task;
  std::string hash;
  std::int64_t run = 0;  // the lab's run of the task (its completed one if any), 0: none
  std::string status;    // that run's: completed, failed, interrupted, running; "" none
  std::string reason;
};

// Writes (or updates) the campaign's row and returns its id.
std::int64_t registerCampaign(notebook::Notebook& lab, const Campaign& c);
// Every task with the lab's run of it; `hashes` are the tasks' taskProtocolHash.
std::vector<TaskState> survey(notebook::Notebook& lab, const Campaign& c,
                              const std::vector<std::string>& hashes);
// Notes the run a task made (campaign_points).
void recordTask(notebook::Notebook& lab, std::int64_t campaign, const Campaign& c,
                const TaskState& t);
// Every point's statistics over its completed runs (campaign_statistics), anew.
void updateStatistics(notebook::Notebook& lab, std::int64_t campaign, const Campaign& c);

}  // namespace rocklab::campaign
