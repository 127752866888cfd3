#pragma once
// `rocklab campaign catalogue`: the paper's experiments as ensembles beside the paper's numbers.
// Each campaign file's [[paper]] claims (lab/campaign/campaign.hpp) set against what the lab's
// runs of that campaign gave, as one Markdown table: the mean with its 95% interval over the
// seeds, or the fraction of seeds that showed what the paper saw, with its interval.

#include <string>
#include <vector>

namespace rocklab::cli {

struct CatalogueOptions {
  std::vector<std::string> files;  // campaign files
  std::string lab = "lab.sqlite";
  std::string out;       // the Markdown file ("" for standard output)
  std::string data_dir;  // the folder holding paper.toml
};

// 0 when written (campaigns not run yet appear as such), 2 on a bad campaign file.
int campaignCatalogue(const CatalogueOptions& o);

}  // namespace rocklab::cli
