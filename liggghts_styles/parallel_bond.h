// The parallel bond's law (Potyondy & Cundall 2004, eq. 6-7, with the moment
// factor of the linear parallel bond, Potyondy 2015) for one bond, free of
// LIGGGHTS: fix bond/breakable loads a bond's inputs from its list entry and
// the atoms, calls law(), and turns the result into forces, torques and the
// breakage verdict (docs/styles/fix_bond_breakable.md gives the equations).
// law() is a template over the number type: double for one bond, a pack
// (bond_lanes.h) for two or four bonds side by side, each lane then bitwise
// the one-bond result.
#ifndef MILL_PARALLEL_BOND_H
#define MILL_PARALLEL_BOND_H

#include "bond_geometry.h"
#include "bond_lanes.h"

namespace mill::parallel_bond {

using namespace mill::bond_geometry;

// One parallel bond's inputs (T = double) or those of several bonds side by
// side (T = Lane2 or Lane4, bond_lanes.h): the pair's state and the bond's history
// and constants.
template <class T>
struct In {
  V3<T> xa, xb, va, vb, wa, wb;
  T ra, rb;
  V3<T> fs, mb;  // stored shear force and bending moment
  T mt;          // stored twisting moment
  T l0, kna, ksa, kni, ksj, inv_area, inv_inertia, rbond, cn, cs;
};

// What the bond law gives: the pair's geometry, the advanced history, the
// stresses and energy, and the forces and torques.
template <class T>
struct Out {
  PairMotionT<T> m;
  V3<T> fs, mb;
  T mt;
  T stretch, fn, sigma, tau, strength, energy;
  V3<T> fb, fa, fdash, mom, ta, tb;
};

// The fix's coefficients the law reads.
struct Coefficients {
  bool damped;
  double moment_factor, cohesion, tan_friction, inv_modulus, stiffness_ratio;
};

// The parallel bond's law for one bond (double) or a pack of bonds:
// the same expressions, so each lane's result is bitwise the one-bond one.
template <class T>
[[gnu::always_inline]] inline void law(const In<T> &in, T dt, bool advance, const Coefficients &k,
                                       Out<T> &o) {
  const V3<T> d = in.xb - in.xa;
  const T len = vsqrt(dot(d, d));
  // The relative motion at the end of the step is needed for the dashpots
  // only; otherwise the geometry (n, the contact point) is enough.
  o.m = k.damped ? pair_motion(d, len, in.va, in.vb, in.wa, in.wb, in.ra, in.rb)
                 : pair_geometry(d, len, in.va, in.vb, in.wa, in.wb, in.ra, in.rb);
  const PairMotionT<T> &m = o.m;
  const V3<T> n = m.n;
  V3<T> fs = in.fs;
  V3<T> mb = in.mb;
  T mt = in.mt;

  if (advance) {
    // The step's increments at its midpoint (second order): the velocities
    // are those of the half step, so the pair's geometry is taken at the half
    // step too, x - v dt/2. Taken at the end of the step, the increments make
    // a first-order error that pumps energy into a tumbling bonded pair
    // (docs/styles/fix_bond_breakable.md, "Energy").
    const V3<T> dmid = d - T(0.5 * dt) * (m.vrel_ab);
    const T lmid = vsqrt(dot(dmid, dmid));
    const PairMotionT<T> h = pair_motion(dmid, lmid, in.va, in.vb, m.wa, m.wb, in.ra, in.rb);
    // Carry the stored shear force and bending moment with the bond plane,
    // onto the midpoint plane, then (after the increment) onto the end plane.
    // The spin about n: half with each move (applied once, at the end, a
    // twisting pair gains 14 % of its energy in 11 turns).
    const T spin = 0.5 * (dot(m.wa, n) + dot(m.wb, n)) * dt;
    fs = rotate_onto_plane(fs, h.n, T(0.5 * spin));
    mb = rotate_onto_plane(mb, h.n, T(0.5 * spin));
    // Potyondy & Cundall 2004, eq. 6: incremental shear force and moments.
    const V3<T> wrel = m.wb - m.wa;
    const T wn = dot(wrel, h.n);
    const T ksa_dt = in.ksa * dt, kni_dt = in.kni * dt;
    fs = fs - ksa_dt * h.vt;               // dF^s = -k^s A dU^s
    mb = mb - kni_dt * (wrel - wn * h.n);  // dM^s = -k^n I dtheta^s
    mt -= in.ksj * wn * dt;                // dM^n = -k^s J dtheta^n
    fs = rotate_onto_plane(fs, n, T(0.5 * spin));
    mb = rotate_onto_plane(mb, n, T(0.5 * spin));
  }
  o.fs = fs;
  o.mb = mb;
  o.mt = mt;

  // Normal force from the total stretch (tension > 0): exact elastic energy
  // (the total form of P&C eq. 6's normal increment).
  const T stretch = len - in.l0;
  const T fn = in.kna * stretch;
  o.stretch = stretch;
  o.fn = fn;

  // Potyondy & Cundall 2004, eq. 7, with the moment-contribution factor beta of
  // the linear parallel bond (Potyondy 2015, sec. 2; Itasca PFC 5 manual,
  // "Linear Parallel Bond Model"): extreme stresses on the bond periphery. The
  // normal force keeps its sign (tension > 0): a compressed bond needs more
  // bending to fail in tension.
  const T mb_sq = dot(mb, mb), fs_sq = dot(fs, fs);
  const T mb_mag = vsqrt(mb_sq);
  const T fs_mag = vsqrt(fs_sq);
  const T sigma_n = fn * in.inv_area;  // mean normal stress, tension > 0
  o.sigma = sigma_n + k.moment_factor * mb_mag * in.rbond * in.inv_inertia;
  o.tau = fs_mag * in.inv_area + k.moment_factor * vfabs(mt) * in.rbond * 0.5 * in.inv_inertia;
  // Mohr-Coulomb shear strength on the mean normal stress (same sources:
  // tau_c = c - sigma_n tan(phi), tension > 0): compression raises it.
  o.strength = k.cohesion - k.tan_friction * sigma_n;
  // Elastic energy: fn^2/(2 kn A) + |Fs|^2/(2 ks A) + |Mb|^2/(2 kn I) + Mt^2/(2 ks J);
  // a bond that breaks now releases it (the energy ledger's "released").
  const T inv_kn = in.l0 * k.inv_modulus;
  o.energy =
      0.5 * fn * stretch + 0.5 * inv_kn *
                               (k.stiffness_ratio * fs_sq * in.inv_area + mb_sq * in.inv_inertia +
                                k.stiffness_ratio * mt * mt * 0.5 * in.inv_inertia);

  // Force on b: spring part plus optional viscous part (fraction of critical
  // damping of the two-body normal / shear oscillator; not part of the stress).
  V3<T> fb = -fn * n + fs;
  o.fdash = {T{}, T{}, T{}};
  if (k.damped) {
    fb = fb - (in.cn * m.vn * n + in.cs * m.vt);
    o.fdash = -(in.cn * m.vn * n + in.cs * m.vt);
  }
  o.fb = fb;
  o.fa = -fb;

  // Torques: force at the contact point plus the bond moments (on b: +M).
  o.mom = mb + mt * n;
  o.ta = cross(m.ra, o.fa) - o.mom;
  o.tb = cross(m.rb, fb) + o.mom;
}

// Lane k of a pack's law as one bond's.
template <class L>
inline Out<double> lane_of(const Out<L> &o, int k) {
  Out<double> s;
  s.m.n = lane(o.m.n, k);
  s.m.ra = lane(o.m.ra, k);
  s.m.rb = lane(o.m.rb, k);
  s.m.wa = lane(o.m.wa, k);
  s.m.wb = lane(o.m.wb, k);
  s.m.vt = lane(o.m.vt, k);
  s.m.vn = o.m.vn[k];
  s.m.vrel_ab = lane(o.m.vrel_ab, k);
  s.fs = lane(o.fs, k);
  s.mb = lane(o.mb, k);
  s.mt = o.mt[k];
  s.stretch = o.stretch[k];
  s.fn = o.fn[k];
  s.sigma = o.sigma[k];
  s.tau = o.tau[k];
  s.strength = o.strength[k];
  s.energy = o.energy[k];
  s.fb = lane(o.fb, k);
  s.fa = lane(o.fa, k);
  s.fdash = lane(o.fdash, k);
  s.mom = lane(o.mom, k);
  s.ta = lane(o.ta, k);
  s.tb = lane(o.tb, k);
  return s;
}

}  // namespace mill::parallel_bond

#endif
