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

namespace mill::flat_joint {

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

}  // namespace mill::flat_joint

#endif
