#pragma once
// Samples a user brings (`sample.kind = "file"`): particles read from rocklab's packing
// format, CSV with a header naming the columns and their units, a LIGGGHTS / LAMMPS data
// file (atom_style sphere or granular), a Yade text export (yade.export.text: x y z r) or
// VTK PolyData (.vtp with a radius array). The box is the file's where it has one (packing
// walls, the data file's xlo xhi ...), else the particles' extent. A file without z is 2D.
// Errors name the file, the line where there is one, and what was expected.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "lab/core/packing.hpp"

namespace rocklab {

enum class SampleFormat { Auto, Rocklab, Csv, Lammps, Yade, Vtp };

// The format of a file by its extension; throws naming the extensions when it is unknown.
SampleFormat sampleFormatOf(const std::string& path);

// What a file holds, in metres, before it becomes a packing of a dimension.
struct SampleFileData {
  int dimension = 3;  // 2 when the file has no z
  std::vector<std::array<double, 3>> centers;
  std::vector<double> radii;
  std::optional<std::array<double, 6>> box;  // xmin xmax ymin ymax zmin zmax, when the file has one
  SampleFormat format = SampleFormat::Auto;
};

// Reads a sample file. `unit` is metres per length unit of the file where the file does
// not say (a CSV header may): 1 for SI, 1e-3 for mm. Throws std::runtime_error.
SampleFileData readSampleFile(const std::string& path, SampleFormat format, double unit);

// The packing of a sample file in D dimensions: a 3D file is accepted for a 2D protocol
// only when all its particles lie in one plane z = const; the box encloses every particle.
template <int D>
Packing<D> samplePacking(const SampleFileData& data, const std::string& path);

// The readers behind readSampleFile, one per format.
namespace sample_formats {
std::string lower(std::string s);  // ASCII lower case: names in headers, extensions
SampleFileData readCsv(const std::string& path, double unit);
SampleFileData readLammps(const std::string& path, double unit);
SampleFileData readYade(const std::string& path, double unit);
SampleFileData readVtp(const std::string& path, double unit);
}  // namespace sample_formats

}  // namespace rocklab
