#include "lab/core/frame.hpp"

#include <cstring>
#include <filesystem>
#include <fstream>

#include "lab/core/simulation.hpp"

namespace rocklab {

namespace {

constexpr char kMagic[8] = {'R', 'K', 'L', 'B', 'F', 'R', 'A', 'M'};

template <int D>
std::array<double, 3> three(const Vec<D>& v) {
  std::array<double, 3> a{0.0, 0.0, 0.0};
  for (int d = 0; d < D; ++d) a[d] = v[d];
  return a;
}

}  // namespace

template <int D>
Frame captureFrame(const Simulation<D>& sim) {
  const auto& P = sim.particles();
  Frame f;
  f.dimension = D;
  f.step = sim.steps();
  f.time = sim.time();
  f.thickness = P.thickness;
  const std::size_t n = P.size();
  f.slot = P.slot_of;
  f.pos.resize(n);
  f.vel.resize(n);
  f.radius = P.radius;
  f.cluster = P.cluster;
  f.spin.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    f.pos[i] = three<D>(P.pos[i]);
    f.vel[i] = three<D>(P.vel[i]);
    f.spin[i] = angNorm(P.spin[i]);
  }
  for (const auto& c : sim.contactForces()) {
    f.contacts.push_back({P.slot_of[c.i], P.slot_of[c.j], c.normal, c.tangential});
  }
  const auto& B = sim.bonds();
  for (std::size_t b = 0; b < B.size(); ++b) {
    if (!B.intact(b)) continue;  // a flat joint broken through is a frictional interface
    const bool joint = !B.face[b].empty();
    f.bonds.push_back({P.slot_of[B.i[b]], P.slot_of[B.j[b]],
                       joint ? B.face[b].normal_force : B.load[b].fn,
                       joint ? B.face[b].shear_force : B.load[b].fs.norm()});
    f.bond_kind.push_back(B.kind[b]);
  }
  for (const auto& w : sim.walls())
    f.walls.push_back({w.name, three<D>(w.point), three<D>(w.normal)});
  return f;
}

std::string encodeFrame(const Frame& f) {
  ArchiveWriter w;
  const_cast<Frame&>(f).visit(w);
  w("cluster", f.cluster);
  std::string out(kMagic, sizeof kMagic);
  const std::uint32_t version = Frame::kVersion;
  out.append(reinterpret_cast<const char*>(&version), sizeof version);
  return out + w.bytes();
}

Frame decodeFrame(const std::string& bytes, const std::string& where) {
  if (bytes.size() < 12 || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0) {
    throw CheckpointError("'" + where + "' is not a rocklab frame");
  }
  std::uint32_t version;
  std::memcpy(&version, bytes.data() + 8, 4);
  if (version < 1 || version > Frame::kVersion) {
    throw CheckpointError("frame '" + where + "' has format version " + std::to_string(version) +
                          "; this rocklab reads version " + std::to_string(Frame::kVersion));
  }
  Frame f;
  ArchiveReader r(bytes.data() + 12, bytes.size() - 12);
  f.visit(r);
  if (version >= 2) r("cluster", f.cluster);
  return f;
}

void writeFrame(const std::string& path, const Frame& f) {
  const std::string bytes = encodeFrame(f);
  const std::string tmp = path + ".partial";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw CheckpointError("cannot write frame '" + tmp + "'");
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out) throw CheckpointError("writing frame '" + tmp + "' failed");
  }
  std::filesystem::rename(tmp, path);
}

Frame readFrame(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw CheckpointError("cannot open frame '" + path + "'");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return decodeFrame(bytes, path);
}

template Frame captureFrame<2>(const Simulation<2>&);
template Frame captureFrame<3>(const Simulation<3>&);

}  // namespace rocklab
