// The flat-joint interface of Potyondy (2012, ARMA 12-501; 3D form: Itasca
// PFC 5/6 manual, "Flat-Joint Model"): the mechanics of one bonded contact
// between two grains, free of LIGGGHTS so that it can be tested on its own.
// docs/styles/fix_bond_flatjoint.md gives the equations; the fix that glues a lump
// with it keeps one history record per pair (kHistory + 3 per element).
//
// The interface is a disc of radius R normal to the line of centres, cut into
// Nr rings x Na sectors. Each element is bonded or broken on its own:
//   - a bonded element carries tension, compression and shear and breaks when
//     its normal stress exceeds the tensile strength or its shear stress the
//     Mohr-Coulomb strength c - sigma tan(phi_b);
//   - a broken element carries compression only, and shear up to
//     mu x its compressive force (Coulomb slip), once the grains' faces
//     touch: an interface made across an installation gap g0 (grains that
//     did not touch) closes that gap before its broken elements push back.
// Because every element sits at its own place on the disc, a partly broken
// interface still carries a moment from its bonded elements, and a fully
// broken one under compression resists rolling until its load has moved to
// its outermost elements: the interlocking that lets a flat-jointed material
// reach the compressive/tensile strength ratio of rock (Potyondy 2012).
#ifndef MILL_FLAT_JOINT_H
#define MILL_FLAT_JOINT_H

#include <stdexcept>
#include <vector>

#include "bond_geometry.h"
#include "bond_lanes.h"

namespace mill::flat_joint {

using bond_geometry::V3;
using bond_geometry::Vec3;

// Most elements one interface may have (Nr x Na).
inline constexpr int kMaxElements = 32;

// Where the elements sit, as fractions of the interface: element e of ring k
// (k = 0..Nr-1, equal radial widths) and sector s (s = 0..Na-1, equal angles)
// is one point at the sector's mid-angle and at the ring's radius of
// gyration, rho = R sqrt((r_in^2 + r_out^2) / 2). With Na >= 3 the intact
// interface then has exactly the area A, the second moment I = pi R^4/4
// (about any in-plane axis) and the polar moment J = pi R^4/2 of the disc:
// intact, it is as stiff as the parallel bond of the same radius.
struct Layout {
  int nr = 1, na = 3;
  std::vector<double> area;      // A_e / A  (sums to 1)
  std::vector<double> px;        // in-plane position / R along t1
  std::vector<double> py;        // in-plane position / R along t2
  std::vector<double> inv_area;  // A / A_e: the element loop multiplies, never divides
  int elements() const { return nr * na; }
};
// Throws std::invalid_argument for nr < 1, na < 3 or nr x na > kMaxElements.
Layout make_layout(int nr, int na);

// The interface's material, per unit area of the interface.
struct Params {
  double kn = 0;        // normal stiffness [Pa/m] (E_b / L0)
  double ks = 0;        // shear stiffness [Pa/m] (kn / (kn/ks))
  double radius = 0;    // R [m]
  double tensile = 0;   // sigma_c, tensile strength of a bonded element [Pa]
  double cohesion = 0;  // c, cohesion of a bonded element [Pa]
  double tan_phi = 0;   // tan of the bonded elements' friction angle [-]
  double mu = 0;        // friction coefficient of broken elements [-]
  // Tension softening (a cohesive law, Hillerborg et al. 1976): 1 is brittle
  // (an element breaks at sigma_c). lambda > 1: past the opening
  // u_t = sigma_c / kn an element's tension falls linearly to zero at
  // u_s = lambda u_t, where it breaks; below that envelope it unloads and
  // reloads along its secant (damage D, stiffness (1 - D) kn in tension,
  // kn in compression). Its fracture energy is lambda sigma_c^2 / (2 kn)
  // per unit area, lambda times the brittle element's.
  double softening = 1.0;
};

// History of one interface, kept by the caller: a reference axis t1 in the
// interface plane (global frame, carried with the pair), the normal it was
// last carried onto, the relative bend rotation of b against a in the
// (t1, t2 = n x t1) frame, and per element its state and its shear force in
// that frame. Held in the frame, the shear forces and the bend rotation turn
// with the pair exactly (objectivity).
inline constexpr int kT1 = 0;      // 3: t1, unit, normal to kNormal
inline constexpr int kNormal = 3;  // 3: the unit normal t1 was last carried onto
inline constexpr int kBend = 6;    // 2: theta_b . t1, theta_b . t2 [rad]
inline constexpr int kHistory = 8;
inline constexpr int kState = 0;  // per element, at kHistory + 3 e: 0 bonded, 1 broken;
                                  // between: bonded, softened to damage D (Params::softening)
inline constexpr int kShear = 1;  // 2: shear force on b along t1, t2 [N]
inline int history_size(int elements) { return kHistory + 3 * elements; }

// A fresh history for a pair along n: every element bonded (or broken when
// `bonded` is false: an unbonded slit interface), no load.
void init_history(double *h, const Layout &lay, Vec3 n, bool bonded);

// One step of the pair, as the caller measured it. The increments are those
// of the step, taken at its midpoint (the bond style's scheme: second order).
struct Step {
  Vec3 n_mid, n_end;  // unit normal a -> b at the midpoint and at the end
  Vec3 du_shear;      // shear displacement increment of b's face at the contact
                      // point relative to a's, normal to n_mid [m]
  Vec3 dtheta;        // rotation increment of b relative to a [rad]
  double spin = 0;    // rotation of the interface frame about n this step [rad]
  Vec3 vrel;          // velocity of b's face at the contact point relative to a's
                      // (half step) [m/s], for the energy released by breaks
  Vec3 wrel;          // spin of b relative to a (half step) [rad/s]
  double dt = 0;      // [s]
  double stretch = 0; // centre distance minus its bonded length, at the end [m]
  double gap0 = 0;    // installation gap: the grains' surface gap when the interface
                      // was made, >= 0 [m]; a broken element touches once the
                      // opening stretch + gap0 is below zero
  bool advance = true;  // false: evaluate only (no increment, no break)
  bool stresses = true; // false: Result::sigma_max and tau_ratio only on a step with a
                        // break (when a break log wants them); 0 on the others
};

// What the interface does to the pair at the end of the step.
struct Result {
  Vec3 force_b;   // force on b (on a: minus it) [N]
  Vec3 moment_b;  // moment on b about the contact point (on a: minus it) [N m]
  double energy = 0;    // elastic energy stored in the elements [J]
  double slipped = 0;   // taken by Coulomb slip this step [J]
  double released = 0;  // stored in elements that broke this step, and what softening
                        // elements dissipated in it [J]
  int bonded = 0;       // bonded elements after the step
  int broke_tension = 0, broke_shear = 0;  // elements that broke this step
  // Over the elements bonded at the start of the step (those that broke in
  // it at their stress at the break; with Step::stresses false, on a step
  // with a break only):
  double sigma_max = 0;  // largest normal stress (tension > 0) [Pa]
  double tau_ratio = 0;  // largest shear stress / shear strength [-]
  bool loaded = false;   // some element carries force (bonded, or broken and pressed)
};

// Advances (step.advance) and evaluates the interface whose history is h.
Result update(double *h, const Layout &lay, const Params &p, const Step &step);

// sin and cos of the small turns the frame makes in one step. Below
// kSeriesTurn (|a| < 1e-3 rad; an impact's steps turn a pair by ~1e-5 rad)
// they are the Taylor series a - a^3/3! + a^5/5! and 1 - a^2/2! + a^4/4!,
// whose truncation errors, below a^7/7! and a^6/6!, are under 2e-22 of
// sin a and 1.4e-21 of cos a there: far below a double's round-off
// (1.1e-16), so the series is the exact value to round-off at a fraction of
// the cost of the library's sin and cos, which it uses above the switch.
inline constexpr double kSeriesTurn = 1.0e-3;
struct SinCos {
  double sin, cos;
};
SinCos turn_sin_cos(double a);

// The frame's reference axis t1 (unit, normal to n0) carried from the
// normal n0 to n1 and turned by `spin` about n1, unit and normal to n1
// again (update() carries its frame so, in two halves, each step): exposed
// for the tests of its rotation and series branch.
Vec3 carry(Vec3 t1, Vec3 n0, Vec3 n1, double spin);

// Stiffnesses of the intact interface, for the critical time step: normal
// and shear [N/m], bending and twisting [N m/rad]. Equal to the parallel
// bond's kn A, ks A, kn I, ks J (Layout: radius of gyration).
struct Stiffness {
  double normal, shear, bending, twisting;
};
Stiffness intact_stiffness(const Layout &lay, const Params &p);

// The sums over an interface's elements that update() and update_intact()
// both make, in one place so that the packed lanes stay bitwise update():
// the force and moment on b in the frame (t1, t2, n) (an element at
// r = x t1 + y t2 pushing f = -N n + S1 t1 + S2 t2 adds r x f =
// -y N t1 + x N t2 + (x S2 - y S1) n) and sum_e N_e^2 / a_e,
// |S_e|^2 / a_e for the stored energy (a_e = A_e / A; a softened element
// opened in tension stores N^2 / (2 (1 - D) kn A_e): inv_keep = 1 / (1 - D)).
template <class T>
struct ElementSums {
  T f1{}, f2{}, fn{}, m1{}, m2{}, mn{}, sum_n{}, sum_s{};
  [[gnu::always_inline]] void add(T normal, T s1, T s2, T x, T y, double inv_a, T inv_keep) {
    sum_n += normal * normal * inv_a * inv_keep;
    sum_s += (s1 * s1 + s2 * s2) * inv_a;
    f1 += s1;
    f2 += s2;
    fn -= normal;
    m1 -= y * normal;
    m2 += x * normal;
    mn += x * s2 - y * s1;
  }
  // sum_e N_e^2 / (2 kn A_e) + |S_e|^2 / (2 ks A_e), A_e = a_e A.
  T energy(T kna_all, T ksa_all) const { return 0.5 * (sum_n / kna_all + sum_s / ksa_all); }
  V3<T> force(V3<T> t1, V3<T> t2, V3<T> n) const { return f1 * t1 + f2 * t2 + fn * n; }
  V3<T> moment(V3<T> t1, V3<T> t2, V3<T> n) const { return m1 * t1 + m2 * t2 + mn * n; }
};

// ---------------------------------------------------------------------------
// Several bonded interfaces side by side (fix bond/flatjoint's packed kernel,
// docs/styles/fix_bond_flatjoint.md, "Packed kernel"): update() for 2 or 4
// interfaces at once, one per lane of a pack (bond_lanes.h), for the common
// case of an impact: every element bonded (intact, or softened to a damage
// D < 1), Step::advance true and Step::stresses false. Each lane does
// update()'s arithmetic in update()'s order, so its result is bitwise
// update()'s (tested: FlatJointKernel.*); a lane in which some element
// would break or soften further this step, or which holds a broken
// element, does not hold: its history is left untouched and its result is
// void, and the caller runs update() for it.

// The step of each lane (the Step fields an intact interface reads).
template <class T>
struct IntactStep {
  V3<T> n_mid, n_end, du_shear, dtheta;
  T spin, stretch;
};
// Each lane's material (Params::kn, ks, radius); the strengths and the
// softening are the fix's, the same in every lane.
template <class T>
struct IntactParams {
  T kn, ks, radius;
};
// What update() returns for a bonded interface that stays so: its
// force and moment, its stored energy and whether it carries force; the
// other Result fields are update()'s constants there (bonded = elements,
// no break, nothing slipped or released, sigma_max = tau_ratio = 0).
template <class T>
struct IntactResult {
  V3<T> force_b, moment_b;
  T energy;
  decltype(T{} < T{}) loaded;
};

namespace detail {
// sin_cos of flat_joint.cpp per lane: the series below kSeriesTurn, the
// library's sin and cos in the (rare) lanes above it.
template <class T>
[[gnu::always_inline]] inline void sin_cos_lanes(T a, T &sn, T &cs) {
  const T a2 = a * a;
  sn = a * (1.0 - a2 * (1.0 / 6.0) * (1.0 - a2 * (1.0 / 20.0)));
  cs = 1.0 - 0.5 * a2 * (1.0 - a2 * (1.0 / 12.0));
  const int big = bond_geometry::lane_bits(bond_geometry::vfabs(a) >= kSeriesTurn);
  if (big == 0) return;  // the usual case: every lane's turn below the switch
  for (int l = 0; l < bond_geometry::kLanes<T>; ++l)
    if (big >> l & 1) {
      sn[l] = std::sin(a[l]);
      cs[l] = std::cos(a[l]);
    }
}
// turn() of flat_joint.cpp per lane (its spin != 0 branch a select).
template <class T>
[[gnu::always_inline]] inline V3<T> turn_lanes(V3<T> t1, V3<T> n0, V3<T> n1, T spin) {
  const V3<T> s = n0 + n1;
  t1 = t1 - (dot(s, t1) / (1.0 + dot(n0, n1))) * s;
  T sn, cs;
  sin_cos_lanes(spin, sn, cs);
  const V3<T> spun = cs * t1 + sn * cross(n1, t1);
  return bond_geometry::select(spin != 0.0, spun, t1);
}
// carry_inline() of flat_joint.cpp per lane.
template <class T>
[[gnu::always_inline]] inline V3<T> carry_lanes(V3<T> t1, V3<T> n0, V3<T> n1, T spin) {
  t1 = turn_lanes(t1, n0, n1, spin);
  t1 = t1 - dot(t1, n1) * n1;
  return (1.0 / bond_geometry::vsqrt(dot(t1, t1))) * t1;
}
template <class T>
[[gnu::always_inline]] inline V3<T> gather_v3(double *const *h, int k) {
  return {bond_geometry::gather<T>(h, k), bond_geometry::gather<T>(h, k + 1),
          bond_geometry::gather<T>(h, k + 2)};
}
}  // namespace detail

// update() of the interfaces whose histories are h[0..lanes-1], each with
// every element bonded at the start of the step; returns the lanes that hold (all ones: held, its
// history advanced and `out` its result; zero: untouched, run update()).
template <class T>
[[gnu::always_inline]] inline auto update_intact(double *const *h, const Layout &lay,
                                                 const IntactParams<T> &mat, const Params &p,
                                                 const IntactStep<T> &s, IntactResult<T> &out)
    -> decltype(T{} < T{}) {
  using M = decltype(T{} < T{});
  using bond_geometry::gather;
  constexpr double kPiLane = 3.14159265358979323846;
  const T radius = mat.radius, area = kPiLane * radius * radius;
  const T kn = mat.kn, kna_all = kn * area, ksa_all = mat.ks * area;
  const double cohesion = p.cohesion, tan_phi = p.tan_phi, tensile = p.tensile;
  const bool softens = p.softening > 1.0;
  const double *px = lay.px.data(), *py = lay.py.data(), *pa = lay.area.data();
  const double *inv_a = lay.inv_area.data();

  // The frame and the bend rotation, advanced as update() does.
  V3<T> t1 = detail::gather_v3<T>(h, kT1);
  t1 = detail::turn_lanes(t1, detail::gather_v3<T>(h, kNormal), s.n_mid, T(0.5 * s.spin));
  const V3<T> t2_mid = cross(s.n_mid, t1);
  const T du1 = dot(s.du_shear, t1);
  const T du2 = dot(s.du_shear, t2_mid);
  const T twist = dot(s.dtheta, s.n_mid);
  const T th1 = gather<T>(h, kBend) + dot(s.dtheta, t1);
  const T th2 = gather<T>(h, kBend + 1) + dot(s.dtheta, t2_mid);
  t1 = detail::carry_lanes(t1, s.n_mid, s.n_end, T(0.5 * s.spin));

  const V3<T> n = s.n_end;
  const V3<T> t2 = cross(n, t1);
  const T zero{}, one = zero + 1.0;
  ElementSums<T> sums;
  M holds = zero == zero;  // all ones
  T shear_out[2 * kMaxElements];
  const int ne = lay.elements();
  for (int e = 0; e < ne; ++e) {
    const T x = radius * px[e], y = radius * py[e];
    const T kna = kna_all * pa[e], ksa = ksa_all * pa[e];
    const int base = kHistory + 3 * e;
    const T damage = gather<T>(h, base + kState);
    holds &= damage < 1.0;  // bonded: intact, or softened to damage D < 1
    T s1 = gather<T>(h, base + kShear), s2 = gather<T>(h, base + kShear + 1);
    s1 -= ksa * (du1 - twist * y);
    s2 -= ksa * (du2 + twist * x);
    const T u = s.stretch + th1 * y - th2 * x;
    T normal = kna * u;
    // A softened element opened in tension carries (1 - D) of it (keep);
    // otherwise keep = 1, and x 1 and / 1 are exact: update()'s values.
    T keep = one, inv_keep = one;
    M grows = zero != zero;  // softening: the damage grows or the element breaks
    if (softens) {
      keep = u > 0.0 ? 1.0 - damage : one;
      inv_keep = 1.0 / keep;
      normal *= keep;
      const T u_t = tensile / kn, u_s = p.softening * u_t;
      const T d_env = 1.0 - tensile * (u_s - u) / ((u_s - u_t) * kn * u);
      grows = (u >= u_s) | ((u > u_t) & (u < u_s) & (d_env > damage));
    }
    const T sigma = keep * kn * u;
    const T strength = cohesion - sigma * tan_phi;
    const T s_sq = s1 * s1 + s2 * s2;
    const T lim = strength * area * pa[e], lim_sq = lim * lim;
    const M positive = strength > 0.0;
    const M shear_fails =
        (positive & (s_sq > lim_sq)) | (~positive & ((strength < 0.0) | (s_sq > 0.0)));
    // Brittle: it breaks past sigma_c (update() then changes its state).
    const M tension = softens ? grows : M(sigma > tensile);
    holds &= ~(shear_fails | tension);
    shear_out[2 * e] = s1;
    shear_out[2 * e + 1] = s2;
    sums.add(normal, s1, s2, x, y, inv_a[e], inv_keep);
  }
  out.energy = sums.energy(kna_all, ksa_all);
  out.loaded = (sums.sum_n > 0.0) | (sums.sum_s > 0.0);
  out.force_b = sums.force(t1, t2, n);
  out.moment_b = sums.moment(t1, t2, n);
  // The history of the lanes that hold.
  const bond_geometry::Spilled3<T> t1_l(t1), n_l(n), bend_l(V3<T>{th1, th2, zero});
  const int held = bond_geometry::lane_bits(holds);
  for (int l = 0; l < bond_geometry::kLanes<T>; ++l) {
    if (!(held >> l & 1)) continue;
    double *hl = h[l];
    hl[kT1] = t1_l.x[l], hl[kT1 + 1] = t1_l.y[l], hl[kT1 + 2] = t1_l.z[l];
    hl[kNormal] = n_l.x[l], hl[kNormal + 1] = n_l.y[l], hl[kNormal + 2] = n_l.z[l];
    hl[kBend] = bend_l.x[l], hl[kBend + 1] = bend_l.y[l];
    for (int e = 0; e < ne; ++e) {
      hl[kHistory + 3 * e + kShear] = shear_out[2 * e][l];
      hl[kHistory + 3 * e + kShear + 1] = shear_out[2 * e + 1][l];
    }
  }
  return holds;
}

}  // namespace mill::flat_joint

#endif
