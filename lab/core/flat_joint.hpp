#pragma once
// The flat-jointed bond (Potyondy 2012, "A flat-jointed bonded-particle material for hard
// rock", ARMA 12-501; the `flatjoint` model of PFC 5). The cement between two particles is
// a flat face of radius R = lambda min(r1, r2) normal to the line of centres (2D: 2R long
// and the disks' thickness t), cut into elements: 2D N pieces along the face; 3D N_r rings
// of N_a sectors. Each element is bonded or not:
//
// - a bonded element carries tension and compression, shear, and its own bending (and 3D
//   twisting) moment about its centroid, all updated incrementally at its centroid. With
//   every element bonded the face is exactly the parallel bond of the same section: its
//   stiffness is the sum of the elements' (parallel axis theorem).
// - it breaks, as in PFC, on its centroid's stresses: in tension when -Fn / A reaches the
//   tensile strength, in shear when |Fs| / A reaches c + sigma tan(phi), sigma = Fn / A
//   (compression raises, tension lowers the shear strength; never below 0).
// - an unbroken face is therefore partly bonded: the bonded elements still resist bending
//   and twisting, and so do the broken ones through their compressive forces' lever arms.
// - a broken element is a frictional interface: a normal force kn A max(approach, 0) at its
//   centroid, no tension, a shear force capped at mu times it (Coulomb), no moment of its own
//   (PFC integrates the compressed part of a broken element's linear stress instead; with N
//   elements the difference is the element's own bending share of the face's, 1 / N^2 in 2D).
//
// The face is removed once every element is broken and every element's surfaces are apart:
// the pair is then left to its contact law, as any pair. Like the parallel bond it acts in
// parallel with the particles' contact law and is installed unloaded.

#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "lab/core/dim.hpp"

namespace rocklab {

enum class BondModel : std::uint8_t { Parallel, FlatJoint };

// One element of a face of radius 1 and (2D) thickness 1; a face of radius R and thickness
// t scales area by R^2 (2D: R t), the centroid by R and the second moments by R^4 (2D: R^3 t).
struct FaceElementShape {
  double area = 0.0;
  double x = 0.0, y = 0.0;  // centroid in the face frame (a1, a2); 2D: along the face, y = 0
  // Second moments of area about the centroid: int x^2, int y^2, int x y (2D: int x^2 only).
  double ixx = 0.0, iyy = 0.0, ixy = 0.0;
};

// The elements of a face: 2D `radial` pieces of equal length; 3D `radial` rings of equal
// width, each of `circumferential` sectors, sector k spanning [k, k + 1) 2 pi / N_a.
struct FaceLayout {
  int dimension = 3, radial = 1, circumferential = 1;
  std::vector<FaceElementShape> elements;

  static FaceLayout of2D(int pieces);
  static FaceLayout of3D(int rings, int sectors);
  template <int D>
  static FaceLayout of(int radial, int circumferential) {
    return D == 3 ? of3D(radial, circumferential) : of2D(radial);
  }
  // The element at the mirror place seen from the other particle (the pair's sides swap,
  // the normal turns over: 2D the face's direction reverses, 3D a2 = n x a1 does).
  std::size_t mirror(std::size_t e) const;
};

// An element's shear force and own moments are kept in the face's frame (a1, a2, n), not
// as world vectors: the frame turns with the bond once per face and step, and the elements'
// components turn with it, where world vectors would each be turned and renormalised
// element by element (most of a joint's step). The face's normal and axis carry the frame.
template <int D>
struct FaceElement {
  std::uint8_t bonded = 1;
  double approach = 0.0;         // m, the surfaces' approach at the centroid (< 0: a gap)
  Vec<2> fs = Vec<2>::Zero();    // N, shear force on j along a1 and a2 (2D: a1 only)
  Vec<2> bend = Vec<2>::Zero();  // N m, own bending moment on j (bonded): 3D about a1 and
                                 // a2; 2D about the out-of-plane axis, in bend[0]
  double twist = 0.0;            // N m, 3D: own twisting moment on j about n (bonded)

  template <class Archive>
  void visit(Archive& ar) {
    ar("bonded", bonded), ar("approach", approach), ar("fs", fs), ar("bend", bend);
    ar("twist", twist);
  }
};

// A flat joint's state: its elements and (3D) the face's first in-plane axis a1, turned
// with the bond as the shear forces are. Empty for a parallel bond.
template <int D>
struct FaceState {
  Vec<D> axis = Vec<D>::Zero();
  std::vector<FaceElement<D>> elements;
  // N, the face's normal force (compression positive) and the magnitude of its shear force
  // at the last step, for frames and readouts.
  double normal_force = 0.0, shear_force = 0.0;

  bool empty() const { return elements.empty(); }
  // Seen from the other particle (BondStore keeps i < j): the elements in mirror order, the
  // shear forces and bending moments on the other particle, in its frame (the normal turns
  // over; 3D a1 stays and a2 = n x a1 turns over, 2D a1 = n rotated by +90 deg turns over).
  void swapSides(const FaceLayout& layout);

  template <class Archive>
  void visit(Archive& ar) {
    ar("axis", axis), ar("elements", elements), ar("normal_force", normal_force);
    ar("shear_force", shear_force);
  }
};

// A face installed on normal n: every element bonded and unloaded; 3D a1 perpendicular to n
// from the coordinate axis least aligned with it.
template <int D>
FaceState<D> installFace(const FaceLayout& layout, const Vec<D>& n) {
  FaceState<D> f;
  f.elements.assign(layout.elements.size(), FaceElement<D>{});
  if constexpr (D == 3) {
    int k = 0;
    for (int a = 1; a < 3; ++a) {
      if (std::abs(n[a]) < std::abs(n[k])) k = a;
    }
    f.axis = n.cross(Vec<3>::Unit(k)).normalized();
  }
  return f;
}

// The material of a face this step: stiffness per area, the bond's drawn strengths, its
// friction angle (bonded) and the broken elements' friction coefficient.
struct FaceMaterial {
  double radius = 0.0, thickness = 0.0;
  double kn = 0.0, ks = 0.0;             // Pa/m
  double tensile = 0.0, cohesion = 0.0;  // Pa
  double tan_friction_angle = 0.0, friction = 0.0;
  bool breakable = true;
};

template <int D>
struct ElementBreak {
  std::uint16_t element = 0;
  Vec<D> offset = Vec<D>::Zero();  // m, its centroid from the face's centre
  bool tensile = true;
  double stress = 0.0;  // Pa, the centroid stress that reached the strength
  double energy = 0.0;  // J, the elastic energy the element gave up
};

template <int D>
struct FaceResult {
  Vec<D> force = Vec<D>::Zero();      // on j
  Ang<D> moment = angZero<Ang<D>>();  // on j about the contact point (the caller adds the
                                      // shear force's arm to each particle's centre)
  Vec<D> shear = Vec<D>::Zero();      // the elements' shear forces summed
  double slip_energy = 0.0;           // J, dissipated by the broken elements' sliding
  bool released = false;              // every element broken, every one apart
};

namespace face {

// An element's centroid in the face frame (x along a1, y along a2), its area and second
// moments at this face's size.
struct Placed {
  double x, y;
  double area, ixx, iyy, ixy;
};

template <int D>
inline Placed place(const FaceElementShape& s, const FaceMaterial& m) {
  const double r = m.radius;
  Placed p;
  p.x = r * s.x;
  if constexpr (D == 3) {
    p.y = r * s.y;
    p.area = s.area * r * r;
    const double r4 = r * r * r * r;
    p.ixx = s.ixx * r4, p.iyy = s.iyy * r4, p.ixy = s.ixy * r4;
  } else {
    p.y = 0.0;
    p.area = s.area * r * m.thickness;
    p.ixx = s.ixx * r * r * r * m.thickness;
    p.iyy = p.ixy = 0.0;
  }
  return p;
}

// Elastic energy an element holds (J). 3D bending: m . K^-1 m / (2 kn), K the centroidal
// tensor [[iyy, -ixy], [-ixy, ixx]] in (a1, a2) (a bend about a1 strains along a2).
template <int D>
inline double energy(const FaceElement<D>& e, const Placed& p, const FaceMaterial& m) {
  const double fn = m.kn * p.area * (e.bonded ? e.approach : std::max(e.approach, 0.0));
  double w = 0.5 * fn * fn / (m.kn * p.area) + 0.5 * e.fs.squaredNorm() / (m.ks * p.area);
  if (!e.bonded) return w;
  if constexpr (D == 3) {
    const double m1 = e.bend[0], m2 = e.bend[1];
    const double det = p.iyy * p.ixx - p.ixy * p.ixy;
    w += 0.5 * (p.ixx * m1 * m1 + 2.0 * p.ixy * m1 * m2 + p.iyy * m2 * m2) / (det * m.kn);
    w += 0.5 * e.twist * e.twist / (m.ks * (p.ixx + p.iyy));
  } else {
    w += 0.5 * e.bend[0] * e.bend[0] / (m.kn * p.ixx);
  }
  return w;
}

// The face frame: a1 (3D the face's axis, 2D n turned by +90 deg) and a2 = n x a1 (3D).
template <int D>
struct Frame {
  Vec<D> a1, a2;
  // A vector of the frame's components (along a1, a2, n) in world coordinates.
  Vec<D> world(double c1, double c2, double cn, const Vec<D>& n) const {
    if constexpr (D == 3) {
      return c1 * a1 + c2 * a2 + cn * n;
    } else {
      return c1 * a1 + cn * n;
    }
  }
};

template <int D>
inline Frame<D> frameOf(const Vec<D>& n, const Vec<D>& axis) {
  if constexpr (D == 3) {
    return {axis, n.cross(axis)};
  } else {
    return {Vec<2>(-n[1], n[0]), Vec<2>::Zero()};
  }
}

// Bonded element k breaks at its centroid's stress sigma (Pa, compression positive) and
// shear strength `strength` (Pa), having reached the tensile strength, the shear strength or
// both: its moments go, its shear force is capped at friction, and the break is recorded
// with the elastic energy the element gave up. The larger ratio of stress to strength names
// the mode when both are reached.
template <int D>
inline void breakElement(FaceElement<D>& e, std::size_t k, const Placed& p, const FaceMaterial& m,
                         const Frame<D>& frame, const Vec<D>& n, double sigma, double strength,
                         bool in_tension, bool in_shear, std::vector<ElementBreak<D>>& breaks) {
  const double tau = e.fs.norm() / p.area;
  const double rt = -sigma / m.tensile;
  const double rs = strength > 0.0 ? tau / strength : HUGE_VAL;
  const bool tensile = in_tension && (!in_shear || rt >= rs);
  const double before = energy<D>(e, p, m);
  e.bonded = 0;
  e.bend = Vec<2>::Zero();
  e.twist = 0.0;
  const double limit = m.friction * m.kn * p.area * std::max(e.approach, 0.0);
  if (e.fs.norm() > limit) e.fs *= limit > 0.0 ? limit / e.fs.norm() : 0.0;
  breaks.push_back({static_cast<std::uint16_t>(k), frame.world(p.x, p.y, 0.0, n), tensile,
                    tensile ? -sigma : tau, before - energy<D>(e, p, m)});
}

}  // namespace face

// One step of a flat joint: turns the face's axis with the bond, moves every element's
// centroid with the relative motion (v = vc + dspin x x), updates its forces and moments,
// breaks the bonded elements that reach a strength (into `breaks`), caps the broken ones'
// shear at friction, and returns the face's force and moment on j.
//
// Everything per element is in the face frame (a1, a2, n), right-handed: with the relative
// velocity (c1, c2, cn) and spin (w1, w2, wn) there, an element at (x, y, 0) moves at
// vt = (c1 - wn y, c2 + wn x), vn = cn + w1 y - w2 x (2D, spin w about the out-of-plane
// axis, a1 x n = -1: vt = c1, vn = cn - w x), and its force (fs1, fs2, fn) has the moment
// (y fn, -x fn, x fs2 - y fs1) about the face's centre (2D -x fn).
template <int D>
FaceResult<D> flatJointStep(const FaceLayout& layout, const FaceMaterial& m, const Vec<D>& n,
                            const Vec<D>& vc, const Ang<D>& dspin, double spin_n, FaceState<D>& f,
                            double dt, std::vector<ElementBreak<D>>& breaks) {
  if constexpr (D == 3) {
    // The face's axis turns with the bond like a shear force, kept a unit vector in the face.
    f.axis += (dt * spin_n) * n.cross(f.axis);
    f.axis = (f.axis - f.axis.dot(n) * n).normalized();
  }
  const face::Frame<D> frame = face::frameOf<D>(n, f.axis);
  const double c1 = vc.dot(frame.a1), cn = vc.dot(n);
  double c2 = 0.0, w1 = 0.0, w2 = 0.0, wn = 0.0;
  if constexpr (D == 3) {
    c2 = vc.dot(frame.a2);
    w1 = dspin.dot(frame.a1), w2 = dspin.dot(frame.a2), wn = dspin.dot(n);
  } else {
    wn = dspin;  // the in-plane spin, about the out-of-plane axis
  }
  FaceResult<D> r;
  double f1 = 0.0, f2 = 0.0, fn_sum = 0.0;  // the face's force on j in the frame
  double m1 = 0.0, m2 = 0.0, mn = 0.0;      // its moment about the face's centre
  bool all_apart = true, all_broken = true;
  for (std::size_t k = 0; k < f.elements.size(); ++k) {
    FaceElement<D>& e = f.elements[k];
    const face::Placed p = face::place<D>(layout.elements[k], m);
    double vn;
    Vec<2> vt;
    if constexpr (D == 3) {
      vn = cn + w1 * p.y - w2 * p.x;
      vt = Vec<2>(c1 - wn * p.y, c2 + wn * p.x);
    } else {
      vn = cn - wn * p.x;
      vt = Vec<2>(c1, 0.0);
    }
    e.approach -= vn * dt;
    const Vec<2> fs_before = e.fs;
    e.fs -= (m.ks * p.area * dt) * vt;
    if (e.bonded) {
      if constexpr (D == 3) {
        e.bend[0] -= m.kn * dt * (p.iyy * w1 - p.ixy * w2);
        e.bend[1] -= m.kn * dt * (p.ixx * w2 - p.ixy * w1);
        e.twist -= m.ks * (p.ixx + p.iyy) * wn * dt;
      } else {
        e.bend[0] -= m.kn * p.ixx * wn * dt;
      }
      const double sigma = m.kn * e.approach;  // Pa, compression positive
      const double strength = std::max(m.cohesion + sigma * m.tan_friction_angle, 0.0);
      const double strength_force = strength * p.area;
      // tau >= strength, on the squares: no root unless the element breaks
      const bool in_tension = -sigma >= m.tensile;
      const bool in_shear = e.fs.squaredNorm() >= strength_force * strength_force;
      if (m.breakable && (in_tension || in_shear)) {
        face::breakElement<D>(e, k, p, m, frame, n, sigma, strength, in_tension, in_shear, breaks);
      }
    } else {
      // Coulomb: the work of the capped force along the slip (relative displacement minus
      // the spring's elastic increment), as the contact kernel books it.
      const double limit = m.friction * m.kn * p.area * std::max(e.approach, 0.0);
      const double fs2 = e.fs.squaredNorm();
      if (fs2 > limit * limit) {
        e.fs *= fs2 > 0.0 ? limit / std::sqrt(fs2) : 0.0;
        const Vec<2> slip = vt * dt + (e.fs - fs_before) / (m.ks * p.area);
        r.slip_energy -= e.fs.dot(slip);
      }
    }
    const double fn = m.kn * p.area * (e.bonded ? e.approach : std::max(e.approach, 0.0));
    f1 += e.fs[0], f2 += e.fs[1], fn_sum += fn;
    if constexpr (D == 3) {
      m1 += p.y * fn, m2 -= p.x * fn, mn += p.x * e.fs[1] - p.y * e.fs[0];
      if (e.bonded) m1 += e.bend[0], m2 += e.bend[1], mn += e.twist;
    } else {
      mn -= p.x * fn;
      if (e.bonded) mn += e.bend[0];
    }
    all_broken = all_broken && !e.bonded;
    all_apart = all_apart && e.approach <= 0.0;
  }
  r.shear = frame.world(f1, f2, 0.0, n);
  r.force = r.shear + fn_sum * n;
  if constexpr (D == 3) {
    r.moment = frame.world(m1, m2, mn, n);
  } else {
    r.moment = mn;
  }
  r.released = all_broken && all_apart;
  f.normal_force = fn_sum;
  f.shear_force = std::sqrt(f1 * f1 + f2 * f2);  // glibc's hypot costs a tenth of the step
  return r;
}

// Elastic energy a face holds (J), in the frame of its last step.
template <int D>
double faceEnergy(const FaceLayout& layout, const FaceMaterial& m, const FaceState<D>& f) {
  double w = 0.0;
  for (std::size_t k = 0; k < f.elements.size(); ++k) {
    w += face::energy<D>(f.elements[k], face::place<D>(layout.elements[k], m), m);
  }
  return w;
}

}  // namespace rocklab
