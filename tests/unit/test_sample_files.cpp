// Samples a user brings: each format read to the same particles, units and boxes as the
// file says, 2D from files without z, errors at file:line; regular lattices against their
// geometry (nearest-neighbour distance, coordination, the simple cubic porosity).

#include <gtest/gtest.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataWriter.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "lab/core/packing_io.hpp"
#include "lab/samples/lattice.hpp"
#include "lab/samples/sample_files.hpp"

namespace rocklab {
namespace {

std::string tempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("rocklab-sample-" + std::to_string(::getpid()) + "-" + name))
      .string();
}

std::string write(const std::string& name, const std::string& text) {
  const std::string path = tempPath(name);
  std::ofstream(path) << text;
  return path;
}

std::string errorOf(const std::string& path, SampleFormat f = SampleFormat::Auto, double unit = 1) {
  try {
    readSampleFile(path, f, unit);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "no error";
}

// Two spheres, the same in every format below: (1, 2, 3) mm r 0.5 mm and (4, 5, 6) mm r 1 mm.
void expectTwoSpheres(const SampleFileData& d) {
  ASSERT_EQ(d.centers.size(), 2u);
  EXPECT_EQ(d.dimension, 3);
  EXPECT_DOUBLE_EQ(d.centers[0][0], 1e-3);
  EXPECT_DOUBLE_EQ(d.centers[1][2], 6e-3);
  EXPECT_DOUBLE_EQ(d.radii[0], 0.5e-3);
  EXPECT_DOUBLE_EQ(d.radii[1], 1e-3);
}

TEST(SampleFiles, CsvHeaderNamesColumnsAndUnits) {
  expectTwoSpheres(readSampleFile(
      write("a.csv", "# from a lab scan\nid,x_mm,y_mm,z_mm,r_mm\n0,1,2,3,0.5\n1,4,5,6,1\n"),
      SampleFormat::Auto, 1.0));
  // Diameters, units in brackets, semicolons; a column without a unit takes sample.file_unit.
  expectTwoSpheres(readSampleFile(
      write("b.csv", "x [m];y [m];z;diameter (mm)\n0.001;0.002;3;1\n0.004;0.005;6;2\n"),
      SampleFormat::Csv, 1e-3));
  const auto d2 =
      readSampleFile(write("c.csv", "x,y,radius\n1,2,0.5\n3,2,0.5\n"), SampleFormat::Auto, 1e-3);
  EXPECT_EQ(d2.dimension, 2);
  EXPECT_FALSE(d2.box);
  EXPECT_NE(
      errorOf(write("d.csv", "x,y,z\n1,2,3\n")).find("d.csv:1: the header names no column 'r'"),
      std::string::npos);
  EXPECT_NE(
      errorOf(write("e.csv", "x,y,z,r\n1,2,3,0.1\n1,2\n")).find("e.csv:3: expected 4 columns"),
      std::string::npos);
  EXPECT_NE(errorOf(write("f.csv", "x,y,z,r\n1,2,3,-1\n"))
                .find("f.csv:2: a particle radius must be "
                      "positive"),
            std::string::npos);
  EXPECT_NE(errorOf(write("g.csv", "x_ft,y,z,r\n1,2,3,1\n")).find("unknown unit 'ft'"),
            std::string::npos);
}

TEST(SampleFiles, LammpsDataFileGivesTheBox) {
  const std::string text =
      "LIGGGHTS data file\n\n2 atoms\n1 atom types\n\n"
      "0 10 xlo xhi\n-1 9 ylo yhi\n0 12 zlo zhi\n\nAtoms # granular\n\n"
      "1 1 1.0 2650 1 2 3\n2 1 2.0 2650 4 5 6 0 0 0\n\nVelocities\n\n1 0 0 0 0 0 0\n";
  const auto d = readSampleFile(write("a.data", text), SampleFormat::Auto, 1e-3);
  expectTwoSpheres(d);
  ASSERT_TRUE(d.box);
  EXPECT_DOUBLE_EQ((*d.box)[2], -1e-3);
  EXPECT_DOUBLE_EQ((*d.box)[5], 12e-3);
  const Packing<3> p = samplePacking<3>(d, "a.data");
  EXPECT_DOUBLE_EQ(p.hi[0], 10e-3);  // the file's box, not the particles' extent
  EXPECT_NE(errorOf(write("b.data",
                          "t\n\n2 atoms\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\n"
                          "Atoms # atomic\n\n1 1 0.5 0.5 0.5\n"))
                .find("b.data:8: Atoms of atom_style atomic"),
            std::string::npos);
  EXPECT_NE(errorOf(write("c.data",
                          "t\n\n3 atoms\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\n"
                          "Atoms\n\n1 1 0.1 1 0.5 0.5 0.5\n"))
                .find("header says 3 atoms, the Atoms section lists 1"),
            std::string::npos);
  EXPECT_NE(errorOf(write("d.data",
                          "t\n\n1 atoms\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\n"
                          "Atoms\n\n1 1 0.1 1 0.5 0.5\n"))
                .find("d.data:10: an atom line"),
            std::string::npos);
  // A centre outside the file's box would start inside a wall.
  const auto out =
      readSampleFile(write("e.data",
                           "t\n\n2 atoms\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\nAtoms\n\n"
                           "1 1 0.1 1 0.5 0.5 2\n2 1 0.1 1 0.5 0.5 0.5\n"),
                     SampleFormat::Lammps, 1.0);
  try {
    samplePacking<3>(out, "e.data");
    ADD_FAILURE() << "a particle outside the box was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("outside the file's box along z"), std::string::npos)
        << e.what();
  }
}

TEST(SampleFiles, YadeTextExportWithAndWithoutFormatLine) {
  expectTwoSpheres(readSampleFile(
      write("a.yade", "#format x_y_z_r\n0.001 0.002 0.003 0.0005\n0.004 0.005 0.006 0.001\n"),
      SampleFormat::Auto, 1.0));
  expectTwoSpheres(
      readSampleFile(write("b.txt", "1 2 3 0.5\n4 5 6 1\n"), SampleFormat::Yade, 1e-3));
  expectTwoSpheres(
      readSampleFile(write("c.yade", "#format x_y_z_r_matId\n1 2 3 0.5 0\n4 5 6 1 0\n"),
                     SampleFormat::Yade, 1e-3));
  EXPECT_EQ(readSampleFile(write("d.yade", "1 2 0.5\n4 5 1\n"), SampleFormat::Yade, 1e-3).dimension,
            2);
  EXPECT_NE(errorOf(write("e.yade", "1 2 3 0.5\n4 5 6\n"), SampleFormat::Yade)
                .find("e.yade:2: expected 4 values"),
            std::string::npos);
}

TEST(SampleFiles, VtpAsciiAndBinaryAsVtkWritesThem) {
  const std::string ascii = R"(<?xml version="1.0"?>
<VTKFile type="PolyData" version="0.1" byte_order="LittleEndian">
  <PolyData>
    <Piece NumberOfPoints="2" NumberOfVerts="0" NumberOfLines="0" NumberOfStrips="0" NumberOfPolys="0">
      <PointData>
        <DataArray type="Float64" Name="radius" format="ascii">0.0005 0.001</DataArray>
      </PointData>
      <Points>
        <DataArray type="Float64" NumberOfComponents="3" format="ascii">0.001 0.002 0.003 0.004 0.005 0.006</DataArray>
      </Points>
    </Piece>
  </PolyData>
</VTKFile>
)";
  expectTwoSpheres(readSampleFile(write("a.vtp", ascii), SampleFormat::Auto, 1.0));
  // VTK's default: appended, base64-free raw binary, zlib compressed; radii as diameters.
  vtkNew<vtkPoints> pts;
  pts->InsertNextPoint(1, 2, 3);
  pts->InsertNextPoint(4, 5, 6);
  vtkNew<vtkDoubleArray> d;
  d->SetName("Diameter");
  d->InsertNextValue(1.0);
  d->InsertNextValue(2.0);
  vtkNew<vtkPolyData> poly;
  poly->SetPoints(pts);
  poly->GetPointData()->AddArray(d);
  vtkNew<vtkXMLPolyDataWriter> w;
  const std::string binary = tempPath("b.vtp");
  w->SetFileName(binary.c_str());
  w->SetInputData(poly);
  w->Write();
  expectTwoSpheres(readSampleFile(binary, SampleFormat::Vtp, 1e-3));
  std::string noRadius = ascii;
  noRadius.replace(noRadius.find("radius"), 6, "speed");
  EXPECT_NE(errorOf(write("c.vtp", noRadius)).find("no point-data array of radii"),
            std::string::npos);
  EXPECT_NE(errorOf(write("d.vtp", "x,y,z,r\n")).find("d.vtp:1: expected a VTK XML PolyData file"),
            std::string::npos);
}

TEST(SampleFiles, RocklabFormatAndDimensions) {
  Packing<3> p;
  p.lo = {0, 0, 0};
  p.hi = {7e-3, 7e-3, 7e-3};
  p.centers = {{1e-3, 2e-3, 3e-3}, {4e-3, 5e-3, 6e-3}};
  p.radii = {0.5e-3, 1e-3};
  const std::string path = tempPath("p.txt");
  writePacking<3>(path, p, "two");
  const auto d = readSampleFile(path, SampleFormat::Auto, 1e-3);  // metres whatever the unit
  expectTwoSpheres(d);
  EXPECT_EQ(samplePacking<3>(d, path).hi[1], 7e-3);
  // A 3D file in a 2D protocol only as one layer.
  EXPECT_THROW(samplePacking<2>(d, path), std::runtime_error);
  const auto layer =
      readSampleFile(write("l.csv", "x,y,z,r\n1,1,5,0.5\n3,1,5,0.5\n"), SampleFormat::Auto, 1e-3);
  const Packing<2> flat = samplePacking<2>(layer, "l.csv");
  EXPECT_DOUBLE_EQ(flat.lo[0], 0.5e-3);  // the extent of the disks
  EXPECT_DOUBLE_EQ(flat.hi[0], 3.5e-3);
  EXPECT_DOUBLE_EQ(flat.hi[1], 1.5e-3);
  const auto two =
      readSampleFile(write("t.csv", "x,y,r\n1,1,0.5\n3,1,0.5\n"), SampleFormat::Auto, 1);
  EXPECT_THROW(samplePacking<3>(two, "t.csv"), std::runtime_error);
  EXPECT_NE(errorOf(tempPath("missing.csv")).find("no such file"), std::string::npos);
  EXPECT_NE(errorOf(write("x.xyz", "1 2 3 4\n")).find("cannot tell the format"), std::string::npos);
}

// Nearest neighbours one spacing apart and the lattice's coordination inside.
template <int D>
void checkLattice(LatticeKind kind, std::array<int, 3> cells, int coordination) {
  LatticeSpec s;
  s.kind = kind;
  s.spacing = 1e-3;
  s.cells = cells;
  const Packing<D> p = latticePacking<D>(s);
  std::size_t expected = latticeSitesPerCell(kind);
  for (int a = 0; a < D; ++a) expected *= cells[a];
  ASSERT_EQ(p.centers.size(), expected);
  const Vec<D> mid = 0.5 * (p.lo + p.hi);
  double nearest = 1e300;
  int inner = 0;
  for (std::size_t i = 0; i < p.centers.size(); ++i) {
    int neighbours = 0;
    for (std::size_t j = 0; j < p.centers.size(); ++j) {
      if (i == j) continue;
      const double r = (p.centers[i] - p.centers[j]).norm();
      nearest = std::min(nearest, r);
      neighbours += std::abs(r - s.spacing) < 1e-12;
    }
    if ((p.centers[i] - mid).norm() < 0.2 * (p.hi - p.lo).minCoeff()) {
      EXPECT_EQ(neighbours, coordination) << i;
      ++inner;
    }
  }
  EXPECT_GT(inner, 0);
  EXPECT_NEAR(nearest, s.spacing, 1e-15);
  for (double r : p.radii) EXPECT_DOUBLE_EQ(r, 0.5e-3);
}

TEST(Lattices, NeighboursAndCoordinationAreTheLattices) {
  checkLattice<2>(LatticeKind::Square, {9, 9, 1}, 4);
  checkLattice<2>(LatticeKind::Hex, {9, 5, 1}, 6);
  checkLattice<3>(LatticeKind::Sc, {5, 5, 5}, 6);
  checkLattice<3>(LatticeKind::Bcc, {5, 5, 5}, 8);
  checkLattice<3>(LatticeKind::Fcc, {4, 4, 4}, 12);
}

TEST(Lattices, SimpleCubicFillsItsBoxAtTheTextbookPorosity) {
  LatticeSpec s;
  s.spacing = 2e-3;
  s.cells = {6, 5, 4};
  const Packing<3> p = latticePacking<3>(s);
  EXPECT_NEAR(p.hi[0] - p.lo[0], 12e-3, 1e-15);
  EXPECT_NEAR(p.hi[2] - p.lo[2], 8e-3, 1e-15);
  EXPECT_NEAR(p.porosity(), 1.0 - std::numbers::pi / 6.0, 1e-12);
}

TEST(Lattices, PerturbationIsBoundedAndSeeded) {
  LatticeSpec s;
  s.kind = LatticeKind::Fcc;
  s.cells = {3, 3, 3};
  const Packing<3> ideal = latticePacking<3>(s);
  s.position_perturbation = 0.1;
  s.radius_perturbation = 0.05;
  s.seed = 7;
  const Packing<3> a = latticePacking<3>(s), b = latticePacking<3>(s);
  s.seed = 8;
  const Packing<3> c = latticePacking<3>(s);
  const double r = 0.5 * s.spacing;
  bool moved = false;
  for (std::size_t i = 0; i < a.centers.size(); ++i) {
    EXPECT_EQ(a.centers[i], b.centers[i]);
    EXPECT_LE((a.centers[i] - ideal.centers[i]).cwiseAbs().maxCoeff(), 0.1 * r + 1e-18);
    EXPECT_LE(std::abs(a.radii[i] / r - 1.0), 0.05 + 1e-15);
    moved = moved || a.centers[i] != c.centers[i];
  }
  EXPECT_TRUE(moved);
}

}  // namespace
}  // namespace rocklab
