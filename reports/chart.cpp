#include "reports/chart.hpp"

#include <vtkAxis.h>
#include <vtkChartLegend.h>
#include <vtkChartMatrix.h>
#include <vtkChartXY.h>
#include <vtkContextScene.h>
#include <vtkContextView.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkPlotPoints.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>
#include <vtkVector.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "reports/offscreen.hpp"

namespace rocklab::reports {

namespace {

// Okabe & Ito's palette, distinguishable with colour-blind vision.
constexpr unsigned char kPalette[][3] = {{0, 0, 0},       {230, 159, 0}, {86, 180, 233},
                                         {0, 158, 115},   {213, 94, 0},  {0, 114, 178},
                                         {204, 121, 167}, {240, 228, 66}};

bool hasSpread(const Series& s) {
  return !s.x.empty() && s.low.size() == s.x.size() && s.high.size() == s.x.size();
}

vtkSmartPointer<vtkTable> columns(const std::vector<const std::vector<double>*>& cols,
                                  const std::vector<std::string>& names) {
  auto table = vtkSmartPointer<vtkTable>::New();
  for (const std::string& name : names) {
    vtkNew<vtkDoubleArray> a;
    a->SetName(name.c_str());
    table->AddColumn(a);
  }
  table->SetNumberOfRows(static_cast<vtkIdType>(cols.front()->size()));
  for (std::size_t c = 0; c < cols.size(); ++c) {
    for (std::size_t i = 0; i < cols[c]->size(); ++i) {
      table->SetValue(static_cast<vtkIdType>(i), static_cast<vtkIdType>(c), (*cols[c])[i]);
    }
  }
  return table;
}

// An ensemble's spread, drawn under its series in its colour: a translucent band between low
// and high about a line; a vertical bar through each point.
void drawSpread(vtkChartXY* chart, const Series& s, const unsigned char* c, std::size_t k) {
  std::string tag = "#";
  tag += std::to_string(k);
  if (!s.markers) {
    const auto table = columns({&s.x, &s.low, &s.high}, {"x" + tag, "low" + tag, "high" + tag});
    vtkPlot* band = chart->AddPlot(vtkChart::AREA);
    band->SetInputData(table);
    band->SetInputArray(0, "x" + tag);
    band->SetInputArray(1, "low" + tag);
    band->SetInputArray(2, "high" + tag);
    band->SetColor(c[0], c[1], c[2], 60);
    band->SetLegendVisibility(false);
    return;
  }
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    if (!(s.high[i] > s.low[i])) continue;
    const std::vector<double> x = {s.x[i], s.x[i]}, y = {s.low[i], s.high[i]};
    const auto table = columns({&x, &y}, {"bar x" + tag, "bar y" + tag});
    vtkPlot* bar = chart->AddPlot(vtkChart::LINE);
    bar->SetInputData(table, 0, 1);
    bar->SetColor(c[0], c[1], c[2], 255);
    bar->SetWidth(1.5f);
    bar->SetLegendVisibility(false);
  }
}

void writeCsv(const Figure& f, const std::string& path) {
  std::ofstream out(path);
  out.precision(10);
  out << "panel,series,x,y,low,high\n";
  for (std::size_t p = 0; p < f.panels.size(); ++p) {
    for (const Series& s : f.panels[p].series) {
      std::string label = s.label;
      for (char& c : label) {
        if (c == ',' || c == '"') c = ' ';
      }
      for (std::size_t k = 0; k < s.x.size(); ++k) {
        out << p + 1 << "," << label << "," << s.x[k] << "," << s.y[k] << ",";
        if (hasSpread(s))
          out << s.low[k] << "," << s.high[k];
        else
          out << ",";
        out << "\n";
      }
    }
  }
}

}  // namespace

void renderFigure(const Figure& f, const std::string& dir) {
  const int panels = static_cast<int>(f.panels.size());
  Canvas canvas(900, 420 * panels + 40);
  vtkNew<vtkContextView> view;
  view->SetRenderWindow(canvas.window());
  view->GetRenderer()->SetBackground(1.0, 1.0, 1.0);
  vtkNew<vtkChartMatrix> matrix;
  matrix->SetSize(vtkVector2i(1, panels));
  matrix->SetGutter(vtkVector2f(30.0f, 60.0f));
  // Room on the left for five-digit tick labels and the axis title beside them.
  matrix->SetBorders(90, 50, 20, 40);
  view->GetScene()->AddItem(matrix);
  for (int p = 0; p < panels; ++p) {
    const Panel& panel = f.panels[p];
    // Panel 1 on top: the matrix counts rows from the bottom.
    auto* chart = vtkChartXY::SafeDownCast(matrix->GetChart(vtkVector2i(0, panels - 1 - p)));
    chart->SetShowLegend(true);
    chart->GetLegend()->GetLabelProperties()->SetFontSize(13);
    chart->GetAxis(vtkAxis::BOTTOM)->SetTitle(panel.x_label);
    chart->GetAxis(vtkAxis::LEFT)->SetTitle(panel.y_label);
    for (int a : {vtkAxis::BOTTOM, vtkAxis::LEFT}) {
      chart->GetAxis(a)->GetTitleProperties()->SetFontSize(15);
      chart->GetAxis(a)->GetLabelProperties()->SetFontSize(13);
    }
    if (p == 0) chart->SetTitle(f.title);
    chart->GetTitleProperties()->SetFontSize(16);
    // Axis ranges with a margin of 5% around all the data, so that points on the extremes
    // (the paper's) stay visible.
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (const Series& s : panel.series) {
      for (std::size_t i = 0; i < s.x.size(); ++i) {
        if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
        lo[0] = std::min(lo[0], s.x[i]), hi[0] = std::max(hi[0], s.x[i]);
        lo[1] = std::min(lo[1], s.y[i]), hi[1] = std::max(hi[1], s.y[i]);
        if (hasSpread(s) && std::isfinite(s.low[i]) && std::isfinite(s.high[i])) {
          lo[1] = std::min(lo[1], s.low[i]), hi[1] = std::max(hi[1], s.high[i]);
        }
      }
    }
    for (int a = 0; a < 2 && hi[0] >= lo[0]; ++a) {
      vtkAxis* axis = chart->GetAxis(a == 0 ? vtkAxis::BOTTOM : vtkAxis::LEFT);
      axis->SetBehavior(vtkAxis::FIXED);
      if (a == 0 && panel.log_x && lo[0] > 0.0) {
        // The same 5% margin, of the decades.
        const double pad = hi[0] > lo[0] ? std::pow(hi[0] / lo[0], 0.05) : 2.0;
        axis->SetLogScale(true);
        axis->SetUnscaledRange(lo[0] / pad, hi[0] * pad);
        continue;
      }
      const double pad = hi[a] > lo[a] ? 0.05 * (hi[a] - lo[a]) : 0.5 * std::abs(hi[a]) + 1.0;
      axis->SetRange(lo[a] - pad, hi[a] + pad);
    }
    for (std::size_t k = 0; k < panel.series.size(); ++k) {
      const Series& s = panel.series[k];
      if (s.x.empty()) continue;
      const auto* c = kPalette[k % 8];
      if (hasSpread(s)) drawSpread(chart, s, c, k);
      const auto table = columns({&s.x, &s.y}, {panel.x_label + "#" + std::to_string(k), s.label});
      vtkPlot* plot = chart->AddPlot(s.markers ? vtkChart::POINTS : vtkChart::LINE);
      plot->SetInputData(table, 0, 1);
      plot->SetColor(c[0], c[1], c[2], 255);
      plot->SetWidth(s.markers ? 1.0f : 2.0f);
      plot->SetLabel(s.label);
      if (auto* pts = vtkPlotPoints::SafeDownCast(plot)) {  // lines derive from points
        pts->SetMarkerStyle(s.markers ? vtkPlotPoints::DIAMOND : vtkPlotPoints::NONE);
        pts->SetMarkerSize(12.0f);
      }
    }
  }
  canvas.savePng(dir + "/" + f.id + ".png");
  writeCsv(f, dir + "/" + f.id + ".csv");
}

}  // namespace rocklab::reports
