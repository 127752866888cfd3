#include "reports/snapshot.hpp"

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkColorTransferFunction.h>
#include <vtkDoubleArray.h>
#include <vtkGlyph3DMapper.h>
#include <vtkLineSource.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRegularPolygonSource.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkSphereSource.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "reports/offscreen.hpp"

namespace rocklab::reports {

namespace {

constexpr double kMm = 1e3;  // everything is drawn in millimetres, so the scale reads in mm

// Viridis (van der Walt & Smith, matplotlib): perceptually uniform, colour-blind safe.
vtkNew<vtkLookupTable> viridis(double lo, double hi) {
  static const double anchors[][3] = {
      {0.267, 0.005, 0.329}, {0.283, 0.141, 0.458}, {0.254, 0.265, 0.530}, {0.207, 0.372, 0.553},
      {0.164, 0.471, 0.558}, {0.128, 0.567, 0.551}, {0.135, 0.659, 0.518}, {0.267, 0.749, 0.441},
      {0.478, 0.821, 0.318}, {0.741, 0.873, 0.150}, {0.993, 0.906, 0.144}};
  vtkNew<vtkColorTransferFunction> ctf;
  for (int k = 0; k < 11; ++k)
    ctf->AddRGBPoint(k / 10.0, anchors[k][0], anchors[k][1], anchors[k][2]);
  vtkNew<vtkLookupTable> lut;
  lut->SetNumberOfTableValues(256);
  for (int i = 0; i < 256; ++i) {
    double rgb[3];
    ctf->GetColor(i / 255.0, rgb);
    lut->SetTableValue(i, rgb[0], rgb[1], rgb[2], 1.0);
  }
  lut->SetTableRange(lo, hi > lo ? hi : lo + 1.0);
  return lut;
}

struct Bounds {
  std::array<double, 3> lo, hi;
};

Bounds boundsOf(const Frame& f) {
  Bounds b{{1e300, 1e300, 1e300}, {-1e300, -1e300, -1e300}};
  for (std::size_t i = 0; i < f.size(); ++i) {
    for (int d = 0; d < 3; ++d) {
      b.lo[d] = std::min(b.lo[d], f.pos[i][d] - f.radius[i]);
      b.hi[d] = std::max(b.hi[d], f.pos[i][d] + f.radius[i]);
    }
  }
  return b;
}

std::array<double, 3> centreOf(const Frame& f) {
  std::array<double, 3> lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (const auto& p : f.pos) {
    for (int d = 0; d < 3; ++d) lo[d] = std::min(lo[d], p[d]), hi[d] = std::max(hi[d], p[d]);
  }
  return {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])};
}

double meanRadius(const Frame& f) {
  double s = 0.0;
  for (double r : f.radius) s += r;
  return f.radius.empty() ? 1.0 : s / static_cast<double>(f.radius.size());
}

// Particles (or the disks of their sections) as glyphs scaled by radius, coloured by value.
vtkNew<vtkActor> particleActor(const std::vector<std::array<double, 3>>& centres,
                               const std::vector<double>& radii, const std::vector<double>& values,
                               vtkLookupTable* lut, bool disks) {
  vtkNew<vtkPoints> pts;
  vtkNew<vtkDoubleArray> radius, value;
  radius->SetName("radius");
  value->SetName("value");
  for (std::size_t i = 0; i < centres.size(); ++i) {
    pts->InsertNextPoint(centres[i][0] * kMm, centres[i][1] * kMm, centres[i][2] * kMm);
    radius->InsertNextValue(radii[i] * kMm);
    value->InsertNextValue(values[i]);
  }
  vtkNew<vtkPolyData> pd;
  pd->SetPoints(pts);
  pd->GetPointData()->AddArray(radius);
  pd->GetPointData()->SetScalars(value);
  vtkNew<vtkGlyph3DMapper> mapper;
  mapper->SetInputData(pd);
  if (disks) {
    vtkNew<vtkRegularPolygonSource> circle;
    circle->SetNumberOfSides(32);
    circle->SetRadius(1.0);
    circle->SetNormal(0.0, 1.0, 0.0);  // facing the camera, which looks along y
    mapper->SetSourceConnection(circle->GetOutputPort());
  } else {
    vtkNew<vtkSphereSource> sphere;
    sphere->SetThetaResolution(12);
    sphere->SetPhiResolution(8);
    sphere->SetRadius(1.0);
    mapper->SetSourceConnection(sphere->GetOutputPort());
  }
  mapper->SetScaleArray("radius");
  mapper->SetScaleModeToScaleByMagnitude();
  mapper->SetLookupTable(lut);
  mapper->SetScalarRange(lut->GetTableRange());
  mapper->SetScalarModeToUsePointData();
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  return actor;
}

// Broken bonds as small markers: between grains tensile vermillion, shear blue; inside
// grains (crushing) larger, reddish purple (Okabe-Ito colours).
void addBreaks(vtkRenderer* r, const std::vector<BreakMark>& breaks, double size,
               bool in_front_along_y, double y_front) {
  for (const int group : {0, 1, 2}) {  // tensile, shear, inside grains
    const bool tensile = group == 0;
    vtkNew<vtkPoints> pts;
    for (const BreakMark& b : breaks) {
      if (group == 2 ? !b.intragranular : (b.intragranular || b.tensile != tensile)) continue;
      pts->InsertNextPoint(b.position[0] * kMm, in_front_along_y ? y_front : b.position[1] * kMm,
                           b.position[2] * kMm);
    }
    if (pts->GetNumberOfPoints() == 0) continue;
    vtkNew<vtkPolyData> pd;
    pd->SetPoints(pts);
    vtkNew<vtkSphereSource> dot;
    dot->SetRadius(group == 2 ? 1.6 * size : size);
    dot->SetThetaResolution(8);
    dot->SetPhiResolution(6);
    vtkNew<vtkGlyph3DMapper> m;
    m->SetInputData(pd);
    m->SetSourceConnection(dot->GetOutputPort());
    m->ScalarVisibilityOff();
    vtkNew<vtkActor> a;
    a->SetMapper(m);
    if (group == 2) {
      a->GetProperty()->SetColor(204 / 255.0, 121 / 255.0, 167 / 255.0);
    } else if (tensile) {
      a->GetProperty()->SetColor(213 / 255.0, 94 / 255.0, 0.0);
    } else {
      a->GetProperty()->SetColor(0.0, 114 / 255.0, 178 / 255.0);
    }
    r->AddActor(a);
  }
}

// A scale bar of a round length (1, 2 or 5 x 10^k mm) near a fifth of the sample's width,
// under the sample, drawn in world coordinates with the particles (the view is parallel).
void addScaleBar(vtkRenderer* r, double x0, double width, double y, double z) {
  const double target = 0.2 * width;
  const double decade = std::pow(10.0, std::floor(std::log10(target)));
  double length = decade;
  for (double m : {2.0, 5.0, 10.0}) {
    if (m * decade <= target) length = m * decade;
  }
  vtkNew<vtkLineSource> line;
  line->SetPoint1(x0, y, z);
  line->SetPoint2(x0 + length, y, z);
  vtkNew<vtkPolyDataMapper> m;
  m->SetInputConnection(line->GetOutputPort());
  vtkNew<vtkActor> bar;
  bar->SetMapper(m);
  bar->GetProperty()->SetColor(0.1, 0.1, 0.1);
  bar->GetProperty()->SetLineWidth(5.0f);
  r->AddActor(bar);
  vtkNew<vtkTextActor> label;
  std::ostringstream text;
  text << length << " mm";
  label->SetInput(text.str().c_str());
  label->GetTextProperty()->SetColor(0.1, 0.1, 0.1);
  label->GetTextProperty()->SetFontSize(16);
  label->GetPositionCoordinate()->SetCoordinateSystemToWorld();
  label->GetPositionCoordinate()->SetValue(x0 + length + 0.02 * width, y, z - 0.01 * width);
  r->AddActor2D(label);
}

void decorate(vtkRenderer* r, vtkLookupTable* lut, const FieldValues& field,
              const std::string& title, const std::vector<BreakMark>& breaks) {
  vtkNew<vtkScalarBarActor> bar;
  bar->SetLookupTable(lut);
  bar->SetTitle(field.label.c_str());
  bar->SetNumberOfLabels(5);
  bar->UnconstrainedFontSizeOn();  // the font sizes below, not scaled to the bar
  bar->SetMaximumWidthInPixels(110);
  bar->GetPositionCoordinate()->SetValue(0.86, 0.1);
  bar->SetWidth(0.12);
  bar->SetHeight(0.8);
  for (vtkTextProperty* t : {bar->GetTitleTextProperty(), bar->GetLabelTextProperty()}) {
    t->SetColor(0.1, 0.1, 0.1);
    t->ShadowOff();
    t->ItalicOff();
    t->SetFontSize(14);
  }
  r->AddActor2D(bar);
  vtkNew<vtkTextActor> text;
  std::string t = title;
  if (!breaks.empty()) {
    t += "\nbroken bonds: tensile (vermillion), shear (blue)";
    const bool crushing = std::any_of(breaks.begin(), breaks.end(),
                                      [](const BreakMark& b) { return b.intragranular; });
    if (crushing) t += ", inside grains (purple)";
  }
  text->SetInput(t.c_str());
  text->GetTextProperty()->SetColor(0.1, 0.1, 0.1);
  text->GetTextProperty()->SetFontSize(16);
  text->SetDisplayPosition(12, 12);
  text->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  text->GetPositionCoordinate()->SetValue(0.02, 0.93);
  r->AddActor2D(text);
}

// The parts every snapshot has: the canvas, a white renderer, the colour map, the centre.
struct Scene {
  Canvas canvas{1000, 800};
  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkLookupTable> lut;
  std::array<double, 3> centre;
  double band;  // mean radius: breaks this close to the mid-plane are drawn on it
  Scene(const Frame& f, const FieldValues& field)
      : lut(viridis(field.lo, field.hi)), centre(centreOf(f)), band(meanRadius(f)) {
    renderer->SetBackground(1.0, 1.0, 1.0);
    canvas.window()->AddRenderer(renderer);
  }
  std::vector<BreakMark> nearMidPlane(const std::vector<BreakMark>& breaks) const {
    std::vector<BreakMark> near;
    for (const BreakMark& b : breaks) {
      if (std::abs(b.position[1] - centre[1]) < band) near.push_back(b);
    }
    return near;
  }
  // A parallel camera looking along +y from `position`, z up.
  void look(const std::array<double, 3>& focus, const std::array<double, 3>& position) {
    vtkCamera* cam = renderer->GetActiveCamera();
    cam->ParallelProjectionOn();
    cam->SetFocalPoint(focus[0], focus[1], focus[2]);
    cam->SetPosition(position[0], position[1], position[2]);
    cam->SetViewUp(0.0, 0.0, 1.0);
    renderer->ResetCamera();
    cam->Zoom(0.95);  // a margin above for the title lines
  }
};

}  // namespace

void renderView(const Frame& f, const FieldValues& field, const std::vector<BreakMark>& breaks,
                const std::string& title, const std::string& png) {
  Scene sc(f, field);
  const auto& c = sc.centre;
  const Bounds b = boundsOf(f);
  const double width = (b.hi[0] - b.lo[0]) * kMm;
  if (f.dimension == 2) {
    // Disks in the x-y plane drawn in the x-z plane, the camera along y.
    std::vector<std::array<double, 3>> centres;
    for (const auto& p : f.pos) centres.push_back({p[0], 0.0, p[1]});
    sc.renderer->AddActor(particleActor(centres, f.radius, field.values, sc.lut, true));
    std::vector<BreakMark> flat;
    for (const BreakMark& m : breaks)
      flat.push_back({{m.position[0], 0.0, m.position[1]}, m.tensile, m.intragranular});
    // Marks half a mean radius across: a flat view has room for them.
    addBreaks(sc.renderer, flat, 0.5 * sc.band * kMm, true, -0.01 * sc.band * kMm);
    addScaleBar(sc.renderer, b.lo[0] * kMm, width, -0.02 * width, b.lo[1] * kMm - 0.06 * width);
    sc.look({c[0] * kMm, 0.0, c[1] * kMm}, {c[0] * kMm, -1e3, c[1] * kMm});
  } else {
    // The half behind the mid-plane y = centre: its cut face shows the interior. Only the
    // particles within a few diameters of the faces the camera sees (the cut, x = min,
    // z = max) are drawn: the rest are hidden behind them, and software GL spends its time
    // on every triangle, seen or not (30,000 spheres: 3.6 s drawn all, 1.5 s culled).
    double rmax = 0.0;
    for (double r : f.radius) rmax = std::max(rmax, r);
    const double depth = 6.0 * rmax;
    std::vector<std::array<double, 3>> centres;
    std::vector<double> radii, values;
    for (std::size_t i = 0; i < f.size(); ++i) {
      const auto& x = f.pos[i];
      if (x[1] < c[1]) continue;
      if (x[1] - c[1] > depth && x[0] - b.lo[0] > depth && b.hi[2] - x[2] > depth) continue;
      centres.push_back(f.pos[i]);
      radii.push_back(f.radius[i]);
      values.push_back(field.values[i]);
    }
    sc.renderer->AddActor(particleActor(centres, radii, values, sc.lut, false));
    addBreaks(sc.renderer, sc.nearMidPlane(breaks), 0.3 * sc.band * kMm, true,
              (c[1] - sc.band) * kMm);
    addScaleBar(sc.renderer, b.lo[0] * kMm, width, b.lo[1] * kMm, b.lo[2] * kMm - 0.06 * width);
    sc.look({c[0] * kMm, c[1] * kMm, c[2] * kMm},
            {c[0] * kMm - 400.0, c[1] * kMm - 1000.0, c[2] * kMm + 350.0});
  }
  decorate(sc.renderer, sc.lut, field, title, breaks);
  sc.canvas.savePng(png);
}

void renderSlice(const Frame& f, const FieldValues& field, const std::vector<BreakMark>& breaks,
                 const std::string& title, const std::string& png) {
  Scene sc(f, field);
  const auto& c = sc.centre;
  // Each sphere the plane y = centre cuts leaves a disk of radius sqrt(r^2 - d^2).
  std::vector<std::array<double, 3>> centres;
  std::vector<double> radii, values;
  for (std::size_t i = 0; i < f.size(); ++i) {
    const double d = f.pos[i][1] - c[1];
    if (std::abs(d) >= f.radius[i]) continue;
    centres.push_back({f.pos[i][0], c[1], f.pos[i][2]});
    radii.push_back(std::sqrt(f.radius[i] * f.radius[i] - d * d));
    values.push_back(field.values[i]);
  }
  sc.renderer->AddActor(particleActor(centres, radii, values, sc.lut, true));
  addBreaks(sc.renderer, sc.nearMidPlane(breaks), 0.25 * sc.band * kMm, true,
            (c[1] - 0.01 * sc.band) * kMm);
  const Bounds b = boundsOf(f);
  const double width = (b.hi[0] - b.lo[0]) * kMm;
  addScaleBar(sc.renderer, b.lo[0] * kMm, width, (c[1] - sc.band) * kMm,
              b.lo[2] * kMm - 0.06 * width);
  sc.look({c[0] * kMm, c[1] * kMm, c[2] * kMm}, {c[0] * kMm, c[1] * kMm - 1e3, c[2] * kMm});
  std::ostringstream where;
  where.precision(4);
  where << title << ", section y = " << c[1] * kMm << " mm";
  decorate(sc.renderer, sc.lut, field, where.str(), breaks);
  sc.canvas.savePng(png);
}

}  // namespace rocklab::reports
