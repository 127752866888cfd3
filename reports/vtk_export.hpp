#pragma once
// VTK XML export of frames for ParaView: particles (.vtp points with radius, velocity,
// displacement, ids), contacts and bonds (.vtp lines with their forces), walls (.vtp
// quads), and a .pvd collection that makes them a time series.

#include <string>
#include <vector>

#include "lab/core/frame.hpp"

namespace rocklab::reports {

struct PvdEntry {
  double time = 0.0;
  int part = 0;
  std::string file;  // relative to the .pvd
};

// Writes <dir>/<stem>_{particles,contacts,bonds,walls}.vtp; displacement is measured from
// `reference` (matched by particle id) when given. Returns the entries for a .pvd.
std::vector<PvdEntry> writeFrameVtk(const Frame& f, const Frame* reference, const std::string& dir,
                                    const std::string& stem);
void writePvd(const std::string& path, const std::vector<PvdEntry>& entries);

}  // namespace rocklab::reports
