// The time-step rule of fix step/adaptive (liggghts_styles/step_limit.h) on
// hand-built pair lists, without LIGGGHTS: the step chosen after each round
// of breaks never exceeds safety x the critical step of any remaining bond,
// nor of the whole remaining network, each computed independently here as
// the largest eigenvalue of M^-1/2 K M^-1/2 (Jacobi) of the 12 x 12 pair
// problem and of the assembled network.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "network_step.h"
#include "step_limit.h"

namespace {

using mill::step_limit::BondedPair;
using mill::step_limit::BondSprings;
using mill::step_limit::kPi;
using mill::step_limit::StepRule;

// Largest eigenvalue of the symmetric n x n matrix a (row-major), by cyclic Jacobi.
double largest_eigenvalue(std::vector<double> a, int n) {
  for (int sweep = 0; sweep < 100; ++sweep) {
    double off = 0.0;
    for (int p = 0; p < n; ++p)
      for (int q = p + 1; q < n; ++q) off += a[p * n + q] * a[p * n + q];
    if (off < 1e-30) break;
    for (int p = 0; p < n; ++p)
      for (int q = p + 1; q < n; ++q) {
        const double apq = a[p * n + q];
        if (std::fabs(apq) < 1e-300) continue;
        const double theta = 0.5 * (a[q * n + q] - a[p * n + p]) / apq;
        const double t =
            (theta >= 0 ? 1.0 : -1.0) / (std::fabs(theta) + std::sqrt(theta * theta + 1.0));
        const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
        for (int k = 0; k < n; ++k) {  // columns p, q
          const double akp = a[k * n + p], akq = a[k * n + q];
          a[k * n + p] = c * akp - s * akq;
          a[k * n + q] = s * akp + c * akq;
        }
        for (int k = 0; k < n; ++k) {  // rows p, q
          const double apk = a[p * n + k], aqk = a[q * n + k];
          a[p * n + k] = c * apk - s * aqk;
          a[q * n + k] = s * apk + c * aqk;
        }
      }
  }
  double m = a[0];
  for (int k = 1; k < n; ++k) m = std::max(m, a[k * n + k]);
  return m;
}

struct Sphere {
  double r, m;
  double x[3];
};
struct Bond {
  int i, j;
};

// The vector d from sphere a's centre to c's, and its length.
double separation(const Sphere &a, const Sphere &c, double (&d)[3]) {
  double l2 = 0.0;
  for (int q = 0; q < 3; ++q) {
    d[q] = c.x[q] - a.x[q];
    l2 += d[q] * d[q];
  }
  return std::sqrt(l2);
}

// Adds the parallel bond between spheres i and j (Potyondy & Cundall 2004,
// eq. 5; axis from i to j, L0 their distance) to the stiffness matrix k of
// the network, 6 coordinates per sphere (u, theta), row-major n x n.
void add_bond_stiffness(const BondSprings &s, const std::vector<Sphere> &sp, const Bond &b,
                        std::vector<double> &k, int n) {
  const Sphere &a = sp[b.i], &c = sp[b.j];
  double d[3];
  const double l0 = separation(a, c, d);
  double e[3][3];  // bond frame: e[0] the axis, e[1], e[2] perpendicular
  for (int q = 0; q < 3; ++q) e[0][q] = d[q] / l0;
  const double helper[3] = {std::fabs(e[0][0]) < 0.9 ? 1.0 : 0.0,
                            std::fabs(e[0][0]) < 0.9 ? 0.0 : 1.0, 0.0};
  double dotp = 0.0;
  for (int q = 0; q < 3; ++q) dotp += helper[q] * e[0][q];
  double nrm = 0.0;
  for (int q = 0; q < 3; ++q) {
    e[1][q] = helper[q] - dotp * e[0][q];
    nrm += e[1][q] * e[1][q];
  }
  for (int q = 0; q < 3; ++q) e[1][q] /= std::sqrt(nrm);
  e[2][0] = e[0][1] * e[1][2] - e[0][2] * e[1][1];
  e[2][1] = e[0][2] * e[1][0] - e[0][0] * e[1][2];
  e[2][2] = e[0][0] * e[1][1] - e[0][1] * e[1][0];
  const double rb = s.radius_multiplier * std::min(a.r, c.r);
  const double area = kPi * rb * rb, inertia = 0.25 * area * rb * rb, polar = 2.0 * inertia;
  const double kn = s.modulus / l0, ks = kn / s.stiffness_ratio;
  const double arm_a = l0 * a.r / (a.r + c.r), arm_c = l0 - arm_a;
  // Each spring: stiffness times g g^T, g the spring's strain as a linear form of
  // the 12 coordinates (u_a, th_a, u_c, th_c) in the global frame.
  auto spring = [&](double stiff, const double(&g)[12]) {
    const int base[4] = {6 * b.i, 6 * b.i + 3, 6 * b.j, 6 * b.j + 3};
    for (int p = 0; p < 12; ++p)
      for (int q = 0; q < 12; ++q)
        k[(base[p / 3] + p % 3) * n + base[q / 3] + q % 3] += stiff * g[p] * g[q];
  };
  double g[12];
  // Axial: (u_c - u_a) . e0.
  for (int q = 0; q < 3; ++q) g[q] = -e[0][q], g[3 + q] = 0, g[6 + q] = e[0][q], g[9 + q] = 0;
  spring(kn * area, g);
  // Shear along t = e1, e2: relative displacement of the contact point,
  // u_c + th_c x (-arm_c e0) - u_a - th_a x (arm_a e0), along t:
  // (u_c - u_a).t - arm_c (e0 x t).th_c - arm_a (e0 x t).th_a.
  for (int w = 1; w <= 2; ++w) {
    double ext[3];  // e0 x t
    ext[0] = e[0][1] * e[w][2] - e[0][2] * e[w][1];
    ext[1] = e[0][2] * e[w][0] - e[0][0] * e[w][2];
    ext[2] = e[0][0] * e[w][1] - e[0][1] * e[w][0];
    for (int q = 0; q < 3; ++q)
      g[q] = -e[w][q], g[3 + q] = -arm_a * ext[q], g[6 + q] = e[w][q], g[9 + q] = -arm_c * ext[q];
    spring(ks * area, g);
    // Bending about t: (th_c - th_a) . t.
    for (int q = 0; q < 3; ++q) g[q] = 0, g[3 + q] = -e[w][q], g[6 + q] = 0, g[9 + q] = e[w][q];
    spring(kn * inertia, g);
  }
  // Twist: (th_c - th_a) . e0.
  for (int q = 0; q < 3; ++q) g[q] = 0, g[3 + q] = -e[0][q], g[6 + q] = 0, g[9 + q] = e[0][q];
  spring(ks * polar, g);
}

// Largest omega^2 of the bonds `bonds` over the spheres (M^-1/2 K M^-1/2).
double network_omega2(const BondSprings &s, const std::vector<Sphere> &sp,
                      const std::vector<Bond> &bonds) {
  const int n = 6 * static_cast<int>(sp.size());
  std::vector<double> k(static_cast<size_t>(n) * n, 0.0);
  for (const Bond &b : bonds) add_bond_stiffness(s, sp, b, k, n);
  std::vector<double> inv_sqrt_m(n);
  for (size_t a = 0; a < sp.size(); ++a)
    for (int q = 0; q < 3; ++q) {
      inv_sqrt_m[6 * a + q] = 1.0 / std::sqrt(sp[a].m);
      inv_sqrt_m[6 * a + 3 + q] = 1.0 / std::sqrt(0.4 * sp[a].m * sp[a].r * sp[a].r);
    }
  for (int p = 0; p < n; ++p)
    for (int q = 0; q < n; ++q) k[p * n + q] *= inv_sqrt_m[p] * inv_sqrt_m[q];
  return largest_eigenvalue(k, n);
}

// The bonds' critical step as fix bond/breakable computes it: per atom the
// sum of its bonds' bond_omega2.
double fix_critical_step(const BondSprings &s, const std::vector<Sphere> &sp,
                         const std::vector<Bond> &bonds) {
  std::vector<double> sum(sp.size(), 0.0);
  for (const Bond &b : bonds) {
    const Sphere &a = sp[b.i], &c = sp[b.j];
    const double l0 =
        std::sqrt((c.x[0] - a.x[0]) * (c.x[0] - a.x[0]) + (c.x[1] - a.x[1]) * (c.x[1] - a.x[1]) +
                  (c.x[2] - a.x[2]) * (c.x[2] - a.x[2]));
    const double w2 = mill::step_limit::bond_omega2(s, BondedPair{a.r, c.r, a.m, c.m, l0});
    sum[b.i] += w2;
    sum[b.j] += w2;
  }
  return mill::step_limit::critical_step(*std::max_element(sum.begin(), sum.end()));
}

// A hand-built lump: 14 spheres of radii 0.6-1.6 mm (density 2580 kg/m3) on
// a jittered cubic lattice, bonded to their neighbours within 1.15 x the sum
// of the radii; sandstone-like springs (E_b 99.3 GPa, kn/ks 3.92).
struct Lump {
  BondSprings springs{99.3e9, 3.92, 1.0};
  std::vector<Sphere> spheres;
  std::vector<Bond> bonds;
};

Lump hand_built_lump() {
  Lump l;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> radius(0.6e-3, 1.6e-3), jitter(-0.1e-3, 0.1e-3);
  const double spacing = 3.0e-3;
  for (int k = 0; k < 14; ++k) {
    Sphere s;
    s.r = radius(rng);
    s.m = 2580.0 * 4.0 / 3.0 * kPi * s.r * s.r * s.r;
    s.x[0] = (k % 3) * spacing + jitter(rng);
    s.x[1] = ((k / 3) % 3) * spacing + jitter(rng);
    s.x[2] = (k / 9) * spacing + jitter(rng);
    l.spheres.push_back(s);
  }
  for (int i = 0; i < 14; ++i)
    for (int j = i + 1; j < 14; ++j) {
      double d2 = 0.0;
      for (int q = 0; q < 3; ++q) d2 += std::pow(l.spheres[j].x[q] - l.spheres[i].x[q], 2);
      if (std::sqrt(d2) < 1.15 * spacing) l.bonds.push_back({i, j});
    }
  return l;
}

}  // namespace

// The closed form of one pair equals the pair's 12 x 12 eigenvalue.
TEST(StepLimit, PairOmegaMatchesEigenvalue) {
  const Lump l = hand_built_lump();
  for (const Bond &b : l.bonds) {
    const double direct = network_omega2(l.springs, l.spheres, {b});
    const Sphere &a = l.spheres[b.i], &c = l.spheres[b.j];
    double l0 = 0.0;
    for (int q = 0; q < 3; ++q) l0 += (c.x[q] - a.x[q]) * (c.x[q] - a.x[q]);
    const double closed =
        mill::step_limit::bond_omega2(l.springs, {a.r, c.r, a.m, c.m, std::sqrt(l0)});
    EXPECT_NEAR(closed / direct, 1.0, 1e-9) << "bond " << b.i << "-" << b.j;
  }
}

// The lump shatters in rounds (a random third of the bonds left breaks each
// round, then all); after each round the step is re-evaluated with the rule
// of the decks (safety 0.5, growth 2, a cap of 4x the first step). The step
// never exceeds safety x 2 / omega of any remaining bond, nor of the
// remaining network; it grows once bonds are gone and reaches the cap when
// none is left.
TEST(StepLimit, StepNeverExceedsAnyRemainingBond) {
  Lump l = hand_built_lump();
  ASSERT_GE(l.bonds.size(), 20u);
  const double dt0 = 0.5 * fix_critical_step(l.springs, l.spheres, l.bonds);
  const StepRule rule{0.5, 4.0 * dt0, 2.0};
  std::mt19937 rng(11);
  double dt = dt0;
  int round = 0;
  while (true) {
    const double dt_bonds = fix_critical_step(l.springs, l.spheres, l.bonds);
    const double next = mill::step_limit::next_step(dt, dt_bonds, rule);
    EXPECT_LE(next, rule.growth * dt * (1 + 1e-15)) << "round " << round;
    EXPECT_LE(next, rule.dt_max) << "round " << round;
    double worst = 0.0;  // largest dt x omega / 2 over the remaining bonds
    for (const Bond &b : l.bonds) {
      const double w2 = network_omega2(l.springs, l.spheres, {b});
      worst = std::max(worst, next * std::sqrt(w2) / 2.0);
      EXPECT_LE(next * std::sqrt(w2) / 2.0, 1.0)
          << "round " << round << ": the step " << next << " s exceeds the critical step of bond "
          << b.i << "-" << b.j;
      EXPECT_LE(next * std::sqrt(w2) / 2.0, rule.safety * (1 + 1e-9))
          << "round " << round << ": the step " << next << " s exceeds " << rule.safety
          << " x the critical step of bond " << b.i << "-" << b.j;
    }
    const double net = l.bonds.empty() ? 0.0 : network_omega2(l.springs, l.spheres, l.bonds);
    EXPECT_LE(next * std::sqrt(net) / 2.0, 1.0)
        << "round " << round << ": the network's critical step";
    EXPECT_LE(next * std::sqrt(net) / 2.0, rule.safety * (1 + 1e-9))
        << "round " << round << ": the network";
    std::printf(
        "round %d: %zu bonds left, step %.4g s (%.3g x the first), dt omega / 2 at most %.3f "
        "(bonds), "
        "%.3f (network)\n",
        round, l.bonds.size(), next, next / dt0, worst, next * std::sqrt(net) / 2.0);
    dt = next;
    if (l.bonds.empty()) break;
    // A round of breaks: a third of the bonds left (all when 3 or fewer).
    std::shuffle(l.bonds.begin(), l.bonds.end(), rng);
    l.bonds.resize(l.bonds.size() <= 3 ? 0 : l.bonds.size() - l.bonds.size() / 3 - 1);
    ++round;
  }
  EXPECT_GT(round, 3);
  // Not vacuous: with no bond left the step reached the cap.
  EXPECT_DOUBLE_EQ(dt, rule.dt_max);
}

// Growth is limited per re-evaluation, and a smaller bound cuts the step at once.
TEST(StepLimit, GrowthLimitedAndShrinksAtOnce) {
  const StepRule rule{0.5, 1e-6, 2.0};
  EXPECT_DOUBLE_EQ(mill::step_limit::next_step(1e-8, 0.0, rule), 2e-8);   // no bonds: growth 2
  EXPECT_DOUBLE_EQ(mill::step_limit::next_step(1e-7, 1e-7, rule), 5e-8);  // safety x bonds' step
  EXPECT_DOUBLE_EQ(mill::step_limit::next_step(8e-7, 0.0, rule), 1e-6);   // the cap
  EXPECT_DOUBLE_EQ(mill::step_limit::next_step(2e-6, 0.0, rule), 1e-6);   // above the cap: cut
  EXPECT_DOUBLE_EQ(mill::step_limit::critical_step(0.0), 0.0);            // no bond: no bound
  EXPECT_DOUBLE_EQ(mill::step_limit::critical_step(4.0), 1.0);            // omega dt = 2
}

namespace {
// Largest |x| over the last half of `steps` steps of one damped oscillator
// (omega 1, damping ratio zeta, x0 = 1) integrated as LIGGGHTS does: velocity
// Verlet whose dashpot force takes the half-step velocity, the one the atoms
// hold when the fixes compute their forces.
double damped_run_amplitude(double zeta, double dt, int steps) {
  double x = 1.0, v = 0.0, a = -x, late = 0.0;
  for (int k = 0; k < steps; ++k) {
    const double v_half = v + 0.5 * dt * a;
    x += dt * v_half;
    a = -x - 2.0 * zeta * v_half;
    v = v_half + 0.5 * dt * a;
    if (k >= steps / 2) late = std::max(late, std::abs(x));
    if (!(std::abs(x) < 1e12)) return HUGE_VAL;
  }
  return late;
}
}  // namespace

// The damped critical step is the integrator's limit: for each damping ratio
// the closed form 2 (sqrt(1 + zeta^2) - zeta) / omega; at 0.98 x it the
// oscillator decays (or, undamped, keeps its amplitude), at 1.02 x it blows
// up. zeta 0.85 is the lab decks' 0.2 per bond on an atom of 18 bonds.
TEST(StepLimit, DampedCriticalStepIsTheIntegratorsLimit) {
  for (const double zeta : {0.0, 0.2, 0.5, 0.85, 2.0}) {
    const double dt = mill::step_limit::damped_critical_step(1.0, 1.0, zeta);
    EXPECT_NEAR(dt, 2.0 * (std::sqrt(1.0 + zeta * zeta) - zeta), 1e-15) << "zeta " << zeta;
    const double below = damped_run_amplitude(zeta, 0.98 * dt, 20000);
    const double above = damped_run_amplitude(zeta, 1.02 * dt, 20000);
    EXPECT_LE(below, 1.0 + 1e-9) << "zeta " << zeta << ": 0.98 x the step grows";
    EXPECT_GT(above, 1e3) << "zeta " << zeta << ": 1.02 x the step stays bounded";
  }
  // Without dashpots it is the undamped step of the same sum.
  EXPECT_DOUBLE_EQ(mill::step_limit::damped_critical_step(4.0, 3.0, 0.0),
                   mill::step_limit::critical_step(4.0));
  EXPECT_DOUBLE_EQ(mill::step_limit::damped_critical_step(0.0, 0.0, 0.2), 0.0);  // no bond
}

// An atom of n equal bonds (each omega_b, damping d) is damped at d sqrt(n):
// its step is 2 / (sqrt(n) omega_b) (sqrt(1 + n d^2) - d sqrt(n)); the
// undamped per-atom sum's step is the first factor alone.
TEST(StepLimit, DampedCriticalStepOfEqualBondsGrowsTheDampingWithTheirNumber) {
  const double w = 3.0e7, d = 0.2;
  for (const int n : {1, 6, 13, 18}) {
    const double zeta = d * std::sqrt(static_cast<double>(n));
    const double want = 2.0 / (std::sqrt(n) * w) * (std::sqrt(1.0 + zeta * zeta) - zeta);
    EXPECT_NEAR(mill::step_limit::damped_critical_step(n * w * w, n * w, d) / want, 1.0, 1e-12)
        << n << " bonds";
  }
  // At 18 bonds the damped step is below half the undamped one (0.46 x):
  // the decks' 0.5 x the undamped step is then past the limit.
  EXPECT_LT(mill::step_limit::damped_critical_step(18 * w * w, 18 * w, d),
            0.5 * mill::step_limit::critical_step(18 * w * w));
  EXPECT_GT(mill::step_limit::damped_critical_step(6 * w * w, 6 * w, d),
            0.5 * mill::step_limit::critical_step(6 * w * w));
}

// ---------------------------------------------------------------------------
// The network's own largest eigenfrequency (network_step.h, fix
// bond/breakable's `step_estimate network`): the Lanczos estimate against
// the dense eigenvalue of the assembled network above (Jacobi, built from
// the springs' strain vectors, not from network_step's force law) and
// against closed forms.
// ---------------------------------------------------------------------------
namespace {

// The hand-built bonds as network_step sees them (as the fix hands them over).
mill::network_step::Bond to_network_bond(const BondSprings &s, const std::vector<Sphere> &sp,
                                         const Bond &b) {
  const Sphere &a = sp[b.i], &c = sp[b.j];
  double d[3];
  const double l0 = separation(a, c, d);
  mill::network_step::Bond nb;
  nb.a = b.i;
  nb.b = b.j;
  nb.n = {d[0] / l0, d[1] / l0, d[2] / l0};
  nb.arm_a = l0 * a.r / (a.r + c.r);
  nb.arm_b = l0 - nb.arm_a;
  const double rb = s.radius_multiplier * std::min(a.r, c.r);
  const double area = kPi * rb * rb, inertia = 0.25 * area * rb * rb;
  const double kn = s.modulus / l0, ks = kn / s.stiffness_ratio;
  nb.kna = kn * area;
  nb.ksa = ks * area;
  nb.kni = kn * inertia;
  nb.ksj = ks * 2.0 * inertia;
  return nb;
}

mill::network_step::Estimate lanczos(const BondSprings &s, const std::vector<Sphere> &sp,
                                     const std::vector<Bond> &bonds) {
  std::vector<mill::network_step::Bond> nb;
  for (const Bond &b : bonds) nb.push_back(to_network_bond(s, sp, b));
  mill::network_step::Atoms atoms;
  for (const Sphere &x : sp) {
    atoms.mass.push_back(x.m);
    atoms.inertia.push_back(0.4 * x.m * x.r * x.r);
  }
  return mill::network_step::largest_omega2(nb, atoms);
}

}  // namespace

// One pair: the Ritz value is the closed form of the pair within 1e-7 (its
// error is of the order of the residual^2 / the spectral gap: (1e-4)^2
// relative here) and the estimate (Ritz value + residual) at most the iteration's
// tolerance (1e-4) above it, not below.
TEST(NetworkStep, OnePairIsThePairsClosedForm) {
  const Lump l = hand_built_lump();
  for (const Bond &b : l.bonds) {
    const Sphere &a = l.spheres[b.i], &c = l.spheres[b.j];
    double l0 = 0.0;
    for (int q = 0; q < 3; ++q) l0 += (c.x[q] - a.x[q]) * (c.x[q] - a.x[q]);
    const double closed =
        mill::step_limit::bond_omega2(l.springs, {a.r, c.r, a.m, c.m, std::sqrt(l0)});
    const auto est = lanczos(l.springs, l.spheres, {b});
    EXPECT_NEAR(est.ritz / closed, 1.0, 1e-7) << "bond " << b.i << "-" << b.j;
    EXPECT_GE(est.omega2, closed * (1.0 - 1e-12)) << "bond " << b.i << "-" << b.j;
    EXPECT_LE(est.omega2, closed * (1.0 + 1e-4)) << "bond " << b.i << "-" << b.j;
  }
}

// The hand-built lump: the Ritz value is the dense network eigenvalue within
// 1e-6, the estimate not below it and at most the iteration's tolerance
// (1e-4) above, and below the per-atom sum, which it replaces; the step it
// gives is the longer one.
TEST(NetworkStep, LumpMatchesTheDenseEigenvalue) {
  const Lump l = hand_built_lump();
  const double dense = network_omega2(l.springs, l.spheres, l.bonds);
  const auto est = lanczos(l.springs, l.spheres, l.bonds);
  const double dt_sum = fix_critical_step(l.springs, l.spheres, l.bonds);
  const double dt_net = mill::step_limit::critical_step(est.omega2);
  std::printf(
      "%zu bonds: omega^2 dense %.9e, Lanczos %.9e (Ritz %.9e + residual %.3e, %d steps); step "
      "network %.4e s, per-atom sum %.4e s (x %.3f)\n",
      l.bonds.size(), dense, est.omega2, est.ritz, est.residual, est.iterations, dt_net, dt_sum,
      dt_net / dt_sum);
  EXPECT_NEAR(est.ritz / dense, 1.0, 1e-6);
  EXPECT_LE(est.ritz, dense * (1.0 + 1e-12));    // the Ritz value never above
  EXPECT_GE(est.omega2, dense * (1.0 - 1e-12));  // an upper estimate
  EXPECT_LE(est.omega2, dense * (1.0 + 1e-4));   // within the tolerance
  EXPECT_GT(dt_net, dt_sum);                     // the sum bounds omega^2 from above
}

// A free chain of n equal spheres along x with stiff axial and soft shear
// springs (kn/ks 1000): its top mode is axial, omega^2 = 2 kn A / m (1 +
// cos(pi / n)) (the free-free chain of masses and springs), against the
// per-atom sum's 4 kn A / m. Ritz value within 1e-6; the estimate at most
// the iteration's tolerance (1e-4) above the closed form, not below.
TEST(NetworkStep, ChainIsTheClosedFormOfItsAxialMode) {
  const BondSprings springs{50e9, 1000.0, 1.0};
  const double r = 1e-3, len = 2.05e-3;
  for (const int n : {2, 5, 20}) {
    std::vector<Sphere> sp(n);
    std::vector<Bond> bonds;
    for (int k = 0; k < n; ++k) {
      sp[k].r = r;
      sp[k].m = 2580.0 * 4.0 / 3.0 * kPi * r * r * r;
      sp[k].x[0] = k * len;
      sp[k].x[1] = sp[k].x[2] = 0.0;
      if (k > 0) bonds.push_back({k - 1, k});
    }
    const double kna = springs.modulus / len * kPi * r * r;
    const double closed = 2.0 * kna / sp[0].m * (1.0 + std::cos(kPi / n));
    const auto est = lanczos(springs, sp, bonds);
    std::printf("chain of %d: omega^2 %.9e, closed form %.9e (%d Lanczos steps)\n", n, est.omega2,
                closed, est.iterations);
    EXPECT_NEAR(est.ritz / closed, 1.0, 1e-6) << n << " spheres";
    EXPECT_GE(est.omega2, closed * (1.0 - 1e-12)) << n << " spheres";
    EXPECT_LE(est.omega2, closed * (1.0 + 1e-4)) << n << " spheres";
  }
}

// No bond: no bound.
TEST(NetworkStep, NoBondGivesZero) {
  mill::network_step::Atoms atoms{{1.0, 1.0}, {1.0, 1.0}};
  EXPECT_EQ(mill::network_step::largest_omega2({}, atoms).omega2, 0.0);
}
