#pragma once
// Four doubles at once, one per lane of an AVX register: the types and operations the lane
// passes share (bond_lanes.hpp, contact_lanes.hpp).
//
// Each AVX operation here (add, multiply, divide, square root) is the correctly rounded IEEE
// operation, as the scalar one; nothing is fused (-ffp-contract=off, no FMA target). A lane
// pass that performs the scalar path's operations in the same order gets the same bits, and
// the benchmark's state hash holds. Where the scalar code branches, both sides are computed
// and each lane takes its own with a mask. The dot and cross products keep Eigen's order.
//
// The functions carry the AVX target themselves (the rest of the binary stays x86-64
// baseline); the passes call them only when the CPU has AVX (lanes::available()).

#include <immintrin.h>

#include <cstdint>

#include <Eigen/Core>

namespace rocklab::lanes {

inline bool available() {
  static const bool avx = __builtin_cpu_supports("avx");
  return avx;
}

#pragma GCC push_options
#pragma GCC target("avx")

// Four doubles: lane k the group's k-th bond or contact.
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

// A 3-vector of four bonds or contacts, component by component.
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
[[gnu::always_inline]] inline V3 gather(const Eigen::Vector3d* a, const std::uint32_t (&idx)[4]) {
  const __m256i xyz = _mm256_set_epi64x(0, -1, -1, -1);
  __m256d c[4];
  transpose(_mm256_maskload_pd(a[idx[0]].data(), xyz), _mm256_maskload_pd(a[idx[1]].data(), xyz),
            _mm256_maskload_pd(a[idx[2]].data(), xyz), _mm256_maskload_pd(a[idx[3]].data(), xyz),
            c);
  return {{c[0]}, {c[1]}, {c[2]}};
}
[[gnu::always_inline]] inline L4 gather(const double* a, const std::uint32_t (&idx)[4]) {
  return {_mm256_set_pd(a[idx[3]], a[idx[2]], a[idx[1]], a[idx[0]])};
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

// In-plane vectors of four (2D): x and y, spins and moments being scalars.
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
[[gnu::always_inline]] inline V2 gather(const Eigen::Vector2d* a, const std::uint32_t (&idx)[4]) {
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

#pragma GCC pop_options

}  // namespace rocklab::lanes
