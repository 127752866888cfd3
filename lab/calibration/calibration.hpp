#pragma once
// A calibration file (lab/calibration/README.md): the targets (key results of protocols with
// their measured values and tolerances), the free parameters (protocol keys with bounds and
// scale, shared by every target protocol that declares them), the seeds of each evaluation,
// the optimiser and its budget. Read and checked before anything runs, every problem with
// its file:line, every target protocol checked with the parameters at their bounds.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "lab/calibration/gaussian_process.hpp"
#include "lab/campaign/campaign.hpp"
#include "lab/protocol/params.hpp"

namespace rocklab::calibration {

enum class Optimizer { Bayesian, LatinHypercube };

struct Target {
  std::string name;                     // unique in the calibration (default: the result)
  int experiment = 0;                   // the protocol and keys that measure it
  std::string result;                   // a key result of that protocol's rig
  std::string unit;                     // the result's, from the rig's declaration
  double value = 0.0, tolerance = 0.0;  // in the unit
  std::string source;                   // where the value was measured (a citation)
  std::string where;                    // file:line of its [[target]]
};

// A protocol with the keys its targets give it: one campaign per batch.
struct Experiment {
  std::string protocol;                   // resolved against the calibration file's folder
  std::vector<protocol::Override> set;    // the calibration's [set] and its targets' own
  std::vector<std::string> results;       // what its targets read
  std::vector<std::int64_t> seeds;        // each evaluation's
  std::vector<std::int64_t> check_seeds;  // the check's: fresh ones after them
};

struct Parameter {
  std::string name;
  std::vector<std::pair<std::string, double>> keys;  // each key takes value x factor
  std::string unit;                                  // the keys' (of the first)
  double low = 0.0, high = 0.0;
  bool log = false;
  std::optional<double> start;
  std::string where;

  double toUnit(double value) const;
  double fromUnit(double u) const;     // exactly
  double rounded(double value) const;  // to 4 significant digits, inside the bounds (see there)
};

struct Calibration {
  std::string file, text, name;
  Optimizer optimizer = Optimizer::Bayesian;
  int budget = 40, batch = 4, threads = 1, check_seeds = 0;
  std::uint64_t seed = 1;                 // the optimiser's random numbers
  std::string material;                   // the material file to write, resolved; empty: none
  std::vector<protocol::Override> fixed;  // its own [set]: the material keys go in the file
  std::vector<Target> targets;
  std::vector<Parameter> parameters;
  std::vector<Experiment> experiments;
  campaign::SlurmOptions slurm;

  // The first batch: the start (when every parameter has one) and a Latin hypercube.
  int designSize() const;
  // The keys a point of the parameters gives an experiment's protocol (those it declares).
  std::vector<protocol::Override> overrides(int experiment, const std::vector<double>& values,
                                            const std::string& origin) const;
  std::vector<double> values(const Point& u) const;  // each rounded (Parameter::rounded)
  Point unit(const std::vector<double>& values) const;
  std::optional<std::vector<double>> start() const;
};

// Throws protocol::ProtocolError with every problem.
Calibration readCalibration(const std::string& path);

// The name of a batch's campaign for an experiment, and of the check's.
std::string batchCampaignName(const Calibration& c, int batch, int experiment);
std::string checkCampaignName(const Calibration& c, int experiment);

}  // namespace rocklab::calibration
