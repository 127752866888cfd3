#pragma once
// `rocklab campaign report`: a campaign's report from the lab notebook (its tables campaigns,
// campaign_points, campaign_statistics): the tasks and their runs, each point's key results
// over its seeds (n, mean, standard deviation, 95% interval) and each rig's figures with
// the spread across the seeds (reports/ensemble.hpp).

#include <string>

#include "reports/report.hpp"

namespace rocklab::reports {

struct CampaignReportOptions {
  std::string lab = "lab.sqlite";
  std::string campaign;  // its name
  std::string out;
  std::string data_dir;  // holds paper.toml
};

// Writes out/index.html, out/key-results.csv and the figures (PNG + CSV). Throws
// std::invalid_argument when the notebook has no such campaign or it has no completed run.
ReportSummary writeCampaignReport(const CampaignReportOptions& o);

}  // namespace rocklab::reports
