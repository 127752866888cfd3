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

#include "lab/core/contact_kernels.hpp"
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

template <int D>
struct FaceElement {
  std::uint8_t bonded = 1;
  double approach = 0.0;              // m, the surfaces' approach at the centroid (< 0: a gap)
  Vec<D> fs = Vec<D>::Zero();         // N, shear force on j
  Ang<D> moment = angZero<Ang<D>>();  // N m, own bending moment on j (bonded elements)
  double twist = 0.0;                 // N m, 3D: own twisting moment on j about n (bonded)

  template <class Archive>
  void visit(Archive& ar) {
    ar("bonded", bonded), ar("approach", approach), ar("fs", fs), ar("moment", moment);
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
  // shear forces and bending moments on the other particle.
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

// An element's centroid on the face, its area and second moments at this face's size.
template <int D>
struct Placed {
  Vec<D> x;
  double area, ixx, iyy, ixy;
};

template <int D>
inline Placed<D> place(const FaceElementShape& s, const FaceMaterial& m, const Vec<D>& a1,
                       const Vec<D>& a2) {
  const double r = m.radius;
  Placed<D> p;
  if constexpr (D == 3) {
    p.x = (r * s.x) * a1 + (r * s.y) * a2;
    p.area = s.area * r * r;
    const double r4 = r * r * r * r;
    p.ixx = s.ixx * r4, p.iyy = s.iyy * r4, p.ixy = s.ixy * r4;
  } else {
    p.x = (r * s.x) * a1;
    p.area = s.area * r * m.thickness;
    p.ixx = s.ixx * r * r * r * m.thickness;
    p.iyy = p.ixy = 0.0;
  }
  return p;
}

// Elastic energy an element holds (J). 3D bending: m . K^-1 m / (2 kn), K the centroidal
// tensor [[iyy, -ixy], [-ixy, ixx]] in (a1, a2) (a bend about a1 strains along a2).
template <int D>
inline double energy(const FaceElement<D>& e, const Placed<D>& p, const FaceMaterial& m,
                     const Vec<D>& a1, const Vec<D>& a2) {
  const double fn = m.kn * p.area * (e.bonded ? e.approach : std::max(e.approach, 0.0));
  double w = 0.5 * fn * fn / (m.kn * p.area) + 0.5 * e.fs.squaredNorm() / (m.ks * p.area);
  if (!e.bonded) return w;
  if constexpr (D == 3) {
    const double m1 = e.moment.dot(a1), m2 = e.moment.dot(a2);
    const double det = p.iyy * p.ixx - p.ixy * p.ixy;
    w += 0.5 * (p.ixx * m1 * m1 + 2.0 * p.ixy * m1 * m2 + p.iyy * m2 * m2) / (det * m.kn);
    w += 0.5 * e.twist * e.twist / (m.ks * (p.ixx + p.iyy));
  } else {
    w += 0.5 * e.moment * e.moment / (m.kn * p.ixx);
  }
  return w;
}

}  // namespace face

// One step of a flat joint: turns the stored vectors with the face, moves every element's
// centroid with the relative motion (v = vc + dspin x x), updates its forces and moments,
// breaks the bonded elements that reach a strength (into `breaks`), caps the broken ones'
// shear at friction, and returns the face's force and moment on j.
template <int D>
FaceResult<D> flatJointStep(const FaceLayout& layout, const FaceMaterial& m, const Vec<D>& n,
                            const Vec<D>& vc, const Ang<D>& dspin, double spin_n, FaceState<D>& f,
                            double dt, std::vector<ElementBreak<D>>& breaks) {
  FaceResult<D> r;
  Vec<D> a1, a2;
  double twist_rate = 0.0;
  Ang<D> bend = dspin;
  if constexpr (D == 3) {
    // The face's axis turns with the bond like a shear force, kept a unit vector in the face.
    f.axis += (dt * spin_n) * n.cross(f.axis);
    f.axis = (f.axis - f.axis.dot(n) * n).normalized();
    a1 = f.axis;
    a2 = n.cross(a1);
    twist_rate = dspin.dot(n);
    bend = dspin - twist_rate * n;
  } else {
    a1 = Vec<2>(-n[1], n[0]);
    a2 = Vec<2>::Zero();
  }
  bool all_apart = true, all_broken = true;
  for (std::size_t k = 0; k < f.elements.size(); ++k) {
    FaceElement<D>& e = f.elements[k];
    const face::Placed<D> p = face::place<D>(layout.elements[k], m, a1, a2);
    followContactFrame<D>(e.fs, n, spin_n, dt);
    if constexpr (D == 3) followContactFrame<D>(e.moment, n, spin_n, dt);
    const Vec<D> v = vc + cross(dspin, p.x);
    const double vn = v.dot(n);
    const Vec<D> vt = v - vn * n;
    e.approach -= vn * dt;
    const Vec<D> fs_turned = e.fs;
    e.fs -= (m.ks * p.area * dt) * vt;
    if (e.bonded) {
      if constexpr (D == 3) {
        const double t1 = bend.dot(a1), t2 = bend.dot(a2);
        e.moment -= (m.kn * dt) * ((p.iyy * t1 - p.ixy * t2) * a1 + (p.ixx * t2 - p.ixy * t1) * a2);
        e.twist -= m.ks * (p.ixx + p.iyy) * twist_rate * dt;
      } else {
        e.moment -= m.kn * p.ixx * dspin * dt;
      }
      const double sigma = m.kn * e.approach;  // Pa, compression positive
      const double tau = e.fs.norm() / p.area;
      const double strength = std::max(m.cohesion + sigma * m.tan_friction_angle, 0.0);
      const bool in_tension = -sigma >= m.tensile, in_shear = tau >= strength;
      if (m.breakable && (in_tension || in_shear)) {
        // The larger ratio of stress to strength names the mode when both are reached.
        const double rt = -sigma / m.tensile;
        const double rs = strength > 0.0 ? tau / strength : HUGE_VAL;
        const bool tensile = in_tension && (!in_shear || rt >= rs);
        const double before = face::energy<D>(e, p, m, a1, a2);
        e.bonded = 0;
        e.moment = angZero<Ang<D>>();
        e.twist = 0.0;
        const double limit = m.friction * m.kn * p.area * std::max(e.approach, 0.0);
        if (e.fs.norm() > limit) e.fs *= limit > 0.0 ? limit / e.fs.norm() : 0.0;
        breaks.push_back({static_cast<std::uint16_t>(k), p.x, tensile, tensile ? -sigma : tau,
                          before - face::energy<D>(e, p, m, a1, a2)});
      }
    } else {
      // Coulomb: the work of the capped force along the slip (relative displacement minus
      // the spring's elastic increment), as the contact kernel books it.
      const double limit = m.friction * m.kn * p.area * std::max(e.approach, 0.0);
      const double fs2 = e.fs.squaredNorm();
      if (fs2 > limit * limit) {
        e.fs *= fs2 > 0.0 ? limit / std::sqrt(fs2) : 0.0;
        const Vec<D> slip = vt * dt + (e.fs - fs_turned) / (m.ks * p.area);
        r.slip_energy -= e.fs.dot(slip);
      }
    }
    const double fn = m.kn * p.area * (e.bonded ? e.approach : std::max(e.approach, 0.0));
    const Vec<D> force = fn * n + e.fs;
    r.force += force;
    r.shear += e.fs;
    r.moment += cross(p.x, force);
    if (e.bonded) {
      if constexpr (D == 3) {
        r.moment += e.moment + e.twist * n;
      } else {
        r.moment += e.moment;
      }
    }
    all_broken = all_broken && !e.bonded;
    all_apart = all_apart && e.approach <= 0.0;
  }
  r.released = all_broken && all_apart;
  f.normal_force = r.force.dot(n);
  f.shear_force = r.shear.norm();
  return r;
}

// Elastic energy a face holds (J), in the frame of its last step.
template <int D>
double faceEnergy(const FaceLayout& layout, const FaceMaterial& m, const Vec<D>& n,
                  const FaceState<D>& f) {
  Vec<D> a1, a2;
  if constexpr (D == 3) {
    a1 = f.axis;
    a2 = n.cross(a1);
  } else {
    a1 = Vec<2>(-n[1], n[0]);
    a2 = Vec<2>::Zero();
  }
  double w = 0.0;
  for (std::size_t k = 0; k < f.elements.size(); ++k) {
    w += face::energy<D>(f.elements[k], face::place<D>(layout.elements[k], m, a1, a2), m, a1, a2);
  }
  return w;
}

}  // namespace rocklab
