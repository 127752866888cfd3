// VTK PolyData samples (.vtp): the points are the centres, a point-data array the radii
// (named radius, radii, r, or diameter / d for diameters), in any encoding VTK writes.

#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataReader.h>

#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "lab/samples/sample_files.hpp"

namespace rocklab::sample_formats {

namespace {

// VTK prints its parse errors and carries on with an empty output: the file is checked to
// be VTK XML PolyData first, so that the error says what was expected.
void checkHeader(const std::string& path) {
  std::ifstream in(path);
  std::string head(512, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  if (head.find("<VTKFile") == std::string::npos || head.find("PolyData") == std::string::npos) {
    throw std::runtime_error(path +
                             ":1: expected a VTK XML PolyData file (<VTKFile type=\"PolyData\">)");
  }
}

}  // namespace

SampleFileData readVtp(const std::string& path, double unit) {
  checkHeader(path);
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(path.c_str());
  reader->GlobalWarningDisplayOff();
  reader->Update();
  vtkPolyData* poly = reader->GetOutput();
  if (reader->GetErrorCode() != 0 || !poly || poly->GetNumberOfPoints() == 0) {
    throw std::runtime_error(path + ": VTK could not read points from this PolyData file");
  }
  vtkPointData* pd = poly->GetPointData();
  vtkDataArray* radii = nullptr;
  double scale = unit;
  std::string names;
  for (int k = 0; k < pd->GetNumberOfArrays(); ++k) {
    const char* raw = pd->GetArrayName(k);
    const std::string name = lower(raw ? raw : "");
    names += (names.empty() ? "" : ", ") + name;
    vtkDataArray* a = pd->GetArray(k);
    if (!a || a->GetNumberOfComponents() != 1) continue;
    if (name == "radius" || name == "radii" || name == "r") {
      radii = a, scale = unit;
      break;
    }
    if (name == "diameter" || name == "d") radii = a, scale = 0.5 * unit;
  }
  if (!radii) {
    throw std::runtime_error(path +
                             ": no point-data array of radii: expected one named radius "
                             "(or radii, r; diameter or d), the file has: " +
                             (names.empty() ? std::string("none") : names));
  }
  SampleFileData d;
  const vtkIdType n = poly->GetNumberOfPoints();
  for (vtkIdType i = 0; i < n; ++i) {
    double x[3];
    poly->GetPoint(i, x);
    const double r = radii->GetTuple1(i) * scale;
    if (!(r > 0.0) || !std::isfinite(r)) {
      throw std::runtime_error(path + ": point " + std::to_string(i) +
                               ": the radius must be positive, it is " + std::to_string(r));
    }
    d.centers.push_back({x[0] * unit, x[1] * unit, x[2] * unit});
    d.radii.push_back(r);
  }
  return d;
}

}  // namespace rocklab::sample_formats
