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
// packed stalled store forwarding: 30 % of the bond loop in perf).
struct Vec3 {
  double x, y, z;
};
inline Vec3 load3(const double *p) { return {p[0], p[1], p[2]}; }
inline void store3(double *p, Vec3 v) {
  p[0] = v.x;
  p[1] = v.y;
  p[2] = v.z;
}
inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator-(Vec3 a) { return {-a.x, -a.y, -a.z}; }
inline Vec3 operator*(double s, Vec3 a) { return {s * a.x, s * a.y, s * a.z}; }
inline double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(Vec3 a, Vec3 b) {
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
struct PairMotion {
  Vec3 n;       // unit vector a -> b
  Vec3 ra, rb;  // contact point from a and from b
  Vec3 wa, wb;  // spins of a and b
  Vec3 vt;      // tangential relative velocity of b's material point w.r.t. a's
  double vn;    // normal relative velocity (> 0: separating)
  Vec3 vrel_ab; // vb - va (centres)
};
[[gnu::always_inline]] inline PairMotion pair_motion(Vec3 d, double len, Vec3 va, Vec3 vb, Vec3 wa,
                                                     Vec3 wb, double ra_s, double rb_s) {
  PairMotion m;
  const double inv_len = 1.0 / len;
  m.n = inv_len * d;
  const double arm_a = len * ra_s / (ra_s + rb_s);
  const double arm_b = len - arm_a;
  m.ra = arm_a * m.n;
  m.rb = -arm_b * m.n;
  m.wa = wa;
  m.wb = wb;
  m.vrel_ab = vb - va;
  const Vec3 vrel = ((vb - va) + cross(wb, m.rb)) - cross(wa, m.ra);
  m.vn = dot(vrel, m.n);
  m.vt = vrel - m.vn * m.n;
  return m;
}

// The same pair without the relative velocity at the contact point (vn, vt
// zero): what a bond needs at the end of its step when it has no dashpots.
[[gnu::always_inline]] inline PairMotion pair_geometry(Vec3 d, double len, Vec3 va, Vec3 vb, Vec3 wa,
                                                       Vec3 wb, double ra_s, double rb_s) {
  PairMotion m;
  m.n = (1.0 / len) * d;
  const double arm_a = len * ra_s / (ra_s + rb_s);
  m.ra = arm_a * m.n;
  m.rb = -(len - arm_a) * m.n;
  m.wa = wa;
  m.wb = wb;
  m.vrel_ab = vb - va;
  m.vn = 0.0;
  m.vt = {0.0, 0.0, 0.0};
  return m;
}

}  // namespace mill::bond_geometry

#endif
