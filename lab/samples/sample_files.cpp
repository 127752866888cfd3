#include "lab/samples/sample_files.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "lab/core/packing_io.hpp"

namespace rocklab {

std::string sample_formats::lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

SampleFormat sampleFormatOf(const std::string& path) {
  const std::string ext = sample_formats::lower(std::filesystem::path(path).extension().string());
  if (ext == ".csv") return SampleFormat::Csv;
  if (ext == ".data" || ext == ".lmp" || ext == ".lammps") return SampleFormat::Lammps;
  if (ext == ".vtp") return SampleFormat::Vtp;
  if (ext == ".yade") return SampleFormat::Yade;
  if (ext == ".txt" || ext == ".packing") return SampleFormat::Rocklab;
  throw std::runtime_error(path + ": cannot tell the format from the extension '" + ext +
                           "': name it with sample.format (rocklab: .txt, .packing; csv: .csv; "
                           "lammps: .data, .lmp; yade: .yade; vtp: .vtp)");
}

namespace {

template <int D>
SampleFileData fromPacking(const Packing<D>& p) {
  SampleFileData d;
  d.dimension = D;
  d.format = SampleFormat::Rocklab;
  std::array<double, 6> box{0, 0, 0, 0, 0, 0};
  for (int a = 0; a < D; ++a) box[2 * a] = p.lo[a], box[2 * a + 1] = p.hi[a];
  d.box = box;
  for (std::size_t i = 0; i < p.centers.size(); ++i) {
    std::array<double, 3> x{0, 0, 0};
    for (int a = 0; a < D; ++a) x[a] = p.centers[i][a];
    d.centers.push_back(x);
    d.radii.push_back(p.radii[i]);
  }
  return d;
}

}  // namespace

SampleFileData readSampleFile(const std::string& path, SampleFormat format, double unit) {
  if (!std::filesystem::is_regular_file(path)) {
    throw std::runtime_error(path + ": no such file (sample.file is relative to the protocol)");
  }
  if (format == SampleFormat::Auto) format = sampleFormatOf(path);
  SampleFileData d;
  switch (format) {
    case SampleFormat::Rocklab:
      // The packing format is in metres by definition: `unit` does not apply.
      d = packingFileDimension(path) == 2 ? fromPacking<2>(readPacking<2>(path))
                                          : fromPacking<3>(readPacking<3>(path));
      break;
    case SampleFormat::Csv:
      d = sample_formats::readCsv(path, unit);
      break;
    case SampleFormat::Lammps:
      d = sample_formats::readLammps(path, unit);
      break;
    case SampleFormat::Yade:
      d = sample_formats::readYade(path, unit);
      break;
    case SampleFormat::Vtp:
      d = sample_formats::readVtp(path, unit);
      break;
    case SampleFormat::Auto:
      break;
  }
  d.format = format;
  if (d.centers.size() < 2) {
    throw std::runtime_error(path + ": a sample needs at least 2 particles, the file has " +
                             std::to_string(d.centers.size()));
  }
  return d;
}

template <int D>
Packing<D> samplePacking(const SampleFileData& data, const std::string& path) {
  if (data.dimension < D) {
    throw std::runtime_error(path +
                             ": the file is 2D (no z), the protocol 3D (protocol.dimension)");
  }
  Packing<D> p;
  // The extent of the particles, and the box the file gives (which must hold them).
  Vec<D> lo = Vec<D>::Constant(1e300), hi = Vec<D>::Constant(-1e300);
  for (std::size_t i = 0; i < data.centers.size(); ++i) {
    Vec<D> x;
    for (int a = 0; a < D; ++a) x[a] = data.centers[i][a];
    lo = lo.cwiseMin(x - Vec<D>::Constant(data.radii[i]));
    hi = hi.cwiseMax(x + Vec<D>::Constant(data.radii[i]));
    p.centers.push_back(x);
    p.radii.push_back(data.radii[i]);
  }
  if (D == 2 && data.dimension == 3) {
    const double z0 = data.centers.front()[2];
    double spread = 0.0;
    for (const auto& c : data.centers) spread = std::max(spread, std::abs(c[2] - z0));
    if (spread > 1e-9 * (hi - lo).maxCoeff()) {
      throw std::runtime_error(path + ": the protocol is 2D but the particles' z spans " +
                               std::to_string(spread) +
                               " m: a 2D sample is one layer (all z equal) or a file without z");
    }
  }
  p.lo = lo, p.hi = hi;
  if (data.box) {
    const auto& b = *data.box;
    for (int a = 0; a < D; ++a) {
      const double tol = 1e-9 * (hi[a] - lo[a]);
      if (!(b[2 * a + 1] > b[2 * a])) {
        throw std::runtime_error(path + ": the file's box has max <= min along axis " +
                                 std::to_string(a));
      }
      // A particle centre outside the box would start inside a wall.
      for (const auto& x : p.centers) {
        if (x[a] < b[2 * a] - tol || x[a] > b[2 * a + 1] + tol) {
          throw std::runtime_error(path + ": a particle centre lies outside the file's box along " +
                                   std::string(1, "xyz"[a]));
        }
      }
      p.lo[a] = b[2 * a], p.hi[a] = b[2 * a + 1];
    }
  }
  return p;
}

template Packing<2> samplePacking<2>(const SampleFileData&, const std::string&);
template Packing<3> samplePacking<3>(const SampleFileData&, const std::string&);

}  // namespace rocklab
