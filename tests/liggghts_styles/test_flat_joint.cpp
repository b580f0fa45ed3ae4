// The flat-joint interface (liggghts_styles/flat_joint.h) against its closed
// forms: layout, break loads of the elements in tension and in shear, the
// moment of a partly broken interface, the rolling resistance of a fully
// broken one, objectivity under rigid rotation, the stiffnesses that set the
// critical time step, the energy of a loading path, and the frame carry
// (its series sin/cos for small turns) against the exact rotation.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "flat_joint.h"

using namespace mill::flat_joint;
using mill::bond_geometry::cross;
using mill::bond_geometry::dot;
using mill::bond_geometry::load3;
using mill::bond_geometry::Vec3;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kR = 1.0e-3;  // interface radius [m]

Params sandstone() {
  Params p;
  p.kn = 2.0e10 / 2.0e-3;  // E_b / L0, Pa/m
  p.ks = p.kn / 2.5;
  p.radius = kR;
  p.tensile = 2.0e7;
  p.cohesion = 4.0e7;
  p.tan_phi = std::tan(30.0 * kPi / 180.0);
  p.mu = 0.5;
  return p;
}

const Vec3 kN{0, 0, 1};

// A fresh interface along +z.
std::vector<double> fresh(const Layout &lay, bool bonded = true) {
  std::vector<double> h(history_size(lay.elements()));
  init_history(h.data(), lay, kN, bonded);
  return h;
}

// One step with the given increments about/along the interface frame.
Step step(double stretch, Vec3 du = {0, 0, 0}, Vec3 dtheta = {0, 0, 0}) {
  Step s;
  s.n_mid = s.n_end = kN;
  s.du_shear = du;
  s.dtheta = dtheta;
  s.vrel = s.wrel = Vec3{0, 0, 0};
  s.dt = 1e-7;
  s.stretch = stretch;
  return s;
}

Step evaluate_only(double stretch) {
  Step s = step(stretch);
  s.advance = false;
  return s;
}

Vec3 t1_of(const std::vector<double> &h) { return load3(h.data() + kT1); }
Vec3 t2_of(const std::vector<double> &h) { return cross(kN, t1_of(h)); }

void set_state(std::vector<double> &h, int e, double state) { h[kHistory + 3 * e + kState] = state; }

}  // namespace

// Areas sum to the disc; the intact interface has the disc's A, I and J
// (radius of gyration per ring), so kn A, ks A, kn I, ks J: the parallel
// bond's stiffnesses and critical time step. Exact to round-off.
TEST(FlatJoint, IntactInterfaceHasTheDiscsStiffness) {
  const Params p = sandstone();
  const double area = kPi * kR * kR, inertia = kPi * std::pow(kR, 4) / 4.0;
  for (auto [nr, na] : {std::pair{1, 3}, {1, 4}, {2, 3}, {2, 6}, {3, 8}}) {
    const Layout lay = make_layout(nr, na);
    double sum = 0;
    for (double a : lay.area) sum += a;
    EXPECT_NEAR(sum, 1.0, 1e-14) << nr << "x" << na;
    const Stiffness k = intact_stiffness(lay, p);
    EXPECT_NEAR(k.normal / (p.kn * area), 1.0, 1e-12);
    EXPECT_NEAR(k.shear / (p.ks * area), 1.0, 1e-12);
    EXPECT_NEAR(k.bending / (p.kn * inertia), 1.0, 1e-12) << nr << "x" << na;
    EXPECT_NEAR(k.twisting / (p.ks * 2.0 * inertia), 1.0, 1e-12) << nr << "x" << na;
  }
  EXPECT_THROW(make_layout(1, 2), std::invalid_argument);
  EXPECT_THROW(make_layout(0, 3), std::invalid_argument);
  EXPECT_THROW(make_layout(5, 8), std::invalid_argument);
}

// Uniform tension: every element reaches sigma_c together, at the stretch
// sigma_c / kn, carrying sigma_c A (0.1 % either side of the closed form).
TEST(FlatJoint, TensionBreakLoadIsStrengthTimesArea) {
  const Params p = sandstone();
  const Layout lay = make_layout(2, 4);
  const double s_break = p.tensile / p.kn;
  auto h = fresh(lay);
  Result r = update(h.data(), lay, p, step(0.999 * s_break));
  EXPECT_EQ(r.broke_tension, 0);
  EXPECT_NEAR(-dot(r.force_b, kN) / (p.tensile * kPi * kR * kR), 0.999, 1e-9);
  EXPECT_NEAR(r.sigma_max / p.tensile, 0.999, 1e-9);
  r = update(h.data(), lay, p, step(1.001 * s_break));
  EXPECT_EQ(r.broke_tension, lay.elements());
  EXPECT_EQ(r.bonded, 0);
  EXPECT_NEAR(dot(r.force_b, r.force_b), 0.0, 1e-30);  // open: carries nothing
  // The energy it held, (sigma_c A)^2 / (2 kn A) at the break, is released.
  const double held = 0.5 * p.kn * kPi * kR * kR * std::pow(1.001 * s_break, 2);
  EXPECT_NEAR(r.released / held, 1.0, 1e-9);
}

// Bending: the element farthest from the axis breaks first, alone, at
// theta = sigma_c / (kn y_max) (one element of three at y = rho sin 60).
TEST(FlatJoint, BendingBreaksTheOuterElementFirst) {
  const Params p = sandstone();
  const Layout lay = make_layout(1, 3);
  auto h = fresh(lay);
  const Vec3 t1 = t1_of(h);
  double ymax = 0;
  for (int e = 0; e < 3; ++e) ymax = std::max(ymax, kR * lay.py[e]);
  EXPECT_NEAR(ymax, kR * std::sqrt(0.5) * std::sin(kPi / 3.0), 1e-15);
  const double theta = p.tensile / (p.kn * ymax);
  Result r = update(h.data(), lay, p, step(0.0, {0, 0, 0}, (0.999 * theta) * t1));
  EXPECT_EQ(r.broke_tension, 0);
  r = update(h.data(), lay, p, step(0.0, {0, 0, 0}, (0.002 * theta) * t1));
  EXPECT_EQ(r.broke_tension, 1);
  EXPECT_EQ(r.bonded, 2);
}

// Shear: uniform shear breaks every element at tau = c - sigma tan(phi_b);
// under compression sigma < 0 the strength rises by |sigma| tan(phi_b).
// After the break the shear force drops to the Coulomb cap mu |N|.
TEST(FlatJoint, ShearBreakLoadFollowsMohrCoulomb) {
  const Params p = sandstone();
  const Layout lay = make_layout(1, 4);
  const double area = kPi * kR * kR;
  for (double sigma : {0.0, -3.0e7}) {
    const double stretch = sigma / p.kn;
    const double strength = p.cohesion - sigma * p.tan_phi;
    const double du = strength / p.ks;  // tau = ks du
    auto h = fresh(lay);
    const Vec3 t1 = t1_of(h);
    Result r = update(h.data(), lay, p, step(stretch, (0.999 * du) * t1));
    EXPECT_EQ(r.broke_shear, 0) << sigma;
    EXPECT_NEAR(dot(r.force_b, t1) / (-0.999 * strength * area), 1.0, 1e-9) << sigma;
    EXPECT_NEAR(r.tau_ratio, 0.999, 1e-9);
    r = update(h.data(), lay, p, step(stretch, (0.002 * du) * t1));
    EXPECT_EQ(r.broke_shear, lay.elements()) << sigma;
    const double cap = p.mu * (-sigma) * area;  // mu |N|, zero without compression
    EXPECT_NEAR(std::fabs(dot(r.force_b, t1)), cap, 1e-9 * strength * area) << sigma;
  }
}

// A partly broken interface (1 x 4, the two elements at y > 0 broken) bent
// about t1: opening the broken side it carries the bonded half only,
// M = -kn theta I / 2 with the compressive force kn theta A R / 4; closing
// the broken side every element carries, M = -kn theta I (the broken ones
// pressed). Closed forms of the layout: points (+-R/2, +-R/2), A/4 each.
TEST(FlatJoint, PartlyBrokenInterfaceCarriesItsClosedFormMoment) {
  const Params p = sandstone();
  const Layout lay = make_layout(1, 4);
  const double area = kPi * kR * kR, inertia = kPi * std::pow(kR, 4) / 4.0;
  const double theta = 1.0e-4;
  for (double sign : {1.0, -1.0}) {
    auto h = fresh(lay);
    for (int e = 0; e < 4; ++e)
      if (lay.py[e] > 0) set_state(h, e, 1.0);
    const Vec3 t1 = t1_of(h);
    const Result r = update(h.data(), lay, p, step(0.0, {0, 0, 0}, (sign * theta) * t1));
    const double m = dot(r.moment_b, t1);
    if (sign > 0) {
      EXPECT_NEAR(m / (-p.kn * theta * inertia / 2.0), 1.0, 1e-12);
      EXPECT_NEAR(dot(r.force_b, kN) / (p.kn * theta * area * kR / 4.0), 1.0, 1e-12);
    } else {
      EXPECT_NEAR(m / (p.kn * theta * inertia), 1.0, 1e-12);
      EXPECT_NEAR(dot(r.force_b, kN), 0.0, 1e-12 * p.kn * theta * area * kR);
    }
    EXPECT_EQ(r.bonded, 2);
  }
}

// A fully broken interface pressed by P = kn A |s| resists rolling: elastic
// (M = kn I theta) until the first elements lift off at theta = |s| / y_max,
// where M = P y_max = P R/2 (1 x 4); beyond, only the pressed side carries,
// M = kn (A/2) (|s| + theta R/2) R/2. The parallel bond's contact stops at
// P R/4 (fix bond/breakable, contact_moment yes).
TEST(FlatJoint, FullyBrokenInterfaceResistsRolling) {
  const Params p = sandstone();
  const Layout lay = make_layout(1, 4);
  const double area = kPi * kR * kR, inertia = kPi * std::pow(kR, 4) / 4.0;
  const double s = -1.0e-7, P = p.kn * area * (-s);
  const double lift = (-s) / (kR / 2.0);
  auto h = fresh(lay, false);
  const Vec3 t1 = t1_of(h);
  // theta about t1 opens y > 0: the moment on b is along -t1.
  Result r = update(h.data(), lay, p, step(s, {0, 0, 0}, (0.5 * lift) * t1));
  EXPECT_NEAR(-dot(r.moment_b, t1) / (p.kn * inertia * 0.5 * lift), 1.0, 1e-12);
  r = update(h.data(), lay, p, step(s, {0, 0, 0}, (0.5 * lift) * t1));
  EXPECT_NEAR(-dot(r.moment_b, t1) / (P * kR / 2.0), 1.0, 1e-9);
  r = update(h.data(), lay, p, step(s, {0, 0, 0}, lift * t1));  // theta = 2 lift
  const double m2 = p.kn * (area / 2.0) * ((-s) + 2.0 * lift * kR / 2.0) * kR / 2.0;
  EXPECT_NEAR(-dot(r.moment_b, t1) / m2, 1.0, 1e-9);
  EXPECT_EQ(r.bonded, 0);
}

// An unbonded interface made across an installation gap g0: its elements
// carry nothing until the faces touch (stretch = -g0), then kn A (stretch +
// g0) in compression, shear capped at mu times that; a bonded one is loaded
// from its bonded length as if there were no gap. Exact to round-off.
TEST(FlatJoint, GappedInterfacePushesOnlyOnceItsFacesTouch) {
  const Params p = sandstone();
  const Layout lay = make_layout(1, 3);
  const double area = kPi * kR * kR, g0 = 2.0e-7;
  auto h = fresh(lay, false);
  Step s = step(-0.5 * g0);
  s.gap0 = g0;
  Result r = update(h.data(), lay, p, s);
  EXPECT_EQ(dot(r.force_b, r.force_b), 0.0);
  EXPECT_FALSE(r.loaded);
  s = step(-1.5 * g0, {2.0e-6, 0, 0});  // closed by g0/2, and sheared far past slip
  s.gap0 = g0;
  r = update(h.data(), lay, p, s);
  const double push = p.kn * area * 0.5 * g0;
  EXPECT_NEAR(dot(r.force_b, kN) / push, 1.0, 1e-12);
  const Vec3 shear = r.force_b - dot(r.force_b, kN) * kN;
  EXPECT_NEAR(std::sqrt(dot(shear, shear)) / (p.mu * push), 1.0, 1e-12);
  EXPECT_NEAR(r.energy / (0.5 * push * 0.5 * g0 + 0.5 * p.mu * p.mu * push * push / (p.ks * area)),
              1.0, 1e-12);
  auto hb = fresh(lay, true);
  Step sb = step(1.0e-8);
  sb.gap0 = g0;
  r = update(hb.data(), lay, p, sb);
  EXPECT_NEAR(dot(r.force_b, kN) / (-p.kn * area * 1.0e-8), 1.0, 1e-12);
}

// A loaded interface turned rigidly with its pair (about an in-plane axis,
// 90 degrees in 2000 steps, with a spin about n): the force and moment turn
// with it, their components in the pair's frame unchanged to 1e-6.
TEST(FlatJoint, RigidRotationChangesNothingInThePairsFrame) {
  const Params p = sandstone();
  const Layout lay = make_layout(2, 4);
  auto h = fresh(lay);
  const Vec3 t1 = t1_of(h), t2 = t2_of(h);
  const Result r0 =
      update(h.data(), lay, p, step(2e-7, 2e-7 * t1 + 1e-7 * t2, 1e-5 * t1 - 2e-5 * t2 + 3e-5 * kN));
  const Vec3 f0{dot(r0.force_b, t1), dot(r0.force_b, t2), dot(r0.force_b, kN)};
  const Vec3 m0{dot(r0.moment_b, t1), dot(r0.moment_b, t2), dot(r0.moment_b, kN)};
  // Rotation about t2 by phi (n turns towards t1), and the frame spins about n.
  const int steps = 2000;
  const double dphi = 0.5 * kPi / steps, spin = 1e-3;
  auto turn = [&](Vec3 v, double phi) {
    return std::cos(phi) * v + std::sin(phi) * cross(t2, v) + (1 - std::cos(phi)) * dot(t2, v) * t2;
  };
  Result r = r0;
  for (int k = 1; k <= steps; ++k) {
    Step s = step(2e-7);
    s.n_mid = turn(kN, (k - 0.5) * dphi);
    s.n_end = turn(kN, k * dphi);
    // The relative rotation is zero; both grains turn by dphi about t2 and
    // spin about n: the frame's spin is the mean spin about n.
    s.spin = spin;
    r = update(h.data(), lay, p, s);
  }
  // The pair's frame at the end: n' = turn(n), and the material frame turned
  // further by the accumulated spin about n'.
  const Vec3 n1 = turn(kN, 0.5 * kPi);
  const double total_spin = steps * spin;
  const Vec3 a1 = turn(t1, 0.5 * kPi), a2 = turn(t2, 0.5 * kPi);
  const Vec3 e1 = std::cos(total_spin) * a1 + std::sin(total_spin) * a2;
  const Vec3 e2 = cross(n1, e1);
  const Vec3 f1{dot(r.force_b, e1), dot(r.force_b, e2), dot(r.force_b, n1)};
  const Vec3 m1{dot(r.moment_b, e1), dot(r.moment_b, e2), dot(r.moment_b, n1)};
  const double fs = std::sqrt(dot(f0, f0)), ms = std::sqrt(dot(m0, m0));
  EXPECT_LT(std::sqrt(dot(f1 - f0, f1 - f0)) / fs, 1e-6);
  EXPECT_LT(std::sqrt(dot(m1 - m0, m1 - m0)) / ms, 1e-6);
  EXPECT_NEAR(r.energy / r0.energy, 1.0, 1e-6);
}

// A loading path in many small steps (stretch, shear, bend and twist
// together, below every strength): the work the interface's force and moment
// take equals the energy it stores (trapezoid rule, 1e-6), and unloading
// along the same path returns it all.
TEST(FlatJoint, WorkOfALoadingPathIsTheStoredEnergy) {
  const Params p = sandstone();
  const Layout lay = make_layout(2, 6);
  auto h = fresh(lay);
  const Vec3 t1 = t1_of(h), t2 = t2_of(h);
  const int steps = 4000;
  const Vec3 du = (1e-7 / steps) * (t1 + 0.5 * t2);
  const Vec3 dth = (2e-5 / steps) * (t1 - t2) + (3e-5 / steps) * kN;
  const double ds = 1e-7 / steps;
  Result prev = update(h.data(), lay, p, evaluate_only(0.0));
  double work = 0, loaded = 0;
  for (int pass = 0; pass < 2; ++pass) {
    const double sign = pass == 0 ? 1.0 : -1.0;
    for (int k = 1; k <= steps; ++k) {
      const double stretch = pass == 0 ? k * ds : (steps - k) * ds;
      const Result r = update(h.data(), lay, p, step(stretch, sign * du, sign * dth));
      EXPECT_EQ(r.bonded, lay.elements());
      // Work done on the interface by the grains: -(force on b) . (b's motion).
      const Vec3 fm = 0.5 * (prev.force_b + r.force_b), mm = 0.5 * (prev.moment_b + r.moment_b);
      work -= dot(fm, sign * du + (sign * ds) * kN) + dot(mm, sign * dth);
      prev = r;
    }
    if (pass == 0) {
      loaded = prev.energy;
      EXPECT_NEAR(work / loaded, 1.0, 1e-6);
    }
  }
  EXPECT_LT(prev.energy, 1e-12 * loaded);
  EXPECT_LT(std::fabs(work), 1e-6 * loaded);
}

// Tension softening (Params::softening = lambda, flat_joint.h): a slow
// uniform pull of an interface follows the linear cohesive envelope, peak
// sigma_c A at u_t = sigma_c / kn, then sigma_c A (u_s - u) / (u_s - u_t)
// down to zero at u_s = lambda u_t, where every element breaks; the work of
// the whole pull, lambda sigma_c^2 A / (2 kn) (the envelope's area), is
// what the elements released (1e-3: the trapezoid rule over 20 000 steps),
// and at every step work = stored + released (energy conservation, 1e-3).
TEST(FlatJoint, SofteningPullFollowsTheCohesiveEnvelope) {
  Params p = sandstone();
  p.softening = 4.0;
  const Layout lay = make_layout(1, 3);
  const double area = kPi * kR * kR, u_t = p.tensile / p.kn, u_s = p.softening * u_t;
  auto h = fresh(lay);
  const int steps = 20000;
  const double du = 1.05 * u_s / steps;
  double work = 0, released = 0, f_prev = 0, peak = 0;
  int broke_at = -1;
  for (int k = 1; k <= steps; ++k) {
    const double u = k * du;
    const Result r = update(h.data(), lay, p, step(u));
    const double f = -dot(r.force_b, kN);  // tension on the interface
    work += 0.5 * (f_prev + f) * du;
    released += r.released;
    f_prev = f;
    peak = std::max(peak, f);
    const double f_env = u <= u_t  ? p.kn * area * u
                         : u < u_s ? p.tensile * area * (u_s - u) / (u_s - u_t)
                                   : 0.0;
    ASSERT_NEAR(f, f_env, 1e-9 * p.tensile * area) << "u / u_t " << u / u_t;
    if (u < u_s) {
      ASSERT_EQ(r.broke_tension, 0) << u / u_t;
      ASSERT_EQ(r.bonded, lay.elements());
      ASSERT_NEAR(work, r.energy + released, 1e-3 * p.tensile * area * u_s) << u / u_t;
    } else if (broke_at < 0) {
      broke_at = k;
      EXPECT_EQ(r.broke_tension, lay.elements());
    }
  }
  EXPECT_NEAR(peak / (p.tensile * area), 1.0, 1e-3);
  EXPECT_GT(broke_at, 0);
  const double fracture = 0.5 * p.tensile * area * u_s;  // lambda sigma_c^2 A / (2 kn)
  EXPECT_NEAR(fracture, p.softening * p.tensile * p.tensile * area / (2.0 * p.kn),
              1e-12 * fracture);
  EXPECT_NEAR(work / fracture, 1.0, 1e-3);
  EXPECT_NEAR(released / fracture, 1.0, 1e-3);
}

// Below the envelope a softened element unloads and reloads along its
// secant, (1 - D) kn, with D = 1 - sigma_env(u_max) / (kn u_max), storing
// (1 - D) kn A u^2 / 2 and releasing nothing; it takes compression with the
// intact kn; reloaded, it meets the envelope where it left it (1e-12).
TEST(FlatJoint, SoftenedElementUnloadsAlongItsSecant) {
  Params p = sandstone();
  p.softening = 3.0;
  const Layout lay = make_layout(1, 4);
  const double area = kPi * kR * kR, u_t = p.tensile / p.kn, u_s = p.softening * u_t;
  auto h = fresh(lay);
  const double u_max = 2.0 * u_t;  // half way down the envelope
  for (int k = 1; k <= 100; ++k) update(h.data(), lay, p, step(k * u_max / 100));
  const double f_env = p.tensile * area * (u_s - u_max) / (u_s - u_t);
  const double secant = f_env / u_max;  // (1 - D) kn A
  for (double frac : {0.75, 0.5, 0.25}) {
    const Result r = update(h.data(), lay, p, step(frac * u_max));
    EXPECT_NEAR(-dot(r.force_b, kN) / (secant * frac * u_max), 1.0, 1e-12) << frac;
    EXPECT_NEAR(r.energy / (0.5 * secant * std::pow(frac * u_max, 2)), 1.0, 1e-12) << frac;
    EXPECT_EQ(r.released, 0.0) << frac;
  }
  const Result c = update(h.data(), lay, p, step(-0.1 * u_t));  // compression: intact kn
  EXPECT_NEAR(dot(c.force_b, kN) / (p.kn * area * 0.1 * u_t), 1.0, 1e-12);
  const Result back = update(h.data(), lay, p, step(u_max));
  EXPECT_NEAR(-dot(back.force_b, kN) / f_env, 1.0, 1e-12);
  EXPECT_EQ(back.released, 0.0);
  EXPECT_EQ(back.bonded, lay.elements());
  // lambda = 1 is the brittle element: it breaks just past u_t.
  p.softening = 1.0;
  auto hb = fresh(lay);
  EXPECT_EQ(update(hb.data(), lay, p, step(1.001 * u_t)).broke_tension, lay.elements());
}

// The frame's small turns take their sin and cos from a Taylor series below
// kSeriesTurn (flat_joint.h: truncation error < 2e-22 relative there): it
// agrees with the library's sin and cos to round-off at every angle a step
// makes, and above the switch it is the library's.
TEST(FlatJoint, SmallTurnSeriesIsTheExactSinAndCos) {
  const double eps = 2.3e-16;  // about one ulp: the series' own rounding
  for (double a : {1e-12, 3e-9, 1e-7, 2.5e-6, 1e-5, 7e-5, 3e-4, 9.99e-4}) {
    for (double sg : {1.0, -1.0}) {
      const SinCos sc = turn_sin_cos(sg * a);
      EXPECT_NEAR(sc.sin, std::sin(sg * a), eps * std::fabs(std::sin(a))) << sg * a;
      EXPECT_NEAR(sc.cos, std::cos(sg * a), eps) << sg * a;
    }
  }
  for (double a : {1e-3, 0.2, -3.0}) {
    const SinCos sc = turn_sin_cos(a);
    EXPECT_EQ(sc.sin, std::sin(a));
    EXPECT_EQ(sc.cos, std::cos(a));
  }
}

// The frame carry (a turn of the normal and a spin about it, as in one
// step) against the same rotations written out with the library's sin and
// cos: equal to round-off at the small angles of a step (series branch) and
// at large ones (library branch).
TEST(FlatJoint, FrameCarryIsTheExactRotation) {
  // v turned by angle about the unit axis k (Rodrigues' rotation formula).
  auto rotate = [](Vec3 v, Vec3 k, double angle) {
    const double c = std::cos(angle), s = std::sin(angle);
    return c * v + s * cross(k, v) + ((1.0 - c) * dot(k, v)) * k;
  };
  auto unit = [](Vec3 v) { return (1.0 / std::sqrt(dot(v, v))) * v; };
  const Vec3 n0 = unit(Vec3{0.3, -0.5, 0.81});
  const Vec3 t0 = unit(cross(n0, Vec3{1, 0, 0}));
  for (double turn : {2e-6, 4e-5, 6e-4, 0.3}) {
    for (double spin : {0.0, 1e-7, -3e-5, 9e-4, 0.25}) {
      const Vec3 axis = unit(cross(n0, Vec3{0.2, 0.9, -0.1}));
      const Vec3 n1 = rotate(n0, axis, turn);
      const Vec3 got = carry(t0, n0, n1, spin);
      const Vec3 want = rotate(rotate(t0, axis, turn), n1, spin);
      for (double d : {got.x - want.x, got.y - want.y, got.z - want.z})
        EXPECT_NEAR(d, 0.0, 1e-15) << "turn " << turn << " spin " << spin;
      EXPECT_NEAR(dot(got, n1), 0.0, 4e-16);
      EXPECT_NEAR(dot(got, got), 1.0, 1e-15);
    }
  }
}

// ---------------------------------------------------------------------------
// The packed kernel (update_intact): each lane is bitwise update() for an
// intact interface that stays intact, and a lane falls back (history
// untouched) exactly when update() changes an element's state or one was
// not intact to begin with. Random interfaces: frames, shears, bend
// rotations, steps (turns above and below the sine series' switch, zero
// spin) and materials per lane, loads from far below to beyond every
// strength, brittle and softening, one ring of three and two rings of four.
namespace {

struct Rng {  // splitmix64: the same draws on every machine
  unsigned long long z;
  double uniform(double a, double b) {
    z += 0x9e3779b97f4a7c15ULL;
    unsigned long long x = z;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
    x ^= x >> 31;
    return a + (b - a) * static_cast<double>(x >> 11) * 0x1.0p-53;
  }
  Vec3 unit() {
    for (;;) {
      const Vec3 v{uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)};
      const double l2 = dot(v, v);
      if (l2 > 0.01 && l2 < 1.0) return (1.0 / std::sqrt(l2)) * v;
    }
  }
};

Vec3 tilt(Vec3 n, Vec3 by) {  // n turned a little, unit
  const Vec3 m = n + by;
  return (1.0 / std::sqrt(dot(m, m))) * m;
}

struct KernelTally {
  int held = 0;
  int held_softened = 0;  // held with a softened element
  int broke = 0;          // fell back: an element breaks or softens in the step
  int damaged = 0;        // fell back: an element was broken before it
};

template <class L>
void check_lanes(Rng &rng, const Layout &lay, double softening, KernelTally &tally) {
  using mill::bond_geometry::kLanes;
  constexpr int N = kLanes<L>;
  const int ne = lay.elements(), hs = history_size(ne);
  std::vector<std::vector<double>> hist(N), orig(N);
  double *hp[N];
  IntactStep<L> st;
  IntactParams<L> mat;
  Step one[N];
  Params par[N];
  Params shared = sandstone();
  shared.softening = softening;
  for (int l = 0; l < N; ++l) {
    const Vec3 n0 = rng.unit();
    hist[l].resize(hs);
    init_history(hist[l].data(), lay, n0, true);
    // A few steps' worth of history: shears, bend, and now and then a broken
    // element (such a lane must fall back) or a softened one (held while its
    // damage does not grow).
    double *h = hist[l].data();
    h[kBend] = rng.uniform(-2e-4, 2e-4);
    h[kBend + 1] = rng.uniform(-2e-4, 2e-4);
    const double kna_e = shared.kn * kPi * kR * kR / ne;
    for (int e = 0; e < ne; ++e) {
      h[kHistory + 3 * e + kShear] = rng.uniform(-1, 1) * kna_e * 1e-7;
      h[kHistory + 3 * e + kShear + 1] = rng.uniform(-1, 1) * kna_e * 1e-7;
    }
    const double pick = rng.uniform(0, 1);
    if (pick < 0.08) h[kHistory + 3 * (ne - 1) + kState] = 1.0;
    if (pick > 0.8 && softening > 1.0)
      h[kHistory + 3 * (ne - 1) + kState] = rng.uniform(0.05, 0.95);
    orig[l] = hist[l];
    hp[l] = h;
    // The step: small turns, spins from 0 to beyond the series' switch.
    Step s;
    s.n_mid = tilt(n0, rng.uniform(0, 1e-4) * rng.unit());
    s.n_end = tilt(s.n_mid, rng.uniform(0, 1e-4) * rng.unit());
    s.du_shear = rng.uniform(0, 3e-8) * rng.unit();
    s.du_shear = s.du_shear - dot(s.du_shear, s.n_mid) * s.n_mid;
    s.dtheta = rng.uniform(0, 2e-5) * rng.unit();
    const double r = rng.uniform(0, 1);
    s.spin = r < 0.15 ? 0.0 : (r < 0.3 ? rng.uniform(-3e-3, 3e-3) : rng.uniform(-1e-4, 1e-4));
    s.dt = 1e-7;
    s.vrel = s.wrel = Vec3{0, 0, 0};
    // Stretch: from compression to beyond the tensile strength (u_t = sigma_c / kn
    // = 2e-6 m at the mean kn).
    s.stretch = rng.uniform(-3e-6, 2.6e-6);
    s.advance = true;
    s.stresses = false;
    one[l] = s;
    Params p = shared;
    p.kn = shared.kn * rng.uniform(0.5, 1.5);
    p.ks = p.kn / rng.uniform(1.5, 3.0);
    p.radius = kR * rng.uniform(0.7, 1.3);
    par[l] = p;
    st.n_mid.x[l] = s.n_mid.x, st.n_mid.y[l] = s.n_mid.y, st.n_mid.z[l] = s.n_mid.z;
    st.n_end.x[l] = s.n_end.x, st.n_end.y[l] = s.n_end.y, st.n_end.z[l] = s.n_end.z;
    st.du_shear.x[l] = s.du_shear.x, st.du_shear.y[l] = s.du_shear.y;
    st.du_shear.z[l] = s.du_shear.z;
    st.dtheta.x[l] = s.dtheta.x, st.dtheta.y[l] = s.dtheta.y, st.dtheta.z[l] = s.dtheta.z;
    st.spin[l] = s.spin;
    st.stretch[l] = s.stretch;
    mat.kn[l] = p.kn, mat.ks[l] = p.ks, mat.radius[l] = p.radius;
  }
  IntactResult<L> out;
  const auto holds = update_intact(hp, lay, mat, shared, st, out);
  for (int l = 0; l < N; ++l) {
    std::vector<double> ref = orig[l];
    const Result r = update(ref.data(), lay, par[l], one[l]);
    bool intact_before = true, states_same = true;  // intact: every element bonded
    for (int e = 0; e < ne; ++e) {
      intact_before = intact_before && orig[l][kHistory + 3 * e + kState] < 1.0;
      states_same =
          states_same && ref[kHistory + 3 * e + kState] == orig[l][kHistory + 3 * e + kState];
    }
    const bool should_hold = intact_before && states_same;
    ASSERT_EQ(holds[l] != 0, should_hold) << "lane " << l << ": stretch " << one[l].stretch;
    if (!should_hold) {
      ++(intact_before ? tally.broke : tally.damaged);
      EXPECT_EQ(hist[l], orig[l]) << "a lane that falls back keeps its history";
      continue;
    }
    ++tally.held;
    for (int e = 0; e < ne; ++e)
      if (orig[l][kHistory + 3 * e + kState] > 0.0) {
        ++tally.held_softened;
        break;
      }
    EXPECT_EQ(r.bonded, ne);
    EXPECT_EQ(r.released, 0.0);
    EXPECT_EQ(r.slipped, 0.0);
    // Bitwise: ==, not a tolerance (each lane does update()'s operations).
    EXPECT_EQ(hist[l], ref) << "lane " << l << ": history";
    EXPECT_EQ(out.force_b.x[l], r.force_b.x);
    EXPECT_EQ(out.force_b.y[l], r.force_b.y);
    EXPECT_EQ(out.force_b.z[l], r.force_b.z);
    EXPECT_EQ(out.moment_b.x[l], r.moment_b.x);
    EXPECT_EQ(out.moment_b.y[l], r.moment_b.y);
    EXPECT_EQ(out.moment_b.z[l], r.moment_b.z);
    EXPECT_EQ(out.energy[l], r.energy);
    EXPECT_EQ(out.loaded[l] != 0, r.loaded);
  }
}

}  // namespace

TEST(FlatJointKernel, LanesAreBitwiseUpdateOrFallBack) {
  using mill::bond_geometry::Lane2;
  using mill::bond_geometry::Lane4;
  Rng rng{12345};
  for (const auto &[nr, na] : {std::pair{1, 3}, std::pair{2, 4}})
    for (const double softening : {1.0, 8.0}) {
      const Layout lay = make_layout(nr, na);
      KernelTally t2, t4;
      for (int k = 0; k < 400; ++k) {
        check_lanes<Lane2>(rng, lay, softening, t2);
        check_lanes<Lane4>(rng, lay, softening, t4);
      }
      // Not vacuous: both outcomes are exercised in both pack widths.
      for (const KernelTally *t : {&t2, &t4}) {
        std::printf(
            "%d x %d, softening %g: %d held (%d softened), %d broke or softened, %d broken "
            "before\n",
            nr, na, softening, t->held, t->held_softened, t->broke, t->damaged);
        EXPECT_GT(t->held, 200) << nr << " x " << na << ", softening " << softening;
        EXPECT_GT(t->broke, 50) << nr << " x " << na << ", softening " << softening;
        EXPECT_GT(t->damaged, 20) << nr << " x " << na << ", softening " << softening;
        if (softening > 1.0) {
          EXPECT_GT(t->held_softened, 50) << nr << " x " << na;
        }
      }
    }
}
