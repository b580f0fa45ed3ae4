// Tests of fix energy/ledger (docs/styles/fix_energy_ledger.md) through real
// liggghts-mill runs: each compares the ledger's columns with a conservation
// law or a closed-form value, with the tolerance stated next to the assertion
// and the figures printed in a one-line summary.
//
// The ledger closes
//   input + work_other = ke_trans + ke_rot + numerical + bond_* + wall_* + contact_* + residual
// where work_other is what the kinetic energy gained beyond the work of the
// element contacts, the bonds (fix bond/breakable) and the surface (fix
// wall/halfspace), and the residual is what the bonds' and the surface's own
// books (work = change of stored + released + dissipated) do not close.
//
// Element, bond and contact constants are those of bond_test_util.h: radius
// 1 mm, density 2500 kg/m3, elements E = 5e9 Pa, nu = 0.25 (deck_head), the
// surface E = 200e9 Pa, nu = 0.3.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "bond_test_util.h"

using namespace mill_test;

namespace {

constexpr double kYoungs = 5e9;        // element Young's modulus (deck_head's default) [Pa]
constexpr double kPoisson = 0.25;      // element Poisson's ratio (deck_head) [-]
constexpr double kWallYoungs = 200e9;  // surface Young's modulus [Pa]
constexpr double kWallPoisson = 0.3;   // surface Poisson's ratio [-]

// The ledger file: rows keyed by column name (header line of the CSV).
struct Ledger {
  std::map<std::string, int> col;
  std::vector<std::vector<double>> rows;
  // Value of column `name` in row k.
  double at(size_t k, const std::string &name) const { return rows[k][col.at(name)]; }
  double last(const std::string &name) const { return at(rows.size() - 1, name); }
  // ke_trans + ke_rot + numerical + every stored, released and dissipated term of row k:
  // what the ledger holds, the right-hand side of the balance less the residual [J].
  double held(size_t k) const {
    double s = 0.0;
    for (const char *c :
         {"ke_trans_J", "ke_rot_J", "numerical_J", "bond_elastic_J", "bond_released_J",
          "bond_damping_J", "bond_friction_J", "wall_elastic_J", "wall_damping_J",
          "wall_friction_J", "contact_elastic_J", "contact_damping_J", "contact_friction_J"})
      s += at(k, c);
    return s;
  }
  // What the element contacts took in row k: damping + friction [J].
  double contact_lost(size_t k) const {
    return at(k, "contact_damping_J") + at(k, "contact_friction_J");
  }
};

// Reads a ledger CSV: one '#' line, the header, then numeric rows.
Ledger read_ledger(const std::string &path) {
  Ledger l;
  std::ifstream in(path);
  std::string line;
  bool header = false;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    std::string tok;
    std::vector<double> row;
    int k = 0;
    while (std::getline(ls, tok, ',')) {
      if (!header)
        l.col[tok] = k++;
      else
        row.push_back(std::strtod(tok.c_str(), nullptr));
    }
    if (header && row.size() == l.col.size()) l.rows.push_back(row);
    header = true;
  }
  return l;
}

// deck_head with the box read from data.txt, shrink-wrapped (pieces fly
// away), and the element-element restitution `restitution`.
std::string ledger_head(double restitution) {
  std::string head = deck_head(0.01, kYoungs, "m m m");
  const size_t a = head.find("region box block");
  const std::string create = "create_box 1 box\n";
  const size_t b = head.find(create);
  head.replace(a, b + create.size() - a, "read_data data.txt\n");
  const std::string rest = "coefficientRestitution peratomtypepair 1 0.5";
  std::ostringstream r;
  r << "coefficientRestitution peratomtypepair 1 " << restitution;
  head.replace(head.find(rest), rest.size(), r.str());
  return head;
}

// Writes data.txt and runs ledger_head(restitution) + body in dir.
RunResult run_ledger_deck(const std::string &dir, const std::vector<Sphere> &atoms,
                          const std::string &body, double restitution = 0.5) {
  {
    std::ofstream out(dir + "/data.txt");
    out << data_text(atoms, 0.02);
  }
  return run_deck(dir, ledger_head(restitution) + body);
}

// `fix ledger all energy/ledger every N file ledger.csv youngs .. poisson ..` plus extra.
std::string ledger_fix(int every, const std::string &extra) {
  std::ostringstream s;
  s << "fix ledger all energy/ledger every " << every << " file ledger.csv youngs " << kYoungs
    << " poisson " << kPoisson << " " << extra << "\n";
  return s.str();
}

// `fix wall all wall/halfspace zplane z ...` on the elements' material.
std::string wall_fix(double z, double restitution, double friction) {
  std::ostringstream s;
  s.precision(17);
  s << "fix wall all wall/halfspace zplane " << z << " youngs " << kYoungs << " poisson "
    << kPoisson << " wall_youngs " << kWallYoungs << " wall_poisson " << kWallPoisson
    << " restitution " << restitution << " friction " << friction << "\n";
  return s.str();
}

// Kinetic energy of the data, translation and rotation [J].
double data_energy(const std::vector<Sphere> &atoms) {
  double e = 0.0;
  for (const auto &s : atoms)
    for (int c = 0; c < 3; ++c)
      e += 0.5 * sphere_mass(s.r) * s.v[c] * s.v[c] + 0.5 * sphere_inertia(s.r) * s.w[c] * s.w[c];
  return e;
}

// Lines `step 0: run 0` then `timestep frac x f_bonds[6]` (the bonds' critical step).
std::string step_from_critical(double frac) {
  std::ostringstream s;
  s << "timestep 1e-9\nrun 0\nvariable dtc equal f_bonds[6]\n"
    << "variable dtr equal " << frac << "*${dtc}\ntimestep ${dtr}\n"
    << "print \"${dtr}\" file dt.txt\n";
  return s.str();
}

double read_scalar(const std::string &path) {
  const auto rows = read_table(path);
  return rows.empty() || rows.front().empty() ? 0.0 : rows.front()[0];
}

}  // namespace

// ===========================================================================
// 1. A bonded 3 x 3 x 3 lump (lattice spacing kL0, turned 20 deg about x and
//    30 deg about y) hits wall/halfspace at 120 m/s normal and 15 m/s along
//    x. Bonds undamped, element contacts and the surface with restitution 1
//    (no dashpots), friction 0.5 on both; time step 0.1 x f_bonds[6]. Over
//    the whole run (until no element has touched anything for the last 20 %
//    of it): |residual| / input < 1e-3 at every row, work_other = 0 (no other
//    force: 1e-9 of input), and at the end the sum of kinetic, stored,
//    released and dissipated energy equals the input (1e-3). The same with
//    flat joints (fix bond/flatjoint, 2 x 4 elements), whose released energy
//    is the elements'.
// ===========================================================================
namespace {
// min_released: the share of the input the broken bonds must release for the
// run to test anything; settled: the pieces must have stopped touching for
// the last 20 % of the run (broken flat joints keep neighbouring elements in
// frictional contact, so their pieces rattle on: the balance is still
// checked at every row).
// adaptive: the step re-evaluated every 1000 steps by fix step/adaptive
// (safety 0.1 of the bonds left, at most 3 x the first step, growth 1.5).
void check_high_speed_impact(const std::string &bonds, const std::string &tag, double min_released,
                             bool settled, bool adaptive = false) {
  const std::string dir = make_run_dir(adaptive      ? "led_impact_ad"
                                       : tag.empty() ? "led_impact"
                                                     : "led_impact_fj");
  const double ax = 20.0 * kPi / 180.0, ay = 30.0 * kPi / 180.0;
  const std::array<double, 3> v0 = {15.0, 0.0, -120.0};
  std::vector<Sphere> atoms;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        double x = (i - 1) * kL0, y = (j - 1) * kL0, z = (k - 1) * kL0;
        const double y1 = std::cos(ax) * y - std::sin(ax) * z;
        const double z1 = std::sin(ax) * y + std::cos(ax) * z;
        const double x2 = std::cos(ay) * x + std::sin(ay) * z1;
        const double z2 = -std::sin(ay) * x + std::cos(ay) * z1;
        Sphere s;
        s.x = {x2, y1, z2};
        s.v = v0;
        atoms.push_back(s);
      }
  double zlow = 1.0;
  for (const auto &s : atoms) zlow = std::min(zlow, s.x[2]);
  const double zplane = zlow - kR - 1e-5;  // 10 um below the lowest element
  const int steps = 15000;
  std::ostringstream d;
  d.precision(17);
  d << ledger_fix(10, "bonds bonds wall wall") << wall_fix(zplane, 1.0, 0.5) << bonds
    << "fix integr all nve/sphere\n"
    << step_from_critical(0.1)
    << (adaptive ? "variable dtmax equal 3*${dtr}\nfix step all step/adaptive bonds bonds safety "
                   "0.1 max "
                   "${dtmax} growth 1.5 every 1000 file steps.csv\n"
                   // A dump in simulated time, as the decks write theirs with the
                   // adaptive step: at the first step at or after each multiple of
                   // 700 first steps (not a multiple of the 1000 between changes).
                   "variable dint equal 700*${dtr}\n"
                   "variable dk equal floor(time/${dint}+1e-6)+1\n"
                   "variable dgap equal ceil((v_dk*${dint}-time)/dt-1e-6)\n"
                   "variable dnext equal step+v_dgap+(v_dgap<1)\n"
                   "variable dtime atom time\n"
                   "dump tdump all custom 1 dumps.txt id v_dtime\n"
                   "dump_modify tdump every v_dnext first yes format \"%d %.17g\"\n"
                 : "")
    << "variable nb equal f_bonds[1]\nthermo 5000\nrun " << steps
    << "\nprint \"${nb}\" file intact.txt\n";
  const auto r = run_ledger_deck(dir, atoms, d.str(), 1.0);
  ASSERT_EQ(r.exit_code, 0) << r.screen;
  const Ledger l = read_ledger(dir + "/ledger.csv");
  ASSERT_GE(l.rows.size(), static_cast<size_t>(steps / 10));
  const double input = l.last("input_J"), e0 = data_energy(atoms);
  double worst_res = 0.0, worst_other = 0.0;
  double last_touch = 0.0;  // last row with an element on the surface or on another
  for (size_t k = 0; k < l.rows.size(); ++k) {
    worst_res = std::max(worst_res, std::fabs(l.at(k, "residual_J")) / input);
    worst_other = std::max(worst_other, std::fabs(l.at(k, "work_other_J")) / input);
    const bool touch = l.at(k, "wall_elastic_J") > 0.0 || l.at(k, "contact_elastic_J") > 0.0 ||
                       (k > 0 && (l.at(k, "wall_friction_J") != l.at(k - 1, "wall_friction_J") ||
                                  l.contact_lost(k) != l.contact_lost(k - 1)));
    if (touch) last_touch = l.at(k, "step");
  }
  const size_t n = l.rows.size() - 1;
  const double final_rel = (l.held(n) - input) / input;
  std::printf(
      "lump impact%s at %.0f m/s (27 elements, 0.1 x f_bonds[6] = %.4g s): input %.6e J (data "
      "%.6e J), max |residual|/input %.3e (tol 1e-3; bonds %.2e J, surface %.2e J at the end), "
      "max |work_other|/input %.2e (tol 1e-9), final (ke + stored + released + dissipated - "
      "input)/input %.3e (tol 1e-3); released %.4g J, wall friction %.4g J, contacts %.4g J, "
      "intact bonds %.0f, last touch at step %.0f of %d, max overlap/r %.3f\n",
      tag.c_str(), std::sqrt(v0[0] * v0[0] + v0[2] * v0[2]), read_scalar(dir + "/dt.txt"), input,
      e0, worst_res,
      l.last("residual_bonds_J"), l.last("residual_wall_J"), worst_other, final_rel,
      l.last("bond_released_J"), l.last("wall_friction_J"), l.contact_lost(l.rows.size() - 1),
      read_scalar(dir + "/intact.txt"), last_touch, steps, l.last("wall_overlap"));
  EXPECT_NEAR(input / e0, 1.0, 1e-9);  // input = 1/2 M v0^2, round-off (1e-9)
  // Non-vacuous: the lump hit the surface, broke bonds and its pieces rubbed.
  EXPECT_GT(l.last("wall_overlap"), 0.05);
  EXPECT_GT(l.last("bond_released_J"), min_released * input);
  EXPECT_GT(l.contact_lost(l.rows.size() - 1), 0.01 * input);
  if (settled) {
    EXPECT_LT(last_touch, 0.8 * steps) << "pieces still touching: window too short";
  }
  if (adaptive) {
    // The step grew once bonds broke, and never above 0.1 x the bonds' critical step.
    std::vector<std::vector<double>> steps;  // step,time_s,dt_s,dt_bonds_s,intact_bonds
    {
      std::ifstream in(dir + "/steps.csv");
      std::string line;
      while (std::getline(in, line)) {
        if (line.empty() || !std::isdigit(static_cast<unsigned char>(line[0]))) continue;
        std::replace(line.begin(), line.end(), ',', ' ');
        std::istringstream ls(line);
        std::vector<double> row;
        double x;
        while (ls >> x) row.push_back(x);
        steps.push_back(row);
      }
    }
    const double dt0 = read_scalar(dir + "/dt.txt");
    double dt_max = 0.0;
    for (const auto &r : steps) {
      ASSERT_EQ(r.size(), 5u);
      dt_max = std::max(dt_max, r[2]);
      if (r[3] > 0) {
        EXPECT_LE(r[2], 0.1 * r[3] * (1 + 1e-9)) << "at step " << r[0];
      }
    }
    std::printf("adaptive: %zu re-evaluations, step %.4g -> %.4g s at most\n", steps.size(), dt0,
                dt_max);
    EXPECT_GT(dt_max, 1.2 * dt0) << "the step did not grow";
    // The dump in simulated time: snapshot k at the first step at or after
    // k x 700 dt0, whatever the step did in between (fix step/adaptive asks
    // the dump's variable again when it changes the step within a run):
    // -2e-6 I <= T_k - k I < the step that ended at T_k (a time within 1e-6 I
    // of a multiple counts as on it),
    // and one snapshot per interval up to the end.
    const double interval = 700 * dt0;
    auto step_at = [&](double step) {  // the step length of the step ending at `step`
      double dt = dt0;
      for (const auto &r : steps)
        if (r[0] < step) dt = r[2];
      return dt;
    };
    std::vector<std::pair<double, double>> snaps;  // step, time
    {
      std::ifstream in(dir + "/dumps.txt");
      std::string line;
      double step = -1;
      bool want_step = false, want_atom = false;
      while (std::getline(in, line)) {
        if (line.rfind("ITEM: TIMESTEP", 0) == 0) {
          want_step = true;
        } else if (want_step) {
          step = std::stod(line), want_step = false;
        } else if (line.rfind("ITEM: ATOMS", 0) == 0) {
          want_atom = true;
        } else if (want_atom) {
          std::istringstream ls(line);
          double id, t;
          ls >> id >> t;
          snaps.emplace_back(step, t);
          want_atom = false;
        }
      }
    }
    const double t_final = steps.empty() ? 0.0 : steps.back()[1];
    ASSERT_GE(snaps.size(), 3u) << "dumps.txt: too few snapshots";
    EXPECT_EQ(static_cast<double>(snaps.size()), std::floor(t_final / interval * (1 + 1e-9)) + 1)
        << "one snapshot per interval up to t = " << t_final << " s";
    double worst_late = 0.0;
    for (size_t k = 0; k < snaps.size(); ++k) {
      const double late = snaps[k].second - k * interval, dt = step_at(snaps[k].first);
      worst_late = std::max(worst_late, late / dt);
      EXPECT_GE(late, -2e-6 * interval) << "snapshot " << k << " at step " << snaps[k].first;
      EXPECT_LT(late, dt + 1e-9 * interval) << "snapshot " << k << " at step " << snaps[k].first
                                            << ": " << late << " s after k x the interval";
    }
    std::printf("dump in simulated time: %zu snapshots every %.4g s, at most %.3f steps late\n",
                snaps.size(), interval, worst_late);
  }
  EXPECT_LT(worst_res, 1e-3);             // bound: residual below 0.1 % of the input
  EXPECT_LT(worst_other, 1e-9);           // no other force: round-off
  EXPECT_LT(std::fabs(final_rel), 1e-3);  // final balance, 0.1 %
}
}  // namespace

TEST(EnergyLedger, HighSpeedImpactConservesWithoutDamping) {
  check_high_speed_impact(bond_fix(), "", 0.01, true);
}
// The same impact with the step re-evaluated every 1000 steps from the bonds
// left (fix step/adaptive): the ledger's books stay exact across the changes
// (the shadow and end terms banked at each, the trapezoid per step).
TEST(EnergyLedger, HighSpeedImpactConservesWithAdaptiveStep) {
  check_high_speed_impact(bond_fix(), " (adaptive step)", 0.01, true, true);
}
// Flat joints release less (0.83 % of the input here: broken elements keep
// carrying compression and friction); the balance bounds are the same.
TEST(EnergyLedger, FlatJointImpactConservesWithoutDamping) {
  check_high_speed_impact(flat_joint_fix(), " (flat joints)", 0.005, false);
}

// ===========================================================================
// 2. One element falls normally at v0 = 10 m/s (no gravity, no spin) onto
//    wall/halfspace with restitution e: after the bounce the surface's
//    dashpot took wall_damping_J = 1/2 m (v0^2 - v1^2), v1 the rebound speed
//    read from the atom (1e-6 relative), and v1 / v0 = e within 1e-3
//    (LIGGGHTS's Hertz dashpot gamma = -2 sqrt(5/6) beta sqrt(S_n m),
//    beta = ln e / sqrt(ln^2 e + pi^2), Tsuji et al. 1992). Step 2e-9 s, about
//    1/5000 of the contact time.
// ===========================================================================
TEST(EnergyLedger, WallDampingMatchesRestitution) {
  const double v0 = 10.0, m = sphere_mass(kR);
  for (double e : {0.2, 0.5, 0.8}) {
    const std::string dir = make_run_dir("led_bounce");
    Sphere s;
    s.x = {0.0, 0.0, kR + 1e-5};  // 10 um above the plane z = 0
    s.v = {0.0, 0.0, -v0};
    std::ostringstream d;
    d.precision(17);
    d << ledger_fix(10, "wall wall") << wall_fix(0.0, e, 0.5) << "fix integr all nve/sphere\n"
      << "timestep 2e-9\nrun 15000\nvariable vz equal vz[1]\nvariable vx equal vx[1]\n"
      << "print \"${vz} ${vx}\" file v1.txt\n";
    const auto r = run_ledger_deck(dir, {s}, d.str());
    ASSERT_EQ(r.exit_code, 0) << r.screen;
    const auto v1row = read_table(dir + "/v1.txt");
    ASSERT_FALSE(v1row.empty());
    const double v1 = v1row.front()[0];
    const Ledger l = read_ledger(dir + "/ledger.csv");
    ASSERT_FALSE(l.rows.empty());
    const double lost = 0.5 * m * (v0 * v0 - v1 * v1), damp = l.last("wall_damping_J");
    std::printf(
        "bounce, e = %.1f: v1/v0 %.8f (v1/(e v0) - 1 = %.3e, tol 1e-3), wall_damping %.9e J, "
        "1/2 m (v0^2 - v1^2) %.9e J, rel. diff %.3e (tol 1e-6), wall_elastic at the end %.3g J, "
        "max overlap/r %.4f\n",
        e, v1 / v0, v1 / (e * v0) - 1.0, damp, lost, damp / lost - 1.0, l.last("wall_elastic_J"),
        l.last("wall_overlap"));
    EXPECT_EQ(l.last("wall_elastic_J"), 0.0);  // exact: the bounce is over
    EXPECT_GT(v1, 0.0);                        // it rebounded
    EXPECT_NEAR(v1 / (e * v0), 1.0, 1e-3);     // restitution within 0.1 %
    EXPECT_NEAR(damp / lost, 1.0, 1e-6);       // dashpot energy, 1e-6 relative
    EXPECT_EQ(v1row.front()[1], 0.0);          // exact: normal impact stays normal
  }
}

// ===========================================================================
// 3. Two bonded elements (centre distance kL0: a 0.1 mm gap, contacts never
//    close) vibrate along the bond from relative velocity 1 m/s (amplitude
//    1/omega = 0.4 um). Bond `damping zeta`, zeta = 0.05: c_n = 2 zeta
//    sqrt(m_red kn A) (docs/styles/fix_bond_breakable.md, "Damping"), so the
//    axial mode omega = sqrt(kn A (1/m1 + 1/m2)) decays as a damped
//    oscillator: the vibration energy (ke + bond_elastic) at whole damped
//    periods Td = 2 pi / (omega sqrt(1 - zeta^2)) is E0 exp(-2 zeta omega t)
//    (1.5 %; the fitted rate within 1 %), and bond_damping_J equals the
//    energy lost, input - (ke + bond_elastic), to 1e-5. Step T/200.
// ===========================================================================
TEST(EnergyLedger, BondDashpotMatchesDecay) {
  const std::string dir = make_run_dir("led_dashpot");
  const double zeta = 0.05, u = 0.5, m = sphere_mass(kR);
  const double omega = std::sqrt(kKn * kArea * 2.0 / m);
  const double td = 2.0 * kPi / (omega * std::sqrt(1.0 - zeta * zeta));
  const double dt = 2.0 * kPi / omega / 200.0;
  const int periods = 5, steps = static_cast<int>((periods + 0.5) * td / dt);
  auto atoms = spinning_pair({0, 0, 0}, {0, 0, 0});
  atoms[0].v = {-u, 0.0, 0.0};
  atoms[1].v = {u, 0.0, 0.0};
  std::ostringstream d;
  d.precision(17);
  d << ledger_fix(1, "bonds bonds") << bond_fix("damping " + std::to_string(zeta))
    << "fix integr all nve/sphere\n"
    << "timestep " << dt << "\nthermo 1000\nrun " << steps << "\n";
  const auto r = run_ledger_deck(dir, atoms, d.str());
  ASSERT_EQ(r.exit_code, 0) << r.screen;
  const Ledger l = read_ledger(dir + "/ledger.csv");
  ASSERT_EQ(l.rows.size(), static_cast<size_t>(steps));
  const double input = l.last("input_J"), e0 = data_energy(atoms);
  // Vibration energy over time, from t = 0 (the input: nothing stored) on.
  std::vector<std::pair<double, double>> e = {{0.0, input}};
  double contact = 0.0;
  for (size_t k = 0; k < l.rows.size(); ++k) {
    e.emplace_back(l.at(k, "time_s"),
                   l.at(k, "ke_trans_J") + l.at(k, "ke_rot_J") + l.at(k, "bond_elastic_J"));
    contact =
        std::max({contact, l.at(k, "contact_elastic_J"), std::fabs(l.at(k, "contact_damping_J")),
                  std::fabs(l.at(k, "contact_friction_J"))});
  }
  auto energy_at = [&e](double t) {
    for (size_t k = 1; k < e.size(); ++k)
      if (e[k].first >= t)
        return e[k - 1].second + (e[k].second - e[k - 1].second) * (t - e[k - 1].first) /
                                     (e[k].first - e[k - 1].first);
    return e.back().second;
  };
  double worst = 0.0, sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
  for (int n = 1; n <= periods; ++n) {
    const double t = n * td, ratio = energy_at(t) / input;
    worst = std::max(worst, std::fabs(ratio / std::exp(-2.0 * zeta * omega * t) - 1.0));
    sx += t, sy += std::log(ratio), sxx += t * t, sxy += t * std::log(ratio);
  }
  const double rate = -(periods * sxy - sx * sy) / (periods * sxx - sx * sx);
  const size_t n = l.rows.size() - 1;
  const double lost =
      input - (l.at(n, "ke_trans_J") + l.at(n, "ke_rot_J") + l.at(n, "bond_elastic_J"));
  const double damp = l.last("bond_damping_J");
  std::printf(
      "bond dashpot, zeta %.2f, omega %.6e rad/s: E(%d Td)/E0 %.5f vs exp(-2 zeta omega t) %.5f, "
      "max rel. diff over n = 1..%d %.3e (tol 1.5e-2), fitted rate %.6e 1/s vs 2 zeta omega "
      "%.6e 1/s (rel. %.3e, tol 1e-2); bond_damping %.9e J, input - (ke + bond_elastic) %.9e J, "
      "rel. diff %.3e (tol 1e-5); input %.6e J (data %.6e J), max contact term %.3g J\n",
      zeta, omega, periods, energy_at(periods * td) / input,
      std::exp(-2.0 * zeta * omega * periods * td), periods, worst, rate, 2.0 * zeta * omega,
      rate / (2.0 * zeta * omega) - 1.0, damp, lost, damp / lost - 1.0, input, e0, contact);
  EXPECT_NEAR(input / e0, 1.0, 1e-9);  // input = kinetic energy of the data, round-off
  EXPECT_EQ(contact, 0.0);             // exact: the elements never touch
  EXPECT_LT(worst, 1.5e-2);            // tolerance 1.5 %
  EXPECT_NEAR(rate / (2.0 * zeta * omega), 1.0, 1e-2);  // tolerance 1 %
  EXPECT_NEAR(damp / lost, 1.0, 1e-5);  // tolerance 1e-5 (start-up shadow term, dt^2)
}

// ===========================================================================
// 4. A free bonded pair (no contact) tumbles at 1e4 rad/s: transverse
//    velocities -+10.5 m/s at centre distance kL0, spins 0 (the bond is bent
//    and sheared as it swings the elements round), and once more with a spin
//    of 3000 rad/s about the bond axis on one element (twist, and bending
//    out of the plane of tumbling). 1e5 steps at 0.1 x f_bonds[6] (11
//    turns), unbreakable bonds. The bonds' share of the residual and the
//    total-energy error ke + bond_elastic + numerical - input stay below
//    1e-6 of the input in the plane, 1e-5 with the twist, at every row.
// ===========================================================================
TEST(EnergyLedger, TumblingPairConservesEnergy) {
  struct Case {
    const char *name;
    std::array<double, 3> w;  // spin of element 1 [rad/s]
    double tol;               // bound on both relative errors
  };
  for (const Case &c :
       {Case{"planar", {0.0, 0.0, 0.0}, 1e-6}, Case{"with twist", {3000.0, 0.0, 0.0}, 1e-5}}) {
    const std::string dir = make_run_dir("led_tumble");
    auto atoms = spinning_pair(c.w, {0, 0, 0});
    atoms[0].x = {-0.5 * kL0, 0.0, 0.0};
    atoms[1].x = {0.5 * kL0, 0.0, 0.0};
    atoms[0].v = {0.0, -10.5, 0.0};
    atoms[1].v = {0.0, 10.5, 0.0};
    const int steps = 100000;
    std::ostringstream d;
    d << ledger_fix(1000, "bonds bonds") << bond_fix("", 1e15, 1e15)
      << "fix integr all nve/sphere\n"
      << step_from_critical(0.1) << "thermo 20000\nrun " << steps << "\n";
    const auto r = run_ledger_deck(dir, atoms, d.str());
    ASSERT_EQ(r.exit_code, 0) << r.screen;
    const Ledger l = read_ledger(dir + "/ledger.csv");
    ASSERT_GE(l.rows.size(), static_cast<size_t>(steps / 1000));
    const double input = l.last("input_J");
    double worst_bonds = 0.0, worst_total = 0.0, bond_max = 0.0, contact = 0.0;
    for (size_t k = 0; k < l.rows.size(); ++k) {
      worst_bonds = std::max(worst_bonds, std::fabs(l.at(k, "residual_bonds_J")) / input);
      const double total = l.at(k, "ke_trans_J") + l.at(k, "ke_rot_J") + l.at(k, "bond_elastic_J") +
                           l.at(k, "numerical_J");
      worst_total = std::max(worst_total, std::fabs(total - input) / input);
      bond_max = std::max(bond_max, l.at(k, "bond_elastic_J"));
      contact = std::max(contact, l.at(k, "contact_elastic_J"));
    }
    const double turns = 2.0 * 10.5 / kL0 * l.last("time_s") / (2.0 * kPi);
    std::printf(
        "tumbling pair (%s), 1e4 rad/s, %.1f turns, 0.1 x f_bonds[6] = %.4g s: input %.6e J, "
        "max |residual_bonds|/input %.3e, max |ke + bond_elastic + numerical - input|/input "
        "%.3e (tol %.0e each), peak bond energy %.3e J, released %.3g J\n",
        c.name, turns, read_scalar(dir + "/dt.txt"), input, worst_bonds, worst_total, c.tol,
        bond_max, l.last("bond_released_J"));
    EXPECT_GT(bond_max, 0.05 * input) << "bond not loaded: test would be vacuous";
    EXPECT_EQ(l.last("bond_released_J"), 0.0);  // exact: the bond holds
    EXPECT_EQ(contact, 0.0);                    // exact: no contact
    EXPECT_LT(worst_bonds, c.tol);              // bound, stated above
    EXPECT_LT(worst_total, c.tol);              // bound, stated above
  }
}

// ===========================================================================
// 5. The checks that stop a run. One element at rest, `run 100`, then
//    `set atom 1 vx 1000` and `run 100`:
//    - speed_bound 50: the run exits non-zero, and the message names the
//      element, its speed and the bound;
//    - speed_bound 0, residual_bound 0.01: the kinetic energy that no force
//      gave must open the balance ("the energy balance does not close").
//    A bond stretched by `displace_atoms` between runs (stored energy that
//    no force put in) must open it too. A ledger defined after the bond fix
//    stops the run with a message naming that fix.
// ===========================================================================
namespace {

// One element at rest at the origin, the ledger with `checks`, 100 steps,
// then element 1 given 1000 m/s along x and 100 steps more.
RunResult run_injection(const std::string &dir, const std::string &checks) {
  Sphere s;
  std::ostringstream d;
  d << ledger_fix(10, checks) << "fix integr all nve/sphere\ntimestep 1e-8\nrun 100\n"
    << "set atom 1 vx 1000\nrun 100\n";
  return run_ledger_deck(dir, {s}, d.str());
}

}  // namespace

TEST(EnergyLedger, SpeedBoundFiresOnInjectedEnergy) {
  const std::string dir = make_run_dir("led_speed");
  const auto r = run_injection(dir, "speed_bound 50");
  const bool names = r.screen.find("element 1 moves at 1000 m/s") != std::string::npos &&
                     r.screen.find("above the speed bound 50 m/s") != std::string::npos;
  std::printf(
      "speed bound 50 m/s, element set to 1000 m/s between runs: exit code %d, message "
      "names the element, speed and bound: %s\n",
      r.exit_code, names ? "yes" : "no");
  EXPECT_NE(r.exit_code, 0) << r.screen;
  EXPECT_TRUE(names) << r.screen;
}

TEST(EnergyLedger, ResidualBoundFiresOnEnergyFromNowhere) {
  const std::string dir = make_run_dir("led_resid");
  const auto r = run_injection(dir, "speed_bound 0 residual_bound 0.01");
  const bool names = r.screen.find("the energy balance does not close") != std::string::npos;
  const Ledger l = read_ledger(dir + "/ledger.csv");
  std::printf(
      "residual bound 1 %%, element set to 1000 m/s between runs: exit code %d, message: %s; "
      "last row: ke %.6g J, work_other %.6g J, residual %.3g J\n",
      r.exit_code, names ? "yes" : "no", l.rows.empty() ? 0.0 : l.last("ke_trans_J"),
      l.rows.empty() ? 0.0 : l.last("work_other_J"), l.rows.empty() ? 0.0 : l.last("residual_J"));
  // work_other is the remainder of the kinetic theorem: a jump of the kinetic
  // energy between runs must not be booked as work of a force.
  EXPECT_NE(r.exit_code, 0) << "the injected energy was booked as work_other; screen:\n"
                            << r.screen;
  EXPECT_TRUE(names);
}

TEST(EnergyLedger, ResidualBoundFiresOnStoredEnergyFromNowhere) {
  const std::string dir = make_run_dir("led_resid_bond");
  std::ostringstream d;
  d << ledger_fix(10, "bonds bonds speed_bound 0 residual_bound 0.01") << bond_fix("", 1e15, 1e15)
    << "fix integr all nve/sphere\ntimestep 1e-8\nrun 100\n"
    << "group a2 id 2\ndisplace_atoms a2 move 1e-6 0 0 units box\nrun 100\n";
  const auto r = run_ledger_deck(dir, spinning_pair({0, 0, 0}, {0, 0, 0}), d.str());
  const bool names = r.screen.find("the energy balance does not close") != std::string::npos;
  const double stored = 0.5 * kKn * kArea * 1e-6 * 1e-6;  // bond stretched by 1 um [J]
  std::printf(
      "residual bound 1 %%, bond stretched by 1 um between runs (%.4g J from nowhere): "
      "exit code %d, message: %s\n",
      stored, r.exit_code, names ? "yes" : "no");
  EXPECT_NE(r.exit_code, 0) << r.screen;
  EXPECT_TRUE(names) << r.screen;
}

TEST(EnergyLedger, MustComeBeforeForceFixes) {
  const std::string dir = make_run_dir("led_order");
  std::ostringstream d;
  d << bond_fix() << ledger_fix(10, "bonds bonds") << "fix integr all nve/sphere\n"
    << "timestep 1e-8\nrun 10\n";
  const auto r = run_ledger_deck(dir, spinning_pair({0, 0, 0}, {0, 0, 0}), d.str());
  const bool names =
      r.screen.find("fix energy/ledger: must be defined before fix bonds (bond/breakable)") !=
      std::string::npos;
  std::printf("ledger after the bond fix: exit code %d, message names fix bonds: %s\n", r.exit_code,
              names ? "yes" : "no");
  EXPECT_NE(r.exit_code, 0) << r.screen;
  EXPECT_TRUE(names) << r.screen;
}

// ===========================================================================
// 5. Two free elements (no bonds, no surface) collide at relative speed
//    2 m/s with element restitution e. Head on (impact parameter 0): the
//    contact's normal dashpot takes all the kinetic energy lost,
//    contact_damping_J = 1/2 m* (v0^2 - v1^2) with v1 the relative speed read
//    from the atoms (1e-5 relative: the dashpot force is LIGGGHTS's own at
//    the half step, its work a trapezoid, O(dt^2)), contact_friction_J stays
//    below 1e-5 of it (nothing acts tangentially), and v1/v0 = e (1e-3, as
//    for the surface). Oblique (impact parameter 0.6 r, friction 0.5): the
//    normal relative motion of two spheres is driven by the normal force
//    only, so contact_damping_J equals the loss of 1/2 m* vn^2 along the
//    normal at first touch (1 %: the normal turns during contact), and the
//    tangential losses (slip, tangential dashpot) are contact_friction_J,
//    over 1 % of the loss. In both, damping + friction is the kinetic
//    energy lost, rotation included (1e-6).
//    Step 2e-9 s, about 1/2000 of the contact time.
// ===========================================================================
TEST(EnergyLedger, ContactDampingMatchesCollisionLoss) {
  const double u = 1.0, m = sphere_mass(kR), mstar = 0.5 * m;
  for (double e : {0.3, 0.7}) {
    for (double b : {0.0, 0.6 * kR}) {
      const std::string dir = make_run_dir("led_collide");
      const double gap = 1e-5;  // between the surfaces at the start, along x
      const double cx = std::sqrt(4.0 * kR * kR - b * b);
      std::vector<Sphere> atoms(2);
      atoms[0].x = {-0.5 * (cx + gap), -0.5 * b, 0.0};
      atoms[1].x = {0.5 * (cx + gap), 0.5 * b, 0.0};
      atoms[0].v = {u, 0.0, 0.0};
      atoms[1].v = {-u, 0.0, 0.0};
      std::ostringstream d;
      d.precision(17);
      d << ledger_fix(10, "") << "fix integr all nve/sphere\ntimestep 2e-9\nrun 20000\n";
      for (int a = 1; a <= 2; ++a)
        d << "variable vx" << a << " equal vx[" << a << "]\nvariable vy" << a << " equal vy[" << a
          << "]\nvariable wz" << a << " equal omegaz[" << a << "]\n";
      d << "print \"${vx1} ${vy1} ${vx2} ${vy2} ${wz1} ${wz2}\" file v1.txt\n";
      const auto r = run_ledger_deck(dir, atoms, d.str(), e);
      ASSERT_EQ(r.exit_code, 0) << r.screen;
      const auto vrow = read_table(dir + "/v1.txt");
      ASSERT_FALSE(vrow.empty());
      const auto &v = vrow.front();
      const Ledger l = read_ledger(dir + "/ledger.csv");
      ASSERT_FALSE(l.rows.empty());
      // Relative velocity (2 - 1) before and after; the normal at first touch.
      const double n[2] = {-cx / (2.0 * kR), -b / (2.0 * kR)};
      const double w0[2] = {-2.0 * u, 0.0}, w1[2] = {v[2] - v[0], v[3] - v[1]};
      const double vn0 = w0[0] * n[0] + w0[1] * n[1], vn1 = w1[0] * n[0] + w1[1] * n[1];
      const double lost_total =
          0.5 * m * (2.0 * u * u - (v[0] * v[0] + v[1] * v[1]) - (v[2] * v[2] + v[3] * v[3])) -
          0.5 * sphere_inertia(kR) * (v[4] * v[4] + v[5] * v[5]);
      const double lost_normal = 0.5 * mstar * (vn0 * vn0 - vn1 * vn1);
      const double damp = l.last("contact_damping_J"), fric = l.last("contact_friction_J");
      std::printf(
          "collision, e = %.1f, b = %.1f r: rebound |vn1/vn0| %.6f (vs e, rel. %.2e), lost %.9e J "
          "(normal %.9e J), contact_damping %.9e J (rel. to normal loss %.3e), contact_friction "
          "%.4g J, contact_elastic at the end %.3g J, residual %.3g J\n",
          e, b / kR, std::fabs(vn1 / vn0), std::fabs(vn1 / vn0) / e - 1.0, lost_total, lost_normal,
          damp, damp / lost_normal - 1.0, fric, l.last("contact_elastic_J"), l.last("residual_J"));
      EXPECT_EQ(l.last("contact_elastic_J"), 0.0);         // exact: the collision is over
      EXPECT_NEAR((damp + fric) / lost_total, 1.0, 1e-6);  // the balance (CSV digits, dt^2)
      if (b == 0.0) {
        EXPECT_NEAR(std::fabs(vn1 / vn0) / e, 1.0, 1e-3);  // restitution within 0.1 %
        EXPECT_NEAR(damp / lost_total, 1.0, 1e-5);         // dashpot takes it all
        EXPECT_LT(std::fabs(fric), 1e-5 * lost_total);     // nothing tangential
      } else {
        EXPECT_NEAR(damp / lost_normal, 1.0, 1e-2);  // the normal dashpot's share
        EXPECT_GT(fric, 1e-2 * lost_total);          // sliding and tangential dashpot took some
      }
    }
  }
}

// ===========================================================================
// 6. fix energy/work: one element flies free under gravity (9.81 m/s2 along
//    -z) and a constant push (addforce 1e-4 N along x). A fix energy/work
//    after each force fix measures that fix's work: for a constant force F_k
//    the ledger's exact velocity-Verlet work is F_k . (x1 - x0) less the end
//    term dt^2/4 F_k . F / m (F the total force; docs/styles/
//    fix_energy_ledger.md), from the element's positions (1e-9 relative),
//    and the two add up to work_other_J (1e-9). A fix energy/work before the ledger
//    is refused by name.
// ===========================================================================
TEST(EnergyLedger, WorkPartsMatchConstantForces) {
  const std::string dir = make_run_dir("led_parts");
  const double g = 9.81, fx = 1e-4, m = sphere_mass(kR);
  Sphere s;
  s.v = {0.5, 0.0, 2.0};
  std::ostringstream d;
  d.precision(17);
  d << ledger_fix(100, "") << "fix grav all gravity " << g << " vector 0 0 -1\n"
    << "fix wg all energy/work gravity\nfix push all addforce " << fx << " 0 0\n"
    << "fix wp all energy/work push\nfix integr all nve/sphere\ntimestep 1e-6\n"
    << "variable x0 equal x[1]\nvariable z0 equal z[1]\nprint \"${x0} ${z0}\" file x0.txt\n"
    << "run 3000\nvariable x1 equal x[1]\nvariable z1 equal z[1]\n"
    << "print \"${x1} ${z1}\" file x1.txt\n";
  const auto r = run_ledger_deck(dir, {s}, d.str());
  ASSERT_EQ(r.exit_code, 0) << r.screen;
  const auto p0 = read_table(dir + "/x0.txt"), p1 = read_table(dir + "/x1.txt");
  ASSERT_FALSE(p0.empty());
  ASSERT_FALSE(p1.empty());
  const Ledger l = read_ledger(dir + "/ledger.csv");
  ASSERT_FALSE(l.rows.empty());
  ASSERT_TRUE(l.col.count("work_gravity_J") && l.col.count("work_push_J"));
  const double q = 0.25 * 1e-6 * 1e-6;  // dt^2 / 4
  const double wg = m * g * (p0.front()[1] - p1.front()[1]) - q * (m * g) * (m * g) / m;
  const double wp = fx * (p1.front()[0] - p0.front()[0]) - q * fx * fx / m;
  std::printf(
      "free flight: work_gravity %.12e J vs m g (z0 - z1) - end term %.12e J (rel. %.2e, tol "
      "1e-9), work_push %.12e J vs F (x1 - x0) - end term %.12e J (rel. %.2e), their sum vs "
      "work_other %.12e J\n",
      l.last("work_gravity_J"), wg, l.last("work_gravity_J") / wg - 1.0, l.last("work_push_J"), wp,
      l.last("work_push_J") / wp - 1.0, l.last("work_other_J"));
  EXPECT_NEAR(l.last("work_gravity_J") / wg, 1.0, 1e-9);
  EXPECT_NEAR(l.last("work_push_J") / wp, 1.0, 1e-9);
  EXPECT_NEAR((l.last("work_gravity_J") + l.last("work_push_J")) / l.last("work_other_J"), 1.0,
              1e-9);

  const std::string bad = make_run_dir("led_parts_order");
  std::ostringstream b;
  b << "fix wg all energy/work gravity\n"
    << ledger_fix(100, "") << "fix integr all nve/sphere\ntimestep 1e-6\nrun 10\n";
  const auto rb = run_ledger_deck(bad, {s}, b.str());
  const bool names =
      rb.screen.find("fix energy/work wg is defined before the ledger") != std::string::npos;
  std::printf("energy/work before the ledger: exit code %d, message names it: %s\n", rb.exit_code,
              names ? "yes" : "no");
  EXPECT_NE(rb.exit_code, 0) << rb.screen;
  EXPECT_TRUE(names) << rb.screen;
}

// ===========================================================================
// 7. The beater's work on a struck lump (fix energy/work ... mesh, as the
//    in-mill deck measures the ore power): a plate turning at omega = 100
//    rad/s about z strikes a sphere at rest at r = 0.3 m, head on (the plate
//    points straight down at contact), so relative to the plate the sphere
//    comes in at V = omega r = 30 m/s and leaves at e V: in the lab at
//    (1 + e) V. The plate, rigid and much heavier, then gave it
//        W = 1/2 m (1 + e)^2 V^2 + 1/2 m V^2 (1 - e^2) = (1 + e) m V^2,
//    its kinetic energy after plus what the contact's dashpot took (the
//    loss of a restitution e collision seen from the plate). Tolerances:
//    0.2 % against the closed form with the e the rebound shows (the plate
//    turns 0.3 deg in the contact, the power is integrated by the
//    trapezoidal rule), 5 % with the contact's nominal e = 0.5; the walls'
//    work (the forces on the sphere) against its kinetic energy to 1e-6.
// ===========================================================================
TEST(EnergyLedger, BeaterWorkOnAStruckSphereIsOnePlusETimesMVSquared) {
  const std::string dir = make_run_dir("led_beater");
  const double omega = 100.0, r = 0.3, R = 0.01, e = 0.5, rho = 2500.0;
  const double delta = 0.1;  // the plate starts 0.1 rad before contact
  const double phi0 = -0.5 * kPi - delta;
  const double u[3] = {std::cos(phi0), std::sin(phi0), 0};
  const double p0[3] = {0.1 * u[0], 0.1 * u[1], -0.1}, e1[3] = {0.25 * u[0], 0.25 * u[1], 0},
               e2[3] = {0, 0, 0.2};  // radial extent 0.1-0.35 m
  write_rect_stl(dir + "/plate.stl", p0, e1, e2);
  std::ostringstream d;
  d.precision(17);
  d << deck_head(0.6, kYoungs) << "fix plate all mesh/surface/stress file plate.stl type 1 "
    << "reference_point 0 0 0\n"
    << "fix rot all move/mesh mesh plate rotate origin 0 0 0 axis 0 0 1 period " << 2 * kPi / omega
    << "\n"
    << "create_atoms 1 single " << R << " " << -r << " 0 units box\n"
    << "set group all diameter " << 2 * R << " density " << rho << "\n"
    << ledger_fix(100, "")
    << "fix walls all wall/gran model hertz tangential history mesh n_meshes 1 meshes plate\n"
    << "fix work_walls all energy/work walls\n"
    << "fix work_beater all energy/work beater mesh plate omega " << omega
    << " axis 0 0 1 origin 0 0 0\n"
    << "fix integr all nve/sphere\n"
    << "variable vx equal vx[1]\nvariable vy equal vy[1]\n"
    << "timestep 1e-6\nthermo 1000\nrun 3000\n"
    << "print \"${vx} ${vy}\" file v1.txt\n";
  const auto res = run_deck(dir, d.str());
  ASSERT_EQ(res.exit_code, 0) << res.screen;
  const Ledger l = read_ledger(dir + "/ledger.csv");
  ASSERT_FALSE(l.rows.empty());
  ASSERT_TRUE(l.col.count("work_beater_J") && l.col.count("work_walls_J")) << res.screen;
  const auto v1 = read_table(dir + "/v1.txt");
  ASSERT_FALSE(v1.empty());
  const double m = rho * 4.0 / 3.0 * kPi * R * R * R, V = omega * r;
  const double speed = std::hypot(v1.front()[0], v1.front()[1]);
  const double e_seen = speed / V - 1.0;  // (1 + e) V in the lab
  const double ke = l.last("ke_trans_J") + l.last("ke_rot_J");
  const double w = l.last("work_beater_J");
  std::printf(
      "beater strike: lab speed after %.5f m/s ((1 + e) V = %.5f), e seen %.4f; work_beater "
      "%.6f J vs (1 + e_seen) m V^2 %.6f J (rel. %.2e, tol 2e-3) and (1 + 0.5) m V^2 %.6f J; "
      "work_walls %.9f J vs kinetic energy %.9f J; contact took %.6f J\n",
      speed, (1 + e) * V, e_seen, w, (1 + e_seen) * m * V * V, w / ((1 + e_seen) * m * V * V) - 1.0,
      (1 + e) * m * V * V, l.last("work_walls_J"), ke, w - l.last("work_walls_J"));
  ASSERT_GT(speed, V);  // struck
  EXPECT_NEAR(w / ((1 + e_seen) * m * V * V), 1.0, 2e-3);
  EXPECT_NEAR(w / ((1 + e) * m * V * V), 1.0, 5e-2);
  EXPECT_NEAR(l.last("work_walls_J") / ke, 1.0, 1e-6);
  // What the beater gave beyond the sphere's kinetic energy went into the
  // contact: 1/2 m V^2 (1 - e^2) in the closed form.
  EXPECT_NEAR((w - ke) / (0.5 * m * V * V * (1 - e_seen * e_seen)), 1.0, 5e-2);
}
