// Tests of fix wall/halfspace (docs/styles/fix_wall_halfspace.md) against
// LIGGGHTS's own `fix wall/gran model hertz tangential history primitive type
// 2 zplane Z`, through real liggghts-mill runs: the same contact law while the
// element's centre stays in front of the plane, and one-sided where the
// primitive plane is two-sided. Tolerances are stated next to each assertion
// and the figures printed in a one-line summary.
//
// Materials: elements (type 1) E = 5e9 Pa, nu = 0.25, density 2500 kg/m3;
// the surface (type 2 for wall/gran) E = 200e9 Pa, nu = 0.3.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "bond_test_util.h"
#include "fix_wall_halfspace.h"

using namespace mill_test;

namespace {

constexpr double kYoungs = 5e9, kPoisson = 0.25;           // elements [Pa], [-]
constexpr double kWallYoungs = 200e9, kWallPoisson = 0.3;  // surface [Pa], [-]

// Y* of an element on the surface [Pa].
double yeff() {
  return LAMMPS_NS::FixWallHalfspace::effective_youngs(kYoungs, kPoisson, kWallYoungs,
                                                       kWallPoisson);
}

// Hertz normal force 4/3 Y* sqrt(r) delta^(3/2) [N].
double hertz_force(double r, double delta) {
  return 4.0 / 3.0 * yeff() * std::sqrt(r) * delta * std::sqrt(delta);
}

// The two surfaces under test, both the plane z = 0 (solid below for
// wall/halfspace), restitution e and friction mu (wall/gran takes them from
// the type 1-2 pair of the material fixes).
enum class Wall { kPrimitive, kHalfspace };

// Deck: two atom types (the elements, and the surface for wall/gran), the box
// from data.txt, shrink-wrapped; Hertz contacts between elements; the surface.
std::string wall_deck_head(Wall w, double e, double mu) {
  std::ostringstream d;
  d.precision(17);
  d << "units si\natom_style granular\natom_modify map array\nboundary m m m\nnewton off\n"
    << "communicate single vel yes\nread_data data.txt\nneighbor 0.0002 bin\n"
    << "neigh_modify delay 0\nhard_particles yes\n"
    << "fix m1 all property/global youngsModulus peratomtype " << kYoungs << " " << kWallYoungs
    << "\nfix m2 all property/global poissonsRatio peratomtype " << kPoisson << " " << kWallPoisson
    << "\nfix m3 all property/global coefficientRestitution peratomtypepair 2 " << e << " " << e
    << " " << e << " " << e << "\nfix m4 all property/global coefficientFriction peratomtypepair 2 "
    << mu << " " << mu << " " << mu << " " << mu << "\n"
    << "pair_style gran model hertz tangential history\npair_coeff * *\n";
  if (w == Wall::kPrimitive)
    d << "fix wall all wall/gran model hertz tangential history primitive type 2 zplane 0.0\n";
  else
    d << "fix wall all wall/halfspace zplane 0.0 youngs " << kYoungs << " poisson " << kPoisson
      << " wall_youngs " << kWallYoungs << " wall_poisson " << kWallPoisson << " restitution " << e
      << " friction " << mu << "\n";
  return d.str();
}

// Writes data.txt (all elements type 1 of 2 types) and runs the deck in dir.
RunResult run_wall_deck(const std::string &dir, const std::vector<Sphere> &atoms, Wall w, double e,
                        double mu, const std::string &body) {
  {
    std::string data = data_text(atoms, 0.02);
    const std::string one = "1 atom types";
    data.replace(data.find(one), one.size(), "2 atom types");
    std::ofstream out(dir + "/data.txt");
    out << data;
  }
  return run_deck(dir, wall_deck_head(w, e, mu) + body);
}

// Numbers printed by `print "..." file path` (one line).
std::vector<double> read_line(const std::string &path) {
  const auto rows = read_table(path);
  return rows.empty() ? std::vector<double>{} : rows.front();
}

// A run's outcome: lowest centre and fastest element over the run (sampled
// every 10 steps), and at the end.
struct Outcome {
  double zmin_end = 0.0;   // lowest centre at the end [m]
  double vmax = 0.0;       // fastest element over the run [m/s]
  double vz_lowest = 0.0;  // vertical velocity of the lowest element at the end [m/s]
};

// Runs atoms against the surface for `steps` of dt and reads the Outcome.
Outcome run_crossing(const std::string &name, const std::vector<Sphere> &atoms, Wall w,
                     const std::string &bonds, double dt, int steps) {
  const std::string dir = make_run_dir(name);
  std::ostringstream d;
  d.precision(17);
  d << bonds << "fix integr all nve/sphere\ntimestep " << dt << "\n"
    << "variable sp atom sqrt(vx*vx+vy*vy+vz*vz)\ncompute smax all reduce max v_sp\n"
    << "compute zlo all reduce min z\nvariable s equal step\nvariable vm equal c_smax\n"
    << "fix pr all print 10 \"${s} ${vm}\" file speed.txt screen no title none\n"
    << "variable zl equal c_zlo\nvariable zl1 equal z[1]\nvariable vz1 equal vz[1]\n"
    << "fix pe all print " << steps
    << " \"${zl} ${zl1} ${vz1}\" file end.txt screen no title none\n"
    << "thermo 10000\nrun " << steps << "\n";
  const auto r = run_wall_deck(dir, atoms, w, 1.0, 0.5, d.str());
  EXPECT_EQ(r.exit_code, 0) << r.screen;
  Outcome o;
  for (const auto &row : read_table(dir + "/speed.txt")) o.vmax = std::max(o.vmax, row[1]);
  const auto end = read_line(dir + "/end.txt");
  EXPECT_EQ(end.size(), 3u);
  if (end.size() == 3) {
    o.zmin_end = end[0];
    o.vz_lowest = end[2];  // element 1 is the lowest in every setup below
    EXPECT_EQ(end[0], end[1]) << "element 1 is not the lowest";
  }
  return o;
}

}  // namespace

// ===========================================================================
// 1. The runaway, and that wall/halfspace ends it.
//    a) Static: an element whose centre is 0.2 r below the plane. The
//       primitive plane pushes it down (overlap r - |z| = 0.8 r), the
//       half-space up (overlap r - z = 1.2 r): F_z = -+4/3 Y* sqrt(r) delta^1.5
//       (1e-9 relative).
//    b) One element thrown normally onto the plane. With restitution 1 the
//       Hertz overlap reaches r (the centre reaches the plane) when
//       1/2 m v^2 = 8/15 Y* sqrt(r) r^(5/2), v* = sqrt(16/15 Y* r^3 / m)
//       (729 m/s here). At 0.9 v* it bounces off both surfaces; at 1.1 v*
//       it ends behind the primitive plane, moving away from it (the test
//       can fail), and in front of the half-space, moving up.
//    c) The smallest runaway: a 1 mm element bonded in front of a 5 mm one
//       (compression-proof bond: cohesion 1e15 Pa; it breaks in tension at
//       sigma_c = 2e7 Pa, as the calibrated rock's do), at 100 m/s (the
//       primitive plane lets the front element through from about 85 m/s).
//       The heavy element presses the front one through the primitive plane,
//       which then fires it off the far side: behind the plane, and above
//       3 x the impact speed. The half-space: no element behind the plane
//       and the fastest element below 3 x the impact speed.
// ===========================================================================

// The z force on one element at rest (run 0) from LIGGGHTS's primitive plane
// (fz[0]) and from wall/halfspace (fz[1]).
static void static_force_z(const Sphere &e, const char *tag, double fz[2]) {
  for (Wall w : {Wall::kPrimitive, Wall::kHalfspace}) {
    const std::string dir = make_run_dir(tag);
    const auto r = run_wall_deck(dir, {e}, w, 0.5, 0.5,
                                 "timestep 1e-9\nrun 0\nvariable fz equal fz[1]\n"
                                 "print \"${fz}\" file fz.txt\n");
    ASSERT_EQ(r.exit_code, 0) << r.screen;
    const auto row = read_line(dir + "/fz.txt");
    ASSERT_FALSE(row.empty());
    fz[w == Wall::kHalfspace] = row[0];
  }
}
TEST(WallHalfspace, OneSidedWhereThePrimitivePlaneIsTwoSided) {
  // a) static force on a centre 0.2 r below the plane.
  {
    Sphere s;
    s.x = {0.0, 0.0, -0.2 * kR};
    double fz[2] = {0.0, 0.0};
    static_force_z(s, "wh_static", fz);
    if (HasFatalFailure()) return;
    const double f_prim = -hertz_force(kR, 0.8 * kR), f_half = hertz_force(kR, 1.2 * kR);
    std::printf(
        "centre 0.2 r behind the plane: F_z primitive %.9e N (analytic %.9e N, overlap 0.8 r), "
        "half-space %.9e N (analytic %.9e N, overlap 1.2 r), rel. diffs %.2e / %.2e (tol 1e-9)\n",
        fz[0], f_prim, fz[1], f_half, fz[0] / f_prim - 1.0, fz[1] / f_half - 1.0);
    EXPECT_NEAR(fz[0] / f_prim, 1.0, 1e-9);  // two-sided: pushed further behind
    EXPECT_NEAR(fz[1] / f_half, 1.0, 1e-9);  // one-sided: pushed back out
  }
  // b) one element thrown at 0.9 and 1.1 x v*.
  const double m = sphere_mass(kR);
  const double vstar = std::sqrt(16.0 / 15.0 * yeff() * kR * kR * kR / m);
  for (double f : {0.9, 1.1}) {
    Sphere s;
    s.x = {0.0, 0.0, kR + 1e-5};
    s.v = {0.0, 0.0, -f * vstar};
    Outcome o[2];
    for (Wall w : {Wall::kPrimitive, Wall::kHalfspace})
      o[w == Wall::kHalfspace] = run_crossing("wh_single", {s}, w, "", 1e-9, 5000);
    std::printf(
        "one element at %.1f x v* = %.1f m/s (v* = %.2f m/s): primitive plane: centre ends at "
        "z = %.4g mm, v_z %.1f m/s; half-space: z = %.4g mm, v_z %.1f m/s, fastest %.1f m/s (bound "
        "3 x impact)\n",
        f, f * vstar, vstar, o[0].zmin_end * 1e3, o[0].vz_lowest, o[1].zmin_end * 1e3,
        o[1].vz_lowest, o[1].vmax);
    if (f < 1.0) {  // below v*: both bounce (the estimate holds)
      EXPECT_GT(o[0].zmin_end, 0.0);
      EXPECT_GT(o[0].vz_lowest, 0.0);
    } else {  // above v*: through the primitive plane
      EXPECT_LT(o[0].zmin_end, 0.0) << "the primitive plane held: test would be vacuous";
      EXPECT_LT(o[0].vz_lowest, 0.0);
    }
    EXPECT_GT(o[1].zmin_end, 0.0);          // never behind the half-space
    EXPECT_GT(o[1].vz_lowest, 0.0);         // bounced
    EXPECT_LT(o[1].vmax, 3.0 * f * vstar);  // bound: 3 x impact speed
  }
  // c) 1 mm element bonded in front of a 5 mm one, at 100 m/s.
  {
    const double v = 100.0, big = 5.0 * kR;
    Sphere front, back;
    front.x = {0.0, 0.0, kR + 1e-5};
    back.r = big;
    back.x = {0.0, 0.0, front.x[2] + kR + 1e-4 + big};  // 0.1 mm gap: bonded
    front.v = back.v = {0.0, 0.0, -v};
    const std::string bonds = bond_fix("", kSigmaT, 1e15);
    Outcome o[2];
    for (Wall w : {Wall::kPrimitive, Wall::kHalfspace})
      o[w == Wall::kHalfspace] = run_crossing("wh_column", {front, back}, w, bonds, 1e-9, 60000);
    std::printf(
        "1 mm element bonded in front of a 5 mm one at %.0f m/s: primitive plane: lowest centre "
        "ends at z = %.4g mm, v_z %.1f m/s, fastest %.1f m/s (%.1f x impact); half-space: "
        "z = %.4g mm, fastest %.1f m/s (%.2f x impact, bound 3)\n",
        v, o[0].zmin_end * 1e3, o[0].vz_lowest, o[0].vmax, o[0].vmax / v, o[1].zmin_end * 1e3,
        o[1].vmax, o[1].vmax / v);
    EXPECT_LT(o[0].zmin_end, 0.0) << "the primitive plane held: test would be vacuous";
    EXPECT_GT(o[0].vmax, 3.0 * v) << "no runaway on the primitive plane: test would be vacuous";
    EXPECT_GT(o[1].zmin_end, 0.0);  // no element behind the half-space
    EXPECT_LT(o[1].vmax, 3.0 * v);  // bound: 3 x impact speed
  }
}

// ===========================================================================
// 2. Below a crossing the law is LIGGGHTS's own. One element hits the plane
//    at 10 m/s, 45 degrees, spinning (2000, -5000, 0) rad/s, restitution
//    0.5, friction 0.5: with wall/gran primitive zplane and with
//    wall/halfspace the rebound velocity and spin agree to 1e-6 (relative to
//    their magnitudes). And the static normal force at overlaps 0.01 r and
//    0.2 r, from both, is 4/3 Y* sqrt(r) delta^1.5 with Y* from
//    FixWallHalfspace::effective_youngs (1e-9 relative).
// ===========================================================================
TEST(WallHalfspace, MatchesLiggghtsWallGranBelowCrossing) {
  const double v0 = 10.0, c45 = std::sqrt(0.5);
  Sphere s;
  s.x = {0.0, 0.0, kR + 1e-5};
  s.v = {v0 * c45, 0.0, -v0 * c45};
  s.w = {2000.0, -5000.0, 0.0};
  std::vector<double> end[2];
  for (Wall w : {Wall::kPrimitive, Wall::kHalfspace}) {
    const std::string dir = make_run_dir("wh_oblique");
    const auto r = run_wall_deck(
        dir, {s}, w, 0.5, 0.5,
        "fix integr all nve/sphere\ntimestep 1e-8\nrun 4000\n"
        "variable a equal vx[1]\nvariable b equal vy[1]\nvariable c equal vz[1]\n"
        "variable d equal omegax[1]\nvariable e equal omegay[1]\nvariable f equal omegaz[1]\n"
        "print \"${a} ${b} ${c} ${d} ${e} ${f}\" file end.txt\n");
    ASSERT_EQ(r.exit_code, 0) << r.screen;
    end[w == Wall::kHalfspace] = read_line(dir + "/end.txt");
    ASSERT_EQ(end[w == Wall::kHalfspace].size(), 6u);
  }
  auto norm = [](const std::vector<double> &a, int o) {
    return std::sqrt(a[o] * a[o] + a[o + 1] * a[o + 1] + a[o + 2] * a[o + 2]);
  };
  std::vector<double> diff(6);
  for (int k = 0; k < 6; ++k) diff[k] = end[1][k] - end[0][k];
  const double dv = norm(diff, 0) / norm(end[0], 0), dw = norm(diff, 3) / norm(end[0], 3);
  std::printf(
      "oblique bounce 10 m/s at 45 deg with spin: wall/gran v (%.9g, %.9g, %.9g) m/s, omega "
      "(%.9g, %.9g, %.9g) rad/s; wall/halfspace v (%.9g, %.9g, %.9g), omega (%.9g, %.9g, %.9g); "
      "rel. diffs |dv|/|v| %.2e, |domega|/|omega| %.2e (tol 1e-6)\n",
      end[0][0], end[0][1], end[0][2], end[0][3], end[0][4], end[0][5], end[1][0], end[1][1],
      end[1][2], end[1][3], end[1][4], end[1][5], dv, dw);
  EXPECT_GT(end[0][2], 0.0);  // it rebounded
  EXPECT_GT(std::fabs(end[0][3] - s.w[0]) + std::fabs(end[0][4] - s.w[1]), 100.0)
      << "the spin did not change: the tangential law was not exercised";
  EXPECT_LT(dv, 1e-6);  // tolerance 1e-6
  EXPECT_LT(dw, 1e-6);  // tolerance 1e-6

  for (double frac : {0.01, 0.2}) {
    Sphere p;
    p.x = {0.0, 0.0, kR * (1.0 - frac)};
    double fz[2] = {0.0, 0.0};
    static_force_z(p, "wh_force", fz);
    if (HasFatalFailure()) return;
    const double f = hertz_force(kR, frac * kR);
    std::printf(
        "normal force at overlap %.2f r: wall/gran %.9e N, wall/halfspace %.9e N, 4/3 Y* sqrt(r) "
        "delta^1.5 = %.9e N (Y* %.6e Pa), rel. diffs %.2e / %.2e (tol 1e-9)\n",
        frac, fz[0], fz[1], f, yeff(), fz[0] / f - 1.0, fz[1] / f - 1.0);
    EXPECT_NEAR(fz[0] / f, 1.0, 1e-9);  // tolerance 1e-9
    EXPECT_NEAR(fz[1] / f, 1.0, 1e-9);  // tolerance 1e-9
  }
}
