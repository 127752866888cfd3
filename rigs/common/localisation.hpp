#pragma once
// Localisation: the failure band in a cloud of damage (broken-bond positions, or the most
// strained particles). Every plane (2D: line) orientation is tried; the points are
// projected on its normal and counted in a sliding window of the trial band's width; the
// band is the orientation and offset whose count stands out most, in Poisson standard
// deviations, from that of a uniform cloud in the points' bounding box (a Hough transform
// with a box kernel, normalised as a scan statistic). Counted raw, the longest windows
// win: on uniform damage in a sample twice as tall as wide the "band" ran along the axis
// or a diagonal, and a band normal to sigma_1, across the short side, lost to them. Windows that
// cut less than the box's smallest cross-section (a corner) are left out: a band crosses the
// sample. Its angle to the axial (sigma_1) direction, its thickness and its contrast over a uniform
// cloud follow. A band within 20 degrees of normal to sigma_1 is a compaction band (Li & Holt
// section 2.3: "a failure zone normal to maximum principal stress"; Olsson 1999), an inclined one
// a shear band.

#include <array>
#include <vector>

namespace rocklab::rigs {

struct Band {
  double angle_to_axial_deg = 0.0;  // between the band (its plane) and the sigma_1 axis, 0..90
  // m, sqrt(12) standard deviations of the points within one trial width of the band's
  // centre: the width of a uniform band with their spread
  double thickness = 0.0;
  double offset = 0.0;             // m, position of the band's centre along its normal
  std::array<double, 3> normal{};  // unit normal of the band
  // points in the band over those a uniform cloud in the same box would put there (about
  // 1.6 at the most for uniform damage: the best of many noisy windows)
  double contrast = 0.0;
  std::size_t points = 0;  // points in the band
  bool is_compaction() const { return angle_to_axial_deg >= 70.0; }
};

// `points` in 2 or 3 dimensions (z ignored in 2D), `axial` the sigma_1 axis (1: y in 2D,
// 2: z in 3D), `width` the trial band width (m). Needs at least 10 points; the
// orientations are tried every 0.25 degrees (2D) or on 20,000 directions (3D, about 0.8
// degrees apart).
Band findBand(const std::vector<std::array<double, 3>>& points, int dimension, int axial,
              double width);

// The incremental strain field between two states of the same particles (`before`, `after`,
// positions in the same order): each particle's strain is the symmetric part of the
// least-squares displacement gradient of its neighbours within `reach` (m) of it in
// `before` (at least `dimension` + 1 of them, else not measured: both parts 0).
struct LocalStrain {
  double shear = 0.0;       // Frobenius norm of the deviatoric part
  double compaction = 0.0;  // minus the trace: volume lost per volume
};
std::vector<LocalStrain> localStrain(const std::vector<std::array<double, 3>>& before,
                                     const std::vector<std::array<double, 3>>& after, int dimension,
                                     double reach);

// Which part of the strain a band is sought in: shear for dilatant (faulting) tests,
// compaction for compactive ones (a compaction band is a zone of localised compaction).
enum class StrainPart { Shear, Compaction };

// The positions (in `before`) of the particles whose `part` of the local strain is in the
// top `fraction` of those farther than `reach` from the sample's faces (near them,
// neighbourhoods are one-sided and the platens drag the particles): where the deformation
// concentrated, the points the band is sought in.
std::vector<std::array<double, 3>> strainedParticles(
    const std::vector<std::array<double, 3>>& before,
    const std::vector<std::array<double, 3>>& after, int dimension, double reach, double fraction,
    StrainPart part);

}  // namespace rocklab::rigs
