// The critical time step of a whole bonded network, not of its atoms one by
// one: the largest eigenfrequency of the linearised bond springs of every
// bond at once, found by the Lanczos method on the mass-normalised
// stiffness. Free of LIGGGHTS (fix bond/breakable gathers its bonds and
// calls it), so that a unit test can check it against dense solutions and
// closed forms (tests/liggghts_styles/test_network_step.cpp).
//
// Why: step_limit.h's per-atom sum of the pairs' omega^2 bounds the network's
// largest eigenvalue from above (exact for one pair and for a uniform
// chain's axial mode), but in a 3-D packing the bonds of one atom point in
// many directions and their modes do not all add: at coordination 6.3 the
// sum is 1.74 x the true omega_max^2, at 15.8 (flat joints at bond gap 1.4)
// 2.35 x, so the step it allows is 1.32 x and 1.53 x shorter than velocity
// Verlet's limit omega_max dt < 2 (Belytschko, Liu & Moran 2000, Nonlinear
// Finite Elements for Continua and Structures, eq. 6.2.12; the system's
// largest frequency, not an element's, is the limit).
//
// The estimate: k steps of the Lanczos recurrence (Lanczos 1950, J. Res.
// Natl. Bur. Stand. 45; Golub & Van Loan 2013, Matrix Computations, 4th ed.,
// Algorithm 10.1.1) on A = M^-1/2 K M^-1/2 from a fixed start vector give a
// tridiagonal T_k whose largest eigenvalue theta is the Ritz value, below
// lambda_max; with y the unit eigenvector of T_k for theta, the residual of
// the Ritz pair is beta_k |y_k|, and theta + beta_k |y_k| is the upper
// estimate of lambda_max used here (Zhou & Li 2011, "Bounding the spectrum
// of large Hermitian matrices", Linear Algebra Appl. 435, 480-493: the
// Ritz value plus its residual, after enough steps that the largest Ritz
// value has settled). The iteration stops
// when that residual is below `tolerance` x theta, or after
// `max_iterations` steps. The caller takes the smaller of it and the
// per-atom sum, which is a strict bound.
#ifndef MILL_NETWORK_STEP_H
#define MILL_NETWORK_STEP_H

#include <vector>

#include "bond_geometry.h"

namespace mill::network_step {

using bond_geometry::Vec3;

// One bond's springs (a parallel bond's, or an intact flat joint's: the
// same kn A, ks A, kn I, ks J; step_limit.h) between atoms a and b of the
// network (indices into Atoms), along the unit normal n from a to b, with
// the contact point at arm_a from a's centre and arm_b from b's.
struct Bond {
  int a = 0, b = 0;
  Vec3 n{1.0, 0.0, 0.0};
  double arm_a = 0.0, arm_b = 0.0;  // [m]
  double kna = 0.0, ksa = 0.0;      // normal and shear stiffness [N/m]
  double kni = 0.0, ksj = 0.0;      // bending and twisting stiffness [N m/rad]
};

// Per atom: mass [kg] and moment of inertia [kg m^2] (spheres: 0.4 m r^2).
struct Atoms {
  std::vector<double> mass, inertia;
};

struct Options {
  int max_iterations = 120;  // Lanczos steps at most
  double tolerance = 1e-4;   // stop when the Ritz residual is below this x theta
  unsigned seed = 12345u;    // of the start vector (deterministic: the same
                             // network gives the same estimate on any rank count)
};

struct Estimate {
  double ritz = 0.0;      // theta: largest Ritz value [1/s^2], <= lambda_max
  double residual = 0.0;  // beta_k |y_k| [1/s^2]
  double omega2 = 0.0;    // theta + residual: the estimate of lambda_max [1/s^2]
  int iterations = 0;     // Lanczos steps taken
};

// y = M^-1/2 K M^-1/2 x for the network (x, y: 6 values per atom, the
// translation then the rotation). Exposed for the tests.
void apply(const std::vector<Bond> &bonds, const Atoms &atoms, const std::vector<double> &x,
           std::vector<double> &y);

// The largest squared eigenfrequency of the free network [1/s^2]; 0 for no bond.
Estimate largest_omega2(const std::vector<Bond> &bonds, const Atoms &atoms,
                        const Options &opt = {});

}  // namespace mill::network_step

#endif
