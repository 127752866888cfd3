#pragma once
// Snapshots of a state frame rendered off screen: particles coloured by a field, broken
// bonds marked by mode, a colour bar and a scale. For 3D samples a cutaway view (the half
// behind the mid-plane y = centre, seen obliquely) and the 2D slice on that plane; for 2D
// samples the disks themselves.

#include <array>
#include <string>
#include <vector>

#include "lab/core/frame.hpp"

namespace rocklab::reports {

struct BreakMark {
  std::array<double, 3> position{};  // m
  bool tensile = true;
  bool intragranular = false;  // a grain crushing: drawn apart from the cement's breaks
};

struct FieldValues {
  std::string label;           // e.g. "displacement (mm)"
  std::vector<double> values;  // one per particle of the frame
  double lo = 0.0, hi = 1.0;   // colour range
};

// 3D samples: the cutaway view; 2D samples: the disks.
void renderView(const Frame& f, const FieldValues& field, const std::vector<BreakMark>& breaks,
                const std::string& title, const std::string& png);
// 3D samples only: the section of the sample by the plane y = centre.
void renderSlice(const Frame& f, const FieldValues& field, const std::vector<BreakMark>& breaks,
                 const std::string& title, const std::string& png);

}  // namespace rocklab::reports
