// Several bonds side by side: packs of 2 or 4 doubles (GCC/Clang vector
// extension) on which fix bond/breakable evaluates that many parallel bonds
// with the same operations, lane by lane, as the one-bond code does on a
// double. Every operation used here (+, -, *, /, sqrt, |x|, comparisons,
// selects) is exact per lane in IEEE arithmetic, so a lane's result is
// bitwise the one-bond result as long as the expressions are the same and
// nothing is contracted into a fused multiply-add (the styles are built with
// -ffp-contract=off).
//
// Why: one bond's evaluation is a chain of dependent square roots and
// divisions (bench/README.md, "The bond kernel against its physical
// limit"); several chains in one instruction stream shorten the wait per
// bond. Lane2 maps onto SSE2 (every x86-64), Lane4 onto AVX when the build
// enables it (MILL_SIMD); without it the compiler splits Lane4 into halves.
#ifndef MILL_BOND_LANES_H
#define MILL_BOND_LANES_H

#include <cmath>
#include <cstdint>
#include <cstring>

#include "bond_geometry.h"

#if defined(__SSE2__) || defined(__AVX__)
#include <immintrin.h>
#endif

namespace mill::bond_geometry {

using Lane2 = double __attribute__((vector_size(16)));
using Lane4 = double __attribute__((vector_size(32)));
using Mask2 = std::int64_t __attribute__((vector_size(16)));  // all ones: true
using Mask4 = std::int64_t __attribute__((vector_size(32)));

// Lane count of a pack.
template <class L>
inline constexpr int kLanes = sizeof(L) / sizeof(double);

[[gnu::always_inline]] inline double vsqrt(double a) { return std::sqrt(a); }
[[gnu::always_inline]] inline Lane2 vsqrt(Lane2 a) {
#if defined(__SSE2__)
  return _mm_sqrt_pd(a);
#else
  return Lane2{std::sqrt(a[0]), std::sqrt(a[1])};
#endif
}
[[gnu::always_inline]] inline Lane4 vsqrt(Lane4 a) {
#if defined(__AVX__)
  return _mm256_sqrt_pd(a);
#else
  return Lane4{std::sqrt(a[0]), std::sqrt(a[1]), std::sqrt(a[2]), std::sqrt(a[3])};
#endif
}

// |a|: the sign bit cleared, as fabs does.
[[gnu::always_inline]] inline double vfabs(double a) { return std::fabs(a); }
template <class L>
[[gnu::always_inline]] inline L vfabs(L a) {
  using M = decltype(a > a);
  const M magnitude = M{} + 0x7fffffffffffffffLL;
  return reinterpret_cast<L>(reinterpret_cast<M>(a) & magnitude);
}

// Per lane: m ? a : b.
template <class L, class M>
[[gnu::always_inline]] inline V3<L> select(M m, V3<L> a, V3<L> b) {
  return {m ? a.x : b.x, m ? a.y : b.y, m ? a.z : b.z};
}

// Element k of rows[0..N-1] as one pack (the same field of N bonds or atoms).
// Built as one initialiser (the compiler inserts the loads into the
// register): filling the pack lane by lane stored each double to the stack
// and read the pack back from there, a store-forwarding stall per gather
// (perf: a third of the flat joint's packed kernel).
template <class L>
[[gnu::always_inline]] inline L gather(const double *const *rows, int k) {
  if constexpr (kLanes<L> == 4)
    return L{rows[0][k], rows[1][k], rows[2][k], rows[3][k]};
  else
    return L{rows[0][k], rows[1][k]};
}
// A pack whose lane k is f(k), built as one initialiser (as gather).
template <class L, class F>
[[gnu::always_inline]] inline L lanes_of(F f) {
  if constexpr (kLanes<L> == 4)
    return L{f(0), f(1), f(2), f(3)};
  else
    return L{f(0), f(1)};
}

// Bit k set where lane k of the mask is true (all ones), without reading
// the lanes one by one.
[[gnu::always_inline]] inline int lane_bits(Mask2 m) {
#if defined(__SSE2__)
  return _mm_movemask_pd(reinterpret_cast<__m128d>(m));
#else
  return (m[0] ? 1 : 0) | (m[1] ? 2 : 0);
#endif
}
[[gnu::always_inline]] inline int lane_bits(Mask4 m) {
#if defined(__AVX__)
  return _mm256_movemask_pd(reinterpret_cast<__m256d>(m));
#else
  return (m[0] ? 1 : 0) | (m[1] ? 2 : 0) | (m[2] ? 4 : 0) | (m[3] ? 8 : 0);
#endif
}

template <class L>
[[gnu::always_inline]] inline V3<L> gather3(const double *const *rows) {
  return {gather<L>(rows, 0), gather<L>(rows, 1), gather<L>(rows, 2)};
}
template <class L>
inline Vec3 lane(V3<L> v, int k) {
  return {v.x[k], v.y[k], v.z[k]};
}

// A pack of 3-vectors stored once (three aligned stores), for reading lane
// by lane: lane() on a pack in registers stores and reloads it per read.
template <class L>
struct Spilled3 {
  alignas(32) double x[kLanes<L>], y[kLanes<L>], z[kLanes<L>];
  explicit Spilled3(const V3<L> &v) {
    std::memcpy(x, &v.x, sizeof(L));
    std::memcpy(y, &v.y, sizeof(L));
    std::memcpy(z, &v.z, sizeof(L));
  }
  Vec3 operator[](int k) const { return {x[k], y[k], z[k]}; }
};

// rotate_onto_plane (bond_geometry.h) on a pack, its three branches turned
// into selects: each lane gets exactly the one-vector result (flushed to +0
// below 1e-100, spun only if theta != 0, renormalised only if the length
// changed).
template <class L>
[[gnu::always_inline]] inline V3<L> rotate_onto_plane(V3<L> v, V3<L> n, L theta) {
  const L mag0_sq = dot(v, v);
  V3<L> p = v - dot(v, n) * n;
  const L c = 1.0 - 0.5 * theta * theta;
  p = select(theta != 0.0, c * p + theta * cross(n, p), p);
  const L mag1_sq = dot(p, p);
  // Lanes not renormalised may divide 0 by 0 here: their quotient is unused.
  const L scale = vsqrt(mag0_sq / mag1_sq);
  p = select((mag1_sq > 0.0) & (mag1_sq != mag0_sq), scale * p, p);
  const L zero = L{};
  return select(mag0_sq < 1e-200, V3<L>{zero, zero, zero}, p);
}

}  // namespace mill::bond_geometry

#endif
