// Checkpoints: one serializer both ways, bit-for-bit restarts, and refusal of files that
// are truncated, damaged or from another format version.

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "lab/core/archive.hpp"
#include "lab/core/frame.hpp"
#include "lab/core/packing.hpp"
#include "tests/support.hpp"

namespace rocklab {
namespace {

using V3 = Eigen::Vector3d;

std::string tempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("rocklab-" + std::to_string(::getpid()) + "-" + name))
      .string();
}

struct Inner {
  double a = 0;
  std::vector<V3> v;
  template <class Ar>
  void visit(Ar& ar) {
    ar("a", a), ar("v", v);
  }
};

TEST(Archive, RoundTripsNestedFields) {
  Inner in{3.5, {V3(1, 2, 3), V3(4, 5, 6)}};
  std::vector<Inner> many{in, Inner{-1, {}}};
  std::string s = "text";
  std::array<std::uint64_t, 2> arr{7, 8};
  ArchiveWriter w;
  w("inner", in), w("many", many), w("s", s), w("arr", arr);

  Inner out;
  std::vector<Inner> many_out;
  std::string s_out;
  std::array<std::uint64_t, 2> arr_out{};
  ArchiveReader r(w.bytes().data(), w.bytes().size());
  r("inner", out), r("many", many_out), r("s", s_out), r("arr", arr_out);
  EXPECT_TRUE(r.atEnd());
  EXPECT_EQ(out.a, 3.5);
  EXPECT_EQ(out.v[1], V3(4, 5, 6));
  EXPECT_EQ(many_out.size(), 2u);
  EXPECT_EQ(many_out[1].a, -1);
  EXPECT_EQ(s_out, "text");
  EXPECT_EQ(arr_out[1], 8u);

  ArchiveReader bad(w.bytes().data(), w.bytes().size());
  double x;
  EXPECT_THROW(bad("other", x), CheckpointError);
}

// A small but complete scene: friction, rotation, damping, a servo wall and moving walls.
Simulation<3> scene() {
  PackingSpec spec;
  spec.count = 150;
  spec.sizes = SizeDistribution::uniform(1.6e-3, 2.4e-3);
  spec.porosity = 0.45;
  spec.seed = 5;
  const Packing<3> p = generatePacking<3>(spec);
  SimulationConfig cfg;
  cfg.contact_law = "hertz";
  cfg.local_damping = 0.3;
  cfg.timestep.update_interval = 37;
  cfg.skin = 2e-5;  // rebuilds during the run
  Simulation<3> sim(testing::table(testing::hertzMaterial(1e8, 0.3, 0.5, 0.1)), cfg);
  for (std::size_t i = 0; i < p.centers.size(); ++i) {
    testing::addParticle<3>(sim, p.centers[i], p.radii[i], V3::Zero());
  }
  testing::addBox<3>(sim, p.lo, p.hi);
  BondKind cement;
  cement.modulus = 1e8;
  cement.stiffness_ratio = 1.0;
  cement.tensile_mean = cement.shear_mean = 2e4;
  cement.tensile_std = cement.shear_std = 2e4;
  sim.cement(sim.addBondKind(cement), 0.2);
  for (int w = 0; w < 6; ++w) {
    ServoControl& s = sim.wall(w).servo;
    s.enabled = true;
    s.target_stress = 2e4;
    s.area = (p.hi - p.lo).prod() / (p.hi - p.lo)[w / 2];
    s.max_speed = 0.05;
  }
  return sim;
}

TEST(Checkpoint, RestartContinuesBitForBit) {
  Simulation<3> a = scene();
  a.run(700);
  const std::string path = tempPath("restart.ckpt");
  a.saveCheckpoint(path);
  a.run(900);
  ASSERT_GT(a.contacts().rebuilds, 2u);
  ASSERT_GT(a.particleContacts(), 100u);
  ASSERT_GT(a.bonds().size(), 0u);
  ASSERT_GT(a.brokenBonds(0, BondBreakMode::Tensile) + a.brokenBonds(0, BondBreakMode::Shear), 0u);

  Simulation<3> b = Simulation<3>::loadCheckpoint(path);
  EXPECT_EQ(b.steps(), 700u);
  b.run(900);
  EXPECT_EQ(a.stateHash(), b.stateHash());
  EXPECT_EQ(a.time(), b.time());
  EXPECT_EQ(a.energy().ledger.viscous, b.energy().ledger.viscous);
  EXPECT_EQ(a.bonds().size(), b.bonds().size());
  EXPECT_EQ(a.bondBreaks().size(), b.bondBreaks().size());
  std::filesystem::remove(path);
}

TEST(Frames, CaptureEncodeDecode) {
  Simulation<3> sim = scene();
  sim.run(50);
  const Frame f = captureFrame(sim);
  EXPECT_EQ(f.size(), sim.particles().size());
  EXPECT_EQ(f.bonds.size(), sim.bonds().size());
  EXPECT_EQ(f.contacts.size(), sim.particleContacts());
  EXPECT_EQ(f.walls.size(), 6u);
  const std::string path = tempPath("frame.rkf");
  writeFrame(path, f);
  const Frame g = readFrame(path);
  EXPECT_EQ(g.step, f.step);
  EXPECT_EQ(g.pos, f.pos);
  EXPECT_EQ(g.slot, f.slot);
  ASSERT_EQ(g.contacts.size(), f.contacts.size());
  EXPECT_EQ(g.contacts.back().normal, f.contacts.back().normal);
  EXPECT_EQ(g.walls[5].name, "zmax");
  std::filesystem::remove(path);
  EXPECT_THROW(decodeFrame("not a frame at all", "x"), CheckpointError);
}

// Version 2 frames carry each particle's grain; version 1 frames (written before grains
// existed) still read, without it.
TEST(Frames, GrainIdsRoundTripAndVersionOneFramesStillRead) {
  Simulation<3> sim = scene();
  Frame f = captureFrame(sim);
  ASSERT_EQ(f.cluster.size(), f.size());
  for (std::size_t i = 0; i < f.size(); ++i) f.cluster[i] = static_cast<std::uint32_t>(i / 3);
  const Frame g = decodeFrame(encodeFrame(f), "v2");
  EXPECT_EQ(g.cluster, f.cluster);

  ArchiveWriter w;
  f.visit(w);  // the version 1 layout: everything but the grains
  std::string v1 = encodeFrame(f).substr(0, 8);
  const std::uint32_t version = 1;
  v1.append(reinterpret_cast<const char*>(&version), sizeof version);
  const Frame h = decodeFrame(v1 + w.bytes(), "v1");
  EXPECT_EQ(h.pos, f.pos);
  EXPECT_TRUE(h.cluster.empty());

  std::string v3 = encodeFrame(f);
  v3[8] = 3;  // a version from the future is refused, not misread
  EXPECT_THROW(decodeFrame(v3, "v3"), CheckpointError);
}

class DamagedCheckpoint : public ::testing::Test {
 protected:
  void SetUp() override {
    Simulation<3> sim = scene();
    sim.run(10);
    sim.saveCheckpoint(path_);
    std::ifstream in(path_, std::ios::binary);
    bytes_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  void TearDown() override { std::filesystem::remove(path_); }
  void rewrite(const std::string& bytes) {
    std::ofstream out(path_, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  std::string refusal() {
    try {
      Simulation<3>::loadCheckpoint(path_);
    } catch (const CheckpointError& e) {
      return e.what();
    }
    return "";
  }
  std::string path_ = tempPath("damaged.ckpt");
  std::string bytes_;
};

TEST_F(DamagedCheckpoint, TruncatedFileIsRefused) {
  rewrite(bytes_.substr(0, bytes_.size() / 2));
  EXPECT_NE(refusal().find("truncated"), std::string::npos) << refusal();
}

TEST_F(DamagedCheckpoint, OtherFormatVersionIsRefused) {
  std::string b = bytes_;
  const std::uint32_t other = Simulation<3>::kCheckpointVersion + 1;
  std::memcpy(b.data() + 8, &other, 4);
  rewrite(b);
  EXPECT_NE(refusal().find("format version"), std::string::npos) << refusal();
}

TEST_F(DamagedCheckpoint, FlippedByteIsRefused) {
  std::string b = bytes_;
  b[b.size() / 2] ^= 0x10;
  rewrite(b);
  EXPECT_NE(refusal().find("damaged"), std::string::npos) << refusal();
}

TEST_F(DamagedCheckpoint, WrongDimensionAndForeignFilesAreRefused) {
  EXPECT_THROW(Simulation<2>::loadCheckpoint(path_), CheckpointError);
  rewrite("hello, this is not a checkpoint at all");
  EXPECT_NE(refusal().find("not a rocklab checkpoint"), std::string::npos) << refusal();
}

}  // namespace
}  // namespace rocklab
