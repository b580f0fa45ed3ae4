// Analytic tests of the CONTACT features of fix bond/breakable
// (docs/styles/fix_bond_breakable.md, section "Contacts"), driven through real
// liggghts-mill runs: `broken_contact`, `contact_moment`, `unbonded_fraction`
// and their keyword errors. Every test compares a number measured in the run
// with a closed-form value or bound computed here (the MPI test: with the
// 1-rank run) and states its tolerance next to the assertion.
//
// Contact model under test (kn, ks, A, I, J, R of the bond, see the doc page):
//   F_n  = kn A (L - L0)              for L < L0, else 0 (compression only)
//   dF_s = -ks A dU_s,  |F_s| <= tan(phi) |F_n|       (Coulomb slip)
//   contact_moment yes: dM_b = -kn I dtheta_s, |M_b| <= |F_n| R / 4
//                       dM_t = -ks J dtheta_n, |M_t| <= tan(phi) |F_n| 2R/3
//   dropped once L > L0 + g min(Ri, Rj)
//
// As in test_bond_analytic.cpp, initial positions and spins come from a data
// file (read_data; LIGGGHTS 3.8's `set` has no omega keyword), and an atom that
// no fix integrates keeps its position and spin: its bond or contact is then
// loaded by a relative rotation growing linearly in time. Positions are set
// between runs with `set atom 2 x VALUE`; each `run 1` evaluates the pair at
// that position once with the history advanced (the contact is dropped or
// re-engaged only in such an advancing step, never in a run's setup).
// The force on an atom (`fx[2]`) is the fix's alone: the elements (radius
// 1 mm, centre distance <= 2.1 mm) never overlap, so `pair gran` adds nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "bond_test_util.h"

using namespace mill_test;

namespace {

const double kTanPhi = std::tan(kPhiDeg * kPi / 180.0);

// Whole text of a file ("" if missing).
std::string slurp(const std::string &path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Columns printed every step by the pair tests: step, x, y, z of atom 2 minus
// atom 1, force on atom 2, intact bonds f_ID[1], broken in tension f_ID[3],
// broken in shear f_ID[4], sum of the per-atom intact counts, torque on atom 2.
const char *kPairPrint =
    "group a2 id 2\n"
    "compute nba all reduce sum f_bonds\n"
    "compute tq all property/atom tqx tqy tqz\n"
    "variable s equal step\nvariable dx equal x[2]-x[1]\nvariable dy equal y[2]-y[1]\n"
    "variable dz equal z[2]-z[1]\n"
    "variable fx equal fx[2]\nvariable fy equal fy[2]\nvariable fz equal fz[2]\n"
    "variable nb equal f_bonds[1]\nvariable nt equal f_bonds[3]\nvariable ns equal f_bonds[4]\n"
    "variable na equal c_nba\n"
    "variable tx equal c_tq[2][1]\nvariable ty equal c_tq[2][2]\nvariable tz equal c_tq[2][3]\n"
    "fix pr all print 1 \"${s} ${dx} ${dy} ${dz} ${fx} ${fy} ${fz} ${nb} ${nt} ${ns} ${na} "
    "${tx} ${ty} ${tz}\" file hist.txt screen no title none\n";
enum Col { STEP = 0, DX, DY, DZ, FX, FY, FZ, NB, NT, NS, NA, TX, TY, TZ, NCOLS };

// One printed row resolved along the line of centres n (from atom 1 to 2):
// L, the signed normal force F_n (tension > 0; the force on atom 2 is
// -F_n n + F_s) and the magnitude of the shear force |F_s|.
struct PairState {
  double len, fn, fs, fmag;
};

PairState resolve(const std::vector<double> &row) {
  PairState p{};
  p.len = std::sqrt(row[DX] * row[DX] + row[DY] * row[DY] + row[DZ] * row[DZ]);
  const double n[3] = {row[DX] / p.len, row[DY] / p.len, row[DZ] / p.len};
  const double f[3] = {row[FX], row[FY], row[FZ]};
  const double fdotn = f[0] * n[0] + f[1] * n[1] + f[2] * n[2];
  p.fn = -fdotn;
  double fs2 = 0.0;
  for (int c = 0; c < 3; ++c) fs2 += (f[c] - fdotn * n[c]) * (f[c] - fdotn * n[c]);
  p.fs = std::sqrt(fs2);
  p.fmag = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  return p;
}

// Index of the first row without an intact bond after one with it (0: none).
size_t break_row(const std::vector<std::vector<double>> &rows) {
  for (size_t k = 1; k < rows.size(); ++k)
    if (rows[k][NB] == 0.0 && rows[k - 1][NB] == 1.0) return k;
  return 0;
}

}  // namespace

// ===========================================================================
// 1. broken_contact yes: a compressed bond broken in shear keeps pushing back.
//    Bonds are made in `run 0`, atom 2 is displaced by -delta along the bond
//    (kn delta = sigma_c), then moved sideways (y) at constant velocity by
//    `fix move linear` (atom 1 is not integrated, nothing spins). The bond
//    breaks in shear at the Mohr-Coulomb strength; the pair is then a contact:
//      F_n = kn A (L - L0) < 0 (1 %), and once the new shear force has built up
//      (ks A per unit sliding, from zero) it slides at |F_s| = tan(phi) |F_n|
//      (1 %), never above it (1 %).
//    It is not a bond any more: f_ID[1] = 0, per-atom counts sum to 0, the
//    end-of-run dump_bonds lists no bond (the one after `run 0` lists 1).
//    With broken_contact no (same deck) the force after the break is exactly
//    0: the spheres do not overlap (surface gap > 0) and nothing else acts.
// ===========================================================================
namespace {

constexpr double kShearV = 0.5;       // sideways speed of atom 2 [m/s]
constexpr double kDt = 1e-8;          // time step [s]
const double kDelta = kSigmaT / kKn;  // compression: kn delta = sigma_c [m]

// Runs the compressed-shear deck; returns the printed rows of the shear run.
std::vector<std::vector<double>> run_compressed_shear(const std::string &dir,
                                                      const std::string &contact_kw, int steps) {
  std::ostringstream d;
  d.precision(17);
  d << bond_fix("broken_contact " + contact_kw + " dump_bonds bonds_*.txt") << "timestep " << kDt
    << "\n"
    << kPairPrint << "thermo 1000\nrun 0\n"
    << "displace_atoms a2 move " << -kDelta << " 0 0 units box\n"
    << "fix mv a2 move linear 0 " << kShearV << " 0\n"
    << "run " << steps << "\n";
  const auto r = run_with_data(dir, spinning_pair({0, 0, 0}, {0, 0, 0}), d.str());
  EXPECT_EQ(r.exit_code, 0) << r.screen;
  return last_run_rows(dir + "/hist.txt");
}

// Steps of the shear run: through the break at (c + tan(phi) kn delta) A and
// three times the sliding distance tan(phi) kn delta / ks after it.
int shear_steps() {
  const double u_break = (kCohesion + kTanPhi * kKn * kDelta) / kKs;
  const double u_slide = kTanPhi * kKn * kDelta / kKs;
  return static_cast<int>((u_break + 3.0 * u_slide) / (kShearV * kDt)) + 100;
}

}  // namespace

TEST(BondContact, BrokenContactPushesBackAndSlidesAtCoulombLimit) {
  const std::string dir = make_run_dir("ct_yes");
  const int steps = shear_steps();
  const auto rows = run_compressed_shear(dir, "yes", steps);
  ASSERT_EQ(rows.size(), static_cast<size_t>(steps));
  const size_t kb = break_row(rows);
  ASSERT_GT(kb, 0u) << "bond did not break";
  EXPECT_EQ(rows[kb - 1][NA], 2.0);  // exact: both atoms counted the bond before
  EXPECT_EQ(rows.back()[NS], 1.0);   // exact count: broken in shear
  EXPECT_EQ(rows.back()[NT], 0.0);   // exact count
  EXPECT_EQ(rows.back()[NB], 0.0);   // exact: f_ID[1], no intact bond
  EXPECT_EQ(rows.back()[NA], 0.0);   // exact: per-atom intact counts sum to 0
  EXPECT_EQ(read_bonds(dir + "/bonds_0.txt").size(), 1u);  // exact: the bond existed
  const std::string dump_end = slurp(dir + "/bonds_" + std::to_string(steps) + ".txt");
  EXPECT_NE(dump_end.find("# bonds 0\n"), std::string::npos) << dump_end;
  EXPECT_EQ(read_bonds(dir + "/bonds_" + std::to_string(steps) + ".txt").size(), 0u);  // exact

  // Sliding: rows past 1.5 x the sliding distance tan(phi)|F_n| / (ks A) after the break.
  const double slide_steps = kTanPhi * kKn * kDelta / kKs / (kShearV * kDt);
  double worst_fn = 0.0, worst_slip = 0.0, max_ratio = 0.0;
  int sliding = 0;
  for (size_t k = kb; k < rows.size(); ++k) {
    if (k == kb) continue;  // the breaking step exerts no force
    const PairState p = resolve(rows[k]);
    const double fn_an = kKn * kArea * (p.len - kL0);
    const double ratio = p.fs / (kTanPhi * std::fabs(p.fn));
    max_ratio = std::max(max_ratio, ratio);
    worst_fn = std::max(worst_fn, std::fabs(p.fn / fn_an - 1.0));
    if (static_cast<double>(k - kb) > 1.5 * slide_steps) {
      worst_slip = std::max(worst_slip, std::fabs(ratio - 1.0));
      ++sliding;
    }
  }
  const PairState before = resolve(rows[kb - 1]);
  const double fs_at_break_m1 = before.fs;
  const double fs_mohr = (kCohesion - kTanPhi * before.fn / kArea) * kArea;
  const PairState last = resolve(rows.back());
  const double fn_last = kKn * kArea * (last.len - kL0);
  std::printf(
      "broken_contact yes: break at step %.0f (|F_s| %.6g N the step before; Mohr-Coulomb at "
      "that F_n %.6g N); "
      "after: F_n %.6g N vs kn A (L-L0) %.6g N (worst rel. error %.3e over %zu rows, tol 1e-2); "
      "sliding |F_s| %.6g N vs tan(phi)|F_n| %.6g N (worst rel. error %.3e over %d rows, tol "
      "1e-2); max |F_s|/(tan(phi)|F_n|) %.6f (tol <= 1.01); intact %g, per-atom sum %g\n",
      rows[kb][STEP], fs_at_break_m1, fs_mohr, last.fn, fn_last, worst_fn, rows.size() - kb - 1,
      last.fs, kTanPhi * std::fabs(last.fn), worst_slip, sliding, max_ratio, rows.back()[NB],
      rows.back()[NA]);
  EXPECT_LT(last.fn, 0.0);      // still compressed
  EXPECT_LT(worst_fn, 0.01);    // tolerance 1 %: F_n = kn A (L - L0)
  EXPECT_GT(sliding, 100);      // non-vacuous: the contact slid
  EXPECT_LT(worst_slip, 0.01);  // tolerance 1 %: |F_s| = tan(phi)|F_n|
  EXPECT_LE(max_ratio, 1.01);   // bound (1 %): Coulomb cap never exceeded
  EXPECT_GT(fs_at_break_m1, 2.0 * kTanPhi * std::fabs(last.fn));  // the bond held more than that
}

TEST(BondContact, WithoutBrokenContactNoForceAfterBreak) {
  const std::string dir = make_run_dir("ct_no");
  const int steps = shear_steps();
  const auto rows = run_compressed_shear(dir, "no", steps);
  ASSERT_EQ(rows.size(), static_cast<size_t>(steps));
  const size_t kb = break_row(rows);
  ASSERT_GT(kb, 0u) << "bond did not break";
  double fmax = 0.0, gap_min = 1.0;
  for (size_t k = kb; k < rows.size(); ++k) {
    const PairState p = resolve(rows[k]);
    fmax = std::max(fmax, p.fmag);
    gap_min = std::min(gap_min, p.len - 2.0 * kR);
  }
  const double f_before = resolve(rows[kb - 1]).fmag;
  std::printf(
      "broken_contact no: break at step %.0f, |F| %.6g N before, max |F| after %.3e N (must be "
      "0), min surface gap %.4e m (> 0)\n",
      rows[kb][STEP], f_before, fmax, gap_min);
  EXPECT_GT(f_before, 0.0);         // non-vacuous: the bond was loaded
  EXPECT_EQ(fmax, 0.0);             // exact: nothing acts after the break
  EXPECT_GT(gap_min, 0.0);          // the spheres do not overlap
  EXPECT_EQ(rows.back()[NS], 1.0);  // exact count: broken in shear
  EXPECT_EQ(rows.back()[NB], 0.0);  // exact count
}

// ===========================================================================
// 2. A contact carries no tension and is dropped past L0 + g min(Ri, Rj).
//    Bonds made in `run 0`; atom 2 set to L0 + 1.5 sigma_c / kn: the bond
//    breaks in tension in the next step and becomes a contact. Then, without
//    time integration of either atom:
//    (a) set to L0 - delta: F_n = kn A (L - L0) (1 %);
//    (b) pulled out at constant speed (fix move linear) from L0 - delta to
//        L0 + delta/2: F_n = kn A (L - L0) (1 %) while L < L0 - 1e-8 m, and the
//        force is exactly 0 at every step with L > L0 (no tension);
//    (c) set to L0 + 0.19 mm (inside L0 + g R = L0 + 0.2 mm): 0 force; then
//        set back to L0 - delta: re-engaged, F_n = kn A (L - L0) (1 %);
//    (d) set to L0 + 0.21 mm (past L0 + g R): 0 force; then set back to
//        L0 - delta: the contact was dropped, the force is exactly 0 (the
//        surface gap is still > 0, so pair gran adds nothing).
// ===========================================================================
TEST(BondContact, NoTensionAndDroppedPastBondingGap) {
  const std::string dir = make_run_dir("ct_open");
  const double delta = kDelta;
  const double v = 0.2;
  const int pull_steps = static_cast<int>(1.5 * delta / (v * kDt));
  const double drop = kGap * kR;  // g min(Ri, Rj) [m]
  std::ostringstream d;
  d.precision(17);
  auto set_x = [&d](double x) { d << "set atom 2 x " << x << "\nrun 1\n"; };
  d << bond_fix("broken_contact yes") << "timestep " << kDt << "\n"
    << kPairPrint << "thermo 1000\nrun 0\n";
  set_x(kL0 + 1.5 * kSigmaT / kKn);  // step 1: breaks in tension
  set_x(kL0 - delta);                // step 2: (a)
  d << "fix mv a2 move linear " << v << " 0 0\nrun " << pull_steps << "\n"  // (b)
    << "unfix mv\nvelocity a2 set 0 0 0 units box\n";
  set_x(kL0 + 0.95 * drop);  // (c)
  set_x(kL0 - delta);
  set_x(kL0 + 1.05 * drop);  // (d)
  set_x(kL0 - delta);
  const auto r = run_with_data(dir, spinning_pair({0, 0, 0}, {0, 0, 0}), d.str());
  ASSERT_EQ(r.exit_code, 0) << r.screen;
  const auto rows = last_run_rows(dir + "/hist.txt");
  ASSERT_EQ(rows.size(), static_cast<size_t>(2 + pull_steps + 4));
  EXPECT_EQ(rows[0][NT], 1.0);  // exact count: broken in tension at step 1
  EXPECT_EQ(rows[0][NB], 0.0);  // exact count
  const double kna = kKn * kArea;

  // (a) closed again after the tension break.
  const PairState a = resolve(rows[1]);
  // (b) pull: every row on either side of L0.
  double worst_closed = 0.0, fmax_open = 0.0;
  int closed = 0, open = 0;
  for (int k = 2; k < 2 + pull_steps; ++k) {
    const PairState p = resolve(rows[k]);
    if (p.len < kL0 - 1e-8) {
      worst_closed = std::max(worst_closed, std::fabs(p.fn / (kna * (p.len - kL0)) - 1.0));
      ++closed;
    } else if (p.len > kL0) {
      fmax_open = std::max(fmax_open, p.fmag);
      ++open;
    }
  }
  const size_t c0 = 2 + pull_steps;
  const PairState c_open = resolve(rows[c0]), c_back = resolve(rows[c0 + 1]);
  const PairState d_open = resolve(rows[c0 + 2]), d_back = resolve(rows[c0 + 3]);
  std::printf(
      "contact without tension: (a) F_n %.6g N vs kn A (L-L0) %.6g N; (b) pull: worst rel. error "
      "%.3e over %d closed rows (tol 1e-2), max |F| %.3e N over %d open rows (must be 0); (c) at "
      "L-L0 = %.4g m |F| %.3e N, back at L-L0 = %.4g m F_n %.6g N vs %.6g N (tol 1e-2); (d) at "
      "L-L0 = %.4g m |F| %.3e N, back at L-L0 = %.4g m |F| %.3e N (must be 0, dropped; surface "
      "gap %.4e m)\n",
      a.fn, kna * (a.len - kL0), worst_closed, closed, fmax_open, open, c_open.len - kL0,
      c_open.fmag, c_back.len - kL0, c_back.fn, kna * (c_back.len - kL0), d_open.len - kL0,
      d_open.fmag, d_back.len - kL0, d_back.fmag, d_back.len - 2.0 * kR);
  EXPECT_NEAR(a.fn / (kna * (a.len - kL0)), 1.0, 0.01);  // tolerance 1 %
  EXPECT_GT(closed, 100);                                // non-vacuous
  EXPECT_GT(open, 100);                                  // non-vacuous
  EXPECT_LT(worst_closed, 0.01);                         // tolerance 1 %
  EXPECT_EQ(fmax_open, 0.0);                             // exact: no tension
  EXPECT_GT(c_open.len - kL0, 0.9 * drop);               // (c) really near the drop length
  EXPECT_EQ(c_open.fmag, 0.0);                           // exact: open contact
  EXPECT_NEAR(c_back.fn / (kna * (c_back.len - kL0)), 1.0, 0.01);  // tolerance 1 %: re-engaged
  EXPECT_GT(d_open.len - kL0, drop);                               // (d) past the drop length
  EXPECT_EQ(d_open.fmag, 0.0);                                     // exact
  EXPECT_LT(d_back.len, kL0);                                      // closed again ...
  EXPECT_EQ(d_back.fmag, 0.0);                                     // ... exact: but dropped
  EXPECT_GT(d_back.len - 2.0 * kR, 0.0);                           // no sphere overlap
  EXPECT_EQ(rows.back()[NB], 0.0);                                 // exact count
}

// ===========================================================================
// 3. contact_moment yes: a compressed contact bent (twisted) by opposite spins
//    -w, +w of the two spheres about z (x, the line of centres), no time
//    integration, so there is no shear at the contact point and no stretch:
//      bending:   |M_b|(t) = min(kn I (2w) t, |F_n| R / 4)
//      twisting:  |M_t|(t) = min(ks J (2w) t, tan(phi) |F_n| 2R/3)
//    with t counted from the start of the compressed run (the contact's
//    history is reset when the bond breaks). The contact is made as in test
//    2 (tension break in one step), then set to L0 - delta, kn delta = sigma_c.
//    The moment is read as the torque on atom 2: `compute property/atom tqx
//    tqy tqz` (LIGGGHTS 3.8's equal-style variables have fx[i] but no torque
//    keyword; c_tq[2][k] picks atom 2's row). With the line of centres along x
//    and no shear force, the torque of the contact force on atom 2 is
//    r x F = 0, so the torque is the contact moment itself (on b: +M):
//    tq_z[2] = M_b,z = -kn I (2w) t (bending) and tq_x[2] = M_t (twisting),
//    up to the caps. Every printed step is compared (1 %).
// ===========================================================================
namespace {

struct MomentCase {
  const char *name;
  int axis;           // 0: twist (spins about x), 2: bend (spins about z)
  double w;           // spin magnitude [rad/s]
  double stiff;       // kn I or ks J [N m]
  double cap_per_fn;  // cap / |F_n| [m]
};

// Prints a case by its name in test listings.
void PrintTo(const MomentCase &mc, std::ostream *os) { *os << mc.name; }

}  // namespace

class BondContactMoment : public ::testing::TestWithParam<MomentCase> {};

TEST_P(BondContactMoment, GrowsLinearlyThenSaturatesAtCap) {
  const MomentCase &mc = GetParam();
  const std::string dir = make_run_dir(std::string("ct_mom_") + mc.name);
  const double delta = kDelta;
  const double fn = kKn * kArea * delta;      // |F_n| [N]
  const double cap = mc.cap_per_fn * fn;      // [N m]
  const double rate = mc.stiff * 2.0 * mc.w;  // |dM/dt| [N m / s]
  const int steps = static_cast<int>(2.0 * cap / (rate * kDt)) + 50;
  std::array<double, 3> wa{0, 0, 0}, wb{0, 0, 0};
  wa[mc.axis] = -mc.w;
  wb[mc.axis] = mc.w;
  std::ostringstream d;
  d.precision(17);
  d << bond_fix("broken_contact yes contact_moment yes") << "timestep " << kDt << "\n"
    << kPairPrint << "thermo 1000\nrun 0\n"
    << "set atom 2 x " << kL0 + 1.5 * kSigmaT / kKn << "\nrun 1\n"
    << "set atom 2 x " << kL0 - delta << "\nrun " << steps << "\n";
  const auto r = run_with_data(dir, spinning_pair(wa, wb), d.str());
  ASSERT_EQ(r.exit_code, 0) << r.screen;
  const auto rows = last_run_rows(dir + "/hist.txt");
  ASSERT_EQ(rows.size(), static_cast<size_t>(1 + steps));
  EXPECT_EQ(rows[0][NT], 1.0);  // exact count: the bond broke in tension at step 1
  const int col = mc.axis == 0 ? TX : TZ;
  // Sign: the moment on b opposes b's relative spin (+w): M = -stiff (2w) t.
  double worst_lin = 0.0, worst_cap = 0.0, worst_fn = 0.0;
  int nlin = 0, ncap = 0;
  for (int k = 1; k <= steps; ++k) {
    const auto &row = rows[k];
    const double t = (row[STEP] - rows[0][STEP]) * kDt;
    const double m = -row[col];
    const PairState p = resolve(row);
    worst_fn = std::max(worst_fn, std::fabs(-p.fn / fn - 1.0));
    const double lin = rate * t;
    if (lin < 0.99 * cap) {
      worst_lin = std::max(worst_lin, std::fabs(m / lin - 1.0));
      ++nlin;
    } else if (lin > 1.01 * cap) {
      worst_cap = std::max(worst_cap, std::fabs(m / (mc.cap_per_fn * std::fabs(p.fn)) - 1.0));
      ++ncap;
    }
  }
  const double m_last = -rows.back()[col];
  std::printf(
      "contact moment (%s): |F_n| %.6g N (worst rel. error to kn A delta %.3e); linear phase %d "
      "steps, worst |M/(stiff 2w t) - 1| %.3e (tol 1e-2); saturated %d steps, M %.6e N m vs cap "
      "%.6e N m, worst rel. error %.3e (tol 1e-2)\n",
      mc.name, fn, worst_fn, nlin, worst_lin, ncap, m_last, cap, worst_cap);
  EXPECT_LT(worst_fn, 0.01);   // tolerance 1 %: the contact is compressed by kn A delta
  EXPECT_GT(nlin, 100);        // non-vacuous
  EXPECT_GT(ncap, 100);        // non-vacuous
  EXPECT_LT(worst_lin, 0.01);  // tolerance 1 %: M = stiff (2w) t
  EXPECT_LT(worst_cap, 0.01);  // tolerance 1 %: M = cap
  // The other torque components stay 0 (pure bending about z / pure twist).
  for (int c : {TX, TY, TZ})
    if (c != col) {
      EXPECT_EQ(rows.back()[c], 0.0);  // exact
    }
}

INSTANTIATE_TEST_SUITE_P(
    Caps, BondContactMoment,
    ::testing::Values(MomentCase{"Bending", 2, 100.0, kKn *kInertia, 0.25 * kR},
                      MomentCase{"Twisting", 0, 200.0, kKs *kPolar, kTanPhi * 2.0 * kR / 3.0}),
    [](const ::testing::TestParamInfo<MomentCase> &info) { return std::string(info.param.name); });

// ===========================================================================
// 4. unbonded_fraction f = 0.3 on an 8 x 8 x 8 simple cubic lattice (spacing
//    L0, only the 3 n^2 (n-1) = 1344 nearest-neighbour pairs are in bonding
//    range): the bonds created number (1-f) 1344 within 3 binomial standard
//    deviations sqrt(1344 f (1-f)); bonds + the unbonded pairs of the fix's
//    screen line = 1344 exactly; f_ID[1] and dump_bonds agree with the
//    screen line; and the choice (a hash of the tags and the seed) is the
//    same on 1 and 2 MPI ranks: identical dump_bonds lists (the 2-rank run
//    splits the lattice at x = 0, 2 by 1 by 1 grid).
// ===========================================================================
namespace {

constexpr int kLat = 8;
constexpr double kFrac = 0.3;

struct UnbondedRun {
  std::vector<std::pair<int, int>> bonds;
  double created = -1.0, unbonded = -1.0, intact = -1.0;
  std::string screen;
};

UnbondedRun run_unbonded(int nprocs) {
  const std::string dir = make_run_dir("ct_unb" + std::to_string(nprocs));
  std::vector<Sphere> atoms;
  for (int k = 0; k < kLat; ++k)
    for (int j = 0; j < kLat; ++j)
      for (int i = 0; i < kLat; ++i) {
        Sphere s;
        const double c = 0.5 * (kLat - 1);
        s.x = {(i - c) * kL0, (j - c) * kL0, (k - c) * kL0};
        atoms.push_back(s);
      }
  std::ostringstream d;
  d.precision(17);
  d << bond_fix("unbonded_fraction " + std::to_string(kFrac) +
                " unbonded_seed 7 dump_bonds "
                "bonds.txt")
    << "timestep 1e-8\nrun 0\nvariable nb equal f_bonds[1]\nprint \"${nb}\" file nb.txt\n";
  UnbondedRun u;
  const auto r = run_with_data(dir, atoms, d.str(), 0.01, nprocs, true);
  EXPECT_EQ(r.exit_code, 0) << r.screen;
  u.screen = r.screen;
  u.bonds = read_bonds(dir + "/bonds.txt");
  const auto nb = read_table(dir + "/nb.txt");
  if (!nb.empty()) u.intact = nb.front()[0];
  std::smatch m;
  if (std::regex_search(r.screen, m, std::regex("fix bond/breakable: created ([0-9]+) bonds")))
    u.created = std::stod(m[1]);
  if (std::regex_search(r.screen, m,
                        std::regex("fix bond/breakable: ([0-9]+) more pairs in bonding range "
                                   "left unbonded \\(unbonded_fraction 0.3\\)")))
    u.unbonded = std::stod(m[1]);
  return u;
}

}  // namespace

TEST(BondUnbonded, FractionIsBinomialAndSameOnTwoRanks) {
  const double pairs = 3.0 * kLat * kLat * (kLat - 1);  // 1344
  const double mean = (1.0 - kFrac) * pairs, sd = std::sqrt(pairs * kFrac * (1.0 - kFrac));
  const auto one = run_unbonded(1);
  const auto two = run_unbonded(2);
  std::printf(
      "unbonded_fraction %.1f: %g candidate pairs; created %g bonds (expected %.1f +- 3 x %.2f), "
      "unbonded %g (screen line), f_ID[1] %g, dump %zu; 2 ranks: created %g, unbonded %g, dump "
      "%zu, same list %s\n",
      kFrac, pairs, one.created, mean, sd, one.unbonded, one.intact, one.bonds.size(), two.created,
      two.unbonded, two.bonds.size(), one.bonds == two.bonds ? "yes" : "no");
  ASSERT_GE(one.created, 0.0) << one.screen;
  ASSERT_GE(one.unbonded, 0.0) << "no 'left unbonded' screen line\n" << one.screen;
  EXPECT_EQ(one.created + one.unbonded, pairs);        // exact: every candidate accounted for
  EXPECT_LT(std::fabs(one.created - mean), 3.0 * sd);  // bound: 3 binomial standard deviations
  EXPECT_EQ(one.intact, one.created);                  // exact: f_ID[1]
  EXPECT_EQ(static_cast<double>(one.bonds.size()), one.created);  // exact: dump_bonds
  EXPECT_NE(two.screen.find("2 by 1 by 1 MPI processor grid"), std::string::npos);
  EXPECT_EQ(two.created, one.created);                                               // exact
  EXPECT_EQ(two.unbonded, one.unbonded);                                             // exact
  EXPECT_TRUE(one.bonds == two.bonds) << "bond lists differ between 1 and 2 ranks";  // exact
}

// ===========================================================================
// 5. Keyword errors of the contact options name the keyword and the value.
// ===========================================================================
namespace {

struct BadContactKw {
  const char *name;
  const char *keywords;  // appended to a valid fix line
  const char *expected;
};

void PrintTo(const BadContactKw &bad, std::ostream *os) { *os << bad.name; }

}  // namespace

class BondContactErrors : public ::testing::TestWithParam<BadContactKw> {};

TEST_P(BondContactErrors, MessageNamesKeyAndValue) {
  const BadContactKw &bad = GetParam();
  const std::string dir = make_run_dir(std::string("ct_err_") + bad.name);
  std::ostringstream d;
  d.precision(17);
  d << bond_fix(bad.keywords) << "timestep 1e-8\nrun 1\n";
  const auto r = run_with_data(dir, spinning_pair({0, 0, 0}, {0, 0, 0}), d.str());
  EXPECT_NE(r.screen.find(bad.expected), std::string::npos)
      << "expected message: " << bad.expected << "\ngot:\n"
      << r.screen;
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(r.screen.find("Loop time"), std::string::npos) << "run went ahead";
}

INSTANTIATE_TEST_SUITE_P(
    Keywords, BondContactErrors,
    ::testing::Values(
        BadContactKw{"MomentFactor", "moment_factor 2",
                     "fix bond/breakable: moment_factor must be in [0, 1], got 2"},
        BadContactKw{"BrokenContact", "broken_contact maybe",
                     "fix bond/breakable: broken_contact must be yes or no, got 'maybe'"},
        BadContactKw{"ContactMoment", "contact_moment 1",
                     "fix bond/breakable: contact_moment must be yes or no, got '1'"},
        BadContactKw{"UnbondedFraction", "unbonded_fraction 1",
                     "fix bond/breakable: unbonded_fraction must be in [0, 1), got 1"}),
    [](const ::testing::TestParamInfo<BadContactKw> &info) {
      return std::string(info.param.name);
    });
