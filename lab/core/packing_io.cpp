#include "lab/core/packing_io.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace rocklab {

namespace {

class LineReader {
 public:
  explicit LineReader(const std::string& path) : path_(path), in_(path) {
    if (!in_) throw std::runtime_error("cannot open packing file '" + path + "'");
  }
  // The next non-comment, non-blank line split into numbers.
  std::vector<double> numbers(const char* what) {
    std::string line;
    while (std::getline(in_, line)) {
      ++line_;
      const auto first = line.find_first_not_of(" \t\r");
      if (first == std::string::npos || line[first] == '#') continue;
      std::istringstream s(line);
      std::vector<double> v;
      std::string tok;
      while (s >> tok) {
        char* end = nullptr;
        const double x = std::strtod(tok.c_str(), &end);
        if (end == tok.c_str() || *end != '\0' || !std::isfinite(x)) {
          fail(std::string("'") + tok + "' is not a finite number (" + what + ")");
        }
        v.push_back(x);
      }
      return v;
    }
    fail(std::string("the file ends before ") + what);
  }
  [[noreturn]] void fail(const std::string& why) const {
    throw std::runtime_error(path_ + ":" + std::to_string(line_) + ": " + why);
  }

 private:
  std::string path_;
  std::ifstream in_;
  int line_ = 0;
};

}  // namespace

int packingFileDimension(const std::string& path) {
  LineReader in(path);
  in.numbers("the particle count");
  const auto walls = in.numbers("the wall line");
  if (walls.size() == 6) return 3;
  if (walls.size() == 4) return 2;
  in.fail("the wall line needs 4 (2D) or 6 (3D) values, found " + std::to_string(walls.size()));
}

template <int D>
Packing<D> readPacking(const std::string& path) {
  LineReader in(path);
  const auto n = in.numbers("the particle count");
  if (n.size() != 1 || n[0] < 1 || n[0] != std::floor(n[0])) {
    in.fail("expected the particle count, a positive integer");
  }
  const auto walls = in.numbers("the wall line");
  if (walls.size() != 2 * D) {
    in.fail("the wall line needs " + std::to_string(2 * D) + " values for a " + std::to_string(D) +
            "D packing, found " + std::to_string(walls.size()));
  }
  Packing<D> p;
  for (int d = 0; d < D; ++d) {
    p.lo[d] = walls[2 * d];
    p.hi[d] = walls[2 * d + 1];
    if (!(p.hi[d] > p.lo[d])) in.fail("a wall pair has max <= min");
  }
  const auto count = static_cast<std::size_t>(n[0]);
  p.centers.reserve(count);
  p.radii.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const auto v = in.numbers("all particles are listed");
    if (v.size() != D + 1) {
      in.fail("a particle line needs " + std::to_string(D + 1) + " values, found " +
              std::to_string(v.size()));
    }
    if (!(v[D] > 0.0)) in.fail("a particle radius must be positive");
    Vec<D> x;
    for (int d = 0; d < D; ++d) x[d] = v[d];
    p.centers.push_back(x);
    p.radii.push_back(v[D]);
  }
  return p;
}

template <int D>
void writePacking(const std::string& path, const Packing<D>& packing, const std::string& comment) {
  const std::string tmp = path + ".partial";
  {
    std::ofstream out(tmp);
    if (!out) throw std::runtime_error("cannot write packing file '" + tmp + "'");
    std::istringstream lines(comment);
    for (std::string line; std::getline(lines, line);) out << "# " << line << '\n';
    out << packing.centers.size() << '\n';
    out.precision(16);  // 17 significant digits: a double survives the round trip
    out << std::scientific;
    for (int d = 0; d < D; ++d) out << (d ? " " : "") << packing.lo[d] << ' ' << packing.hi[d];
    out << '\n';
    for (std::size_t i = 0; i < packing.centers.size(); ++i) {
      for (int d = 0; d < D; ++d) out << packing.centers[i][d] << ' ';
      out << packing.radii[i] << '\n';
    }
    if (!out) throw std::runtime_error("writing packing file '" + tmp + "' failed");
  }
  std::filesystem::rename(tmp, path);
}

template Packing<2> readPacking<2>(const std::string&);
template Packing<3> readPacking<3>(const std::string&);
template void writePacking<2>(const std::string&, const Packing<2>&, const std::string&);
template void writePacking<3>(const std::string&, const Packing<3>&, const std::string&);

}  // namespace rocklab
