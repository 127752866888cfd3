#pragma once
// Four bonds at once, one per lane of an AVX register (3D, and 2D below). The scalar bond pass is
// bound by the latency of each bond's chain of roots and divisions (perf puts its samples on the
// instructions waiting for them; sorting the bonds or prefetching their particles changed
// nothing): a bond's ~480 instructions do not fit the out-of-order window, so bonds hardly
// overlap. Four lanes run four chains side by side and quarter the arithmetic.
//
// Every lane performs the operations of BondSection<D>::of, bondForce<D> and
// followContactFrame<D> in the same order, so a bond gets the same bits in a lane as on the
// scalar path (lanes.hpp says why). Keep the two in step: a change to the scalar formulas
// must be made here too (test_bonds.cpp and test_determinism.cpp compare the two bit for
// bit on samples whose bonds break). BondForces calls these only when the CPU has AVX.

#include <cstdint>
#include <numbers>

#include "lab/core/bonds.hpp"
#include "lab/core/lanes.hpp"

namespace rocklab::lanes {

#pragma GCC push_options
#pragma GCC target("avx")

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

// The kinematics of bonds b..b+3, as the scalar pass's (BondForces::compute): the normal,
// the contact point's relative velocity, the spins and the lever arms (gaps and overlaps
// shared halfway). V is V3 or V2, S the spins' V3 or L4.
//
// Into the caller's variables, not returned as one aggregate: GCC kept such a struct's
// fourteen registers in memory, and the 3D bond pass took 20% longer (perf, 2,000 bonded
// spheres).
template <class V, class S, int D>
[[gnu::always_inline]] inline void kinematics(const ParticleStore<D>& P, const BondStore<D>& B,
                                              std::size_t b, V& n, V& vc, S& si, S& sj, L4& li,
                                              L4& lj) {
  const std::uint32_t is[4] = {B.i[b], B.i[b + 1], B.i[b + 2], B.i[b + 3]};
  const std::uint32_t js[4] = {B.j[b], B.j[b + 1], B.j[b + 2], B.j[b + 3]};
  const V d = gather(P.pos.data(), js) - gather(P.pos.data(), is);
  const L4 dist = sqrt(dot(d, d));
  n = d / dist;
  const L4 ri = gather(P.radius.data(), is), rj = gather(P.radius.data(), js);
  const L4 overlap = ri + rj - dist;  // < 0: a gap
  li = ri - both(0.5) * overlap, lj = rj - both(0.5) * overlap;
  si = gather(P.spin.data(), is), sj = gather(P.spin.data(), js);
  vc = gather(P.vel.data(), js) - gather(P.vel.data(), is) - cross(lj * sj + li * si, n);
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
  V3 n, vc, si, sj;
  L4 li, lj;
  kinematics(P, B, b, n, vc, si, sj, li, lj);
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
  V2 n, vc;
  L4 si, sj, li, lj;
  kinematics(P, B, b, n, vc, si, sj, li, lj);
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
