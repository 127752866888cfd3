#include "lab/cli/catalogue_commands.hpp"

#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>

#include "lab/campaign/campaign.hpp"
#include "lab/campaign/statistics.hpp"
#include "lab/cli/lab_commands.hpp"
#include "lab/notebook/notebook.hpp"
#include "reports/html.hpp"
#include "reports/key_results.hpp"
#include "reports/paper.hpp"
#include "reports/run_data.hpp"
#include "rigs/common/outputs.hpp"
#include "rigs/registry.hpp"

namespace rocklab::cli {

namespace fs = std::filesystem;

namespace {

std::string num(double x) {
  return reports::num(x, 4);
}

// For each claim, each point's values of its result, one per completed run of the campaign
// (none when the campaign has not run in the lab). Each run is read once, for every claim.
std::vector<std::vector<std::vector<double>>> valuesByClaim(notebook::Notebook& lab,
                                                            const campaign::Campaign& c) {
  std::vector<std::vector<std::vector<double>>> out(
      c.paper.size(), std::vector<std::vector<double>>(c.points.size()));
  auto id = lab.db().prepare("SELECT id FROM campaigns WHERE name = ?");
  id.bind(1, c.name);
  if (!id.step()) return out;
  auto q = lab.db().prepare(
      "SELECT p.point, p.run_id FROM campaign_points p JOIN runs r ON r.id = p.run_id "
      "WHERE p.campaign_id = ? AND r.status = 'completed' ORDER BY p.point, p.seed");
  q.bind(1, id.integer(0));
  while (q.step()) {
    const auto point = static_cast<std::size_t>(q.integer(0));
    if (point >= c.points.size()) continue;
    const reports::RunData run = reports::loadRun(lab, q.integer(1));
    for (std::size_t k = 0; k < c.paper.size(); ++k) {
      if (const auto v = reports::evaluateKeyResult(run, c.paper[k].result)) {
        out[k][point].push_back(*v);
      }
    }
  }
  return out;
}

// The ensemble's cell and the verdict against the paper's number, a claim about the mean.
std::pair<std::string, std::string> meanCells(const std::vector<double>& v,
                                              const reports::PaperNumber* paper) {
  const campaign::Summary s = campaign::summarize(v);
  if (s.n < 2) return {num(s.mean) + " (one seed)", "&ndash;"};
  const double half = 0.5 * (s.high - s.low);
  const std::string cell = num(s.mean) + " &plusmn; " + num(half);
  if (!paper) return {cell, "&ndash;"};
  if (paper->value >= s.low && paper->value <= s.high) return {cell, "inside the interval"};
  std::ostringstream o;
  o << "outside: " << (s.mean > paper->value ? "+" : "") << num(s.mean - paper->value) << " ("
    << num(std::abs(s.mean - paper->value) / half) << " half-widths)";
  return {cell, o.str()};
}

// The fraction of seeds inside [low, high]: a claim about each sample.
std::pair<std::string, std::string> fractionCells(const std::vector<double>& v,
                                                  const campaign::PaperClaim& claim) {
  const campaign::Summary s = campaign::summarize(v);
  std::size_t k = 0;
  for (double x : v) k += x >= claim.low && x <= claim.high;
  const campaign::Proportion p = campaign::proportion(k, v.size());
  std::ostringstream cell, verdict;
  cell << num(s.mean);
  if (s.n >= 2) cell << " &plusmn; " << num(0.5 * (s.high - s.low));
  verdict << k << " of " << v.size() << " seeds in [" << num(claim.low) << ", " << num(claim.high)
          << "]: " << num(p.fraction) << ", 95% CI [" << num(p.low) << ", " << num(p.high) << "]";
  return {cell.str(), verdict.str()};
}

std::string escaped(std::string s) {
  for (std::size_t k = 0; (k = s.find('|', k)) != std::string::npos; k += 2) s.replace(k, 1, "\\|");
  return s;
}

}  // namespace

int campaignCatalogue(const CatalogueOptions& o) {
  std::vector<campaign::Campaign> campaigns;
  std::vector<std::string> problems;
  const reports::Paper paper = reports::loadPaper(o.data_dir + "/paper.toml");
  for (const std::string& f : o.files) {
    try {
      campaigns.push_back(campaign::readCampaign(f));
    } catch (const protocol::ProtocolError& e) {
      for (const auto& p : e.problems()) problems.push_back(p);
      continue;
    }
    for (const campaign::PaperClaim& c : campaigns.back().paper) {
      if (!c.number.empty() && !paper.byKey(c.number)) {
        problems.push_back(c.at + ": paper.number = \"" + c.number + "\" is not a [[number]] of " +
                           o.data_dir + "/paper.toml");
      }
    }
  }
  if (!problems.empty()) {
    for (const auto& p : problems) std::cerr << p << "\n";
    return 2;
  }
  if (!fs::exists(o.lab)) {
    std::cerr << "no lab notebook at '" << o.lab << "'\n";
    return 2;
  }
  notebook::Notebook lab(o.lab);
  std::ostringstream md;
  md << "| experiment | result | the paper | ensemble: mean &plusmn; 95% CI | n | against the "
        "paper |\n|---|---|---|---|---|---|\n";
  for (const campaign::Campaign& c : campaigns) {
    const std::string rig(rigs::checkProtocol(c.protocol, c.fixed).rig->name);
    const rigs::Outputs* outputs = rigs::rigOutputs(rig);
    const auto values = valuesByClaim(lab, c);
    for (std::size_t k = 0; k < c.paper.size(); ++k) {
      const campaign::PaperClaim& claim = c.paper[k];
      const reports::PaperNumber* number =
          claim.number.empty() ? nullptr : paper.byKey(claim.number);
      const auto* decl = outputs ? outputs->keyResult(claim.result) : nullptr;
      std::string unit;
      if (decl && decl->unit != "-") unit.append(" ").append(decl->unit);
      std::ostringstream said;
      if (number) said << num(number->value) << unit << " (" << number->source << ")";
      if (number && !claim.says.empty()) said << ": ";
      said << claim.says;
      for (const campaign::Point& point : c.points) {
        if (!claim.concerns(point)) continue;
        const auto& v = values[k][static_cast<std::size_t>(point.index)];
        md << "| `" << c.name << "`";
        if (c.points.size() > 1) md << " " << point.label();
        md << " | `" << claim.result << "`" << unit << " | " << escaped(said.str()) << " | ";
        if (v.empty()) {
          md << "not run | 0 | &ndash; |\n";
          continue;
        }
        const auto [cell, verdict] =
            claim.fraction ? fractionCells(v, claim) : meanCells(v, number);
        md << cell << " | " << v.size() << " | " << verdict << " |\n";
      }
    }
  }
  if (o.out.empty()) {
    std::cout << md.str();
    return 0;
  }
  // Written whole or not at all: a catalogue cut short would pass for a finished one.
  writeWhole(o.out, md.str());
  std::cout << "wrote " << o.out << "\n";
  return 0;
}

}  // namespace rocklab::cli
