#pragma once
// Four touching particle pairs at once, one per lane of an AVX register (2D and 3D), as the
// bond pass does with bonds (bond_lanes.hpp). A touching pair costs some 400 instructions in
// one chain of roots and divisions (the normal, the frame's turn, the Coulomb cap); four lanes
// run four chains side by side.
//
// Every lane performs the operations of ContactModelImpl::interact, pairShape<D>, the law's
// evaluate and contactForce<D> (contact_kernels.hpp) in the same order, so a pair gets the
// same bits in a lane as on the scalar path (lanes.hpp says why). Keep them in step: a
// change to the scalar formulas must be made here too (test_contact_kernels.cpp and
// test_determinism.cpp compare the two bit for bit, sliding and sticking, damped and not).
// A law without a lane form here (LaneLaw) runs on the scalar path.

#include <cstdint>
#include <numbers>
#include <type_traits>

#include "lab/core/contact_law_hertz.hpp"
#include "lab/core/contact_law_linear.hpp"
#include "lab/core/lanes.hpp"

namespace rocklab::lanes {

#pragma GCC push_options
#pragma GCC target("avx")

inline __m256d less(L4 a, L4 b) {  // a < b, false on NaN as in C++
  return _mm256_cmp_pd(a.v, b.v, _CMP_LT_OQ);
}
inline __m256d greater(L4 a, L4 b) {  // a > b
  return _mm256_cmp_pd(a.v, b.v, _CMP_GT_OQ);
}
// std::min(a, b) and std::max(a, b) exactly, signed zeros included: (b < a) ? b : a and
// (a < b) ? b : a (the AVX min and max return their second operand on ties).
inline L4 minOf(L4 a, L4 b) {
  return select(less(b, a), b, a);
}
inline L4 maxOf(L4 a, L4 b) {
  return select(less(a, b), b, a);
}

// A field of four pairs' parameters into lanes.
template <class P>
inline L4 field(const P* const (&p)[4], double P::*member) {
  return {_mm256_set_pd(p[3]->*member, p[2]->*member, p[1]->*member, p[0]->*member)};
}

// What the pair loop needs of a law's LawState, lane by lane (kn is for walls and servos).
struct LawLanes {
  L4 fn_elastic, ks, cn, cs;
};

// A contact's size (ContactShape), lane by lane.
struct ShapeLanes {
  L4 rstar, area, length;
};

template <class Law>
struct LaneLaw : std::false_type {};

// LinearLaw::evaluate.
template <>
struct LaneLaw<LinearLaw> : std::true_type {
  static LawLanes evaluate(const LinearParams* const (&p)[4], L4 overlap, const ShapeLanes& g,
                           L4 mstar) {
    const L4 a_over_l = g.area / g.length;
    const L4 kn = field(p, &LinearParams::kn) + field(p, &LinearParams::modulus) * a_over_l;
    const L4 ks = field(p, &LinearParams::ks) + field(p, &LinearParams::shear_modulus) * a_over_l;
    const L4 damp = field(p, &LinearParams::damp);
    const __m256d damped = _mm256_cmp_pd(damp.v, _mm256_setzero_pd(), _CMP_NEQ_UQ);
    const L4 zero = both(0.0);
    return {kn * overlap, ks, select(damped, damp * sqrt(mstar * kn), zero),
            select(damped, damp * sqrt(mstar * ks), zero)};
  }
};

// HertzLaw::evaluate.
template <>
struct LaneLaw<HertzLaw> : std::true_type {
  static LawLanes evaluate(const HertzParams* const (&p)[4], L4 overlap, const ShapeLanes& g,
                           L4 mstar) {
    const L4 estar = field(p, &HertzParams::estar), gstar = field(p, &HertzParams::gstar);
    const L4 damp = field(p, &HertzParams::damp);
    const L4 a = sqrt(g.rstar * overlap);
    const __m256d damped = _mm256_cmp_pd(damp.v, _mm256_setzero_pd(), _CMP_NEQ_UQ);
    const L4 am = sqrt(a * mstar), zero = both(0.0);
    return {both(4.0 / 3.0) * estar * a * overlap, both(8.0) * gstar * a,
            select(damped, field(p, &HertzParams::cn_per_am) * am, zero),
            select(damped, field(p, &HertzParams::cs_per_am) * am, zero)};
  }
};

// Lane types of a dimension: the vectors (V3, V2) and the spins and torques (V3, L4).
template <int D>
struct Types;
template <>
struct Types<3> {
  using V = V3;
  using S = V3;
};
template <>
struct Types<2> {
  using V = V2;
  using S = L4;
};

// The outcome of each pair of a group, lane k of each array (2D: ti and tj in row 0).
struct ContactsOut {
  alignas(32) double force[3][4];
  alignas(32) double ti[3][4];
  alignas(32) double tj[3][4];
  alignas(32) double friction[4];  // subtracted from the total where the pair slides
  alignas(32) double viscous[4];   // added to the total
  int sliding = 0;                 // bit k: pair k slides
  int over = 0;                    // bit k: pair k's overlap passes the guard's limit
};

template <class V>
inline void store(const V& v, double (&out)[3][4]) {
  _mm256_store_pd(out[0], v.x.v);
  _mm256_store_pd(out[1], v.y.v);
  if constexpr (std::is_same_v<V, V3>) _mm256_store_pd(out[2], v.z.v);
}
inline void store(L4 s, double (&out)[3][4]) {
  _mm256_store_pd(out[0], s.v);
}

// Pairs (is[k], js[k]) of the pair slots ps[k], all touching: the force on j and the torques
// on i and j of each, its dissipation, and its new shear spring written back to shear[ps[k]]
// for the first `valid` lanes (the others repeat lane 0 and are dropped). `View` is the pair
// loop's PairView.
template <int D, class Law, bool kEnergy, class View>
inline void fourContacts(const View& v, const std::uint32_t (&is)[4], const std::uint32_t (&js)[4],
                         const std::uint32_t (&ps)[4],
                         const typename Law::Params* const (&params)[4], int valid,
                         ContactsOut& out) {
  using V = typename Types<D>::V;
  using S = typename Types<D>::S;
  const double dt = v.dt;
  // interact(): the kinematics.
  const V d = gather(v.pos, js) - gather(v.pos, is);
  const L4 ri = gather(v.radius, is), rj = gather(v.radius, js);
  const L4 reach = ri + rj;
  const L4 dist = sqrt(dot(d, d));
  const V n = d / dist;
  const L4 overlap = reach - dist;
  const L4 half = both(0.5);
  const L4 li = ri - half * overlap, lj = rj - half * overlap;
  const S wi = gather(v.spin, is), wj = gather(v.spin, js);
  const V vc = gather(v.vel, js) - gather(v.vel, is) - cross(lj * wj + li * wi, n);
  const L4 rmin = minOf(ri, rj);
  ShapeLanes g;  // pairShape<D>
  g.rstar = ri * rj / (ri + rj);
  if constexpr (D == 3) {
    g.area = both(std::numbers::pi) * rmin * rmin;
  } else {
    g.area = both(2.0) * rmin * both(v.thickness);
  }
  g.length = ri + rj;
  const L4 imsum = gather(v.inv_mass, is) + gather(v.inv_mass, js);
  const L4 zero = both(0.0);
  const L4 mstar = select(greater(imsum, zero), both(1.0) / imsum, zero);
  out.over = _mm256_movemask_pd(greater(overlap, both(v.overlap_limit) * rmin));

  // contactForce().
  const LawLanes s = LaneLaw<Law>::evaluate(params, overlap, g, mstar);
  const L4 vn = dot(vc, n);
  const V vt = vc - vn * n;
  const L4 fn = s.fn_elastic - s.cn * vn;
  V fs = gather(v.shear, ps);
  if constexpr (D == 3) {
    followContactFrame(fs, n, half * dot(wi + wj, n), dt);
  } else {
    followContactFrame(fs, n);
  }
  const V fs_rotated = fs;
  fs = fs - (s.ks * both(dt)) * vt;
  const L4 limit = field(params, &Law::Params::mu) * maxOf(s.fn_elastic, zero);
  const L4 fs2 = dot(fs, fs);
  const __m256d sliding = greater(fs2, limit * limit);
  fs = select(sliding, select(greater(fs2, zero), limit / sqrt(fs2), zero) * fs, fs);
  const V ft = select(sliding, fs, fs - s.cs * vt);
  if constexpr (kEnergy) {
    V slip = both(dt) * vt;
    slip = select(greater(s.ks, zero), slip + (fs - fs_rotated) / s.ks, slip);
    _mm256_store_pd(out.friction, dot(fs, slip).v);
    const L4 viscous = select(sliding, zero, s.cs * dot(vt, vt) * both(dt));
    _mm256_store_pd(out.viscous, (viscous + s.cn * vn * vn * both(dt)).v);
  }
  out.sliding = _mm256_movemask_pd(sliding);
  const V force = fn * n + ft;
  const auto ncf = cross(n, ft);
  store(force, out.force);
  store(li * ncf, out.ti);
  store(lj * ncf, out.tj);

  alignas(32) double x[4], y[4], z[4];
  _mm256_store_pd(x, fs.x.v);
  _mm256_store_pd(y, fs.y.v);
  if constexpr (D == 3) _mm256_store_pd(z, fs.z.v);
  for (int k = 0; k < valid; ++k) {
    if constexpr (D == 3) {
      v.shear[ps[k]] = Eigen::Vector3d(x[k], y[k], z[k]);
    } else {
      v.shear[ps[k]] = Eigen::Vector2d(x[k], y[k]);
    }
  }
}

#pragma GCC pop_options

}  // namespace rocklab::lanes
