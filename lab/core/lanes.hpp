#pragma once
// Several doubles at once, one per lane of a vector register: the types and operations the
// lane passes share (bond_lanes.hpp, contact_lanes.hpp). Two widths:
//   avx     four lanes (__m256d), on any CPU with AVX;
//   avx512  eight lanes (__m512d), on a CPU with AVX-512F. The contact pass is bound by the
//           latency of each pair's chain of roots and divisions, not by their throughput:
//           eight chains side by side finish in about the time of four (contact_lanes.hpp).
//
// Each vector operation here (add, multiply, divide, square root) is the correctly rounded IEEE
// operation, as the scalar one; nothing is fused (-ffp-contract=off, no FMA target). A lane
// pass that performs the scalar path's operations in the same order gets the same bits at
// either width, and the benchmark's state hash holds. Where the scalar code branches, both
// sides are computed and each lane takes its own with a mask. The dot and cross products keep
// Eigen's order.
//
// Each width's functions carry their target themselves (the rest of the binary stays x86-64
// baseline); the passes call them only when the CPU has it (available(), wide()). The
// operations on vectors of lanes (lane_vectors.inc) are written once and compiled for each
// width inside its namespace and target, as its `L` and `Mask` are.

#include <immintrin.h>

#include <cstdint>

#include <Eigen/Core>

namespace rocklab::lanes {

// The CPU has AVX: the four-lane passes can run.
inline bool available() {
  static const bool avx = __builtin_cpu_supports("avx");
  return avx;
}

// The CPU (and the system, which saves the registers) has AVX-512F: eight lanes can run.
inline bool wide() {
  static const bool avx512 = __builtin_cpu_supports("avx512f");
  return avx512;
}

#pragma GCC push_options
#pragma GCC target("avx")

namespace avx {

// Four doubles: lane k the group's k-th bond or contact.
struct L {
  __m256d v;
  static constexpr int width = 4;
};
using Mask = __m256d;  // all bits set in a lane where true

inline L both(double a) {
  return {_mm256_set1_pd(a)};
}
inline L load(const double* p) {  // p[k] to lane k
  return {_mm256_loadu_pd(p)};
}
inline void store(L a, double* p) {  // lane k to p[k]; p aligned to 32 bytes
  _mm256_store_pd(p, a.v);
}
inline L operator+(L a, L b) {
  return {_mm256_add_pd(a.v, b.v)};
}
inline L operator-(L a, L b) {
  return {_mm256_sub_pd(a.v, b.v)};
}
inline L operator*(L a, L b) {
  return {_mm256_mul_pd(a.v, b.v)};
}
inline L operator/(L a, L b) {
  return {_mm256_div_pd(a.v, b.v)};
}
inline L operator-(L a) {  // flips the sign bit, as scalar negation
  return {_mm256_xor_pd(a.v, _mm256_set1_pd(-0.0))};
}
inline L sqrt(L a) {
  return {_mm256_sqrt_pd(a.v)};
}
inline L abs(L a) {
  return {_mm256_andnot_pd(_mm256_set1_pd(-0.0), a.v)};
}
// Lane by lane: a where the mask is set, else b.
inline L select(Mask mask, L a, L b) {
  return {_mm256_blendv_pd(b.v, a.v, mask)};
}
inline Mask less(L a, L b) {  // a < b, false on NaN as in C++
  return _mm256_cmp_pd(a.v, b.v, _CMP_LT_OQ);
}
inline Mask greater(L a, L b) {  // a > b
  return _mm256_cmp_pd(a.v, b.v, _CMP_GT_OQ);
}
inline Mask equal(L a, L b) {  // a == b
  return _mm256_cmp_pd(a.v, b.v, _CMP_EQ_OQ);
}
inline Mask notEqual(L a, L b) {  // a != b, true on NaN as in C++
  return _mm256_cmp_pd(a.v, b.v, _CMP_NEQ_UQ);
}
inline Mask greaterEqual(L a, L b) {  // a >= b
  return _mm256_cmp_pd(a.v, b.v, _CMP_GE_OQ);
}
inline Mask lessEqual(L a, L b) {  // a <= b
  return _mm256_cmp_pd(a.v, b.v, _CMP_LE_OQ);
}
inline Mask andMask(Mask a, Mask b) {
  return _mm256_and_pd(a, b);
}
inline Mask orMask(Mask a, Mask b) {
  return _mm256_or_pd(a, b);
}
inline Mask andNotMask(Mask a, Mask b) {  // a and not b
  return _mm256_andnot_pd(b, a);
}
inline int bits(Mask m) {  // bit k: lane k
  return _mm256_movemask_pd(m);
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

// The 3-vectors a[idx[k]] of four particles, component by component. A masked load reads the
// three doubles and nothing past them (the last particle's vector ends the array).
[[gnu::always_inline]] inline void gather3(const Eigen::Vector3d* a, const std::uint32_t* idx,
                                           __m256d (&c)[4]) {
  const __m256i xyz = _mm256_set_epi64x(0, -1, -1, -1);
  transpose(_mm256_maskload_pd(a[idx[0]].data(), xyz), _mm256_maskload_pd(a[idx[1]].data(), xyz),
            _mm256_maskload_pd(a[idx[2]].data(), xyz), _mm256_maskload_pd(a[idx[3]].data(), xyz),
            c);
}
[[gnu::always_inline]] inline L gather(const double* a, const std::uint32_t* idx) {
  return {_mm256_set_pd(a[idx[3]], a[idx[2]], a[idx[1]], a[idx[0]])};
}
[[gnu::always_inline]] inline void gather2(const Eigen::Vector2d* a, const std::uint32_t* idx, L& x,
                                           L& y) {
  x = {_mm256_set_pd(a[idx[3]].x(), a[idx[2]].x(), a[idx[1]].x(), a[idx[0]].x())};
  y = {_mm256_set_pd(a[idx[3]].y(), a[idx[2]].y(), a[idx[1]].y(), a[idx[0]].y())};
}
// A field of four structs into lanes.
template <class P>
[[gnu::always_inline]] inline L field(const P* const* p, double P::*member) {
  return {_mm256_set_pd(p[3]->*member, p[2]->*member, p[1]->*member, p[0]->*member)};
}

#include "lab/core/lane_vectors.inc"

}  // namespace avx

#pragma GCC pop_options

#pragma GCC push_options
#pragma GCC target("avx512f")

namespace avx512 {

// Eight doubles: lane k the group's k-th contact.
struct L {
  __m512d v;
  static constexpr int width = 8;
};
using Mask = __mmask8;  // bit k set where lane k is true

inline L both(double a) {
  return {_mm512_set1_pd(a)};
}
inline L load(const double* p) {
  return {_mm512_loadu_pd(p)};
}
inline void store(L a, double* p) {  // p aligned to 64 bytes
  _mm512_store_pd(p, a.v);
}
inline L operator+(L a, L b) {
  return {_mm512_add_pd(a.v, b.v)};
}
inline L operator-(L a, L b) {
  return {_mm512_sub_pd(a.v, b.v)};
}
inline L operator*(L a, L b) {
  return {_mm512_mul_pd(a.v, b.v)};
}
inline L operator/(L a, L b) {
  return {_mm512_div_pd(a.v, b.v)};
}
inline L operator-(L a) {  // flips the sign bit (integer xor: AVX-512F has no xor_pd)
  return {_mm512_castsi512_pd(
      _mm512_xor_si512(_mm512_castpd_si512(a.v), _mm512_set1_epi64(INT64_MIN)))};
}
// The zero-masking forms with every lane set: the plain ones read an undefined register that
// GCC 12 warns about.
inline L sqrt(L a) {
  return {_mm512_maskz_sqrt_pd(0xff, a.v)};
}
inline L abs(L a) {
  return {_mm512_abs_pd(a.v)};
}
inline L select(Mask mask, L a, L b) {
  return {_mm512_mask_blend_pd(mask, b.v, a.v)};
}
inline Mask less(L a, L b) {
  return _mm512_cmp_pd_mask(a.v, b.v, _CMP_LT_OQ);
}
inline Mask greater(L a, L b) {
  return _mm512_cmp_pd_mask(a.v, b.v, _CMP_GT_OQ);
}
inline Mask equal(L a, L b) {
  return _mm512_cmp_pd_mask(a.v, b.v, _CMP_EQ_OQ);
}
inline Mask notEqual(L a, L b) {
  return _mm512_cmp_pd_mask(a.v, b.v, _CMP_NEQ_UQ);
}
inline Mask greaterEqual(L a, L b) {
  return _mm512_cmp_pd_mask(a.v, b.v, _CMP_GE_OQ);
}
inline Mask lessEqual(L a, L b) {
  return _mm512_cmp_pd_mask(a.v, b.v, _CMP_LE_OQ);
}
inline Mask andMask(Mask a, Mask b) {
  return a & b;
}
inline Mask orMask(Mask a, Mask b) {
  return a | b;
}
inline Mask andNotMask(Mask a, Mask b) {
  return a & static_cast<Mask>(~b);
}
inline int bits(Mask m) {
  return m;
}

// Two halves of four lanes into eight.
inline __m512d join(__m256d lo, __m256d hi) {
  return _mm512_maskz_insertf64x4(0xff, _mm512_castpd256_pd512(lo), hi, 1);
}
[[gnu::always_inline]] inline void gather3(const Eigen::Vector3d* a, const std::uint32_t* idx,
                                           __m512d (&c)[4]) {
  __m256d lo[4], hi[4];
  avx::gather3(a, idx, lo);
  avx::gather3(a, idx + 4, hi);
  for (int k = 0; k < 3; ++k) c[k] = join(lo[k], hi[k]);
}
[[gnu::always_inline]] inline L gather(const double* a, const std::uint32_t* idx) {
  return {_mm512_set_pd(a[idx[7]], a[idx[6]], a[idx[5]], a[idx[4]], a[idx[3]], a[idx[2]], a[idx[1]],
                        a[idx[0]])};
}
[[gnu::always_inline]] inline void gather2(const Eigen::Vector2d* a, const std::uint32_t* idx, L& x,
                                           L& y) {
  avx::L xl, yl, xh, yh;
  avx::gather2(a, idx, xl, yl);
  avx::gather2(a, idx + 4, xh, yh);
  x = {join(xl.v, xh.v)};
  y = {join(yl.v, yh.v)};
}
template <class P>
[[gnu::always_inline]] inline L field(const P* const* p, double P::*member) {
  return {_mm512_set_pd(p[7]->*member, p[6]->*member, p[5]->*member, p[4]->*member, p[3]->*member,
                        p[2]->*member, p[1]->*member, p[0]->*member)};
}

#include "lab/core/lane_vectors.inc"

}  // namespace avx512

#pragma GCC pop_options

// The four-lane names the bond pass uses.
using L4 = avx::L;
using V3 = avx::V3;
using V2 = avx::V2;
using avx::both;
using avx::gather;
using avx::load;
using avx::transpose;

}  // namespace rocklab::lanes
