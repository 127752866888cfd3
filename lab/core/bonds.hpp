#pragma once
// Parallel bonds (Potyondy & Cundall 2004, "A bonded-particle model for rock"): cement of
// radius R = lambda min(r1, r2) between two particles, acting in parallel with their
// contact law. The bond carries a normal force, a shear force, a bending moment and (3D) a
// twisting moment, all updated incrementally from the relative motion; it breaks when the
// largest tensile or shear stress at its periphery reaches its strength. As PFC 5's linear
// parallel bond, the shear strength may grow with the compression the bond carries (a
// friction angle) and the moments' share of those stresses may be scaled down.

#include <cstdint>
#include <string>
#include <vector>

#include "lab/core/contact_kernels.hpp"
#include "lab/core/dim.hpp"
#include "lab/core/fields.hpp"
#include "lab/core/flat_joint.hpp"
#include "lab/core/particles.hpp"

namespace rocklab {

// How a strength drawn at or below zero from normal(mean, std) is handled. With the paper's
// 8 +- 8 MPa about 16% of draws are <= 0. Such a bond would break under no load at all
// (its peripheral stress 0 already reaches its strength, as in PFC), so by default it is
// not installed and the contact stays uncemented (`Skip`); `Resample` draws again until
// positive (a truncated normal, which raises the mean strength).
enum class NegativeStrength : std::uint8_t { Skip, Resample };

enum class BondBreakMode : std::uint8_t { Tensile, Shear };

// A family of bonds with their properties. The defaults are the paper's cement (section
// 1: bond modulus 4 GPa, kn/ks 0.5, strengths 8 +- 8 MPa); `grains()` gives those of the
// intragranular bonds of breakable grains (section 2.2). One declaration serves both
// protocol sections, `bonds.*` and `grain_bonds.*`.
struct BondKind {
  std::string name = "cement";
  bool intragranular = false;
  double modulus = 4.0 * kGPa;       // Pa, bond modulus E: normal stiffness per area kn = E / L
  double stiffness_ratio = 0.5;      // -, kn / ks of the bond
  double radius_multiplier = 1.0;    // -, lambda
  double tensile_mean = 8.0 * kMPa;  // Pa
  double tensile_std = 8.0 * kMPa;   // Pa
  double shear_mean = 8.0 * kMPa;    // Pa
  double shear_std = 8.0 * kMPa;     // Pa
  // rad, phi: under a compressive normal stress sigma_n = Fn / A the shear strength is
  // c + sigma_n tan(phi), c the drawn shear strength (Mohr-Coulomb; Potyondy 2015, the
  // linear parallel bond's pb_fa). A tensile normal stress leaves it at c: tension is the
  // tensile criterion's. 0: a shear strength independent of the load, as in PFC 3 (the
  // paper's).
  double friction_angle = 0.0;
  // -, beta in [0, 1]: the share of the bending and twisting moments in the peak stresses,
  // sigma = -Fn / A + beta |Mb| R / I and tau = |Fs| / A + beta |Mt| R / J (PFC 5's moment
  // contribution factor, pb_mcf; Potyondy 2015). The moments still act on the particles.
  // 1: the full beam stresses (Potyondy & Cundall 2004, the paper's).
  double moment_factor = 1.0;
  NegativeStrength negative = NegativeStrength::Skip;
  // The cement's model: PFC's parallel bond, or its flat joint (flat_joint.hpp), whose face of
  // radius R carries the same stiffness cut into elements that break one by one. A flat joint
  // breaks on its elements' centroid stresses, so moment_factor does not apply to it;
  // tensile and shear strengths are its elements' tensile strength and cohesion.
  BondModel model = BondModel::Parallel;
  std::int64_t flat_joint_radial = 2;           // 2D: elements along the face; 3D: rings
  std::int64_t flat_joint_circumferential = 3;  // 3D: sectors per ring (PFC's usual 1 x 3)
  double flat_joint_friction = 0.5;             // -, friction coefficient of broken elements
  // PFC 5's slit elements (fj_slit; Potyondy 2012): the fraction of a flat joint's elements
  // installed unbonded, each drawn alone. They carry compression and friction but no tension
  // from the start: a cemented rock's grain boundaries are not cemented all over, and this is
  // what lets a flat-jointed material's tensile strength fall while its compressive strength
  // holds (UCS / sigma_t of 10 and more).
  double flat_joint_slit_fraction = 0.0;

  // The intragranular bonds of breakable grains: stiffer and stronger than the cement, and
  // never missing (a grain is not born cracked: draws <= 0 are drawn again).
  static BondKind grains();

  template <class F>
  void fields(F& f) {
    static constexpr Choice<NegativeStrength> kNegative[] = {
        {"skip", NegativeStrength::Skip}, {"resample", NegativeStrength::Resample}};
    // Strengths reach 1e5 MPa, beyond any rock's: an unbreakable bond is a legitimate choice
    // (benchmarks, and tests of one failure mode alone).
    const Range strength = Range::closed(-1e5, 1e5), spread = Range::closed(0, 1e5);
    f(modulus, {"modulus_GPa", units::GPa, Range::leftOpen(0, 1e4),
                "bond modulus E, normal stiffness per area kn = E / L (L = r1 + r2)"});
    f(stiffness_ratio,
      {"stiffness_ratio", units::none, Range::leftOpen(0, 100), "kn / ks of the bonds"});
    f(radius_multiplier, {"radius_multiplier", units::none, Range::leftOpen(0, 10),
                          "bond radius over the smaller particle radius"});
    f(tensile_mean, {"tensile_strength_mean_MPa", units::MPa, strength, "mean tensile strength"});
    f(tensile_std, {"tensile_strength_std_MPa", units::MPa, spread, "tensile strength std"});
    f(shear_mean, {"shear_strength_mean_MPa", units::MPa, strength, "mean shear strength"});
    f(shear_std, {"shear_strength_std_MPa", units::MPa, spread, "shear strength std"});
    f(friction_angle,
      {"friction_angle_deg", units::deg, Range::closed(0, 85),
       "bond friction angle: under a compressive normal stress sigma_n the shear strength is "
       "the drawn one plus sigma_n tan(angle) (PFC 5 pb_fa); 0: independent of load"});
    f(moment_factor, {"moment_factor", units::none, Range::closed(0, 1),
                      "share of the bending and twisting moments in the bond's peak stresses "
                      "(PFC 5 pb_mcf); 1: the full beam stresses"});
    f(negative,
      {"negative_strength",
       units::text,
       {},
       "a strength drawn <= 0: skip (no bond: it would break unloaded) or resample"},
      kNegative);
    static constexpr Choice<BondModel> kModel[] = {{"parallel", BondModel::Parallel},
                                                   {"flat_joint", BondModel::FlatJoint}};
    f(model,
      {"model",
       units::text,
       {},
       "parallel (Potyondy & Cundall 2004) or flat_joint (Potyondy 2012)"},
      kModel);
    f(flat_joint_radial, {"flat_joint_elements_radial", units::none, Range::closed(1, 16),
                          "flat joint: 2D elements along the face, 3D rings of elements"});
    f(flat_joint_circumferential,
      {"flat_joint_elements_circumferential", units::none, Range::closed(1, 16),
       "flat joint, 3D: elements around each ring"});
    f(flat_joint_friction, {"flat_joint_friction", units::none, Range::closed(0, 10),
                            "flat joint: friction coefficient of the broken elements"});
    f(flat_joint_slit_fraction,
      {"flat_joint_slit_fraction", units::none, Range::rightOpen(0, 1),
       "flat joint: fraction of the elements installed unbonded (slit), each drawn alone"});
  }
  // A mean at or below zero with Resample would loop for ever drawing a positive strength.
  void validate() const;
  template <class Archive>
  void visit(Archive& ar) {
    ar("name", name), ar("intragranular", intragranular), ar("modulus", modulus);
    ar("stiffness_ratio", stiffness_ratio), ar("radius_multiplier", radius_multiplier);
    ar("tensile_mean", tensile_mean), ar("tensile_std", tensile_std);
    ar("shear_mean", shear_mean), ar("shear_std", shear_std);
    ar("friction_angle", friction_angle), ar("moment_factor", moment_factor);
    ar("negative", negative), ar("model", model), ar("flat_joint_radial", flat_joint_radial);
    ar("flat_joint_circumferential", flat_joint_circumferential);
    ar("flat_joint_friction", flat_joint_friction);
    ar("flat_joint_slit_fraction", flat_joint_slit_fraction);
  }
  template <int D>
  FaceLayout faceLayout() const {
    return FaceLayout::of<D>(static_cast<int>(flat_joint_radial),
                             static_cast<int>(flat_joint_circumferential));
  }
};

// Section properties of a bond of radius R: 3D a disk (A = pi R^2, I = pi R^4 / 4,
// J = pi R^4 / 2); 2D a rectangle 2R wide and t thick (A = 2 R t, I = 2 R^3 t / 3, no
// twist).
template <int D>
struct BondSection {
  double radius = 0.0, area = 0.0, inertia = 0.0, polar = 0.0;
  static BondSection of(double r, double thickness) {
    BondSection s;
    s.radius = r;
    if constexpr (D == 3) {
      s.area = std::numbers::pi * r * r;
      s.inertia = std::numbers::pi * r * r * r * r / 4.0;
      s.polar = 2.0 * s.inertia;
    } else {
      s.area = 2.0 * r * thickness;
      s.inertia = 2.0 * r * r * r * thickness / 3.0;
    }
    return s;
  }
};

// The forces a bond holds: normal force (compression positive), shear force on j, bending
// moment on j and twisting moment on j about n (3D).
template <int D>
struct BondLoad {
  double fn = 0.0;
  Vec<D> fs = Vec<D>::Zero();
  Ang<D> mb = angZero<Ang<D>>();
  double mt = 0.0;

  template <class Archive>
  void visit(Archive& ar) {
    ar("fn", fn), ar("fs", fs), ar("mb", mb), ar("mt", mt);
  }
};

template <int D>
struct BondKinematics {
  Vec<D> n;       // unit normal from i to j
  Vec<D> vc;      // velocity of j's contact point relative to i's
  Ang<D> dspin;   // spin of j minus spin of i
  double spin_n;  // mean spin about n (turns the stored vectors with the bond, 3D)
};

template <int D>
struct BondResult {
  Vec<D> force;    // on j
  Ang<D> moment;   // bond moment on j (the shear force's arm is added by the caller)
  double tensile;  // Pa, largest tensile stress at the periphery
  double shear;    // Pa, largest shear stress at the periphery
};

// One step of a bond: turns the stored vectors with the bond, adds the increments
// (dFn = kn A d(approach), dFs = -ks A vt dt, dMb = -kn I dtheta_b, dMt = -ks J dtheta_t)
// and returns the load and the peripheral stresses
// sigma = -Fn / A + |Mb| R / I, tau = |Fs| / A + |Mt| R / J (Potyondy & Cundall 2004, eq. 7).
// bond_lanes.hpp repeats these operations, in this order, four bonds at a time.
template <int D>
inline BondResult<D> bondForce(const BondSection<D>& s, double kn, double ks,
                               const BondKinematics<D>& k, BondLoad<D>& b, double dt) {
  const Vec<D>& n = k.n;
  const double vn = k.vc.dot(n);
  const Vec<D> vt = k.vc - vn * n;
  followContactFrame<D>(b.fs, n, k.spin_n, dt);
  b.fn -= kn * s.area * vn * dt;
  b.fs -= (ks * s.area * dt) * vt;
  if constexpr (D == 3) {
    followContactFrame<D>(b.mb, n, k.spin_n, dt);
    const double twist = k.dspin.dot(n);
    b.mb -= (kn * s.inertia * dt) * (k.dspin - twist * n);
    b.mt -= ks * s.polar * twist * dt;
  } else {
    b.mb -= kn * s.inertia * k.dspin * dt;
  }
  BondResult<D> r;
  r.force = b.fn * n + b.fs;
  if constexpr (D == 3) {
    r.moment = b.mb + b.mt * n;
    r.shear = b.fs.norm() / s.area + std::abs(b.mt) * s.radius / s.polar;
  } else {
    r.moment = b.mb;
    r.shear = b.fs.norm() / s.area;
  }
  r.tensile = -b.fn / s.area + angNorm(b.mb) * s.radius / s.inertia;
  return r;
}

// Elastic energy a bond holds (J).
template <int D>
inline double bondEnergy(const BondSection<D>& s, double kn, double ks, const BondLoad<D>& b) {
  double e = 0.5 * b.fn * b.fn / (kn * s.area) + 0.5 * b.fs.squaredNorm() / (ks * s.area) +
             0.5 * angDot(b.mb, b.mb) / (kn * s.inertia);
  if constexpr (D == 3) e += 0.5 * b.mt * b.mt / (ks * s.polar);
  return e;
}

// All bonds of a scene, in flat arrays. Bonds keep their order (installation order, broken
// ones removed) so that forces add up in the same order on any thread count; `i < j` are
// particle indices, remapped when particles are reordered.
template <int D>
struct BondStore {
  std::vector<std::uint32_t> i, j;
  std::vector<std::uint8_t> kind;
  std::vector<double> radius;          // m, R
  std::vector<double> kn, ks;          // Pa/m, stiffness per area
  std::vector<double> tensile, shear;  // Pa, strengths
  std::vector<BondLoad<D>> load;       // parallel bonds
  std::vector<FaceState<D>> face;      // flat joints (empty for a parallel bond)

  std::size_t size() const { return i.size(); }
  // Whether bond b still holds cement: a parallel bond always (a break removes it), a flat
  // joint while one of its elements is bonded.
  bool intact(std::size_t b) const {
    if (face[b].empty()) return true;
    for (const auto& e : face[b].elements) {
      if (e.bonded) return true;
    }
    return false;
  }
  // Keeps the bonds whose flag is 0, in order.
  void removeFlagged(const std::vector<std::uint8_t>& broken);

  template <class Archive>
  void visit(Archive& ar) {
    ar("i", i), ar("j", j), ar("kind", kind), ar("radius", radius), ar("kn", kn), ar("ks", ks);
    ar("tensile", tensile), ar("shear", shear), ar("load", load), ar("face", face);
  }
};

template <int D>
struct BondBreak {
  std::uint64_t step = 0;
  double time = 0.0;
  Vec<D> position = Vec<D>::Zero();  // the bond's centre
  BondBreakMode mode = BondBreakMode::Tensile;
  ParticleId a, b;
  std::uint8_t kind = 0;
  double stress = 0.0;  // Pa, the peripheral stress that broke it

  template <class Archive>
  void visit(Archive& ar) {
    ar("step", step), ar("time", time), ar("position", position), ar("mode", mode);
    ar("a.slot", a.slot), ar("a.generation", a.generation), ar("b.slot", b.slot);
    ar("b.generation", b.generation), ar("kind", kind), ar("stress", stress);
  }
};

struct CementReport {
  std::size_t candidates = 0;  // pairs touching or closer than the gap tolerance
  std::size_t installed = 0;
  std::size_t skipped_nonpositive = 0;  // draws <= 0 with NegativeStrength::Skip
  std::size_t redrawn = 0;              // draws <= 0 drawn again (NegativeStrength::Resample)
  template <class Archive>
  void visit(Archive& ar) {
    ar("candidates", candidates), ar("installed", installed);
    ar("skipped_nonpositive", skipped_nonpositive), ar("redrawn", redrawn);
  }
};

}  // namespace rocklab
