#pragma once
// Packing files, the format of the benchmark packings (data/peers): lines starting with
// '#' are comments; then N; then the wall inner faces "xmin xmax ymin ymax [zmin zmax]"
// (m); then one particle per line "x y [z] r" (m). Four wall values make a 2D file.

#include <string>

#include "lab/core/packing.hpp"

namespace rocklab {

// The dimension of a packing file (2 or 3), read from its wall line.
int packingFileDimension(const std::string& path);

// Reads a packing; errors name the file and line.
template <int D>
Packing<D> readPacking(const std::string& path);

// Writes a packing with `comment` lines first; written to a temporary file and renamed.
template <int D>
void writePacking(const std::string& path, const Packing<D>& packing, const std::string& comment);

}  // namespace rocklab
