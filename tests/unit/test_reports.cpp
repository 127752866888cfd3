// Reports: charts and snapshots rendered off screen show what they should (pixel
// statistics, not file existence), and exported VTK files read back with VTK's readers.

#include <gtest/gtest.h>

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataReader.h>

#include <filesystem>
#include <fstream>
#include <set>

#include "reports/chart.hpp"
#include "reports/ensemble.hpp"
#include "reports/snapshot.hpp"
#include "reports/vtk_export.hpp"

namespace rocklab::reports {
namespace {

namespace fs = std::filesystem;

struct Pixels {
  int width = 0, height = 0;
  std::vector<std::array<int, 3>> rgb;
  // Pixels within `tol` of a colour.
  std::size_t count(std::array<int, 3> c, int tol = 12) const {
    std::size_t n = 0;
    for (const auto& p : rgb) {
      n += std::abs(p[0] - c[0]) <= tol && std::abs(p[1] - c[1]) <= tol &&
           std::abs(p[2] - c[2]) <= tol;
    }
    return n;
  }
  double nonWhiteFraction() const {
    return 1.0 - static_cast<double>(count({255, 255, 255}, 8)) / static_cast<double>(rgb.size());
  }
  std::size_t distinct() const {
    std::set<int> s;
    for (const auto& p : rgb) s.insert((p[0] / 8) << 16 | (p[1] / 8) << 8 | (p[2] / 8));
    return s.size();
  }
};

Pixels readPng(const std::string& path) {
  vtkNew<vtkPNGReader> r;
  r->SetFileName(path.c_str());
  r->Update();
  vtkImageData* img = r->GetOutput();
  Pixels p;
  int dims[3];
  img->GetDimensions(dims);
  p.width = dims[0], p.height = dims[1];
  const int comps = img->GetNumberOfScalarComponents();
  auto* data = static_cast<unsigned char*>(img->GetScalarPointer());
  for (int i = 0; i < dims[0] * dims[1]; ++i) {
    p.rgb.push_back({data[i * comps], data[i * comps + 1], data[i * comps + 2]});
  }
  return p;
}

std::string tempDir(const std::string& name) {
  const auto d =
      fs::temp_directory_path() / ("rocklab-rep-" + std::to_string(::getpid()) + "-" + name);
  fs::create_directories(d);
  return d.string();
}

TEST(Charts, CurvesAreDrawnAndTheCsvHoldsTheirPoints) {
  const std::string dir = tempDir("chart");
  Figure f;
  f.id = "test-figure";
  f.title = "two panels";
  Panel a{"strain", "stress (MPa)", {}};
  Series s1{"first", {}, {}, false}, s2{"second", {}, {}, false};
  for (int i = 0; i <= 100; ++i) {
    s1.x.push_back(i * 0.01);
    s1.y.push_back(30 + 60 * i * 0.01);
    s2.x.push_back(i * 0.01);
    s2.y.push_back(30 + 40 * std::sqrt(i * 0.01));
  }
  a.series = {s1, s2};
  Panel b{"strain", "broken bonds", {{"first", s1.x, s1.x, false}}};
  f.panels = {a, b};
  renderFigure(f, dir);
  const Pixels p = readPng(dir + "/test-figure.png");
  EXPECT_EQ(p.width, 900);
  EXPECT_EQ(p.height, 2 * 420 + 40);
  // The second series is drawn in the palette's orange (230, 159, 0), 2 px wide along a
  // curve a few hundred pixels long.
  EXPECT_GT(p.count({230, 159, 0}, 30), 400u);
  // Black: the first series (twice), axes and text.
  EXPECT_GT(p.count({0, 0, 0}, 40), 1500u);
  std::ifstream csv(dir + "/test-figure.csv");
  std::string line;
  int rows = 0;
  std::getline(csv, line);
  EXPECT_EQ(line, "panel,series,x,y,low,high");
  while (std::getline(csv, line)) ++rows;
  EXPECT_EQ(rows, 3 * 101);
  fs::remove_all(dir);
}

// An ensemble's spread: a translucent band about a line in the line's colour, error bars
// through points; the CSV holds both bounds.
TEST(Charts, ASpreadIsABandAboutALineAndBarsThroughPoints) {
  const std::string dir = tempDir("spread");
  Series mean{"mean", {}, {}, false}, points{"points", {0.2, 0.5, 0.8}, {40, 50, 60}, true};
  for (int i = 0; i <= 100; ++i) {
    mean.x.push_back(i * 0.01);
    mean.y.push_back(30 + 60 * i * 0.01);
    mean.low.push_back(mean.y.back() - 8.0);
    mean.high.push_back(mean.y.back() + 8.0);
  }
  points.low = {35, 45, 55};
  points.high = {45, 55, 65};
  Figure f{"spread", "spread", "", {Panel{"strain", "stress (MPa)", {points, mean}}}};
  renderFigure(f, dir);
  const Pixels p = readPng(dir + "/spread.png");
  // The band: orange (230, 159, 0) at alpha 60/255 over white, about (249, 232, 195), a
  // strip 16 MPa high (a fifth of the axis) along the whole width.
  EXPECT_GT(p.count({249, 232, 195}, 8), 20000u);
  std::ifstream csv(dir + "/spread.csv");
  std::string line;
  std::getline(csv, line);
  std::getline(csv, line);
  EXPECT_EQ(line, "1,points,0.2,40,35,45");
  std::getline(csv, line);
  std::getline(csv, line);
  std::getline(csv, line);
  EXPECT_EQ(line, "1,mean,0,30,22,38");
  fs::remove_all(dir);
}

// A run's mention leaves a text: "run 12" as a word, "-run12" in an id; other numbers stay.
TEST(Ensembles, ARunsMentionIsDroppedFromItsFiguresTexts) {
  EXPECT_EQ(withoutRun("run 12 biaxial-ucs-quick (virgin)", 12), "biaxial-ucs-quick (virgin)");
  EXPECT_EQ(withoutRun("failure-envelope-run12", 12), "failure-envelope");
  EXPECT_EQ(withoutRun("Failure envelope, run 12 triaxial", 12), "Failure envelope, triaxial");
  EXPECT_EQ(withoutRun("run 123 and rerun 12", 12), "run 123 and rerun 12");
  EXPECT_EQ(withoutRun("run 12", 12), "");
}

// Three seeds' figures of a loading and an unloading (y = a x, a = 1, 2, 3; unloading 0.1
// above): the curve is their mean branch by branch with a band of one standard deviation;
// points are averaged point by point; numbers that differ in labels become mean +- std; the
// paper's point, the same in every run, stays as it is.
TEST(Ensembles, CurvesAreAveragedBranchByBranchAndPointsPointByPoint) {
  std::vector<RunFigures> runs;
  for (int a = 1; a <= 3; ++a) {
    Series curve{"run " + std::to_string(a) + " loading", {}, {}, false};
    for (int i = 0; i <= 50; ++i) curve.x.push_back(i / 50.0), curve.y.push_back(a * i / 50.0);
    for (int i = 1; i <= 25; ++i) {
      const double x = 1.0 - i / 50.0;
      curve.x.push_back(x), curve.y.push_back(a * x + 0.1);
    }
    Series fit{"Mohr-Coulomb: phi = " + std::to_string(29 + a) + " deg",
               {1.0, 2.0},
               {10.0 * a, 20.0 * a},
               true};
    Series paper{"paper: UCS", {0.0}, {12.0}, true};
    Figure f{"stress-run" + std::to_string(a),
             "Stress, run " + std::to_string(a) + " ucs",
             "Caption.",
             {Panel{"strain", "stress", {curve, fit, paper}}, Panel{"strain", "y", {curve}}}};
    runs.push_back({a, {f}});
  }
  const std::vector<Figure> out = combineFigures(runs);
  ASSERT_EQ(out.size(), 1u);
  const Figure& f = out.front();
  EXPECT_EQ(f.id, "stress");
  EXPECT_EQ(f.title, "Stress, ucs");
  EXPECT_NE(f.caption.find("Over 3 seeds (runs 1, 2, 3)"), std::string::npos) << f.caption;
  ASSERT_EQ(f.panels.at(0).series.size(), 3u);
  const Series& c = f.panels[0].series[0];
  EXPECT_EQ(c.label, "loading");
  ASSERT_EQ(c.x.size(), 240u);  // two branches of 120 points
  EXPECT_DOUBLE_EQ(c.x.front(), 0.0);
  EXPECT_DOUBLE_EQ(c.x[119], 1.0);
  EXPECT_DOUBLE_EQ(c.x[120], 1.0);
  EXPECT_DOUBLE_EQ(c.x.back(), 0.5);
  for (std::size_t k = 0; k < 120; ++k) {  // mean 2x, std x (of x, 2x, 3x)
    EXPECT_NEAR(c.y[k], 2.0 * c.x[k], 1e-9);
    EXPECT_NEAR(c.high[k] - c.y[k], c.x[k], 1e-9);
  }
  EXPECT_NEAR(c.y.back(), 2.0 * 0.5 + 0.1, 1e-9);
  const Series& fit = f.panels[0].series[1];
  EXPECT_EQ(fit.label, "Mohr-Coulomb: phi = 31 +- 1 deg");
  EXPECT_EQ(fit.x, (std::vector<double>{1.0, 2.0}));
  EXPECT_EQ(fit.y, (std::vector<double>{20.0, 40.0}));
  EXPECT_NEAR(fit.high[1] - fit.y[1], 20.0, 1e-9);  // of 20, 40, 60
  EXPECT_TRUE(f.panels[0].series[2].low.empty());   // the paper's: no spread

  EXPECT_EQ(f.panels.at(1).series.at(0).x.size(), 240u);

  // A seed whose points differ in number: that panel has the runs' series overlaid, as each
  // labelled them; the other is still their mean.
  runs[2].figures[0].panels[0].series[1].x.push_back(3.0);
  runs[2].figures[0].panels[0].series[1].y.push_back(90.0);
  const Figure part = combineFigures(runs).front();
  EXPECT_NE(part.caption.find("In panel 1, the seeds' runs (1, 2, 3) are overlaid"),
            std::string::npos)
      << part.caption;
  EXPECT_NE(part.caption.find("Over 3 seeds"), std::string::npos);
  ASSERT_EQ(part.panels[0].series.size(), 9u);
  EXPECT_EQ(part.panels[0].series[3].label, "run 2 loading");
  EXPECT_TRUE(part.panels[0].series[0].low.empty());
  EXPECT_EQ(part.panels[1].series.size(), 1u);
  EXPECT_FALSE(part.panels[1].series[0].low.empty());
}

// A lattice of 7^3 spheres (an odd count: the mid-plane cuts a layer through its centres),
// its field rising along x.
Frame lattice(int dimension) {
  Frame f;
  f.dimension = dimension;
  const int n = 7;
  std::uint32_t slot = 0;
  for (int x = 0; x < n; ++x) {
    for (int y = 0; y < (dimension == 3 ? n : 1); ++y) {
      for (int z = 0; z < n; ++z) {
        f.slot.push_back(slot++);
        const double px = 2e-3 * x + 1e-3, pz = 2e-3 * z + 1e-3;
        if (dimension == 3) {
          f.pos.push_back({px, 2e-3 * y + 1e-3, pz});
        } else {
          f.pos.push_back({px, pz, 0.0});
        }
        f.vel.push_back({0.0, 0.0, 0.0});
        f.radius.push_back(0.95e-3);
        f.spin.push_back(0.0);
      }
    }
  }
  for (std::size_t i = 0; i + 1 < f.size(); ++i) {
    f.contacts.push_back({f.slot[i], f.slot[i + 1], 1.0 + i, 0.5});
    if (i % 3 == 0) {
      f.bonds.push_back({f.slot[i], f.slot[i + 1], 2.0 * i, 0.1});
      f.bond_kind.push_back(0);
    }
  }
  for (int a = 0; a < dimension; ++a) {
    Frame::Plane lo, hi;
    lo.name = std::string(1, "xyz"[a]) + "min";
    hi.name = std::string(1, "xyz"[a]) + "max";
    lo.normal[a] = 1.0;
    hi.normal[a] = -1.0;
    hi.point[a] = 14e-3;
    f.walls.push_back(lo);
    f.walls.push_back(hi);
  }
  return f;
}

FieldValues rampAlongX(const Frame& f) {
  FieldValues v;
  v.label = "displacement (mm)";
  for (const auto& p : f.pos) v.values.push_back(p[0] * 1e3);
  v.lo = 0.0;
  v.hi = 14.0;
  return v;
}

void checkSnapshot(const Pixels& p) {
  // Particles cover a good part of the image, in many shades of the colour map.
  EXPECT_GT(p.nonWhiteFraction(), 0.15);
  EXPECT_GT(p.distinct(), 40u);
  // Both ends of viridis are there (the colour bar at least, and particles at both ends).
  EXPECT_GT(p.count({68, 1, 84}, 25), 200u);
  EXPECT_GT(p.count({253, 231, 37}, 30), 200u);
  // The break markers: vermillion (tensile) and blue (shear), shaded.
  EXPECT_GT(p.count({213, 94, 0}, 45), 5u);
  EXPECT_GT(p.count({0, 114, 178}, 45), 5u);
}

TEST(Snapshots, ViewAndSliceOfASphereSample) {
  const std::string dir = tempDir("snap3");
  const Frame f = lattice(3);
  const std::vector<BreakMark> breaks = {{{6e-3, 7e-3, 5e-3}, true}, {{8e-3, 7e-3, 9e-3}, false}};
  renderView(f, rampAlongX(f), breaks, "lattice", dir + "/view.png");
  renderSlice(f, rampAlongX(f), breaks, "lattice", dir + "/slice.png");
  checkSnapshot(readPng(dir + "/view.png"));
  checkSnapshot(readPng(dir + "/slice.png"));
  fs::remove_all(dir);
}

TEST(Snapshots, DiskSample) {
  const std::string dir = tempDir("snap2");
  const Frame f = lattice(2);
  renderView(f, rampAlongX(f), {{{7e-3, 8e-3, 0.0}, true}, {{9e-3, 6e-3, 0.0}, false}}, "disks",
             dir + "/view.png");
  checkSnapshot(readPng(dir + "/view.png"));
  fs::remove_all(dir);
}

vtkSmartPointer<vtkPolyData> readVtp(const std::string& path) {
  vtkNew<vtkXMLPolyDataReader> r;
  r->SetFileName(path.c_str());
  r->Update();
  return r->GetOutput();
}

TEST(VtkExport, FilesReadBackWithTheirCountsAndValues) {
  const std::string dir = tempDir("vtk");
  Frame f = lattice(3);
  Frame moved = f;
  for (auto& p : moved.pos) p[2] += 1e-4;  // displaced along z by 0.1 mm
  moved.vel[5] = {0.1, 0.2, 0.3};
  const auto entries = writeFrameVtk(moved, &f, dir, "frame");
  ASSERT_EQ(entries.size(), 4u);
  writePvd(dir + "/series.pvd", entries);

  auto particles = readVtp(dir + "/frame_particles.vtp");
  ASSERT_EQ(particles->GetNumberOfPoints(), static_cast<vtkIdType>(f.size()));
  EXPECT_NEAR(particles->GetPointData()->GetArray("radius")->GetTuple1(7), 0.95e-3, 1e-15);
  EXPECT_NEAR(particles->GetPointData()->GetArray("velocity")->GetComponent(5, 2), 0.3, 1e-15);
  EXPECT_NEAR(particles->GetPointData()->GetArray("displacement")->GetComponent(9, 2), 1e-4, 1e-12);
  EXPECT_EQ(particles->GetPointData()->GetArray("id")->GetTuple1(11), 11.0);
  auto contacts = readVtp(dir + "/frame_contacts.vtp");
  EXPECT_EQ(contacts->GetNumberOfLines(), static_cast<vtkIdType>(f.contacts.size()));
  EXPECT_NEAR(contacts->GetCellData()->GetArray("normal_force")->GetTuple1(3), 4.0, 1e-12);
  auto bonds = readVtp(dir + "/frame_bonds.vtp");
  EXPECT_EQ(bonds->GetNumberOfLines(), static_cast<vtkIdType>(f.bonds.size()));
  EXPECT_NEAR(bonds->GetCellData()->GetArray("normal_force")->GetTuple1(2), 12.0, 1e-12);
  auto walls = readVtp(dir + "/frame_walls.vtp");
  EXPECT_EQ(walls->GetNumberOfPolys(), 6);
  std::ifstream pvd(dir + "/series.pvd");
  const std::string text((std::istreambuf_iterator<char>(pvd)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("file=\"frame_bonds.vtp\""), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rocklab::reports
