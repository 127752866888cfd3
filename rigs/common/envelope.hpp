#pragma once
// The failure envelope of a rock from a sweep of confinements (Li & Holt, section 2.3,
// Figure 6): each test's critical point, where the sample turns to dilate or to compact,
// and the Mohr-Coulomb line (equation 1) through the dilatant ones; the compactive ones
// draw the end cap.

#include <cstddef>
#include <vector>

namespace rocklab::rigs {

// One test's record against axial strain: deviatoric stress q = sigma_1 - sigma_3 and
// volumetric strain (compaction positive), sampled at the same instants.
struct LoadingCurve {
  std::vector<double> axial_strain, q, volumetric_strain;
  template <class Archive>
  void visit(Archive& ar) {
    ar("axial_strain", axial_strain), ar("q", q), ar("volumetric_strain", volumetric_strain);
  }
};

struct CriticalPoint {
  bool found = false;
  // Dilatant: the sample turned to dilate, the point is the peak of q (the "dilatant peak").
  // Compactive: it never turned to dilate, the point is the onset of compactive yield:
  // where the volumetric strain rises 10% above its early (elastic) trend against axial
  // strain (shear-enhanced compaction, C* of Wong, David & Zhu 1997), or the deviatoric
  // stress falls 10% below its own, whichever comes first (a sample whose compaction
  // decelerates still yields: the cemented grains give way without faster compaction).
  bool compactive = false;
  std::size_t index = 0;
  double axial_strain = 0.0, q = 0.0, volumetric_strain = 0.0;
};

// A sample has turned to dilate when its volumetric strain at the end lies below its
// maximum by more than max(1e-4, 10% of that maximum): a margin above the servo walls'
// noise (about 1e-5 in the quick protocols). The elastic trends are the least-squares lines
// over the points between 5% and 25% of the final axial strain.
CriticalPoint criticalPoint(const LoadingCurve& c);

struct EnvelopePoint {
  double sigma3 = 0.0, sigma1 = 0.0;  // Pa
  bool compactive = false;
};

struct MohrCoulomb {
  bool fitted = false;
  double friction_angle_deg = 0.0;
  double ucs = 0.0;             // Pa, the intercept sigma_1 at sigma_3 = 0
  double passive_factor = 0.0;  // N = tan^2(45 deg + phi/2), the slope d sigma_1 / d sigma_3
  std::size_t points = 0;       // dilatant points fitted
  double rms_residual = 0.0;    // Pa
};

// Least squares of sigma_1 = N sigma_3 + UCS over the dilatant points (equation 1); needs
// two distinct confinements and N >= 1 (a non-negative friction angle), else not fitted.
MohrCoulomb fitMohrCoulomb(const std::vector<EnvelopePoint>& points);

}  // namespace rocklab::rigs
