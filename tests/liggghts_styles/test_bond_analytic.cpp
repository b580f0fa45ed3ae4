// Analytic tests of fix bond/breakable (Potyondy & Cundall 2004 parallel bond,
// Potyondy 2015 linear parallel bond strength) driven through real
// liggghts-mill runs. Every test compares a number measured in the run with a
// closed-form value or bound computed here (the MPI test: with the 1-rank
// run), and states its tolerance next to the assertion.
//
// Model under test (docs/styles/fix_bond_breakable.md):
//   A = pi R^2, I = pi R^4/4, J = pi R^4/2, R = lambda min(Ri, Rj)
//   kn = E_b / L0, ks = kn / stiffness_ratio
//   sigma = F_n/A + beta |M_b| R / I   (F_n signed, tension > 0) > sigma_c -> tension
//   tau   = |F_s|/A + beta |M_t| R / J                          > tau_c   -> shear
//   tau_c = c - (F_n/A) tan(phi)
//   beta = `moment_factor` (default 1).
//
// Initial positions, velocities and spins are written to a data file
// (read_data; LIGGGHTS 3.8's `set` has no omega keyword). An atom that no fix
// integrates keeps its position and spin, so two spheres with opposite spins
// load their bond with a moment growing linearly in time.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "bond_test_util.h"
#include "network_step.h"

using namespace mill_test;

namespace {

// `moment_factor beta` unless beta is the default 1 (then the default is used).
std::string beta_keyword(double beta) {
  if (beta == 1.0) return "";
  std::ostringstream s;
  s << "moment_factor " << beta;
  return s.str();
}

// Kinetic energy, translational plus rotational (0.4 m r^2), of the data [J].
double kinetic_energy(const std::vector<Sphere> &atoms) {
  double e = 0.0;
  for (const auto &s : atoms)
    for (int c = 0; c < 3; ++c)
      e += 0.5 * sphere_mass(s.r) * s.v[c] * s.v[c] + 0.5 * sphere_inertia(s.r) * s.w[c] * s.w[c];
  return e;
}

// Deterministic pseudo-random numbers in [-0.5, 0.5].
struct Lcg {
  unsigned s;
  double operator()() {
    s = s * 1103515245u + 12345u;
    return ((s >> 8) & 0xffff) / 65535.0 - 0.5;
  }
};

// Mean period from upward crossings (needs >= 3).
double mean_period(const std::vector<double> &up) {
  return (up.back() - up.front()) / static_cast<double>(up.size() - 1);
}

// Eigenvalues of the symmetric matrix a (n x n, row major) by cyclic Jacobi
// rotations; ascending.
std::vector<double> jacobi_eigenvalues(std::vector<double> a, int n) {
  auto at = [&a, n](int i, int j) -> double & { return a[static_cast<size_t>(i) * n + j]; };
  for (int sweep = 0; sweep < 100; ++sweep) {
    double off = 0.0, diag = 0.0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) (i == j ? diag : off) += at(i, j) * at(i, j);
    if (off <= 1e-30 * diag) break;
    for (int p = 0; p < n; ++p)
      for (int q = p + 1; q < n; ++q) {
        if (at(p, q) == 0.0) continue;
        const double theta = (at(q, q) - at(p, p)) / (2.0 * at(p, q));
        const double t =
            (theta >= 0.0 ? 1.0 : -1.0) / (std::fabs(theta) + std::sqrt(theta * theta + 1.0));
        const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
        for (int k = 0; k < n; ++k) {  // columns p, q
          const double kp = at(k, p), kq = at(k, q);
          at(k, p) = c * kp - s * kq;
          at(k, q) = s * kp + c * kq;
        }
        for (int k = 0; k < n; ++k) {  // rows p, q
          const double pk = at(p, k), qk = at(q, k);
          at(p, k) = c * pk - s * qk;
          at(q, k) = s * pk + c * qk;
        }
      }
  }
  std::vector<double> ev(n);
  for (int i = 0; i < n; ++i) ev[i] = at(i, i);
  std::sort(ev.begin(), ev.end());
  return ev;
}

// Analytic stable step 2 / omega_max (velocity Verlet) of a free bonded pair
// along x with radii ra, rb, centre distance len: the 12 x 12 stiffness of
// (u_a, theta_a, u_b, theta_b) from the normal spring kn A, the shear spring
// ks A acting at the contact point (arms len ra/(ra+rb), len rb/(ra+rb)), the
// bending spring kn I and the twisting spring ks J; mass-normalised with
// m and 0.4 m r^2; largest eigenvalue by Jacobi.
double pair_exact_step(double ra, double rb, double len) {
  const double rbond = std::min(ra, rb);
  const double area = kPi * rbond * rbond, inertia = 0.25 * area * rbond * rbond;
  const double polar = 2.0 * inertia;
  const double kn = kEb / len, ks = kn / kRatio;
  const double arm_a = len * ra / (ra + rb), arm_b = len - arm_a;
  // Relative displacement at the contact: U = u_b - u_a + arm_b n x th_b + arm_a n x th_a,
  // relative rotation Th = th_b - th_a, n = x.
  const double nx[3][3] = {{0, 0, 0}, {0, 0, -1}, {0, 1, 0}};  // [n]_x for n = (1,0,0)
  double bu[3][12] = {}, bt[3][12] = {};
  for (int i = 0; i < 3; ++i) {
    bu[i][6 + i] += 1.0;
    bu[i][i] -= 1.0;
    for (int j = 0; j < 3; ++j) {
      bu[i][9 + j] += arm_b * nx[i][j];
      bu[i][3 + j] += arm_a * nx[i][j];
    }
    bt[i][9 + i] = 1.0;
    bt[i][3 + i] = -1.0;
  }
  const double du[3] = {kn * area, ks * area, ks * area};          // normal, shear, shear
  const double dth[3] = {ks * polar, kn * inertia, kn * inertia};  // twist, bend, bend
  const double ma = sphere_mass(ra), mb = sphere_mass(rb);
  const double mass[12] = {ma, ma, ma, sphere_inertia(ra), sphere_inertia(ra), sphere_inertia(ra),
                           mb, mb, mb, sphere_inertia(rb), sphere_inertia(rb), sphere_inertia(rb)};
  std::vector<double> k(144, 0.0);
  for (int p = 0; p < 12; ++p)
    for (int q = 0; q < 12; ++q) {
      double s = 0.0;
      for (int i = 0; i < 3; ++i) s += bu[i][p] * du[i] * bu[i][q] + bt[i][p] * dth[i] * bt[i][q];
      k[p * 12 + q] = s / std::sqrt(mass[p] * mass[q]);
    }
  const auto ev = jacobi_eigenvalues(k, 12);
  return 2.0 / std::sqrt(ev.back());
}

// Columns printed every step by the moment-break tests: step, bond energy,
// intact bonds, broken in tension, broken in shear.
const char *kBreakPrint =
    "variable s equal step\nvariable e equal f_bonds[5]\nvariable nb equal f_bonds[1]\n"
    "variable nt equal f_bonds[3]\nvariable ns equal f_bonds[4]\n"
    "fix pr all print 1 \"${s} ${e} ${nb} ${nt} ${ns}\" file hist.txt screen no title none\n";

// Result of a run in which the single bond breaks under a growing moment:
// the break step and the bond energy one step before.
struct BreakRun {
  bool ok = false;
  double step_break = 0.0;            // first step with no intact bond
  double energy_last = 0.0;           // bond energy at the last intact step
  double tension = 0.0, shear = 0.0;  // break counters at the end
};

BreakRun read_break_run(const std::string &path) {
  BreakRun br;
  const auto rows = last_run_rows(path);
  if (rows.size() < 3) return br;
  for (size_t k = 1; k < rows.size(); ++k)
    if (rows[k][2] == 0.0 && rows[k - 1][2] == 1.0) {
      if (rows[k][0] != rows[k - 1][0] + 1.0) return br;  // a step missing
      br.step_break = rows[k][0];
      br.energy_last = rows[k - 1][1];
      br.ok = true;
      break;
    }
  br.tension = rows.back()[3];
  br.shear = rows.back()[4];
  return br;
}

// Deck body of the moment-break tests: the bond fix with moment_factor beta,
// the kBreakPrint columns, `steps` steps of dt.
std::string moment_break_deck(double beta, double dt, int steps) {
  std::ostringstream d;
  d.precision(17);
  d << bond_fix(beta_keyword(beta)) << "timestep " << dt << "\n"
    << kBreakPrint << "thermo 1000\nrun " << steps << "\n";
  return d.str();
}

// Test name of a moment_factor parameter.
std::string beta_name(const ::testing::TestParamInfo<double> &info) {
  return info.param == 1.0 ? std::string("Beta1") : std::string("Beta05");
}

}  // namespace

// ===========================================================================
// 1. Pure bending breaks in tension at M_b = sigma_c I / (beta R).
//    Opposite spins -w, +w about z (normal to the bond along x), no time
//    integration: no shear, no stretch, M_b(t) = kn I (2w) t. The moment at
//    break is read twice: from the bond energy M^2 / (2 kn I) at the last
//    intact step, and from the break step t*: M = kn I 2w t*.
// ===========================================================================
class BondBendingBreak : public ::testing::TestWithParam<double> {};

TEST_P(BondBendingBreak, BreaksAtTensileStrengthOverBeta) {
  const double beta = GetParam();
  const std::string dir = make_run_dir("an_bend");
  const double w = 100.0, dt = 1e-8;
  const double m_star = kSigmaT * kInertia / (beta * kR);
  const double rate = kKn * kInertia * 2.0 * w * dt;  // moment per step [N m]
  const int steps = static_cast<int>(1.5 * m_star / rate) + 100;
  const auto r =
      run_with_data(dir, spinning_pair({0, 0, -w}, {0, 0, w}), moment_break_deck(beta, dt, steps));
  ASSERT_EQ(r.exit_code, 0) << r.screen;
  const auto br = read_break_run(dir + "/hist.txt");
  ASSERT_TRUE(br.ok) << "bond did not break within " << steps << " steps";
  const double m_energy = std::sqrt(2.0 * kKn * kInertia * br.energy_last);
  const double m_time = rate * br.step_break;
  std::printf(
      "bending break (beta %.2f): M from energy %.6e N m, from t* %.6e N m, analytic %.6e N m, "
      "rel. errors %.3e / %.3e (tol 1e-2)\n",
      beta, m_energy, m_time, m_star, m_energy / m_star - 1.0, m_time / m_star - 1.0);
  EXPECT_NEAR(m_energy / m_star, 1.0, 0.01);  // tolerance 1 %
  EXPECT_NEAR(m_time / m_star, 1.0, 0.01);    // tolerance 1 %
  // The moment one step before is M(t* - dt): energy and time agree to round-off (1e-6).
  EXPECT_NEAR(m_energy / (m_time - rate), 1.0, 1e-6);
  EXPECT_EQ(br.tension, 1.0);  // exact count: broken in tension
  EXPECT_EQ(br.shear, 0.0);    // exact count
}

INSTANTIATE_TEST_SUITE_P(MomentFactor, BondBendingBreak, ::testing::Values(1.0, 0.5), beta_name);

// ===========================================================================
// 2. Pure twisting breaks in shear at M_t = c J / (beta R).
//    Opposite spins -w, +w about the bond axis x, no time integration:
//    M_t(t) = ks J (2w) t; energy M_t^2 / (2 ks J).
// ===========================================================================
class BondTwistBreak : public ::testing::TestWithParam<double> {};

TEST_P(BondTwistBreak, BreaksAtCohesionOverBeta) {
  const double beta = GetParam();
  const std::string dir = make_run_dir("an_twist");
  const double w = 200.0, dt = 1e-8;
  const double m_star = kCohesion * kPolar / (beta * kR);
  const double rate = kKs * kPolar * 2.0 * w * dt;  // moment per step [N m]
  const int steps = static_cast<int>(1.5 * m_star / rate) + 100;
  const auto r =
      run_with_data(dir, spinning_pair({-w, 0, 0}, {w, 0, 0}), moment_break_deck(beta, dt, steps));
  ASSERT_EQ(r.exit_code, 0) << r.screen;
  const auto br = read_break_run(dir + "/hist.txt");
  ASSERT_TRUE(br.ok) << "bond did not break within " << steps << " steps";
  const double m_energy = std::sqrt(2.0 * kKs * kPolar * br.energy_last);
  const double m_time = rate * br.step_break;
  std::printf(
      "twist break (beta %.2f): M_t from energy %.6e N m, from t* %.6e N m, analytic %.6e N m, "
      "rel. errors %.3e / %.3e (tol 1e-2)\n",
      beta, m_energy, m_time, m_star, m_energy / m_star - 1.0, m_time / m_star - 1.0);
  EXPECT_NEAR(m_energy / m_star, 1.0, 0.01);           // tolerance 1 %
  EXPECT_NEAR(m_time / m_star, 1.0, 0.01);             // tolerance 1 %
  EXPECT_NEAR(m_energy / (m_time - rate), 1.0, 1e-6);  // round-off (1e-6)
  EXPECT_EQ(br.shear, 1.0);                            // exact count: broken in shear
  EXPECT_EQ(br.tension, 0.0);                          // exact count
}

INSTANTIATE_TEST_SUITE_P(MomentFactor, BondTwistBreak, ::testing::Values(1.0, 0.5), beta_name);

// ===========================================================================
// 3. A compressed bond needs more bending to break, by exactly F_n / A:
//    sigma = F_n/A + |M_b| R / I with F_n = -kn A delta < 0, so
//    M* = (sigma_c - F_n/A) I / R = (sigma_c + kn delta) I / R.
//    Bonds are made in `run 0`, atom 2 is displaced by -delta along the bond,
//    then the pair is bent as in test 1 (delta chosen so that kn delta =
//    sigma_c: M* is twice the uncompressed value).
// ===========================================================================
TEST(BondCompressedBending, BreaksAtStrengthPlusCompression) {
  const std::string dir = make_run_dir("an_cbend");
  const double w = 100.0, dt = 1e-8;
  const double delta = kSigmaT / kKn;      // kn delta = sigma_c
  const double fn = -kKn * kArea * delta;  // signed normal force [N]
  const double m_star = (kSigmaT - fn / kArea) * kInertia / kR;
  const double rate = kKn * kInertia * 2.0 * w * dt;
  const int steps = static_cast<int>(1.5 * m_star / rate) + 100;
  std::ostringstream d;
  d.precision(17);
  d << bond_fix() << "timestep " << dt << "\n"
    << "group a2 id 2\nrun 0\n"
    << "displace_atoms a2 move " << -delta << " 0 0 units box\n"
    << "run 0\nvariable e0 equal f_bonds[5]\nprint \"${e0}\" file e0.txt\n"
    << kBreakPrint << "thermo 1000\nrun " << steps << "\n";
  const auto r = run_with_data(dir, spinning_pair({0, 0, -w}, {0, 0, w}), d.str());
  ASSERT_EQ(r.exit_code, 0) << r.screen;
  const auto br = read_break_run(dir + "/hist.txt");
  ASSERT_TRUE(br.ok) << "bond did not break within " << steps << " steps";
  // After the displacement (run 0) the bond holds only the normal energy F_n^2 / (2 kn A).
  const auto e0rows = read_table(dir + "/e0.txt");
  ASSERT_FALSE(e0rows.empty());
  const double e_first = e0rows.front()[0];
  const double e_normal = fn * fn / (2.0 * kKn * kArea);
  const double m_energy = std::sqrt(2.0 * kKn * kInertia * (br.energy_last - e_first));
  const double m_time = rate * br.step_break;
  std::printf(
      "compressed bending: F_n %.4g N, normal energy %.6e J (analytic %.6e J); M from energy "
      "%.6e N m, from t* %.6e N m, analytic %.6e N m (uncompressed %.6e), rel. errors %.3e / "
      "%.3e (tol 1e-2)\n",
      fn, e_first, e_normal, m_energy, m_time, m_star, kSigmaT * kInertia / kR,
      m_energy / m_star - 1.0, m_time / m_star - 1.0);
  EXPECT_NEAR(e_first / e_normal, 1.0, 1e-6);  // elastic normal energy, round-off 1e-6
  EXPECT_NEAR(m_energy / m_star, 1.0, 0.01);   // tolerance 1 %
  EXPECT_NEAR(m_time / m_star, 1.0, 0.01);     // tolerance 1 %
  EXPECT_EQ(br.tension, 1.0);                  // exact count: broken in tension
  EXPECT_EQ(br.shear, 0.0);                    // exact count
}

// ===========================================================================
// 4. Mohr-Coulomb shear strength: a compressed pair sheared slowly breaks at
//    |F_s| = (c - tan(phi) F_n / A) A, F_n < 0.
//    Bonds made in `run 0`, atom 2 displaced by -delta along the bond, then
//    moved sideways (y) at constant velocity by `fix move linear`; atom 1 is
//    not integrated. Neither sphere spins, so the bond carries no moment
//    (checked: the bond energy is the normal plus the shear term only) and
//    tau = |F_s| / A exactly. F_n and F_s are measured from the force on
//    atom 2 split along the current bond direction.
// ===========================================================================
TEST(BondCompressedShear, BreaksAtMohrCoulombStrength) {
  const std::string dir = make_run_dir("an_cshear");
  const double vy = 0.5, dt = 1e-8;
  const double delta = kSigmaT / kKn;  // compressive normal stress = 2e7 Pa
  const double tan_phi = std::tan(kPhiDeg * kPi / 180.0);
  const double fs_guess = (kCohesion + tan_phi * kKn * delta) * kArea;
  const int steps = static_cast<int>(1.5 * fs_guess / (kKs * kArea * vy * dt)) + 100;
  std::ostringstream d;
  d.precision(17);
  d << bond_fix() << "timestep " << dt << "\n"
    << "group a2 id 2\nrun 0\n"
    << "displace_atoms a2 move " << -delta << " 0 0 units box\n"
    << "fix mv a2 move linear 0 " << vy << " 0\n"
    << "variable s equal step\nvariable dx equal x[2]-x[1]\nvariable dy equal y[2]-y[1]\n"
    << "variable dz equal z[2]-z[1]\n"
    << "variable fx equal fx[2]\nvariable fy equal fy[2]\nvariable fz equal fz[2]\n"
    << "variable e equal f_bonds[5]\nvariable nb equal f_bonds[1]\n"
    << "variable nt equal f_bonds[3]\nvariable ns equal f_bonds[4]\n"
    << "fix pr all print 1 \"${s} ${dx} ${dy} ${dz} ${fx} ${fy} ${fz} ${e} ${nb} ${nt} ${ns}\" "
       "file hist.txt screen no title none\n"
    << "thermo 1000\nrun " << steps << "\n";
  const auto r = run_with_data(dir, spinning_pair({0, 0, 0}, {0, 0, 0}), d.str());
  ASSERT_EQ(r.exit_code, 0) << r.screen;
  const auto rows = last_run_rows(dir + "/hist.txt");
  ASSERT_GT(rows.size(), 10u);
  size_t last = 0;
  for (size_t k = 1; k < rows.size(); ++k)
    if (rows[k][8] == 0.0 && rows[k - 1][8] == 1.0) {
      last = k - 1;
      break;
    }
  ASSERT_GT(last, 0u) << "bond did not break";
  const auto &row = rows[last];
  const double len = std::sqrt(row[1] * row[1] + row[2] * row[2] + row[3] * row[3]);
  const double n[3] = {row[1] / len, row[2] / len, row[3] / len};
  const double f[3] = {row[4], row[5], row[6]};
  const double fdotn = f[0] * n[0] + f[1] * n[1] + f[2] * n[2];
  const double fn = -fdotn;  // force on b is -F_n n + F_s (tension > 0)
  double fs = 0.0;
  for (int c = 0; c < 3; ++c) fs += (f[c] - fdotn * n[c]) * (f[c] - fdotn * n[c]);
  fs = std::sqrt(fs);
  const double fn_analytic = kKn * kArea * (len - kL0);
  const double fs_star = (kCohesion - tan_phi * fn / kArea) * kArea;
  const double e_no_moment = fn * fn / (2.0 * kKn * kArea) + fs * fs / (2.0 * kKs * kArea);
  std::printf(
      "compressed shear at step %.0f: F_n %.6g N (kn A (L-L0) %.6g N), |F_s| %.6g N, "
      "Mohr-Coulomb (c - tan(phi) F_n/A) A %.6g N (cohesion only %.6g N), rel. error %.3e "
      "(tol 1e-2); bond energy %.6e J vs normal+shear %.6e J\n",
      row[0], fn, fn_analytic, fs, fs_star, kCohesion * kArea, fs / fs_star - 1.0, row[7],
      e_no_moment);
  EXPECT_LT(fn, 0.0);                            // compressed
  EXPECT_NEAR(fn / fn_analytic, 1.0, 1e-4);      // elastic normal force, 1e-4 (print precision)
  EXPECT_NEAR(row[7] / e_no_moment, 1.0, 1e-4);  // no moment in the bond, 1e-4
  EXPECT_NEAR(fs / fs_star, 1.0, 0.01);          // tolerance 1 %
  EXPECT_EQ(rows.back()[10], 1.0);               // exact count: broken in shear
  EXPECT_EQ(rows.back()[9], 0.0);                // exact count
}

// ===========================================================================
// 5. Objectivity: a bonded 2 x 2 x 3 block spinning rigidly (v = w x r,
//    omega = w, about a skew axis through its centre), integrated with
//    nve/sphere for 10^4 steps at half the fix's critical step, stores no
//    elastic energy beyond the centripetal stretch: bond energy < 1e-9 of
//    the kinetic energy. The stretch that holds the spheres on their circles
//    stores ~ m w^2 / (kn A) ~ 1.4e-10 of the kinetic energy at w = 10 rad/s
//    (measured ~1.0e-10, scaling as w^2 from 5 to 40 rad/s, i.e. physical,
//    not an objectivity error). A bond whose shear increment ignored the
//    spins would store ~ (ks A) (w L t)^2 / 2 per bond (printed, ~5e-3 J,
//    10^5 x the kinetic energy) and fail.
// ===========================================================================
TEST(BondObjectivity, RigidSpinStoresNoEnergy) {
  const std::string dir = make_run_dir("an_spin");
  const double wmag = 10.0;  // [rad/s]
  const double axis[3] = {0.3, 0.5, 0.81};
  const double an = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
  const std::array<double, 3> w = {wmag * axis[0] / an, wmag * axis[1] / an, wmag * axis[2] / an};
  std::vector<Sphere> atoms;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        Sphere s;
        s.x = {(i - 0.5) * kL0, (j - 0.5) * kL0, (k - 1.0) * kL0};
        s.v = {w[1] * s.x[2] - w[2] * s.x[1], w[2] * s.x[0] - w[0] * s.x[2],
               w[0] * s.x[1] - w[1] * s.x[0]};
        s.w = w;
        atoms.push_back(s);
      }
  const int steps = 10000;
  std::ostringstream d;
  d.precision(17);
  d << "fix integr all nve/sphere\n"
    << bond_fix() << "compute rke all erotate/sphere\n"
    << "variable s equal step\nvariable k equal ke+c_rke\nvariable e equal f_bonds[5]\n"
    << "variable nb equal f_bonds[1]\nvariable nbr equal f_bonds[2]\n"
    << "variable dtc equal f_bonds[6]\n"
    << "timestep 1e-9\nrun 0\n"
    << "variable dth equal 0.5*${dtc}\ntimestep ${dth}\n"
    << "fix pr all print 1 \"${s} ${k} ${e} ${nb} ${nbr} ${dtc}\" file hist.txt screen no "
       "title none\n"
    << "thermo 2000\nrun " << steps << "\n";
  const auto r = run_with_data(dir, atoms, d.str());
  ASSERT_EQ(r.exit_code, 0) << r.screen;
  const auto rows = last_run_rows(dir + "/hist.txt");
  ASSERT_EQ(rows.size(), static_cast<size_t>(steps));
  const double ke0 = kinetic_energy(atoms);  // bonds unloaded at the start
  double emax = 0.0;
  for (const auto &row : rows) emax = std::max(emax, row[2]);
  const double dt = 0.5 * rows.front()[5];
  const double t_end = steps * dt;
  const double nonobjective = 0.5 * kKs * kArea * std::pow(wmag * kL0 * t_end, 2);
  std::printf(
      "rigid spin: %d steps of %.4g s (rotation %.3f rad), KE %.6e J, max bond energy %.3e J = "
      "%.3e KE (tol 1e-9); a non-objective shear spring would store ~%.3e J per bond; bonds "
      "%.0f -> %.0f, broken %.0f\n",
      steps, dt, wmag * t_end, ke0, emax, emax / ke0, nonobjective, rows.front()[3], rows.back()[3],
      rows.back()[4]);
  EXPECT_EQ(rows.front()[3], 20.0);  // exact count: 2x2x3 simple cubic block has 20 bonds
  EXPECT_EQ(rows.back()[3], 20.0);   // exact count: none lost
  EXPECT_EQ(rows.back()[4], 0.0);    // exact count: none broken
  EXPECT_LT(emax, 1e-9 * ke0);       // bound: 1e-9 of the kinetic energy
  EXPECT_NEAR(rows.back()[1] / ke0, 1.0, 1e-6);  // kinetic energy kept, 1e-6
}

// ===========================================================================
// 6. Small-amplitude bond vibration periods against the analytic ones.
//    (a) Atom 1 frozen, atom 2 free: transverse displacement y and rotation
//        theta_z of atom 2 form a 2-DOF system with stiffness
//          K = [[ks A, -ks A L/2], [-ks A L/2, ks A L^2/4 + kn I]]
//        and mass diag(m, 0.4 m R^2). Each eigenmode is started alone (initial
//        (v_y, omega_z) along its eigenvector) and the period of y(t) is
//        measured.
//    (b) Pure bending: both atoms free with spins -w, +w about z (no shear at
//        the contact): T = 2 pi sqrt(I_s / (2 kn I)).
//    (c) Pure twisting: atom 1 frozen, atom 2 spinning about the bond axis:
//        T = 2 pi sqrt(I_s / (ks J)).
// ===========================================================================
namespace {

// Runs the pair with the given initial state and integrated group; prints
// time and `column` (an equal-style expression) every step; returns the
// measured period of that column about zero.
double measure_period(const std::string &name, const std::vector<Sphere> &atoms,
                      const std::string &integrated, const std::string &column, double dt,
                      int steps, int *crossings) {
  const std::string dir = make_run_dir(name);
  std::ostringstream d;
  d.precision(17);
  d << "group a1 id 1\ngroup a2 id 2\n"
    << "fix integr " << integrated << " nve/sphere\n"
    << bond_fix() << "compute om all property/atom omegax omegay omegaz\n"
    << "timestep " << dt << "\n"
    << "variable t equal time\nvariable c equal " << column << "\n"
    << "variable nb equal f_bonds[1]\n"
    << "fix pr all print 1 \"${t} ${c} ${nb}\" file hist.txt screen no title none\n"
    << "thermo 5000\nrun " << steps << "\n";
  const auto r = run_with_data(dir, atoms, d.str());
  EXPECT_EQ(r.exit_code, 0) << r.screen;
  const auto rows = last_run_rows(dir + "/hist.txt");
  EXPECT_GT(rows.size(), static_cast<size_t>(steps / 2));
  if (rows.empty()) return 0.0;
  EXPECT_EQ(rows.back()[2], 1.0) << "bond broke";
  const auto up = crossings_up(rows, 1, 0.0);
  *crossings = static_cast<int>(up.size());
  return up.size() >= 3 ? mean_period(up) : 0.0;
}

}  // namespace

TEST(BondVibration, ShearRotationModes) {
  const double m = sphere_mass(kR), is = sphere_inertia(kR);
  const double ksa = kKs * kArea, arm = 0.5 * kL0;
  // Mass-normalised 2x2 stiffness and its eigenpairs.
  const double k11 = ksa / m, k22 = (ksa * arm * arm + kKn * kInertia) / is;
  const double k12 = -ksa * arm / std::sqrt(m * is);
  const double tr = k11 + k22, det = k11 * k22 - k12 * k12;
  const double disc = std::sqrt(tr * tr - 4.0 * det);
  const double lam[2] = {0.5 * (tr - disc), 0.5 * (tr + disc)};
  for (int mode = 0; mode < 2; ++mode) {
    const double omega = std::sqrt(lam[mode]);
    const double period = 2.0 * kPi / omega;
    // Eigenvector of the normalised matrix (k12, lam - k11), back to (v_y, omega_z).
    double e1 = k12, e2 = lam[mode] - k11;
    const double en = std::sqrt(e1 * e1 + e2 * e2);
    e1 /= en;
    e2 /= en;
    const double amp = 0.05;  // scale: |v_y| <= 0.05 m/s, amplitude ~1e-8 m
    double vy = amp * e1 / std::sqrt(m), wz = amp * e2 / std::sqrt(is);
    const double s = amp / std::max(std::fabs(vy), std::fabs(wz * kR));
    vy *= s;
    wz *= s;
    auto atoms = spinning_pair({0, 0, 0}, {0, 0, wz});
    atoms[1].v = {0.0, vy, 0.0};
    const double dt = 2.0 * kPi / std::sqrt(lam[1]) / 200.0;
    const int steps = static_cast<int>(10.5 * period / dt);
    int n = 0;
    const double measured =
        measure_period(mode == 0 ? "an_vib_lo" : "an_vib_hi", atoms, "a2", "y[2]", dt, steps, &n);
    std::printf(
        "shear-rotation mode %d: eigenvector (v_y %.4g m/s, omega_z %.4g rad/s), period measured "
        "%.6e s over %d crossings, analytic %.6e s, rel. error %.3e (tol 2e-2)\n",
        mode, vy, wz, measured, n, period, measured / period - 1.0);
    EXPECT_GE(n, 5);
    EXPECT_NEAR(measured / period, 1.0, 0.02);  // tolerance 2 %
  }
}

TEST(BondVibration, PureBendingAndTwistingModes) {
  const double is = sphere_inertia(kR);
  const double w = 10.0;  // initial spin [rad/s]; moment amplitude ~ kn I w / Omega, tiny
  {
    const double period = 2.0 * kPi * std::sqrt(is / (2.0 * kKn * kInertia));
    const double dt = period / 200.0;
    int n = 0;
    const double measured =
        measure_period("an_vib_bend", spinning_pair({0, 0, -w}, {0, 0, w}), "all", "c_om[2][3]", dt,
                       static_cast<int>(10.5 * period / dt), &n);
    std::printf(
        "pure bending mode: period measured %.6e s over %d crossings, analytic %.6e s, rel. "
        "error %.3e (tol 2e-2)\n",
        measured, n, period, measured / period - 1.0);
    EXPECT_GE(n, 5);
    EXPECT_NEAR(measured / period, 1.0, 0.02);  // tolerance 2 %
  }
  {
    const double period = 2.0 * kPi * std::sqrt(is / (kKs * kPolar));
    const double dt = period / 200.0;
    int n = 0;
    const double measured =
        measure_period("an_vib_twist", spinning_pair({0, 0, 0}, {w, 0, 0}), "a2", "c_om[2][1]", dt,
                       static_cast<int>(10.5 * period / dt), &n);
    std::printf(
        "pure twisting mode: period measured %.6e s over %d crossings, analytic %.6e s, rel. "
        "error %.3e (tol 2e-2)\n",
        measured, n, period, measured / period - 1.0);
    EXPECT_GE(n, 5);
    EXPECT_NEAR(measured / period, 1.0, 0.02);  // tolerance 2 %
  }
}

// ===========================================================================
// 7. Energy conservation without damping at half the fix's critical step
//    f_ID[6] (read in `run 0`): a free 3 x 3 x 2 bonded block with random
//    velocities and spins, 10^5 steps. Drift = mean total energy (kinetic +
//    rotational + bond f_ID[5]) over the last 5 % of the samples minus that
//    over the first 5 %, relative to E0: below 0.5 %. No contacts (the
//    largest contact count of any atom stays 0).
// ===========================================================================
TEST(BondCluster, EnergyDriftAtHalfCriticalStep) {
  const std::string dir = make_run_dir("an_drift");
  std::vector<Sphere> atoms;
  Lcg rnd{2024u};
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        Sphere s;
        s.x = {(i - 1.0) * kL0, (j - 1.0) * kL0, (k - 0.5) * kL0};
        s.v = {0.2 * rnd(), 0.2 * rnd(), 0.2 * rnd()};
        s.w = {200.0 * rnd(), 200.0 * rnd(), 200.0 * rnd()};
        atoms.push_back(s);
      }
  std::array<double, 3> vcm{};  // no net momentum: the block stays in place
  for (const auto &s : atoms)
    for (int c = 0; c < 3; ++c) vcm[c] += s.v[c] / atoms.size();
  for (auto &s : atoms)
    for (int c = 0; c < 3; ++c) s.v[c] -= vcm[c];
  const int steps = 100000;
  std::ostringstream d;
  d.precision(17);
  d << "fix integr all nve/sphere\n"
    << bond_fix() << "compute rke all erotate/sphere\n"
    << "compute ca all contact/atom\ncompute cmax all reduce max c_ca\n"
    << "variable s equal step\nvariable etot equal ke+c_rke+f_bonds[5]\n"
    << "variable b equal f_bonds[5]\nvariable c equal c_cmax\nvariable nb equal f_bonds[2]\n"
    << "variable dtc equal f_bonds[6]\n"
    << "timestep 1e-9\nrun 0\n"
    << "variable dth equal 0.5*${dtc}\ntimestep ${dth}\n"
    << "fix pr all print 100 \"${s} ${etot} ${b} ${c} ${nb} ${dtc}\" file hist.txt screen no "
       "title none\n"
    << "thermo 20000\nrun " << steps << "\n";
  const auto r = run_with_data(dir, atoms, d.str());
  ASSERT_EQ(r.exit_code, 0) << r.screen;
  const auto rows = last_run_rows(dir + "/hist.txt");
  ASSERT_EQ(rows.size(), static_cast<size_t>(steps / 100));
  const double e0 = kinetic_energy(atoms);  // bonds unloaded at the start
  const size_t win = rows.size() / 20;
  double first = 0.0, lastw = 0.0, worst = 0.0, bond_max = 0.0, contacts = 0.0;
  for (size_t k = 0; k < win; ++k) {
    first += rows[k][1] / win;
    lastw += rows[rows.size() - win + k][1] / win;
  }
  for (const auto &row : rows) {
    worst = std::max(worst, std::fabs(row[1] / e0 - 1.0));
    bond_max = std::max(bond_max, row[2]);
    contacts = std::max(contacts, row[3]);
  }
  const double drift = (lastw - first) / e0;
  std::printf(
      "energy at 0.5 x f_ID[6] = %.4g s: E0 %.6e J, drift %.3e (tol 5e-3), max |E/E0-1| %.3e, "
      "peak bond energy %.3e J, max contacts %.0f, broken %.0f\n",
      0.5 * rows.front()[5], e0, drift, worst, bond_max, contacts, rows.back()[4]);
  EXPECT_GT(bond_max, 0.2 * e0) << "block does not vibrate";  // non-vacuous: bonds loaded
  EXPECT_EQ(contacts, 0.0);                                   // exact: no sphere contact
  EXPECT_EQ(rows.back()[4], 0.0);                             // exact count: no bond broken
  EXPECT_LT(std::fabs(drift), 5e-3);                          // bound: 0.5 % drift
}

// ===========================================================================
// 8. Critical time step f_ID[6] against the exact stability limit of a free
//    bonded pair: dt_exact = 2 / omega_max of the mass-normalised 12 x 12
//    stiffness (pair_exact_step), for equal radii and a 1:2 pair. Tolerance
//    20 %. Then the limit is shown to be real: each free pair with a small
//    random velocity blows up at 1.2 dt_exact (energy x > 100 in 10 steps)
//    and not at 0.8 dt_exact (energy within x 10 over 2000 steps).
// ===========================================================================
namespace {

// f_ID[6] printed after `run 0` for a pair of radii ra, rb at centre distance len.
double fix_critical_step(double ra, double rb, double len) {
  const std::string dir = make_run_dir("an_dtcrit");
  Sphere a, b;
  a.r = ra;
  b.r = rb;
  b.x = {len, 0.0, 0.0};
  const auto r = run_with_data(dir, {a, b},
                               "fix integr all nve/sphere\n" + bond_fix() +
                                   "timestep 1e-9\nrun 0\nvariable dtc equal f_bonds[6]\n"
                                   "print \"${dtc}\" file dtc.txt\n");
  EXPECT_EQ(r.exit_code, 0) << r.screen;
  const auto rows = read_table(dir + "/dtc.txt");
  return rows.empty() ? 0.0 : rows.front()[0];
}

// Largest total energy over the initial one, for a free pair of radii ra, rb
// at centre distance len with small random velocities and spins, run `steps`
// steps at time step dt (strengths raised so that nothing breaks).
double energy_growth(double ra, double rb, double len, double dt, int steps) {
  const std::string dir = make_run_dir("an_stab");
  Lcg rnd{77u};
  std::vector<Sphere> atoms(2);
  atoms[0].r = ra;
  atoms[1].r = rb;
  atoms[1].x = {len, 0.0, 0.0};
  for (auto &s : atoms)
    for (int c = 0; c < 3; ++c) {
      s.v[c] = 1e-4 * rnd();
      s.w[c] = 0.1 * rnd();
    }
  std::ostringstream d;
  d.precision(17);
  d << "fix integr all nve/sphere\n"
    << bond_fix("", 1e15, 1e15) << "compute rke all erotate/sphere\n"
    << "variable s equal step\nvariable etot equal ke+c_rke+f_bonds[5]\n"
    << "timestep " << dt << "\n"
    << "fix pr all print 1 \"${s} ${etot}\" file hist.txt screen no title none\n"
    << "thermo 1000\nrun " << steps << "\n";
  const auto r = run_with_data(dir, atoms, d.str());
  EXPECT_EQ(r.exit_code, 0) << r.screen;
  const auto rows = read_table(dir + "/hist.txt");
  EXPECT_EQ(rows.size(), static_cast<size_t>(steps));
  if (rows.empty()) return 0.0;
  double emax = 0.0;
  for (const auto &row : rows) emax = std::max(emax, row[1]);
  return emax / kinetic_energy(atoms);  // bonds unloaded at the start
}

}  // namespace

// Equal radii and a 1:2 pair, surface gap 0.1 mm (< gap x min radius).
const struct { double ra, rb; } kStepPairs[] = {{kR, kR}, {kR, 2.0 * kR}};

TEST(BondTimeStep, CriticalStepMatchesPairEigenvalue) {
  for (const auto &p : kStepPairs) {
    const double len = p.ra + p.rb + 0.1e-3;
    const double exact = pair_exact_step(p.ra, p.rb, len);
    const double fix = fix_critical_step(p.ra, p.rb, len);
    std::printf(
        "critical step, radii %.1f:%.1f mm: f_ID[6] %.6e s, exact 2/omega_max %.6e s, ratio "
        "%.4f (tol |ratio-1| < 0.2)\n",
        p.ra * 1e3, p.rb * 1e3, fix, exact, fix / exact);
    EXPECT_NEAR(fix / exact, 1.0, 0.2);  // tolerance 20 %
  }
}

TEST(BondTimeStep, ExactStepIsTheStabilityLimit) {
  for (const auto &p : kStepPairs) {
    const double len = p.ra + p.rb + 0.1e-3;
    const double exact = pair_exact_step(p.ra, p.rb, len);
    const double unstable = energy_growth(p.ra, p.rb, len, 1.2 * exact, 10);
    const double stable = energy_growth(p.ra, p.rb, len, 0.8 * exact, 2000);
    std::printf(
        "stability of the free %.1f:%.1f mm pair (dt_exact %.4e s): max E/E0 %.3e at 1.2 "
        "dt_exact (10 steps, must be > 100), %.3f at 0.8 dt_exact (2000 steps, must be < 10)\n",
        p.ra * 1e3, p.rb * 1e3, exact, unstable, stable);
    EXPECT_GT(unstable, 100.0);  // bound: blows up
    EXPECT_LT(stable, 10.0);     // bound: Verlet energy error stays bounded
  }
}

// ===========================================================================
// 8b. step_estimate network: the critical step of the whole bonded network
//    (network_step.h). A free 3 x 3 x 3 cluster (jittered cubic lattice,
//    54 bonds) reports f_ID[6] = 2 / sqrt(omega^2) of network_step's
//    estimate on the same bonds within 1e-4 (what the fix hands over; each
//    estimate is within its tolerance, 1e-4, above the true omega^2, and the
//    atoms' order sets the start vector), the same on 2 ranks (split
//    through the cluster) to round-off, and longer than the
//    per-atom sum's (step_estimate sum). The step is the real limit: with
//    small random velocities and spins the cluster blows up at 1.2 x it
//    (energy x > 100 within 12 steps) and not at 0.8 x it (x < 10 over
//    2000 steps).
// ===========================================================================
namespace {

std::vector<Sphere> jittered_cluster() {
  Lcg rnd{4242u};
  std::vector<Sphere> atoms;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        Sphere s;
        s.x = {(i - 1) * kL0 + 4e-5 * rnd(), (j - 1) * kL0 + 4e-5 * rnd(),
               (k - 1) * kL0 + 4e-5 * rnd()};
        for (int c = 0; c < 3; ++c) {
          s.v[c] = 1e-4 * rnd();
          s.w[c] = 0.1 * rnd();
        }
        atoms.push_back(s);
      }
  return atoms;
}

// network_step's estimate for the cluster's bonds (surface gap < kGap kR:
// the lattice neighbours), springs as the fix makes them.
double cluster_network_omega2(const std::vector<Sphere> &atoms) {
  std::vector<mill::network_step::Bond> bonds;
  mill::network_step::Atoms net;
  for (const auto &s : atoms) {
    net.mass.push_back(sphere_mass(s.r));
    net.inertia.push_back(sphere_inertia(s.r));
  }
  for (size_t a = 0; a < atoms.size(); ++a)
    for (size_t b = a + 1; b < atoms.size(); ++b) {
      double d[3], len = 0.0;
      for (int c = 0; c < 3; ++c) {
        d[c] = atoms[b].x[c] - atoms[a].x[c];
        len += d[c] * d[c];
      }
      len = std::sqrt(len);
      if (len - atoms[a].r - atoms[b].r >= kGap * std::min(atoms[a].r, atoms[b].r)) continue;
      mill::network_step::Bond bd;
      bd.a = static_cast<int>(a);
      bd.b = static_cast<int>(b);
      bd.n = {d[0] / len, d[1] / len, d[2] / len};
      bd.arm_a = len * atoms[a].r / (atoms[a].r + atoms[b].r);
      bd.arm_b = len - bd.arm_a;
      const double kn = kEb / len, ks = kn / kRatio;
      bd.kna = kn * kArea;
      bd.ksa = ks * kArea;
      bd.kni = kn * kInertia;
      bd.ksj = ks * kPolar;
      bonds.push_back(bd);
    }
  EXPECT_EQ(bonds.size(), 54u) << "the lattice's neighbours";
  return mill::network_step::largest_omega2(bonds, net).omega2;
}

// f_ID[6] after `run 0`, and with steps > 0 the largest total energy over
// the initial one in `steps` steps at time step dt.
std::pair<double, double> run_cluster(const std::string &estimate, int nprocs, double dt,
                                      int steps) {
  const std::string dir = make_run_dir("an_net_" + estimate + std::to_string(nprocs));
  const auto atoms = jittered_cluster();
  std::ostringstream d;
  d.precision(17);
  d << "fix integr all nve/sphere\n"
    << bond_fix("step_estimate " + estimate, 1e15, 1e15) << "compute rke all erotate/sphere\n"
    << "variable s equal step\nvariable etot equal ke+c_rke+f_bonds[5]\n"
    << "timestep " << (dt > 0.0 ? dt : 1e-9) << "\nrun 0\n"
    << "variable dtc equal f_bonds[6]\nprint \"${dtc}\" file dtc.txt\n";
  if (steps > 0)
    d << "fix pr all print 1 \"${s} ${etot}\" file hist.txt screen no title none\n"
      << "thermo 1000\nrun " << steps << "\n";
  const auto r = run_with_data(dir, atoms, d.str(), 0.01, nprocs, nprocs > 1);
  EXPECT_EQ(r.exit_code, 0) << r.screen;
  const auto dtc = read_table(dir + "/dtc.txt");
  const double step = dtc.empty() ? 0.0 : dtc.front()[0];
  if (steps <= 0) return {step, 0.0};
  const auto rows = read_table(dir + "/hist.txt");
  EXPECT_EQ(rows.size(), static_cast<size_t>(steps));
  double emax = 0.0;
  for (const auto &row : rows) emax = std::max(emax, row[1]);
  return {step, emax / kinetic_energy(atoms)};  // bonds unloaded at the start
}

}  // namespace

TEST(BondTimeStep, NetworkStepIsTheClustersLimit) {
  const double want = 2.0 / std::sqrt(cluster_network_omega2(jittered_cluster()));
  const double net1 = run_cluster("network", 1, 0.0, 0).first;
  const double net2 = run_cluster("network", 2, 0.0, 0).first;
  const double sum = run_cluster("sum", 1, 0.0, 0).first;
  std::printf(
      "cluster of 27, 54 bonds: f_ID[6] network %.9e s (2 ranks %.9e s), network_step %.9e s, "
      "per-atom sum %.6e s (network x %.3f)\n",
      net1, net2, want, sum, net1 / sum);
  EXPECT_NEAR(net1 / want, 1.0, 1e-4);
  EXPECT_NEAR(net2 / net1, 1.0, 1e-12);
  EXPECT_GT(net1, 1.05 * sum);  // the sum bounds omega^2 from above: a shorter step
  const double unstable = run_cluster("network", 1, 1.2 * net1, 12).second;
  const double stable = run_cluster("network", 1, 0.8 * net1, 2000).second;
  std::printf(
      "max E/E0: %.3e at 1.2 x the network step (12 steps, must be > 100), %.3f at 0.8 x (2000 "
      "steps, must be < 10)\n",
      unstable, stable);
  EXPECT_GT(unstable, 100.0);
  EXPECT_LT(stable, 10.0);
}

// ===========================================================================
// 9. 1 vs 2 MPI ranks: a bonded 10 x 2 x 2 bar along x, centred on x = 0 where
//    the 2-rank run splits the box, pulled apart at both ends (end faces moved
//    outwards by `fix move linear`). The tensile waves meet in the middle, so
//    the bonds across the rank boundary break. Both runs must log the same
//    break events (step, mode, tags exactly; sigma, tau within 1e-6) and end
//    with the same intact-bond count.
// ===========================================================================
namespace {

struct BreakEvent {
  long step;
  std::string mode;
  int tag_i, tag_j;
  double x, sigma, tau;
  bool operator<(const BreakEvent &o) const {
    return std::tie(step, tag_i, tag_j) < std::tie(o.step, o.tag_i, o.tag_j);
  }
};

std::vector<BreakEvent> read_break_log(const std::string &path) {
  std::vector<BreakEvent> ev;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    BreakEvent e;
    double t, y, z;
    if (ls >> e.step >> t >> e.x >> y >> z >> e.mode >> e.tag_i >> e.tag_j >> e.sigma >> e.tau)
      ev.push_back(e);
  }
  std::sort(ev.begin(), ev.end());
  return ev;
}

constexpr int kBarN = 10;  // atoms along x

// Initial x of atom `tag` of the bar (tags run x fastest).
double bar_x(int tag) { return ((tag - 1) % kBarN - 0.5 * (kBarN - 1)) * kL0; }

std::pair<std::vector<BreakEvent>, double> run_bar(int nprocs, std::string *screen) {
  const std::string dir = make_run_dir("an_bar" + std::to_string(nprocs));
  std::vector<Sphere> atoms;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < kBarN; ++i) {
        Sphere s;
        s.x = {bar_x(i + 1), (j - 0.5) * kL0, (k - 0.5) * kL0};
        atoms.push_back(s);
      }
  const double v = 3.0;
  std::ostringstream d;
  d.precision(17);
  d << "variable xl equal " << bar_x(1) + 0.5 * kL0 << "\nvariable xr equal "
    << bar_x(kBarN) - 0.5 * kL0 << "\n"
    << "region left block INF ${xl} INF INF INF INF units box\n"
    << "region right block ${xr} INF INF INF INF INF units box\n"
    << "group left region left\ngroup right region right\n"
    << "group ends union left right\ngroup inner subtract all ends\n"
    << "fix integr inner nve/sphere\n"
    << "fix ml left move linear " << -v << " 0 0\nfix mr right move linear " << v << " 0 0\n"
    << bond_fix("break_log breaks.txt") << "timestep 1e-8\n"
    << "thermo 500\nrun 2000\n"
    << "variable nb equal f_bonds[1]\nprint \"${nb}\" file end.txt\n";
  const auto r = run_with_data(dir, atoms, d.str(), 0.02, nprocs, true);
  EXPECT_EQ(r.exit_code, 0) << r.screen;
  *screen = r.screen;
  const auto end = read_table(dir + "/end.txt");
  return {read_break_log(dir + "/breaks.txt"), end.empty() ? -1.0 : end.front()[0]};
}

}  // namespace

TEST(BondMpi, BreaksAcrossRankBoundaryMatchOneRank) {
  std::string screen1, screen2;
  const auto one = run_bar(1, &screen1);
  const auto two = run_bar(2, &screen2);
  EXPECT_NE(screen2.find("2 by 1 by 1 MPI processor grid"), std::string::npos);
  ASSERT_FALSE(one.first.empty()) << "no bond broke: test would be vacuous";
  int across = 0;
  for (const auto &e : one.first)
    if (bar_x(e.tag_i) * bar_x(e.tag_j) < 0.0) ++across;
  std::printf(
      "bar pulled apart: %zu break events (1 rank) vs %zu (2 ranks), %d across x = 0; "
      "intact at end %g vs %g\n",
      one.first.size(), two.first.size(), across, one.second, two.second);
  for (const auto &e : one.first)
    std::printf("  step %ld %s %d-%d at x %.4g, sigma %.6g tau %.6g\n", e.step, e.mode.c_str(),
                e.tag_i, e.tag_j, e.x, e.sigma, e.tau);
  EXPECT_GT(across, 0) << "no bond across the rank boundary broke";
  EXPECT_EQ(one.second, two.second);              // exact intact count
  ASSERT_EQ(one.first.size(), two.first.size());  // exact event count
  for (size_t k = 0; k < one.first.size(); ++k) {
    const auto &a = one.first[k], &b = two.first[k];
    EXPECT_EQ(a.step, b.step);                                       // exact
    EXPECT_EQ(a.mode, b.mode);                                       // exact
    EXPECT_EQ(a.tag_i, b.tag_i);                                     // exact
    EXPECT_EQ(a.tag_j, b.tag_j);                                     // exact
    EXPECT_NEAR(a.sigma, b.sigma, 1e-6 * std::fabs(a.sigma) + 1.0);  // 1e-6 relative (+1 Pa)
    EXPECT_NEAR(a.tau, b.tau, 1e-6 * std::fabs(a.tau) + 1.0);        // 1e-6 relative (+1 Pa)
  }
}
