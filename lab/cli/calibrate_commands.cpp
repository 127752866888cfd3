#include "lab/cli/calibrate_commands.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

#include "lab/calibration/calibration.hpp"
#include "lab/calibration/ledger.hpp"
#include "lab/calibration/material_file.hpp"
#include "lab/calibration/optimizer.hpp"
#include "lab/campaign/toml_text.hpp"
#include "lab/cli/build_info.hpp"
#include "lab/cli/campaign_commands.hpp"
#include "lab/cli/lab_commands.hpp"
#include "reports/calibration_report.hpp"

namespace rocklab::cli {

namespace fs = std::filesystem;
using calibration::Calibration;
using calibration::Evaluation;

namespace {

// Below this chance (as the surrogates see it) that some point inside the bounds meets every
// target, at two batch ends in a row, the targets are out of reach together.
constexpr double kReachProbability = 0.01;

std::string calibrationDir(const std::string& lab, const std::string& name) {
  return fs::absolute(lab).string() + ".calibrations/" + name;
}

std::string quotedKey(const std::string& key) {
  return "\"" + key + "\"";
}

// A batch's campaign for one experiment: its evaluations as the points of a zipped sweep over
// the parameters' keys, at the calibration's seeds (the same for every evaluation: common
// random numbers, so that two points differ by their parameters and not by their samples).
std::string campaignText(const Calibration& c, int experiment, const std::string& name,
                         const std::vector<std::int64_t>& seeds,
                         const std::vector<const Evaluation*>& points) {
  const calibration::Experiment& x = c.experiments.at(static_cast<std::size_t>(experiment));
  std::ostringstream t;
  t << "# Written by `rocklab calibrate " << c.file << "` (calibration " << c.name
    << "): one batch of its evaluations\n# for " << x.protocol
    << ". The calibration writes it again when it goes on; edits are not kept.\n\n";
  t << "[campaign]\nname = \"" << name << "\"\nprotocol = \"" << fs::absolute(x.protocol).string()
    << "\"\nseeds = [";
  for (std::size_t k = 0; k < seeds.size(); ++k) t << (k ? ", " : "") << seeds[k];
  t << "]\ncombine = \"zip\"\nthreads = " << c.threads << "\n\n[set]\n";
  for (const auto& o : x.set) t << quotedKey(o.key) << " = " << o.value << "\n";
  std::vector<std::pair<std::string, std::vector<std::string>>> sweep;
  for (const Evaluation* e : points) {
    const auto overrides = c.overrides(experiment, e->values, "");
    for (std::size_t k = 0; k < overrides.size(); ++k) {
      if (sweep.size() <= k) sweep.push_back({overrides[k].key, {}});
      sweep[k].second.push_back(overrides[k].value);
    }
  }
  if (!sweep.empty()) t << "\n[sweep]\n";
  for (const auto& [key, values] : sweep) {
    t << quotedKey(key) << " = [";
    for (std::size_t k = 0; k < values.size(); ++k) t << (k ? ", " : "") << values[k];
    t << "]\n";
  }
  const std::string slurm = campaign::slurmTableText(c.slurm);
  if (!slurm.empty()) t << "\n" << slurm;
  return t.str();
}

calibration::TargetValue readTarget(notebook::Notebook& lab, const std::string& campaign, int point,
                                    const std::string& result) {
  auto q = lab.db().prepare(
      "SELECT s.n, s.mean, s.std, s.ci95_low, s.ci95_high FROM campaign_statistics s JOIN "
      "campaigns c ON c.id = s.campaign_id WHERE c.name = ? AND s.point = ? AND s.name = ?");
  q.bind(1, campaign).bind(2, point).bind(3, result);
  calibration::TargetValue v;
  if (!q.step()) return v;
  auto real = [&](int col) { return q.isNull(col) ? calibration::kNaN : q.real(col); };
  v = {q.integer(0), real(1), real(2), real(3), real(4)};
  return v;
}

// x to `digits` significant digits: a fitted strength times its standard deviation's factor
// written 33.26, not 33.260000000000005.
double roundedTo(double x, int digits) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*g", digits, x);
  return std::strtod(buf, nullptr);
}

std::string valueText(double v, int precision = 4) {
  if (!std::isfinite(v)) return "-";
  std::ostringstream s;
  s << std::setprecision(precision) << v;
  return s.str();
}

std::string meanText(const calibration::TargetValue& v, const std::string& unit) {
  if (v.n == 0) return "no completed run";
  std::string s = valueText(v.mean);
  if (std::isfinite(v.high)) s += " +- " + valueText((v.high - v.low) / 2.0, 2);
  return s + " " + unit + " (n " + std::to_string(v.n) + ")";
}

class Driver {
 public:
  Driver(const CalibrateOptions& o, const Calibration& c, notebook::Notebook& lab)
      : o_(o), c_(c), lab_(lab), ledger_(lab, c), dir_(calibrationDir(o.lab, c.name)) {}

  int run();

 private:
  // Runs a batch's (or the check's) campaigns and records its evaluations; false when
  // interrupted.
  bool evaluate(std::vector<Evaluation>& batch, bool check);
  std::vector<std::vector<double>> nextBatch(const std::vector<Evaluation>& all, int batch,
                                             std::vector<std::string>& kinds) const;
  bool outOfReach(const std::vector<Evaluation>& all, calibration::Reach& reach) const;
  void print(const Evaluation& e) const;
  std::string material(const std::vector<Evaluation>& all, int best) const;

  const CalibrateOptions& o_;
  const Calibration& c_;
  notebook::Notebook& lab_;
  calibration::Ledger ledger_;
  std::string dir_;
};

void Driver::print(const Evaluation& e) const {
  std::ostringstream s;
  s << "  " << (e.kind == "check" ? "check" : "e" + std::to_string(e.index)) << ":";
  for (std::size_t k = 0; k < c_.parameters.size(); ++k) {
    s << " " << c_.parameters[k].name << "=" << valueText(e.values[k]);
  }
  s << " ->";
  for (std::size_t t = 0; t < c_.targets.size(); ++t) {
    s << " " << c_.targets[t].name << " " << meanText(e.targets[t], c_.targets[t].unit);
  }
  if (e.status == "evaluated") {
    s << "; misfit " << valueText(e.misfit, 3) << (e.within ? ", within tolerance" : "");
  } else {
    s << "; " << e.status;
  }
  std::cerr << s.str() << "\n";
}

bool Driver::evaluate(std::vector<Evaluation>& batch, bool check) {
  const int b = batch.front().batch;
  std::vector<const Evaluation*> points;
  for (const Evaluation& e : batch) points.push_back(&e);
  for (std::size_t x = 0; x < c_.experiments.size(); ++x) {
    const int e = static_cast<int>(x);
    const std::string name =
        check ? calibration::checkCampaignName(c_, e) : calibration::batchCampaignName(c_, b, e);
    const std::string file = dir_ + "/" + name + ".toml";
    writeWhole(file, campaignText(c_, e, name,
                                  check ? c_.experiments[x].check_seeds : c_.experiments[x].seeds,
                                  points));
    CampaignOptions co;
    co.file = file;
    co.lab = o_.lab;
    co.jobs = o_.jobs;
    co.quiet = o_.quiet;
    co.scheduler = o_.scheduler;
    co.wait = true;
    // A batch's runs that did not complete were killed or interrupted with the calibration
    // (or failed, and fail again the same way: a seed's run is deterministic).
    co.rerun_failed = true;
    const int code = campaignRun(co);
    if (code == 130) return false;
    if (code == 2) throw std::runtime_error("the batch's campaign " + file + " is not valid");
  }
  for (std::size_t k = 0; k < batch.size(); ++k) {
    Evaluation& e = batch[k];
    bool all = true;
    for (std::size_t t = 0; t < c_.targets.size(); ++t) {
      const calibration::Target& target = c_.targets[t];
      const std::string name = check ? calibration::checkCampaignName(c_, target.experiment)
                                     : calibration::batchCampaignName(c_, b, target.experiment);
      // A batch with no key of an experiment has one point there, shared by its evaluations.
      const bool swept = !c_.overrides(target.experiment, e.values, "").empty();
      e.targets[t] = readTarget(lab_, name, swept ? static_cast<int>(k) : 0, target.result);
      all = all && e.targets[t].n > 0;
    }
    e.status = all ? "evaluated" : "failed";
    if (all) {
      const std::vector<double> err = calibration::errors(c_, e);
      e.misfit = calibration::misfit(err);
      e.within = calibration::withinTolerance(err);
    }
    ledger_.record(e);
    print(e);
  }
  return true;
}

std::vector<std::vector<double>> Driver::nextBatch(const std::vector<Evaluation>& all, int batch,
                                                   std::vector<std::string>& kinds) const {
  int used = 0;
  for (const Evaluation& e : all) used += e.counts();
  const int left = c_.budget - used;
  const auto start = c_.start();
  const std::size_t d = c_.parameters.size();
  std::vector<std::vector<double>> out;
  if (c_.optimizer == calibration::Optimizer::LatinHypercube) {
    // The whole budget as one design (the start first), run batch by batch in its order.
    const int n = c_.budget - (start ? 1 : 0);
    std::vector<std::vector<double>> design;
    if (start) design.push_back(*start);
    for (const auto& u : calibration::latinHypercube(n, d, c_.seed)) design.push_back(c_.values(u));
    for (int k = used; k < std::min<int>(used + c_.batch, static_cast<int>(design.size())); ++k) {
      out.push_back(design[static_cast<std::size_t>(k)]);
    }
    kinds.assign(out.size(), "latin_hypercube");
    if (used == 0 && start) kinds.front() = "start";
    return out;
  }
  if (used == 0) {
    // The first batch: the start and a Latin hypercube around the box.
    if (start) out.push_back(*start);
    const int n = c_.designSize() - static_cast<int>(out.size());
    for (const auto& u : calibration::latinHypercube(n, d, c_.seed)) out.push_back(c_.values(u));
    kinds.assign(out.size(), "design");
    if (start) kinds.front() = "start";
    return out;
  }
  const auto done = calibration::evaluatedPoints(c_, all);
  if (done.size() < 2) {
    // Too few to model (the design's runs failed): more of the box.
    for (const auto& u : calibration::latinHypercube(std::min(c_.batch, left), d,
                                                     c_.seed + static_cast<std::uint64_t>(batch))) {
      out.push_back(c_.values(u));
    }
    kinds.assign(out.size(), "design");
    return out;
  }
  for (const auto& u :
       calibration::proposeBatch(done, std::min(c_.batch, left),
                                 c_.seed * 1000003u + static_cast<std::uint64_t>(batch))) {
    out.push_back(c_.values(u));
  }
  kinds.assign(out.size(), "bayesian");
  return out;
}

bool Driver::outOfReach(const std::vector<Evaluation>& all, calibration::Reach& reach) const {
  if (c_.optimizer != calibration::Optimizer::Bayesian) return false;
  const auto done = calibration::evaluatedPoints(c_, all);
  if (static_cast<int>(done.size()) <= c_.designSize()) return false;
  // Now, and at the end of the batch before (the last batch's evaluations left out).
  int last = 0;
  for (const Evaluation& e : all) last = std::max(last, e.batch);
  std::vector<Evaluation> before;
  for (const Evaluation& e : all) {
    if (e.batch < last) before.push_back(e);
  }
  const auto earlier = calibration::evaluatedPoints(c_, before);
  reach = calibration::assessReach(calibration::Surrogate(done), done);
  if (reach.probability >= kReachProbability) return false;
  if (static_cast<int>(earlier.size()) < c_.designSize()) return false;
  return calibration::assessReach(calibration::Surrogate(earlier), earlier).probability <
         kReachProbability;
}

// The calibrated keys as a material file: each parameter's keys, grouped by table.
std::string Driver::material(const std::vector<Evaluation>& all, int best) const {
  const Evaluation& e = all.at(static_cast<std::size_t>(best));
  std::ostringstream t;
  t << "# Material calibrated by `rocklab calibrate " << c_.file << "` (calibration " << c_.name
    << ",\n# evaluation " << best << ", rocklab " << kVersion << ", " << notebook::utcNow()
    << "). A protocol beside its target runs the target on it with\n#   include = \""
    << fs::relative(fs::absolute(c_.material),
                    fs::absolute(c_.experiments.front().protocol).parent_path())
           .string()
    << "\"\n#   base = \"" << fs::path(c_.experiments.front().protocol).filename().string()
    << "\"\n"
    << "# Targets, mean +- 95% interval over the calibration's seeds";
  const Evaluation* check = nullptr;
  for (const Evaluation& x : all) {
    if (x.kind == "check" && x.status == "evaluated") check = &x;
  }
  if (check) t << ", then over " << c_.check_seeds << " fresh seeds";
  t << ":\n";
  for (std::size_t k = 0; k < c_.targets.size(); ++k) {
    const calibration::Target& g = c_.targets[k];
    t << "#   " << g.name << " (" << fs::path(c_.experiments[g.experiment].protocol).stem().string()
      << "): target " << valueText(g.value) << " +- " << valueText(g.tolerance, 3) << " " << g.unit
      << (g.source.empty() ? "" : " (" + g.source + ")") << "; reached "
      << meanText(e.targets[k], g.unit);
    if (check) t << "; check " << meanText(check->targets[k], g.unit);
    t << "\n";
  }
  // The file as it was, the calibration's own material keys and the fitted values written in
  // (the fitted last: a key is fitted or fixed, never both).
  std::vector<std::pair<std::string, std::string>> keys;
  for (const protocol::Override& o : c_.fixed) {
    if (calibration::isMaterialKey(o.key)) keys.emplace_back(o.key, o.value);
  }
  for (std::size_t k = 0; k < c_.parameters.size(); ++k) {
    for (const auto& [key, factor] : c_.parameters[k].keys) {
      keys.emplace_back(key, campaign::numberText(roundedTo(e.values[k] * factor, 10)));
    }
  }
  std::string previous;
  if (std::ifstream in(c_.material); in) previous.assign(std::istreambuf_iterator<char>(in), {});
  return calibration::materialText(previous, t.str(), keys);
}

int Driver::run() {
  std::vector<Evaluation> all = ledger_.load();
  const std::string finished = ledger_.status();
  std::string status = finished == "running" ? "" : finished, reason = ledger_.reason();
  std::cerr << "calibration " << c_.name << ": " << c_.targets.size() << " targets, "
            << c_.parameters.size() << " parameters, "
            << (c_.optimizer == calibration::Optimizer::Bayesian ? "bayesian" : "latin hypercube")
            << ", at most " << c_.budget << " evaluations of "
            << c_.experiments.front().seeds.size() << " seeds -> " << o_.lab
            << (all.empty() ? "" : " (going on)") << "\n";
  for (const Evaluation& e : all) {
    if (e.status != "proposed") print(e);
  }
  // Evaluations that failed (every run of a target lost: a node gone, the binary replaced
  // under the pool) are run once more each time an unreached calibration is run again,
  // before it goes on. Their whole batch is taken again, so that its campaigns are the same
  // files: they rerun only the runs that did not complete. A run that fails by itself fails
  // again the same way (a seed's run is deterministic) and stays failed.
  if (status != "reached") {
    std::set<int> lost;
    for (const Evaluation& e : all) {
      if (e.counts() && e.status == "failed") lost.insert(e.batch);
    }
    for (Evaluation& e : all) {
      if (e.counts() && lost.count(e.batch)) e.status = "proposed";
    }
    if (!lost.empty()) status.clear(), reason.clear();
  }
  while (status.empty()) {
    // A batch proposed but not evaluated (a run killed halfway) goes first.
    std::vector<Evaluation> batch;
    for (const Evaluation& e : all) {
      if (e.counts() && e.status == "proposed" && (batch.empty() || e.batch == batch[0].batch)) {
        batch.push_back(e);
      }
    }
    if (batch.empty()) {
      int used = 0, last = -1;
      for (const Evaluation& e : all) {
        used += e.counts();
        last = std::max(last, e.batch);
      }
      calibration::Reach reach;
      if (std::any_of(all.begin(), all.end(), [](const Evaluation& e) { return e.within; })) {
        status = "reached";
        break;
      }
      if (used >= c_.budget) {
        status = "budget";
        reason = "the budget of " + std::to_string(c_.budget) + " evaluations is spent";
        break;
      }
      if (outOfReach(all, reach)) {
        status = "unreachable";
        std::ostringstream r;
        r << "no point inside the bounds meets every target (at most a "
          << valueText(100.0 * reach.probability, 2) << "% chance, as the surrogates see it, after "
          << used << " evaluations); the closest predicted:";
        for (std::size_t t = 0; t < c_.targets.size(); ++t) {
          const auto& p = reach.at_closest[t];
          const calibration::Target& g = c_.targets[t];
          r << " " << g.name << " " << valueText(g.value + p.mean * g.tolerance) << " +- "
            << valueText(2.0 * std::sqrt(p.variance) * g.tolerance, 2) << " " << g.unit
            << " (target " << valueText(g.value) << ")";
        }
        r << " at";
        const auto v = c_.values(reach.closest);
        for (std::size_t k = 0; k < v.size(); ++k) {
          r << " " << c_.parameters[k].name << "=" << valueText(v[k]);
        }
        reason = r.str();
        break;
      }
      std::vector<std::string> kinds;
      const auto values = nextBatch(all, last + 1, kinds);
      batch = ledger_.propose(last + 1, kinds, values, static_cast<int>(all.size()));
      all.insert(all.end(), batch.begin(), batch.end());
    }
    std::cerr << "calibration " << c_.name << ": batch " << batch.front().batch << ", "
              << batch.size() << " evaluations\n";
    if (!evaluate(batch, false)) return 130;
    for (const Evaluation& e : batch) all[static_cast<std::size_t>(e.index)] = e;
  }
  const int best = calibration::bestEvaluation(all);
  // The best point on fresh seeds, once.
  if (status == "reached" && c_.check_seeds > 0 &&
      std::none_of(all.begin(), all.end(), [](const Evaluation& e) {
        return e.kind == "check" && e.status != "proposed";
      })) {
    std::vector<Evaluation> check;
    for (const Evaluation& e : all) {
      if (e.kind == "check") check.push_back(e);
    }
    if (check.empty()) {
      int last = 0;
      for (const Evaluation& e : all) last = std::max(last, e.batch);
      check = ledger_.propose(last + 1, {"check"}, {all[static_cast<std::size_t>(best)].values},
                              static_cast<int>(all.size()));
      all.insert(all.end(), check.begin(), check.end());
    }
    std::cerr << "calibration " << c_.name << ": evaluation " << best << " checked on "
              << c_.check_seeds << " fresh seeds\n";
    if (!evaluate(check, true)) return 130;
    all[static_cast<std::size_t>(check.front().index)] = check.front();
  }
  std::string written;
  if (status == "reached" && !c_.material.empty()) {
    writeWhole(c_.material, material(all, best));
    written = c_.material;
  }
  ledger_.finish(status, reason, best, written);
  int evaluations = 0;
  for (const Evaluation& e : all) evaluations += e.counts();
  std::cerr << "calibration " << c_.name << ": " << status;
  if (status == "reached") std::cerr << " at evaluation " << best;
  std::cerr << " (" << evaluations << " evaluations)" << (reason.empty() ? "" : ": " + reason)
            << "\n";
  if (best >= 0) {
    std::cerr << "best";
    print(all[static_cast<std::size_t>(best)]);
  }
  if (!written.empty()) std::cerr << "wrote " << written << "\n";
  const std::string out = o_.report.empty() ? dir_ + "/report" : o_.report;
  const auto r = reports::writeCalibrationReport({o_.lab, c_, out});
  std::cerr << "wrote " << out << "/index.html (" << r.files.size() << " files)\n";
  return status == "reached" ? 0 : 1;
}

}  // namespace

int calibrate(const CalibrateOptions& o) {
  Calibration c;
  try {
    c = calibration::readCalibration(o.file);
  } catch (const protocol::ProtocolError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  }
  if (o.check_only) {
    std::size_t seeds = c.experiments.front().seeds.size();
    std::cout << o.file << ": a valid calibration: " << c.targets.size() << " targets from "
              << c.experiments.size() << " protocols, " << c.parameters.size()
              << " parameters, at most " << c.budget << " evaluations of " << seeds << " seeds ("
              << c.budget * static_cast<int>(seeds * c.experiments.size()) << " runs at most)\n";
    return 0;
  }
  try {
    notebook::Notebook lab(o.lab);
    Driver d(o, c, lab);
    return d.run();
  } catch (const std::exception& e) {
    std::cerr << "calibration " << c.name << ": " << e.what() << "\n";
    return 1;
  }
}

}  // namespace rocklab::cli
