// The per-bond vector arithmetic shared by the bond styles (fix
// bond/breakable, the flat-joint interface): a 3-vector by value, the
// contact-plane update of stored shear vectors, and the relative motion of a
// bonded pair at its contact point. Header-only: everything here is inlined
// into the bond loops.
#ifndef MILL_BOND_GEOMETRY_H
#define MILL_BOND_GEOMETRY_H

#include <cmath>

namespace mill::bond_geometry {

// Small 3-vector helpers: dot product, cross product c = a x b, Euclidean norm.
inline double dot3(const double *a, const double *b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline double norm3(const double *a) { return std::sqrt(dot3(a, a)); }

// A 3-vector by value for the per-bond arithmetic: the compiler keeps its
// components in registers (arrays written through pointers and read back
// packed stalled store forwarding: 30 % of the bond loop in perf). T is
// double, or a pack of doubles (bond_lanes.h) when several bonds are
// evaluated side by side with the same operations in each lane.
template <class T>
struct V3 {
  T x, y, z;
};
using Vec3 = V3<double>;
inline Vec3 load3(const double *p) { return {p[0], p[1], p[2]}; }
inline void store3(double *p, Vec3 v) {
  p[0] = v.x;
  p[1] = v.y;
  p[2] = v.z;
}
template <class T>
inline V3<T> operator+(V3<T> a, V3<T> b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class T>
inline V3<T> operator-(V3<T> a, V3<T> b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class T>
inline V3<T> operator-(V3<T> a) {
  return {-a.x, -a.y, -a.z};
}
template <class T>
inline V3<T> operator*(T s, V3<T> a) {
  return {s * a.x, s * a.y, s * a.z};
}
template <class T>
inline T dot(V3<T> a, V3<T> b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class T>
inline V3<T> cross(V3<T> a, V3<T> b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

// Moves a stored contact-plane vector v onto the plane normal to n and spins it
// about n by the small angle theta: the rigid-body update of the contact frame
// used by PFC3D for the parallel bond (Potyondy & Cundall 2004, sec. 2.2; Itasca
// PFC manual, "contact force update"). |v| is kept exactly; the spin uses the
// second-order rotation v cos(theta) + (n x v) sin(theta) with
// cos ~ 1 - theta^2/2, sin ~ theta (theta = spin x dt << 1 for a stable dt).
[[gnu::always_inline]] inline Vec3 rotate_onto_plane(Vec3 v, Vec3 n, double theta) {
  const double mag0_sq = dot(v, v);
  // |v| < 1e-100: flush, denormal arithmetic is ~100x slower
  if (mag0_sq < 1e-200) return {0.0, 0.0, 0.0};
  v = v - dot(v, n) * n;
  if (theta != 0.0) {
    const double c = 1.0 - 0.5 * theta * theta;
    v = c * v + theta * cross(n, v);
  }
  const double mag1_sq = dot(v, v);
  if (mag1_sq > 0.0 && mag1_sq != mag0_sq) v = std::sqrt(mag0_sq / mag1_sq) * v;
  return v;
}

// Relative motion of a bonded (or touching) pair a-b at the contact point,
// which splits the line of centres Ra : Rb so that a rigid rotation of the
// pair gives no relative motion there (objective shear increment).
template <class T>
struct PairMotionT {
  V3<T> n;        // unit vector a -> b
  V3<T> ra, rb;   // contact point from a and from b
  V3<T> wa, wb;   // spins of a and b
  V3<T> vt;       // tangential relative velocity of b's material point w.r.t. a's
  T vn;           // normal relative velocity (> 0: separating)
  V3<T> vrel_ab;  // vb - va (centres)
};
using PairMotion = PairMotionT<double>;
template <class T>
[[gnu::always_inline]] inline PairMotionT<T> pair_motion(V3<T> d, T len, V3<T> va, V3<T> vb,
                                                         V3<T> wa, V3<T> wb, T ra_s, T rb_s) {
  PairMotionT<T> m;
  const T inv_len = 1.0 / len;
  m.n = inv_len * d;
  const T arm_a = len * ra_s / (ra_s + rb_s);
  const T arm_b = len - arm_a;
  m.ra = arm_a * m.n;
  m.rb = -arm_b * m.n;
  m.wa = wa;
  m.wb = wb;
  m.vrel_ab = vb - va;
  const V3<T> vrel = ((vb - va) + cross(wb, m.rb)) - cross(wa, m.ra);
  m.vn = dot(vrel, m.n);
  m.vt = vrel - m.vn * m.n;
  return m;
}

// The same pair without the relative velocity at the contact point (vn, vt
// zero): what a bond needs at the end of its step when it has no dashpots.
template <class T>
[[gnu::always_inline]] inline PairMotionT<T> pair_geometry(V3<T> d, T len, V3<T> va, V3<T> vb,
                                                           V3<T> wa, V3<T> wb, T ra_s, T rb_s) {
  PairMotionT<T> m;
  m.n = T(1.0 / len) * d;
  const T arm_a = len * ra_s / (ra_s + rb_s);
  m.ra = arm_a * m.n;
  m.rb = -(len - arm_a) * m.n;
  m.wa = wa;
  m.wb = wb;
  m.vrel_ab = vb - va;
  m.vn = T{};
  m.vt = {T{}, T{}, T{}};
  return m;
}

}  // namespace mill::bond_geometry

#endif
