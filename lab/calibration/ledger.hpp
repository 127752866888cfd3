#pragma once
// What the lab notebook keeps of a calibration (tables calibrations, calibration_evaluations
// and calibration_values, lab/notebook/README.md): every evaluation as proposed, with its
// parameters, and, once its campaigns have run, its targets' seed means. A calibration
// killed halfway is read back from these rows and goes on from its first evaluation not
// evaluated; its runs are found again by their protocols' hashes, so none runs twice.

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "lab/calibration/calibration.hpp"
#include "lab/calibration/optimizer.hpp"
#include "lab/notebook/notebook.hpp"

namespace rocklab::calibration {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct TargetValue {
  std::int64_t n = 0;  // completed runs
  double mean = kNaN, std = kNaN, low = kNaN, high = kNaN;
};

struct Evaluation {
  int index = 0, batch = 0;
  std::string kind;                  // start, design, bayesian, latin_hypercube, check
  std::string status = "proposed";   // proposed, evaluated, failed
  std::vector<double> values;        // the parameters', in their keys' unit
  std::vector<TargetValue> targets;  // the calibration's order
  double misfit = kNaN;
  bool within = false;
  bool counts() const { return kind != "check"; }  // toward the budget and the optimiser
};

// Each target's error in tolerances, (mean - value) / tolerance.
std::vector<double> errors(const Calibration& c, const Evaluation& e);
// What the optimisers see of the evaluated points (not the check).
std::vector<Evaluated> evaluatedPoints(const Calibration& c, const std::vector<Evaluation>& all);
// The evaluation the calibration settles on: the least misfit within tolerance, else the
// least misfit; -1 for none evaluated.
int bestEvaluation(const std::vector<Evaluation>& all);

class Ledger {
 public:
  // Registers the calibration, or finds it. Throws std::runtime_error when the lab has a
  // calibration of this name from another text (its evaluations would not be this one's).
  Ledger(notebook::Notebook& lab, const Calibration& c);
  // The calibration's row of a lab, read only: its id, or 0 when it has not run there.
  static std::int64_t find(notebook::Notebook& lab, const std::string& name);
  Ledger(notebook::Notebook& lab, const Calibration& c, std::int64_t id);

  std::vector<Evaluation> load() const;
  // Appends a batch of proposed points, each of its kind (one transaction), and returns their
  // evaluations.
  std::vector<Evaluation> propose(int batch, const std::vector<std::string>& kinds,
                                  const std::vector<std::vector<double>>& values, int first_index);
  void record(const Evaluation& e);
  void finish(const std::string& status, const std::string& reason, int best,
              const std::string& material);
  std::string status() const;
  std::string reason() const;

 private:
  notebook::Notebook& lab_;
  const Calibration& c_;
  std::int64_t id_ = 0;
};

}  // namespace rocklab::calibration
