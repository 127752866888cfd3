// The text formats of sample files: CSV, LIGGGHTS / LAMMPS data files, Yade text exports.

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "lab/samples/sample_files.hpp"

namespace rocklab::sample_formats {

namespace {

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r"), b = s.find_last_not_of(" \t\r");
  return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}

// A text file read line by line, its errors at "file:line: ".
class Lines {
 public:
  explicit Lines(const std::string& path) : path_(path), in_(path) {
    if (!in_) throw std::runtime_error(path + ": cannot read the sample file");
  }
  bool next(std::string& line) {
    if (!std::getline(in_, line)) return false;
    ++line_;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  }
  [[noreturn]] void fail(const std::string& why) const {
    throw std::runtime_error(path_ + ":" + std::to_string(line_) + ": " + why);
  }
  [[noreturn]] void failAtEnd(const std::string& why) const {
    throw std::runtime_error(path_ + ": " + why);
  }
  double number(const std::string& token, const std::string& what) const {
    char* end = nullptr;
    const double x = std::strtod(token.c_str(), &end);
    if (token.empty() || *end != '\0' || !std::isfinite(x)) {
      fail(what + ": '" + token + "' is not a finite number");
    }
    return x;
  }

 private:
  std::string path_;
  std::ifstream in_;
  int line_ = 0;
};

std::vector<std::string> splitOn(const std::string& line, char sep) {
  std::vector<std::string> out;
  if (sep == ' ') {
    std::istringstream s(line);
    for (std::string t; s >> t;) out.push_back(t);
    return out;
  }
  std::string cell;
  std::istringstream s(line);
  while (std::getline(s, cell, sep)) out.push_back(trim(cell));
  if (!line.empty() && line.back() == sep) out.emplace_back();
  return out;
}

// Metres per unit of a unit's name in a header ("mm", "um"), none when unknown.
std::optional<double> metresPer(const std::string& u) {
  static const std::map<std::string, double> units = {{"m", 1.0},   {"cm", 1e-2}, {"mm", 1e-3},
                                                      {"um", 1e-6}, {"µm", 1e-6}, {"micron", 1e-6}};
  const auto it = units.find(u);
  if (it == units.end()) return std::nullopt;
  return it->second;
}

void checkRadius(const Lines& in, double r) {
  if (!(r > 0.0)) in.fail("a particle radius must be positive");
}

}  // namespace

// CSV: a header naming x, y, optionally z, and r (or radius, d, diameter), each with its
// unit as `x_mm`, `x [mm]`, `x (mm)` or `x/mm` (else `unit`); other columns are ignored.
SampleFileData readCsv(const std::string& path, double unit) {
  Lines in(path);
  std::string line;
  do {
    if (!in.next(line)) in.failAtEnd("the file ends before the header line (x, y, [z,] r)");
  } while (trim(line).empty() || trim(line)[0] == '#');
  const char sep = line.find(',') != std::string::npos    ? ','
                   : line.find(';') != std::string::npos  ? ';'
                   : line.find('\t') != std::string::npos ? '\t'
                                                          : ' ';
  struct Column {
    int index = -1;
    double scale = 1.0;  // metres per value (a diameter's is half that, for the radius)
  };
  std::map<std::string, Column> cols;  // x, y, z, r
  const auto header = splitOn(line, sep);
  for (std::size_t k = 0; k < header.size(); ++k) {
    std::string h = lower(trim(header[k])), name = h, u;
    for (const char* open : {"[", "(", "/", "_"}) {
      const auto at = h.find(open);
      if (at == std::string::npos) continue;
      name = trim(h.substr(0, at));
      u = trim(h.substr(at + 1));
      if (!u.empty() && (u.back() == ']' || u.back() == ')')) u.pop_back();
      u = trim(u);
      break;
    }
    std::string role = name == "radius" ? "r" : name == "diameter" ? "d" : name;
    if (role != "x" && role != "y" && role != "z" && role != "r" && role != "d") continue;
    std::optional<double> scale = unit;
    if (!u.empty()) {
      scale = metresPer(u);
      if (!scale) in.fail("column '" + header[k] + "': unknown unit '" + u + "' (m, cm, mm, um)");
    }
    if (role == "d") role = "r", *scale *= 0.5;
    if (cols.count(role)) in.fail("two columns give " + role);
    cols[role] = {static_cast<int>(k), *scale};
  }
  for (const char* need : {"x", "y", "r"}) {
    if (!cols.count(need)) {
      in.fail("the header names no column '" + std::string(need) +
              "': expected x, y, [z,] r (or radius, d, diameter), with units as x_mm or x [mm]");
    }
  }
  SampleFileData d;
  d.dimension = cols.count("z") ? 3 : 2;
  while (in.next(line)) {
    if (trim(line).empty() || trim(line)[0] == '#') continue;
    const auto cells = splitOn(line, sep);
    std::array<double, 4> v{0, 0, 0, 0};
    int slot = 0;
    for (const char* role : {"x", "y", "z", "r"}) {
      const auto it = cols.find(role);
      if (it != cols.end()) {
        if (it->second.index >= static_cast<int>(cells.size())) {
          in.fail("expected " + std::to_string(header.size()) + " columns as the header, found " +
                  std::to_string(cells.size()));
        }
        v[slot] =
            in.number(cells[it->second.index], "column " + std::string(role)) * it->second.scale;
      }
      ++slot;
    }
    checkRadius(in, v[3]);
    d.centers.push_back({v[0], v[1], v[2]});
    d.radii.push_back(v[3]);
  }
  return d;
}

// A LAMMPS / LIGGGHTS data file (read_data): the header's "N atoms" and box bounds, then
// the Atoms section of atom_style sphere or granular: id type diameter density x y z
// [ix iy iz]. Other sections are skipped.
SampleFileData readLammps(const std::string& path, double unit) {
  Lines in(path);
  std::string line;
  if (!in.next(line)) in.failAtEnd("empty file: expected a LAMMPS data file");  // the title
  SampleFileData d;
  std::array<double, 6> box{0, 0, 0, 0, 0, 0};
  int bounds = 0;
  long long atoms = -1;
  auto words = [](const std::string& l) { return splitOn(trim(l.substr(0, l.find('#'))), ' '); };
  bool in_atoms = false, skipping = false;
  while (in.next(line)) {
    const auto w = words(line);
    if (w.empty()) continue;
    const bool keyword = std::isalpha(static_cast<unsigned char>(w[0][0]));
    if (keyword) {
      in_atoms = w[0] == "Atoms";
      skipping = !in_atoms;
      if (in_atoms) {
        const auto hash = line.find('#');
        const std::string style = hash == std::string::npos ? "" : trim(line.substr(hash + 1));
        if (!style.empty() && style != "sphere" && style != "granular") {
          in.fail("Atoms of atom_style " + style +
                  ": rocklab reads atom_style sphere or granular (id type diameter density x y z)");
        }
        if (atoms < 0) in.fail("the header gives no 'N atoms' line before the Atoms section");
        if (bounds != 3) in.fail("the header gives no xlo xhi, ylo yhi and zlo zhi lines");
      }
      continue;
    }
    if (in_atoms) {
      if (w.size() != 7 && w.size() != 10) {
        in.fail(
            "an atom line of atom_style sphere / granular has 7 values (id type diameter "
            "density x y z) or 10 (with image flags), found " +
            std::to_string(w.size()));
      }
      const double dia = in.number(w[2], "diameter") * unit;
      checkRadius(in, dia);
      d.centers.push_back(
          {in.number(w[4], "x") * unit, in.number(w[5], "y") * unit, in.number(w[6], "z") * unit});
      d.radii.push_back(0.5 * dia);
      continue;
    }
    if (skipping) continue;
    // The header: counts and box bounds.
    if (w.size() == 2 && w[1] == "atoms") {
      atoms = static_cast<long long>(in.number(w[0], "the atom count"));
    } else if (w.size() == 4 && (w[2] == "xlo" || w[2] == "ylo" || w[2] == "zlo")) {
      const int a = w[2][0] - 'x';
      box[2 * a] = in.number(w[0], w[2]) * unit;
      box[2 * a + 1] = in.number(w[1], w[3]) * unit;
      ++bounds;
    } else if (w.size() == 6 && w[3] == "xy") {
      in.fail("a triclinic box (xy xz yz): rocklab's walls make an orthogonal box");
    }
  }
  if (atoms < 0) in.failAtEnd("no 'N atoms' line: expected a LAMMPS data file");
  if (static_cast<long long>(d.centers.size()) != atoms) {
    in.failAtEnd("the header says " + std::to_string(atoms) + " atoms, the Atoms section lists " +
                 std::to_string(d.centers.size()));
  }
  d.box = box;
  return d;
}

// yade.export.text / textExt: a "#format x_y_z_r[_...]" line, then the columns it names;
// without it, "x y z r" (3D) or "x y r" (2D) per line.
SampleFileData readYade(const std::string& path, double unit) {
  Lines in(path);
  std::string line;
  std::vector<std::string> names;
  SampleFileData d;
  std::size_t width = 0;
  while (in.next(line)) {
    const std::string t = trim(line);
    if (t.empty()) continue;
    if (t[0] == '#') {
      if (t.rfind("#format", 0) == 0 && names.empty()) {
        std::string f = trim(t.substr(7));
        for (char& c : f) c = c == '_' ? ' ' : c;
        names = splitOn(f, ' ');
        if (std::find(names.begin(), names.end(), "r") == names.end() ||
            std::find(names.begin(), names.end(), "x") == names.end() ||
            std::find(names.begin(), names.end(), "y") == names.end()) {
          in.fail("the #format line names no x, y and r");
        }
      }
      continue;
    }
    const auto w = splitOn(t, ' ');
    if (names.empty()) {
      if (w.size() != 3 && w.size() != 4) {
        in.fail("expected x y z r (or x y r in 2D) per line, found " + std::to_string(w.size()) +
                " values (a #format line names other columns)");
      }
      names = w.size() == 4 ? std::vector<std::string>{"x", "y", "z", "r"}
                            : std::vector<std::string>{"x", "y", "r"};
    }
    if (width == 0) width = w.size();
    if (w.size() < names.size() || w.size() != width) {
      in.fail("expected " + std::to_string(std::max(width, names.size())) + " values, found " +
              std::to_string(w.size()));
    }
    std::array<double, 3> x{0, 0, 0};
    double r = 0.0;
    for (std::size_t k = 0; k < names.size(); ++k) {
      const std::string& n = names[k];
      if (n == "x" || n == "y" || n == "z") x[n[0] - 'x'] = in.number(w[k], n) * unit;
      if (n == "r") r = in.number(w[k], "r") * unit;
    }
    checkRadius(in, r);
    d.centers.push_back(x);
    d.radii.push_back(r);
  }
  d.dimension = std::find(names.begin(), names.end(), "z") == names.end() ? 2 : 3;
  return d;
}

}  // namespace rocklab::sample_formats
