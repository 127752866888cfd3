// Packing files: round trip, and errors that name the file and line.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "lab/core/packing_io.hpp"

namespace rocklab {
namespace {

std::string tempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("rocklab-" + std::to_string(::getpid()) + "-" + name))
      .string();
}

TEST(PackingIo, RoundTrip3DAnd2D) {
  Packing<3> p;
  p.lo = {0, 0, 0};
  p.hi = {1, 2, 3};
  p.centers = {{0.1, 0.2, 0.3}, {0.4, 0.5, 0.6}};
  p.radii = {0.01, 0.02};
  const auto path = tempPath("p3.txt");
  writePacking<3>(path, p, "two spheres\nsecond comment line");
  EXPECT_EQ(packingFileDimension(path), 3);
  const auto q = readPacking<3>(path);
  EXPECT_EQ(q.centers.size(), 2u);
  EXPECT_NEAR(q.centers[1].y(), 0.5, 1e-12);
  EXPECT_NEAR(q.radii[1], 0.02, 1e-14);
  EXPECT_NEAR(q.hi.z(), 3.0, 1e-12);

  Packing<2> d;
  d.hi = {1, 1};
  d.centers = {{0.5, 0.5}};
  d.radii = {0.1};
  const auto path2 = tempPath("p2.txt");
  writePacking<2>(path2, d, "a disk");
  EXPECT_EQ(packingFileDimension(path2), 2);
  EXPECT_NEAR(readPacking<2>(path2).radii[0], 0.1, 1e-14);
  std::filesystem::remove(path);
  std::filesystem::remove(path2);
}

TEST(PackingIo, ErrorsNameFileAndLine) {
  const auto path = tempPath("bad.txt");
  {
    std::ofstream out(path);
    out << "# comment\n2\n0 1 0 1 0 1\n0.5 0.5 0.5 0.1\n0.5 0.5 oops 0.1\n";
  }
  try {
    readPacking<3>(path);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":5:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("oops"), std::string::npos) << e.what();
  }
  {
    std::ofstream out(path);
    out << "3\n0 1 0 1 0 1\n0.5 0.5 0.5 0.1\n";
  }
  EXPECT_THROW(readPacking<3>(path), std::runtime_error);  // ends early
  EXPECT_THROW(readPacking<2>(path), std::runtime_error);  // wrong dimension
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace rocklab
