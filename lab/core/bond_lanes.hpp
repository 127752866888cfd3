#pragma once
// Four bonds at once, one per lane of an AVX register (3D, and 2D below). The scalar bond pass is
// bound by the latency of each bond's chain of roots and divisions (perf puts its samples on the
// instructions waiting for them; sorting the bonds or prefetching their particles changed
// nothing): a bond's ~480 instructions do not fit the out-of-order window, so bonds hardly
// overlap. Four lanes run four chains side by side and quarter the arithmetic.
//
// Every lane performs the operations of BondSection<D>::of, bondForce<D> and
// followContactFrame<D> in the same order, and each AVX operation (add, multiply, divide,
// square root) is the correctly rounded IEEE operation, as the scalar one; nothing is fused
// (-ffp-contract=off, no FMA target). So a bond gets the same bits in a lane as on the
// scalar path, and the benchmark's state hash holds. Where the scalar code branches, both
// sides are computed and each lane takes its own with a mask. Keep the two in step: a
// change to the scalar formulas must be made here too (test_bonds.cpp and
// test_determinism.cpp compare the two bit for bit on samples whose bonds break).
//
// The functions carry the AVX target themselves (the rest of the binary stays x86-64
// baseline); BondForces calls them only when the CPU has AVX (lanes::available()).

#include <immintrin.h>

#include <cstdint>
#include <numbers>

#include "lab/core/bonds.hpp"

namespace rocklab::lanes {

inline bool available() {
  static const bool avx = __builtin_cpu_supports("avx");
  return avx;
}

#pragma GCC push_options
#pragma GCC target("avx")

// Four doubles: lane k the group's k-th bond.
struct L4 {
  __m256d v;
};
inline L4 both(double a) {
  return {_mm256_set1_pd(a)};
}
inline L4 load(const double* p) {  // p[k] to lane k
  return {_mm256_loadu_pd(p)};
}
inline L4 operator+(L4 a, L4 b) {
  return {_mm256_add_pd(a.v, b.v)};
}
inline L4 operator-(L4 a, L4 b) {
  return {_mm256_sub_pd(a.v, b.v)};
}
inline L4 operator*(L4 a, L4 b) {
  return {_mm256_mul_pd(a.v, b.v)};
}
inline L4 operator/(L4 a, L4 b) {
  return {_mm256_div_pd(a.v, b.v)};
}
inline L4 operator-(L4 a) {  // flips the sign bit, as scalar negation
  return {_mm256_xor_pd(a.v, _mm256_set1_pd(-0.0))};
}
inline L4 sqrt(L4 a) {
  return {_mm256_sqrt_pd(a.v)};
}
inline L4 abs(L4 a) {
  return {_mm256_andnot_pd(_mm256_set1_pd(-0.0), a.v)};
}
// Lane by lane: a where the mask is set, else b.
inline L4 select(__m256d mask, L4 a, L4 b) {
  return {_mm256_blendv_pd(b.v, a.v, mask)};
}

// A 3-vector of four bonds, component by component.
struct V3 {
  L4 x, y, z;
};
inline V3 operator+(const V3& a, const V3& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
inline V3 operator-(const V3& a, const V3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline V3 operator*(L4 s, const V3& a) {
  return {s * a.x, s * a.y, s * a.z};
}
inline V3 operator/(const V3& a, L4 s) {
  return {a.x / s, a.y / s, a.z / s};
}
// Eigen's order for 3-vectors: (a0 b0 + a1 b1) + a2 b2.
inline L4 dot(const V3& a, const V3& b) {
  return (a.x * b.x + a.y * b.y) + a.z * b.z;
}
inline V3 cross(const V3& a, const V3& b) {  // Eigen's formula
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline V3 select(__m256d mask, const V3& a, const V3& b) {
  return {select(mask, a.x, b.x), select(mask, a.y, b.y), select(mask, a.z, b.z)};
}

// Rows r0..r3 become columns: out[c] holds element c of each row, lane k from row k.
inline void transpose(__m256d r0, __m256d r1, __m256d r2, __m256d r3, __m256d (&out)[4]) {
  const __m256d t0 = _mm256_unpacklo_pd(r0, r1), t1 = _mm256_unpackhi_pd(r0, r1);
  const __m256d t2 = _mm256_unpacklo_pd(r2, r3), t3 = _mm256_unpackhi_pd(r2, r3);
  out[0] = _mm256_permute2f128_pd(t0, t2, 0x20);
  out[1] = _mm256_permute2f128_pd(t1, t3, 0x20);
  out[2] = _mm256_permute2f128_pd(t0, t2, 0x31);
  out[3] = _mm256_permute2f128_pd(t1, t3, 0x31);
}

// The 3-vectors a[idx[k]] of four particles into lanes. A masked load reads the three
// doubles and nothing past them (the last particle's vector ends the array).
inline V3 gather(const Eigen::Vector3d* a, const std::uint32_t (&idx)[4]) {
  const __m256i xyz = _mm256_set_epi64x(0, -1, -1, -1);
  __m256d c[4];
  transpose(_mm256_maskload_pd(a[idx[0]].data(), xyz), _mm256_maskload_pd(a[idx[1]].data(), xyz),
            _mm256_maskload_pd(a[idx[2]].data(), xyz), _mm256_maskload_pd(a[idx[3]].data(), xyz),
            c);
  return {{c[0]}, {c[1]}, {c[2]}};
}
inline L4 gather(const double* a, const std::uint32_t (&idx)[4]) {
  return {_mm256_set_pd(a[idx[3]], a[idx[2]], a[idx[1]], a[idx[0]])};
}

// The eight doubles of four bonds' loads (fn, fs, mb, mt), transposed into lanes and back.
static_assert(sizeof(BondLoad<3>) == 8 * sizeof(double), "BondLoad<3> is eight packed doubles");
inline void gather(const BondLoad<3>* l, L4 (&out)[8]) {
  for (int half = 0; half < 8; half += 4) {
    __m256d c[4];
    transpose(_mm256_loadu_pd(&l[0].fn + half), _mm256_loadu_pd(&l[1].fn + half),
              _mm256_loadu_pd(&l[2].fn + half), _mm256_loadu_pd(&l[3].fn + half), c);
    for (int k = 0; k < 4; ++k) out[half + k] = {c[k]};
  }
}
inline void scatter(const L4 (&in)[8], BondLoad<3>* l) {
  for (int half = 0; half < 8; half += 4) {
    __m256d r[4];
    transpose(in[half].v, in[half + 1].v, in[half + 2].v, in[half + 3].v, r);
    for (int k = 0; k < 4; ++k) _mm256_storeu_pd(&l[k].fn + half, r[k]);
  }
}

// followContactFrame (contact_kernels.hpp), both of its branches masked.
inline void followContactFrame(V3& v, const V3& n, L4 spin_n, double dt) {
  const L4 m2 = dot(v, v);
  V3 w = v + (both(dt) * spin_n) * cross(n, v);
  w = w - dot(w, n) * n;
  const L4 m2_new = dot(w, w);
  const __m256d turned = _mm256_cmp_pd(m2_new.v, _mm256_setzero_pd(), _CMP_GT_OQ);
  // A lane with m2_new = 0 divides by zero here; select drops it.
  w = select(turned, sqrt(m2 / m2_new) * w, w);
  v = select(_mm256_cmp_pd(m2.v, _mm256_setzero_pd(), _CMP_EQ_OQ), v, w);
}

// Four bonds' section, load and step: the lanes of BondSection<3>::of and bondForce<3>.
struct Bonds4 {
  // In: the section's radius, stiffnesses per area and the stored load.
  L4 radius, kn, ks;
  L4 fn, mt;
  V3 fs, mb;
  // Out (step): force and moment on j, the peripheral stresses.
  V3 force, moment;
  L4 tensile, shear;

  void step(const V3& n, const V3& vc, const V3& dspin, L4 spin_n, double dt) {
    const L4 pi = both(std::numbers::pi);
    const L4 area = pi * radius * radius;
    const L4 inertia = pi * radius * radius * radius * radius / both(4.0);
    const L4 polar = both(2.0) * inertia;
    const L4 vn = dot(vc, n);
    const V3 vt = vc - vn * n;
    followContactFrame(fs, n, spin_n, dt);
    fn = fn - kn * area * vn * both(dt);
    fs = fs - (ks * area * both(dt)) * vt;
    followContactFrame(mb, n, spin_n, dt);
    const L4 twist = dot(dspin, n);
    mb = mb - (kn * inertia * both(dt)) * (dspin - twist * n);
    mt = mt - ks * polar * twist * both(dt);
    force = fn * n + fs;
    moment = mb + mt * n;
    shear = sqrt(dot(fs, fs)) / area + abs(mt) * radius / polar;
    tensile = -fn / area + sqrt(dot(mb, mb)) * radius / inertia;
  }
};

// The 2D pass: disks of thickness t, in-plane vectors and scalar spins and moments
// (BondSection<2>: area 2 r t, inertia 2 r^3 t / 3; no twist, and the frame turns with the
// normal only).
struct V2 {
  L4 x, y;
};
inline V2 operator+(const V2& a, const V2& b) {
  return {a.x + b.x, a.y + b.y};
}
inline V2 operator-(const V2& a, const V2& b) {
  return {a.x - b.x, a.y - b.y};
}
inline V2 operator*(L4 s, const V2& a) {
  return {s * a.x, s * a.y};
}
inline V2 operator/(const V2& a, L4 s) {
  return {a.x / s, a.y / s};
}
inline L4 dot(const V2& a, const V2& b) {  // Eigen's order: a0 b0 + a1 b1
  return a.x * b.x + a.y * b.y;
}
inline V2 cross(L4 w, const V2& r) {  // w x r, dim.hpp
  return {-w * r.y, w * r.x};
}
inline L4 cross(const V2& a, const V2& b) {  // the out-of-plane component, dim.hpp
  return a.x * b.y - a.y * b.x;
}
inline V2 select(__m256d mask, const V2& a, const V2& b) {
  return {select(mask, a.x, b.x), select(mask, a.y, b.y)};
}
inline V2 gather(const Eigen::Vector2d* a, const std::uint32_t (&idx)[4]) {
  return {{_mm256_set_pd(a[idx[3]].x(), a[idx[2]].x(), a[idx[1]].x(), a[idx[0]].x())},
          {_mm256_set_pd(a[idx[3]].y(), a[idx[2]].y(), a[idx[1]].y(), a[idx[0]].y())}};
}

// followContactFrame<2>: the spring leaves the normal's direction at its length, both
// branches masked.
inline void followContactFrame(V2& v, const V2& n) {
  const L4 m2 = dot(v, v);
  V2 w = v - dot(v, n) * n;
  const L4 m2_new = dot(w, w);
  const __m256d turned = _mm256_cmp_pd(m2_new.v, _mm256_setzero_pd(), _CMP_GT_OQ);
  w = select(turned, sqrt(m2 / m2_new) * w, w);
  v = select(_mm256_cmp_pd(m2.v, _mm256_setzero_pd(), _CMP_EQ_OQ), v, w);
}

// The kinematics of bonds b..b+3, as the scalar pass's (BondForces::compute): the normal,
// the contact point's relative velocity, the spins and the lever arms (gaps and overlaps
// shared halfway). V is V3 or V2, S the spins' V3 or L4.
template <class V, class S>
struct Kinematics4 {
  V n, vc;
  S si, sj;
  L4 li, lj;
};

template <class V, class S, int D>
inline Kinematics4<V, S> kinematics(const ParticleStore<D>& P, const BondStore<D>& B,
                                    std::size_t b) {
  const std::uint32_t is[4] = {B.i[b], B.i[b + 1], B.i[b + 2], B.i[b + 3]};
  const std::uint32_t js[4] = {B.j[b], B.j[b + 1], B.j[b + 2], B.j[b + 3]};
  const V d = gather(P.pos.data(), js) - gather(P.pos.data(), is);
  const L4 dist = sqrt(dot(d, d));
  const V n = d / dist;
  const L4 ri = gather(P.radius.data(), is), rj = gather(P.radius.data(), js);
  const L4 overlap = ri + rj - dist;  // < 0: a gap
  const L4 li = ri - both(0.5) * overlap, lj = rj - both(0.5) * overlap;
  const S si = gather(P.spin.data(), is), sj = gather(P.spin.data(), js);
  const V vc = gather(P.vel.data(), js) - gather(P.vel.data(), is) - cross(lj * sj + li * si, n);
  return {n, vc, si, sj, li, lj};
}

// What the caller settles for each bond of the group, lane k of each array.
struct Settled {
  alignas(32) double force[3][4];
  alignas(32) double ti[3][4];
  alignas(32) double tj[3][4];
  alignas(32) double tensile[4];
  alignas(32) double shear[4];
};

// Bonds b..b+3: the operations of the scalar path (BondForces::compute), lane by lane; the
// loads are written back and the outcome of each bond is left in `out`.
inline void fourBonds(const ParticleStore<3>& P, BondStore<3>& B, std::size_t b, double dt,
                      Settled& out) {
  const auto [n, vc, si, sj, li, lj] = kinematics<V3, V3>(P, B, b);
  const V3 dspin = sj - si;
  const L4 spin_n = both(0.5) * dot(si + sj, n);

  Bonds4 w;
  w.radius = load(&B.radius[b]), w.kn = load(&B.kn[b]), w.ks = load(&B.ks[b]);
  L4 stored[8];  // fn, fs, mb, mt
  gather(&B.load[b], stored);
  w.fn = stored[0], w.fs = {stored[1], stored[2], stored[3]};
  w.mb = {stored[4], stored[5], stored[6]}, w.mt = stored[7];
  w.step(n, vc, dspin, spin_n, dt);
  const L4 updated[8] = {w.fn, w.fs.x, w.fs.y, w.fs.z, w.mb.x, w.mb.y, w.mb.z, w.mt};
  scatter(updated, &B.load[b]);

  const V3 ncf = cross(n, w.fs);
  const V3 ti = li * ncf + w.moment, tj = w.moment - lj * ncf;
  const V3* vectors[3] = {&w.force, &ti, &tj};
  double(*const dest[3])[4] = {out.force, out.ti, out.tj};
  for (int v = 0; v < 3; ++v) {
    _mm256_store_pd(dest[v][0], vectors[v]->x.v);
    _mm256_store_pd(dest[v][1], vectors[v]->y.v);
    _mm256_store_pd(dest[v][2], vectors[v]->z.v);
  }
  _mm256_store_pd(out.tensile, w.tensile.v);
  _mm256_store_pd(out.shear, w.shear.v);
}

// What the caller settles for each 2D bond of the group, lane k of each array.
struct Settled2 {
  alignas(32) double force[2][4];
  alignas(32) double ti[4];
  alignas(32) double tj[4];
  alignas(32) double tensile[4];
  alignas(32) double shear[4];
};

// Bonds b..b+3 of a 2D scene: the operations of the scalar path (BondForces::compute with
// BondSection<2>::of and bondForce<2>), lane by lane; the loads are written back and the
// outcome of each bond is left in `out`.
inline void fourBonds(const ParticleStore<2>& P, BondStore<2>& B, std::size_t b, double dt,
                      Settled2& out) {
  const auto [n, vc, si, sj, li, lj] = kinematics<V2, L4>(P, B, b);
  const L4 dspin = sj - si;

  const L4 radius = load(&B.radius[b]), kn = load(&B.kn[b]), ks = load(&B.ks[b]);
  const L4 t = both(P.thickness);
  const L4 area = both(2.0) * radius * t;
  const L4 inertia = both(2.0) * radius * radius * radius * t / both(3.0);
  BondLoad<2>* l = &B.load[b];
  L4 fn{_mm256_set_pd(l[3].fn, l[2].fn, l[1].fn, l[0].fn)};
  V2 fs{{_mm256_set_pd(l[3].fs.x(), l[2].fs.x(), l[1].fs.x(), l[0].fs.x())},
        {_mm256_set_pd(l[3].fs.y(), l[2].fs.y(), l[1].fs.y(), l[0].fs.y())}};
  L4 mb{_mm256_set_pd(l[3].mb, l[2].mb, l[1].mb, l[0].mb)};

  const L4 vn = dot(vc, n);
  const V2 vt = vc - vn * n;
  followContactFrame(fs, n);
  fn = fn - kn * area * vn * both(dt);
  fs = fs - (ks * area * both(dt)) * vt;
  mb = mb - kn * inertia * dspin * both(dt);
  const V2 force = fn * n + fs;
  const L4 shear = sqrt(dot(fs, fs)) / area;
  const L4 tensile = -fn / area + abs(mb) * radius / inertia;

  alignas(32) double fn_out[4], fsx[4], fsy[4], mb_out[4];
  _mm256_store_pd(fn_out, fn.v);
  _mm256_store_pd(fsx, fs.x.v);
  _mm256_store_pd(fsy, fs.y.v);
  _mm256_store_pd(mb_out, mb.v);
  for (int k = 0; k < 4; ++k) {
    l[k].fn = fn_out[k];
    l[k].fs = Eigen::Vector2d(fsx[k], fsy[k]);
    l[k].mb = mb_out[k];
  }
  const L4 ncf = cross(n, fs);
  _mm256_store_pd(out.force[0], force.x.v);
  _mm256_store_pd(out.force[1], force.y.v);
  _mm256_store_pd(out.ti, (li * ncf + mb).v);
  _mm256_store_pd(out.tj, (mb - lj * ncf).v);
  _mm256_store_pd(out.tensile, tensile.v);
  _mm256_store_pd(out.shear, shear.v);
}

#pragma GCC pop_options

}  // namespace rocklab::lanes
