#pragma once
// A calibration's report from the lab notebook (tables calibrations, calibration_evaluations,
// calibration_values): each target against the evaluations, the parameters' path, what the
// surrogates say of the parameters within tolerance and of which target is sensitive to which
// parameter, and every evaluation with its runs' wall time.

#include <string>

#include "lab/calibration/calibration.hpp"
#include "reports/report.hpp"

namespace rocklab::reports {

struct CalibrationReportOptions {
  std::string lab;
  const calibration::Calibration& calibration;
  std::string out;
};

// Writes out/index.html, out/evaluations.csv and the figures. Throws std::invalid_argument
// when the lab has no such calibration.
ReportSummary writeCalibrationReport(const CalibrationReportOptions& o);

}  // namespace rocklab::reports
