// `rocklab report` and `rocklab export` end to end on a small oedometer run (two runs
// overlaid): every file the HTML references exists, the figures are not blank, the
// exported VTK files read back with the counts the run recorded.

#include <gtest/gtest.h>

#include "tests/e2e/command.hpp"

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataReader.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>

#include "lab/core/frame.hpp"
#include "lab/notebook/queries.hpp"

namespace {

namespace fs = std::filesystem;

class Report : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("rocklab-report-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    lab_ = (dir_ / "lab.sqlite").string();
    std::ofstream p(dir_ / "small.toml");
    p << "[protocol]\nname = \"small\"\nrig = \"oedometer\"\n[sample]\ncount = 400\n"
         "size_distribution = \"uniform\"\nd_min_mm = 0.8\nd_max_mm = 1.2\n"
         "porosity_initial = 0.42\n[formation]\naxial_stress_MPa = 10\nlateral_stress_MPa = 5\n"
         "[loading]\naxial_strain_max = 0.005\ncycle_at_axial_strain = [0.002]\n";
  }
  void TearDown() override {
    if (!getenv("KEEP")) fs::remove_all(dir_);
  }
  fs::path dir_;
  std::string lab_;
};

double nonWhite(const std::string& png) {
  vtkNew<vtkPNGReader> r;
  r->SetFileName(png.c_str());
  r->Update();
  vtkImageData* img = r->GetOutput();
  int d[3];
  img->GetDimensions(d);
  const int c = img->GetNumberOfScalarComponents();
  auto* px = static_cast<unsigned char*>(img->GetScalarPointer());
  std::size_t n = 0;
  for (int i = 0; i < d[0] * d[1]; ++i)
    n += px[i * c] < 240 || px[i * c + 1] < 240 || px[i * c + 2] < 240;
  return static_cast<double>(n) / (d[0] * d[1]);
}

TEST_F(Report, TwoRunsOverlaidWithSnapshotsAndParaViewExport) {
  std::string out;
  for (int k = 0; k < 2; ++k) {
    ASSERT_EQ(
        rocklab::testing::runRocklab(
            "run " + (dir_ / "small.toml").string() + " --quiet --threads 1 --lab " + lab_, &out),
        0)
        << out;
  }
  const std::string rep = (dir_ / "report").string();
  ASSERT_EQ(rocklab::testing::runRocklab("report 1 2 --lab " + lab_ + " --out " + rep, &out), 0)
      << out;
  std::ifstream in(rep + "/index.html");
  const std::string html((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // Every file the page references exists, and the figures are not blank.
  std::regex ref("(?:src|href)=\"([^\"#:]+)\"");
  int images = 0, csvs = 0;
  for (auto it = std::sregex_iterator(html.begin(), html.end(), ref); it != std::sregex_iterator();
       ++it) {
    const std::string file = (*it)[1];
    EXPECT_TRUE(fs::exists(rep + "/" + file)) << file;
    if (file.ends_with(".png")) {
      ++images;
      // Line charts ink a few per cent of their area (axes, curves, text), snapshots far
      // more (particles); a blank image has none.
      const bool chart = file.starts_with("oedometer-");
      EXPECT_GT(nonWhite(rep + "/" + file), chart ? 0.01 : 0.10) << file;
    }
    csvs += file.ends_with(".csv");
  }
  EXPECT_GE(images, 2 + 2 * 2 * 2);  // figures 1 and 2; per run 2 frames, view and slice
  EXPECT_EQ(csvs, 2);
  // Both runs overlay in the figures' data.
  std::ifstream csv(rep + "/oedometer-figure1.csv");
  const std::string data((std::istreambuf_iterator<char>(csv)), std::istreambuf_iterator<char>());
  EXPECT_NE(data.find("run 1 small"), std::string::npos);
  EXPECT_NE(data.find("run 2 small"), std::string::npos);
  EXPECT_NE(data.find("paper: formation state"), std::string::npos);
  // The run table and the paper's numbers beside the run's.
  EXPECT_NE(html.find("formation_axial_stress"), std::string::npos);
  EXPECT_NE(html.find("Time per stage"), std::string::npos);

  // ParaView export: one .vtp per frame and part, a .pvd, counts as recorded.
  const std::string vtk = (dir_ / "vtk").string();
  ASSERT_EQ(rocklab::testing::runRocklab("export 1 --vtk " + vtk + " --lab " + lab_, &out), 0)
      << out;
  EXPECT_TRUE(fs::exists(vtk + "/run1.pvd"));
  rocklab::notebook::Notebook nb(lab_);
  const auto frames =
      rocklab::notebook::query(nb, "SELECT path, step, stage FROM snapshots WHERE run_id = 1");
  ASSERT_EQ(frames.rows.size(), 2u);
  for (const auto& row : frames.rows) {
    const rocklab::Frame f = rocklab::readFrame(nb.resolve(row[0].str()));
    const std::string stem = vtk + "/run1-" + row[2].str() + "-" + row[1].str();
    vtkNew<vtkXMLPolyDataReader> r;
    r->SetFileName((stem + "_particles.vtp").c_str());
    r->Update();
    EXPECT_EQ(r->GetOutput()->GetNumberOfPoints(), static_cast<vtkIdType>(f.size()));
    EXPECT_EQ(r->GetOutput()->GetPointData()->GetArray("radius")->GetTuple1(0), f.radius[0]);
    vtkNew<vtkXMLPolyDataReader> b;
    b->SetFileName((stem + "_bonds.vtp").c_str());
    b->Update();
    EXPECT_EQ(b->GetOutput()->GetNumberOfLines(), static_cast<vtkIdType>(f.bonds.size()));
  }
}

// The permeameter's figures (Li & Holt Figures 11-14): the pressure field, k/k0 against
// porosity and under loading beside Kozeny-Carman, and the solvers' cost, each drawn and
// with its data behind it.
TEST_F(Report, PermeameterFiguresAreDrawnWithTheirData) {
  std::string out;
  ASSERT_EQ(rocklab::testing::runRocklab(std::string("run ") + ROCKLAB_SOURCE_DIR +
                                             "/protocols/permeameter-plane-strain-2d-quick.toml"
                                             " --quiet --threads 1 --lab " +
                                             lab_,
                                         &out),
            0)
      << out;
  const std::string rep = (dir_ / "report").string();
  ASSERT_EQ(rocklab::testing::runRocklab("report 1 --lab " + lab_ + " --out " + rep, &out), 0)
      << out;
  for (const char* id : {"pressure-field-run1", "permeability-porosity", "permeability-loading",
                         "flow-solver-cost"}) {
    const std::string png = rep + "/" + id + ".png";
    ASSERT_TRUE(fs::exists(png)) << png;
    EXPECT_GT(nonWhite(png), 0.02) << png;
    std::ifstream csv(rep + "/" + id + ".csv");
    std::string line;
    int rows = 0;
    while (std::getline(csv, line)) ++rows;
    EXPECT_GT(rows, 4) << id;
  }
  // The protocol's key results headline the report, evaluated (a number, not "not recorded").
  std::ifstream in(rep + "/index.html");
  const std::string html((std::istreambuf_iterator<char>(in)), {});
  const auto keys = html.find("<h2>Key results</h2>");
  ASSERT_NE(keys, std::string::npos);
  EXPECT_LT(keys, html.find("<h2>Figures</h2>"));
  const auto row = html.find("<td>k_over_k0_at_half_peak_stress</td><td class=\"n\">0.", keys);
  EXPECT_NE(row, std::string::npos);
  EXPECT_EQ(html.find("not recorded"), std::string::npos);
}

TEST_F(Report, MissingRunsAndLabsAreRefused) {
  std::string out;
  EXPECT_NE(rocklab::testing::runRocklab(
                "report 1 --lab " + lab_ + " --out " + (dir_ / "r").string(), &out),
            0);
  EXPECT_NE(out.find("no lab notebook"), std::string::npos) << out;
}

}  // namespace
