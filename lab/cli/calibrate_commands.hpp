#pragma once
// `rocklab calibrate C.toml`: a calibration (lab/calibration/calibration.hpp) run batch by
// batch, each batch one campaign per target protocol (a local pool or a Slurm job array), every
// evaluation's parameters and targets kept in the lab notebook, so that the same command
// resumes a calibration killed halfway. It ends by checking the best point on fresh seeds,
// writing the material file and the report.

#include <string>

namespace rocklab::cli {

struct CalibrateOptions {
  std::string file;
  std::string lab = "lab.sqlite";
  int jobs = 0;  // local pool: runs at once (0: the cores over each run's threads)
  bool quiet = false;
  std::string scheduler = "local";  // or "slurm"
  bool check_only = false;          // validate the file, run nothing
  std::string report;               // the report's folder (default <lab>.calibrations/NAME/report)
};

// 0: every target reached (and the material written); 1: not reached (the budget spent, or
// a target out of reach); 2: a bad calibration file; 130: interrupted (resume by running the
// same command again).
int calibrate(const CalibrateOptions& o);

}  // namespace rocklab::cli
