#pragma once
// Bonds several at once, one per lane of a vector register (3D, and 2D below): four per AVX
// register, eight per AVX-512 register. The scalar bond pass is bound by the latency of each
// bond's chain of roots and divisions (perf puts its samples on the instructions waiting for
// them; sorting the bonds or prefetching their particles changed nothing): a bond's ~480
// instructions do not fit the out-of-order window, so bonds hardly overlap. The lanes run four
// or eight chains side by side.
//
// Every lane performs the operations of BondSection<D>::of, bondForce<D> and
// followContactFrame<D> in the same order, so a bond gets the same bits in a lane as on the
// scalar path (lanes.hpp says why). Keep the two in step: a change to the scalar formulas
// must be made here too (test_bonds.cpp and test_determinism.cpp compare the paths bit for
// bit on samples whose bonds break). BondForces calls these only when the CPU has the width.

#include <cstdint>
#include <numbers>
#include <utility>
#include <vector>

#include "lab/core/bonds.hpp"
#include "lab/core/lanes.hpp"

namespace rocklab::lanes {

static_assert(sizeof(BondLoad<3>) == 8 * sizeof(double), "BondLoad<3> is eight packed doubles");

#pragma GCC push_options
#pragma GCC target("avx")
namespace avx {

// The eight doubles of four bonds' loads (fn, fs, mb, mt), transposed into lanes and back.
inline void gatherLoads(const BondLoad<3>* l, L (&out)[8]) {
  for (int half = 0; half < 8; half += 4) {
    __m256d c[4];
    transpose(_mm256_loadu_pd(&l[0].fn + half), _mm256_loadu_pd(&l[1].fn + half),
              _mm256_loadu_pd(&l[2].fn + half), _mm256_loadu_pd(&l[3].fn + half), c);
    for (int k = 0; k < 4; ++k) out[half + k] = {c[k]};
  }
}
inline void scatterLoads(const L (&in)[8], BondLoad<3>* l) {
  for (int half = 0; half < 8; half += 4) {
    __m256d r[4];
    transpose(in[half].v, in[half + 1].v, in[half + 2].v, in[half + 3].v, r);
    for (int k = 0; k < 4; ++k) _mm256_storeu_pd(&l[k].fn + half, r[k]);
  }
}

#include "lab/core/bond_lanes.inc"

}  // namespace avx
#pragma GCC pop_options

#pragma GCC push_options
#pragma GCC target("avx512f")
namespace avx512 {

// Eight bonds' loads: each half of the lanes as four bonds'.
inline void gatherLoads(const BondLoad<3>* l, L (&out)[8]) {
  avx::L lo[8], hi[8];
  avx::gatherLoads(l, lo);
  avx::gatherLoads(l + 4, hi);
  for (int k = 0; k < 8; ++k) out[k] = {join(lo[k].v, hi[k].v)};
}
inline void scatterLoads(const L (&in)[8], BondLoad<3>* l) {
  avx::L lo[8], hi[8];
  for (int k = 0; k < 8; ++k) {
    lo[k] = {_mm512_maskz_extractf64x4_pd(0xf, in[k].v, 0)};
    hi[k] = {_mm512_maskz_extractf64x4_pd(0xf, in[k].v, 1)};  // see sqrt() in lanes.hpp
  }
  avx::scatterLoads(lo, l);
  avx::scatterLoads(hi, l + 4);
}

#include "lab/core/bond_lanes.inc"

}  // namespace avx512
#pragma GCC pop_options

}  // namespace rocklab::lanes
