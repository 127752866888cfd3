#pragma once
// Line charts for reports: a figure of one or more stacked panels, several series each
// (several runs overlay), rendered off screen to PNG with the CSV behind it.

#include <string>
#include <vector>

namespace rocklab::reports {

struct Series {
  std::string label;
  std::vector<double> x, y;
  bool markers = false;  // points (e.g. a value from the paper) instead of a line
  // A spread about y (an ensemble's, one per x; empty: none): a band about a line, error
  // bars on points.
  std::vector<double> low, high;
};

struct Panel {
  std::string x_label, y_label;
  std::vector<Series> series;
  bool log_x = false;  // x on a log scale (every x positive): a rate halved at each point
};

struct Figure {
  std::string id;  // file stem: id.png, id.csv
  std::string title;
  std::string caption;
  std::vector<Panel> panels;
};

// Writes dir/<id>.png and dir/<id>.csv (columns panel, series, x, y, low, high; the last two
// empty without a spread).
void renderFigure(const Figure& f, const std::string& dir);

}  // namespace rocklab::reports
