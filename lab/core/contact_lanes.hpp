#pragma once
// Touching particle pairs several at once, one per lane of a vector register (2D and 3D), as
// the bond pass does with bonds (bond_lanes.hpp): four per AVX register, eight per AVX-512
// register. A touching pair costs some 400 instructions in one chain of roots and divisions
// (the normal, the frame's turn, the Coulomb cap) that does not fit the out-of-order window
// twice; the lanes run four or eight chains side by side. On the benchmark scene (Hertz, 10k
// spheres, one thread) eight lanes take two thirds of the time four take (perf).
//
// Every lane performs the operations of ContactModelImpl::interact, pairShape<D>, the law's
// evaluate and contactForce<D> (contact_kernels.hpp) in the same order, so a pair gets the
// same bits in a lane as on the scalar path (lanes.hpp says why). Keep them in step: a
// change to the scalar formulas must be made here too (test_contact_kernels.cpp and
// test_determinism.cpp compare the paths bit for bit, sliding and sticking, damped and not).
// A law without a lane form (LaneLaw) runs on the scalar path.

#include <cstdint>
#include <numbers>
#include <type_traits>

#include "lab/core/contact_law_hertz.hpp"
#include "lab/core/contact_law_linear.hpp"
#include "lab/core/lanes.hpp"

namespace rocklab::lanes {

// The laws with a lane form (contact_lanes.inc).
template <class Law>
struct LaneLaw : std::false_type {};
template <>
struct LaneLaw<LinearLaw> : std::true_type {};
template <>
struct LaneLaw<HertzLaw> : std::true_type {};

#pragma GCC push_options
#pragma GCC target("avx")
namespace avx {
#include "lab/core/contact_lanes.inc"
}  // namespace avx
#pragma GCC pop_options

#pragma GCC push_options
#pragma GCC target("avx512f")
namespace avx512 {
#include "lab/core/contact_lanes.inc"
}  // namespace avx512
#pragma GCC pop_options

}  // namespace rocklab::lanes
