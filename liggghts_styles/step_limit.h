// The time-step rule of the bonded lumps, shared by fix bond/breakable (its
// critical-step estimate) and fix step/adaptive (the step it sets between
// runs): the exact largest eigenfrequency of one free bonded pair, and the
// choice of the next step from the remaining bonds' critical step.
// Header-only and free of LIGGGHTS, so that a unit test can check the rule
// on a hand-built pair list (tests/liggghts_styles/test_step_limit.cpp).
#ifndef MILL_STEP_LIMIT_H
#define MILL_STEP_LIMIT_H

#include <algorithm>
#include <cmath>

namespace mill::step_limit {

constexpr double kPi = 3.14159265358979323846;

// The bond springs' constants (docs/styles/fix_bond_breakable.md).
struct BondSprings {
  double modulus = 0.0;            // E_b [Pa]
  double stiffness_ratio = 1.0;    // kn/ks [-]
  double radius_multiplier = 1.0;  // lambda: bond radius = lambda min(Ri, Rj) [-]
};

// The two spheres of one bond and its initial length.
struct BondedPair {
  double ri, rj;  // radii [m]
  double mi, mj;  // masses [kg]
  double l0;      // initial bond length [m]
};

// The largest squared eigenfrequency of the free bonded pair [1/s^2], exact
// and in closed form: the 12 x 12 pair problem splits into the axial mode,
// kn A (1/mi + 1/mj); the twist, ks J (1/Ii + 1/Ij); and, in each of the two
// transverse planes, a shear-bending block of rank 2 (shear spring ks A on
// g = (-1, 1, -ri', -rj') over (ui, uj, theta_i, theta_j), ri' and rj' the
// arms from the centres to the contact point, bending spring kn I on
// h = (0, 0, -1, 1)) whose non-zero eigenvalues are those of the 2 x 2 Gram
// matrix
//   [ ks A g.M^-1.g            sqrt(ks A kn I) g.M^-1.h ]
//   [ sqrt(ks A kn I) g.M^-1.h   kn I h.M^-1.h          ].
// Springs: Potyondy & Cundall 2004, eq. 5 (A = pi R^2, I = pi R^4 / 4,
// J = 2 I; kn = E_b / L0, ks = kn / (kn/ks)); I_sphere = 2/5 m r^2.
inline double bond_omega2(const BondSprings &s, const BondedPair &p) {
  const double rb = s.radius_multiplier * std::min(p.ri, p.rj);
  const double area = kPi * rb * rb, inertia = 0.25 * area * rb * rb;
  const double kn = s.modulus / p.l0, ks = kn / s.stiffness_ratio;
  const double arm_i = p.l0 * p.ri / (p.ri + p.rj), arm_j = p.l0 - arm_i;
  const double inv_m = 1.0 / p.mi + 1.0 / p.mj;
  const double inv_ii = 1.0 / (0.4 * p.mi * p.ri * p.ri);
  const double inv_ij = 1.0 / (0.4 * p.mj * p.rj * p.rj);
  const double w2_axial = kn * area * inv_m;
  const double w2_twist = ks * 2.0 * inertia * (inv_ii + inv_ij);
  const double a = ks * area * (inv_m + arm_i * arm_i * inv_ii + arm_j * arm_j * inv_ij);
  const double c = kn * inertia * (inv_ii + inv_ij);
  const double gh = arm_i * inv_ii - arm_j * inv_ij;
  const double w2_bend =
      0.5 * (a + c) + std::sqrt(0.25 * (a - c) * (a - c) + ks * area * kn * inertia * gh * gh);
  return std::max({w2_axial, w2_twist, w2_bend});
}

// The critical step of velocity Verlet for the largest per-atom sum of its
// bonds' squared eigenfrequencies [s]: omega dt < 2 (the sum bounds the
// atom's share of the network's largest eigenvalue; exact for one pair).
// 0 when no bond is left (no bound from the bonds).
inline double critical_step(double max_omega2_sum) {
  return max_omega2_sum > 0.0 ? 2.0 / std::sqrt(max_omega2_sum) : 0.0;
}

// The critical step of one atom's springs with their dashpots [s]. The
// bonds' dashpots damp each pair's mode at the fraction `damping` of
// critical (fix bond/breakable, `damping`); an atom's top mode, whose
// squared frequency is the sum omega2_sum of its bonds' omega_b^2, is then
// damped at
//   zeta = damping x (sum of omega_b) / sqrt(sum of omega_b^2)
// (the dashpots add as damping x 2 / omega_b times each bond's stiffness;
// zeta = damping for one bond, up to damping x sqrt(n) for n equal ones),
// and velocity Verlet, whose dashpot force takes the half-step velocity,
// is stable for
//   omega dt < 2 (sqrt(1 + zeta^2) - zeta)
// (its recurrence x_{k+2} - 2 x_{k+1} + x_k = -h^2 x_{k+1} - 2 zeta h
// (x_{k+1} - x_k), h = omega dt, by the Jury conditions; the central
// difference method's bound in Belytschko, Liu & Moran 2000, Nonlinear
// Finite Elements for Continua and Structures, eq. 6.2.12). With no
// dashpots (damping 0) it is critical_step(omega2_sum). 0 when the atom has
// no bond.
inline double damped_critical_step(double omega2_sum, double omega_sum, double damping) {
  if (!(omega2_sum > 0.0)) return 0.0;
  const double omega = std::sqrt(omega2_sum);
  const double zeta = damping * omega_sum / omega;
  return 2.0 / omega * (std::sqrt(1.0 + zeta * zeta) - zeta);
}

// The step rule of fix step/adaptive (docs/styles/fix_step_adaptive.md).
struct StepRule {
  double safety = 0.5;  // the step is at most this share of the bonds' critical step [-]
  double dt_max = 0.0;  // and at most this, the contacts' and the speed's bound [s]
  double growth = 2.0;  // and grows by at most this factor per re-evaluation [-]
};

// The next step from the current one and the remaining bonds' critical step
// dt_bonds (0: no bond left): the smallest of safety x dt_bonds, dt_max and
// growth x dt_now. It may shrink at once (a smaller bound), never grows by
// more than `growth`, and is never above safety x dt_bonds.
inline double next_step(double dt_now, double dt_bonds, const StepRule &rule) {
  double dt = std::min(rule.dt_max, rule.growth * dt_now);
  if (dt_bonds > 0.0) dt = std::min(dt, rule.safety * dt_bonds);
  return dt;
}

}  // namespace mill::step_limit

#endif
