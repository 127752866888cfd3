#pragma once
// A frame: what an observer needs of the state at one instant to draw or export it —
// particles (with their stable ids), touching contacts and intact bonds with their forces,
// and the walls. Positions are stored as 3-vectors (z = 0 in 2D) so that readers need no
// dimension. Frames are written with the checkpoint serializer (one schema both ways).

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "lab/core/archive.hpp"

namespace rocklab {

template <int D>
class Simulation;

struct Frame {
  // Version 2 added `cluster`; version 1 frames still read (without it).
  static constexpr std::uint32_t kVersion = 2;
  int dimension = 3;
  std::uint64_t step = 0;
  double time = 0.0;
  double thickness = 1.0;  // 2D disk thickness

  std::vector<std::uint32_t> slot;  // stable particle ids
  std::vector<std::array<double, 3>> pos, vel;
  std::vector<double> radius;
  std::vector<double> spin;            // |spin| (rad/s)
  std::vector<std::uint32_t> cluster;  // grain of each particle (kNoCluster: none; v2)

  struct Link {
    std::uint32_t a = 0, b = 0;  // particle slots
    double normal = 0.0;         // N, compression positive
    double tangential = 0.0;     // N, magnitude
    template <class Archive>
    void visit(Archive& ar) {
      ar("a", a), ar("b", b), ar("normal", normal), ar("tangential", tangential);
    }
  };
  std::vector<Link> contacts;  // touching particle pairs
  std::vector<Link> bonds;     // intact bonds
  std::vector<std::uint8_t> bond_kind;

  struct Plane {
    std::string name;
    std::array<double, 3> point{}, normal{};
    template <class Archive>
    void visit(Archive& ar) {
      ar("name", name), ar("point", point), ar("normal", normal);
    }
  };
  std::vector<Plane> walls;

  std::size_t size() const { return slot.size(); }

  template <class Archive>
  void visit(Archive& ar) {
    ar("dimension", dimension), ar("step", step), ar("time", time), ar("thickness", thickness);
    ar("slot", slot), ar("pos", pos), ar("vel", vel), ar("radius", radius), ar("spin", spin);
    ar("contacts", contacts), ar("bonds", bonds), ar("bond_kind", bond_kind), ar("walls", walls);
  }
};

template <int D>
Frame captureFrame(const Simulation<D>& sim);

// Binary frame files: a magic word, the format version, then the serialized frame.
std::string encodeFrame(const Frame& f);
Frame decodeFrame(const std::string& bytes, const std::string& where);
void writeFrame(const std::string& path, const Frame& f);
Frame readFrame(const std::string& path);

}  // namespace rocklab
