// Tests of fix bond/breakable driven through real liggghts-mill runs.
// Each test states its tolerance next to the assertion.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "bond_test_util.h"

using namespace mill_test;

namespace {

const double kMass = sphere_mass(kR);  // element mass [kg]
const double kKnA = kKn * kArea;       // axial stiffness of the bond [N/m]

// Two elements on the x axis, centre distance kL0, diameter 2 kR.
std::string pair_atoms() {
  std::ostringstream s;
  s.precision(17);
  s << "create_atoms 1 single 0 0 0 units box\n"
    << "create_atoms 1 single " << kL0 << " 0 0 units box\n"
    << "set group all diameter " << 2 * kR << " density " << kRho << "\n"
    << "group a1 id 1\ngroup a2 id 2\n";
  return s.str();
}

// Last row of a fix print table.
std::vector<double> last_row(const std::string &path) {
  const auto rows = read_table(path);
  return rows.empty() ? std::vector<double>{} : rows.back();
}

}  // namespace

// Free axial oscillation of two bonded elements: period 2 pi sqrt(m_red / (kn A)).
// Tolerance: 1 %.
TEST(BondPair, AxialOscillationPeriod) {
  const std::string dir = make_run_dir("period");
  const double mred = 0.5 * kMass;
  const double period = 2.0 * kPi * std::sqrt(mred / kKnA);
  const double dt = period / 400.0;
  std::ostringstream d;
  d.precision(17);
  d << deck_head(0.01) << pair_atoms() << "velocity a2 set 0.5 0 0 units box\n"
    << "velocity a1 set -0.5 0 0 units box\n"
    << "fix integr all nve/sphere\n"
    << bond_fix() << "timestep " << dt << "\n"
    << "variable t equal time\nvariable dx equal x[2]-x[1]\n"
    << "fix pr all print 1 \"${t} ${dx}\" file osc.txt screen no title none\n"
    << "thermo 1000\nrun 4000\n";
  const auto r = run_deck(dir, d.str());
  ASSERT_EQ(r.exit_code, 0) << r.screen;
  const auto rows = read_table(dir + "/osc.txt");
  ASSERT_GT(rows.size(), 3000u);
  const auto up = crossings_up(rows, 1, kL0);
  ASSERT_GE(up.size(), 5u);
  const double measured = (up.back() - up.front()) / (up.size() - 1);
  RecordProperty("period_measured_s", std::to_string(measured));
  RecordProperty("period_analytic_s", std::to_string(period));
  std::printf("axial period: measured %.6e s, analytic %.6e s, rel. error %.3e (tol 1e-2)\n",
              measured, period, std::fabs(measured / period - 1.0));
  EXPECT_NEAR(measured / period, 1.0, 0.01);
}

// Runs a pair whose atom 2 is moved at velocity (vx, vy, 0) with atom 1 held;
// returns the fix print rows (t |F2| intact tension shear energy).
// `fix` replaces the bond/breakable line (e.g. flat_joint_fix()).
std::vector<std::vector<double>> run_prescribed_pair(const std::string &dir, double vx, double vy,
                                                     int steps, double dt,
                                                     const std::string &fix = "") {
  std::ostringstream d;
  d.precision(17);
  d << deck_head(0.01) << pair_atoms()
    << (fix.empty() ? bond_fix("break_log breaks.txt dump_bonds bonds_*.txt every 500") : fix)
    << "fix mv a2 move linear "
    << vx << " " << vy << " 0\n"
    << "timestep " << dt << "\n"
    << "variable t equal time\n"
    << "variable f2 equal sqrt(fx[2]^2+fy[2]^2+fz[2]^2)\n"
    << "variable nb equal f_bonds[1]\nvariable nt equal f_bonds[3]\nvariable ns equal "
       "f_bonds[4]\nvariable en equal f_bonds[5]\n"
    << "fix pr all print 1 \"${t} ${f2} ${nb} ${nt} ${ns} ${en}\" file force.txt screen no title "
       "none\n"
    << "thermo 500\nrun " << steps << "\n";
  const auto r = run_deck(dir, d.str());
  EXPECT_EQ(r.exit_code, 0) << r.screen;
  return read_table(dir + "/force.txt");
}

// The peak of |F| (column 1) against `expected`, printed and checked to 1 %.
void expect_peak_force(const std::vector<std::vector<double>> &rows, double expected,
                       const char *what) {
  ASSERT_FALSE(rows.empty());
  double fmax = 0.0;
  for (const auto &row : rows) fmax = std::max(fmax, row[1]);
  std::printf("%s: peak force %.6g N, expected %.6g N, rel. error %.3e (tol 1e-2)\n", what, fmax,
              expected, std::fabs(fmax / expected - 1.0));
  EXPECT_NEAR(fmax / expected, 1.0, 0.01);
}

// Slow pull: the bond breaks in tension when |F| reaches sigma_t A. Tolerance 1 %.
TEST(BondPair, SlowPullBreaksAtTensileStrength) {
  const std::string dir = make_run_dir("pull");
  const auto rows = run_prescribed_pair(dir, 0.2, 0.0, 2000, 1e-8);
  expect_peak_force(rows, kSigmaT * kArea, "pull");
  EXPECT_EQ(rows.back()[2], 0.0) << "bond still intact at the end";
  EXPECT_EQ(rows.back()[3], 1.0) << "not broken in tension";
  EXPECT_EQ(rows.back()[4], 0.0);
  // The break log names the mode and the pair; periodic bond dumps show the
  // bond before (steps 500, 1000) and not after (1500, 2000) the break.
  std::ifstream log(dir + "/breaks.txt");
  std::stringstream ls;
  ls << log.rdbuf();
  EXPECT_NE(ls.str().find(" tension 1 2 "), std::string::npos) << ls.str();
  EXPECT_EQ(read_bonds(dir + "/bonds_500.txt").size(), 1u);
  EXPECT_EQ(read_bonds(dir + "/bonds_1000.txt").size(), 1u);
  EXPECT_EQ(read_bonds(dir + "/bonds_1500.txt").size(), 0u);
  std::ifstream dump(dir + "/bonds_2000.txt");
  std::stringstream ds;
  ds << dump.rdbuf();
  EXPECT_NE(ds.str().find("# step 2000\n"), std::string::npos) << ds.str();
  EXPECT_NE(ds.str().find("# columns: tag_i tag_j\n"), std::string::npos) << ds.str();
}

// Slow shear: breaks in shear when |F| reaches cohesion x A (no normal
// compression, so the Mohr-Coulomb term is zero). Tolerance 1 %.
TEST(BondPair, SlowShearBreaksAtShearStrength) {
  const std::string dir = make_run_dir("shear");
  const auto rows = run_prescribed_pair(dir, 0.0, 0.5, 2000, 1e-8);
  expect_peak_force(rows, kCohesion * kArea, "shear");
  EXPECT_EQ(rows.back()[2], 0.0) << "bond still intact at the end";
  EXPECT_EQ(rows.back()[3], 0.0);
  EXPECT_EQ(rows.back()[4], 1.0) << "not broken in shear";
}

// Compression to 24x the tensile strength (in magnitude) must not break the
// bond; the force must be the elastic knA*delta. Tolerance: exact count, 1 % force.
TEST(BondPair, CompressionDoesNotBreak) {
  const std::string dir = make_run_dir("compress");
  const int steps = 500;
  const double dt = 1e-8, v = -10.0;
  const auto rows = run_prescribed_pair(dir, v, 0.0, steps, dt);
  ASSERT_EQ(rows.size(), static_cast<size_t>(steps));
  const double delta = std::fabs(v) * dt * steps;
  const double expected = kKnA * delta;
  std::printf("compression: stress %.3g Pa (tensile strength %.3g Pa), force %.6g N vs %.6g N\n",
              expected / kArea, kSigmaT, rows.back()[1], expected);
  EXPECT_GT(expected / kArea, 10 * kSigmaT);
  EXPECT_EQ(rows.back()[2], 1.0) << "compressed bond broke";
  EXPECT_EQ(rows.back()[3] + rows.back()[4], 0.0);
  EXPECT_NEAR(rows.back()[1] / expected, 1.0, 0.01);
}

// A free cluster of bonded elements vibrating without damping: kinetic +
// rotational + bond energy drifts < 0.1 % over 100k steps.
TEST(BondCluster, EnergyConservedWithoutDamping) {
  const std::string dir = make_run_dir("energy");
  std::ostringstream d;
  d.precision(17);
  d << deck_head(0.01);
  // 3 x 3 x 2 simple-cubic block with a few stray velocities (deterministic).
  int id = 0;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        d << "create_atoms 1 single " << i * kL0 << " " << j * kL0 << " " << k * kL0
          << " units box\n";
        ++id;
      }
  d << "set group all diameter " << 2 * kR << " density " << kRho << "\n";
  unsigned s = 12345u;
  auto rnd = [&s]() {
    s = s * 1103515245u + 12345u;
    return ((s >> 8) & 0xffff) / 65535.0 - 0.5;
  };
  for (int a = 1; a <= id; ++a)
    d << "group g" << a << " id " << a << "\nvelocity g" << a << " set " << 0.2 * rnd() << " "
      << 0.2 * rnd() << " " << 0.2 * rnd() << " units box\n";
  // dt well below the bond critical step (printed by the fix, ~4e-7 s here).
  d << "fix integr all nve/sphere\n"
    << bond_fix() << "timestep 4e-9\n"
    << "compute rke all erotate/sphere\n"
    << "variable t equal step\nvariable e equal ke+c_rke+f_bonds[5]\n"
    << "variable k equal ke\nvariable r equal c_rke\nvariable b equal f_bonds[5]\n"
    << "fix pr all print 100 \"${t} ${e} ${k} ${r} ${b}\" file energy.txt screen no title none\n"
    << "thermo 10000\nrun 100000\n";
  const auto r = run_deck(dir, d.str());
  ASSERT_EQ(r.exit_code, 0) << r.screen;
  const auto rows = read_table(dir + "/energy.txt");
  ASSERT_GE(rows.size(), 1000u);
  const double e0 = rows.front()[1];
  double worst = 0.0, bond_max = 0.0, rot_max = 0.0;
  for (const auto &row : rows) {
    worst = std::max(worst, std::fabs(row[1] / e0 - 1.0));
    bond_max = std::max(bond_max, row[4]);
    rot_max = std::max(rot_max, row[3]);
  }
  std::printf(
      "energy: E0 %.6e J, max |E/E0-1| %.3e over %zu samples (tol 1e-3); peak bond "
      "energy %.3e J, peak rotational %.3e J\n",
      e0, worst, rows.size(), bond_max, rot_max);
  EXPECT_GT(bond_max, 0.2 * e0) << "cluster does not vibrate";
  EXPECT_GT(rot_max, 0.0) << "no rotation exercised";
  EXPECT_LT(worst, 1e-3);
}

// Cantilever of 11 elements clamped at atom 1, tip load P: static tip
// deflection = P L^3 / (3 E_b I) with I = pi R^4 / 4 of the bond disc.
// Tolerance: 5 %.
TEST(Cantilever, TipDeflectionMatchesEulerBernoulli) {
  const std::string dir = make_run_dir("cantilever");
  const int n = 10;  // bonds
  const double load = 0.05;
  const double inertia = 0.25 * kPi * std::pow(kR, 4);
  const double length = n * kL0;
  const double expected = load * std::pow(length, 3) / (3.0 * kEb * inertia);
  const double mu = kMass / kL0;
  const double omega1 = 3.516 * std::sqrt(kEb * inertia / (mu * std::pow(length, 4)));
  const double gamma = 2.0 * omega1 * kMass;  // critical damping of mode 1
  std::ostringstream d;
  d.precision(17);
  d << deck_head(0.03);
  for (int i = 0; i <= n; ++i) d << "create_atoms 1 single " << i * kL0 << " 0 0 units box\n";
  d << "set group all diameter " << 2 * kR << " density " << kRho << "\n"
    << "group clamp id 1\ngroup beam subtract all clamp\ngroup tip id " << n + 1 << "\n"
    << "fix integr beam nve/sphere\n"
    << bond_fix() << "fix load tip addforce 0 " << load << " 0\n"
    << "fix damp beam viscous " << gamma << "\n"
    << "timestep 5e-8\n"
    << "variable t equal time\nvariable y equal y[" << n + 1 << "]\n"
    << "variable nb equal f_bonds[1]\n"
    << "fix pr all print 20 \"${t} ${y} ${nb}\" file tip.txt screen no title none\n"
    << "thermo 5000\nrun 40000\n";
  const auto r = run_deck(dir, d.str());
  ASSERT_EQ(r.exit_code, 0) << r.screen;
  const auto rows = read_table(dir + "/tip.txt");
  ASSERT_GT(rows.size(), 1000u);
  double sum = 0.0;
  int cnt = 0;
  for (size_t k = rows.size() - 250; k < rows.size(); ++k, ++cnt) sum += rows[k][1];
  const double measured = sum / cnt;
  std::printf(
      "cantilever: tip deflection %.6e m, Euler-Bernoulli %.6e m, rel. error %.3e "
      "(tol 5e-2)\n",
      measured, expected, std::fabs(measured / expected - 1.0));
  EXPECT_EQ(rows.back()[2], n);
  EXPECT_NEAR(measured / expected, 1.0, 0.05);
}

namespace {

// A bonded 4x4x3 block flung apart by a velocity field so that bonds break
// and fragments collide; shared by the restart tests.
std::string burst_setup() {
  std::ostringstream d;
  d.precision(17);
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i)
        d << "create_atoms 1 single " << (i - 1.5) * kL0 << " " << j * kL0 << " " << k * kL0
          << " units box\n";
  // Centred on x = 0, where a 2-rank run splits the box.
  d << "set group all diameter " << 2 * kR << " density " << kRho << "\n"
    << "variable vx atom 300*x\nvariable vy atom -200*(y-0.00315)\n"
    << "variable vz atom 100*(z-0.0021)\n"
    << "velocity all set v_vx v_vy v_vz units box\n";
  return d.str();
}


const char *kBurstFix =
    "fix bonds all bond/breakable modulus 2e10 stiffness_ratio 2.5 tensile_strength 5e6 "
    "cohesion 5e6 friction_angle 30 gap 0.2 max_bonds 16 dump_bonds bonds.txt\n";

}  // namespace

// Straight run vs a run split by write_restart / read_restart (the two halves
// on np_first / np_second ranks); positions must agree within tol [m]. With
// during_run the file is written by `restart 1000` inside a longer run (at the
// end of step 1000, while the fix holds the bond history in its bond list),
// not by write_restart between runs. (LIGGGHTS reneighbours on a restart step,
// so the fix's pre_exchange has stored the history by then.)
void check_restart(int np_first, int np_second, double tol, bool during_run = false,
                   const std::string &fix = kBurstFix) {
  const std::string dir =
      make_run_dir("restart" + std::to_string(np_first) + std::to_string(np_second) +
                   (during_run ? "r" : "") + (fix == kBurstFix ? "" : "fj"));
  const std::string tail =
      "variable nb equal f_bonds[2]\nthermo_style custom step atoms f_bonds[1] f_bonds[2]\n"
      "thermo 500\n";
  std::ostringstream straight, first, second;
  straight << head_split_x(0.05) << burst_setup() << "fix integr all nve/sphere\n"
           << fix << "timestep 5e-8\n"
           << tail << "run 2000\n"
           << "print \"${nb}\" file straight_nb.txt\n"
           << "write_dump all custom straight.dump id x y z modify format \"%d %.17g %.17g "
              "%.17g\"\n";
  first << head_split_x(0.05) << burst_setup() << "fix integr all nve/sphere\n"
        << fix << "timestep 5e-8\n"
        << tail
        << (during_run ? "restart 1000 mid.restart\nrun 1500\n" : "run 1000\nwrite_restart mid.restart\n");
  // `restart N file` appends the step to the file name.
  second << "atom_modify map array\nread_restart " << (during_run ? "mid.restart.1000" : "mid.restart")
         << "\nnewton off\n"
         << "communicate single vel yes\nneighbor 0.0002 bin\nneigh_modify delay 0\n"
         << "hard_particles yes\n"
         << "fix m1 all property/global youngsModulus peratomtype 5e9\n"
         << "fix m2 all property/global poissonsRatio peratomtype 0.25\n"
         << "fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5\n"
         << "fix m4 all property/global coefficientFriction peratomtypepair 1 0.5\n"
         << "pair_style gran model hertz tangential history\npair_coeff * *\n"
         << "fix integr all nve/sphere\n"
         << fix << "timestep 5e-8\n"
         << tail << "run 1000\n"
         << "print \"${nb}\" file restart_nb.txt\n"
         << "write_dump all custom restart.dump id x y z modify format \"%d %.17g %.17g "
            "%.17g\"\n";
  auto r = run_deck(dir, straight.str());
  ASSERT_EQ(r.exit_code, 0) << r.screen;
  r = run_deck(dir, first.str(), np_first);
  ASSERT_EQ(r.exit_code, 0) << r.screen;
  std::rename((dir + "/screen.txt").c_str(), (dir + "/screen_first.txt").c_str());
  r = run_deck(dir, second.str(), np_second);
  ASSERT_EQ(r.exit_code, 0) << r.screen;
  const auto nb_straight = last_row(dir + "/straight_nb.txt");
  const auto nb_restart = last_row(dir + "/restart_nb.txt");
  ASSERT_FALSE(nb_straight.empty());
  ASSERT_FALSE(nb_restart.empty());
  const auto ps = read_positions(dir + "/straight.dump");
  const auto pr = read_positions(dir + "/restart.dump");
  ASSERT_EQ(ps.size(), 48u);
  ASSERT_EQ(pr.size(), 48u);
  double worst = 0.0;
  for (const auto &kv : ps)
    for (int c = 0; c < 3; ++c)
      worst = std::max(worst, std::fabs(kv.second[c] - pr.at(kv.first)[c]));
  std::printf(
      "restart (%d then %d ranks): broken %g (straight) vs %g (restarted), max |dx| %.3e m "
      "(tol %.0e)\n",
      np_first, np_second, nb_straight[0], nb_restart[0], worst, tol);
  EXPECT_GT(nb_straight[0], 0.0) << "scenario breaks no bond: test would be vacuous";
  if (np_first > 1) {  // the first half must really have been split over the ranks
    std::ifstream in(dir + "/screen_first.txt");
    std::stringstream ss;
    ss << in.rdbuf();
    EXPECT_NE(ss.str().find("2 by 1 by 1 MPI processor grid"), std::string::npos);
    EXPECT_EQ(ss.str().find("Nlocal:    24 ave 48 max 0 min"), std::string::npos)
        << "all atoms on one rank";
  }
  EXPECT_EQ(nb_straight[0], nb_restart[0]);
  EXPECT_LT(worst, tol);
}

// write_restart mid-run + read_restart gives the same broken-bond count and
// positions as a straight run. Tolerance: equal counts, |dx| < 1e-12 m.
TEST(Restart, RestartedRunMatchesStraightRun) { check_restart(1, 1, 1e-12); }

// Written on 2 ranks, read on 1: per-atom bond data is redistributed by atom.
// Tolerance: equal counts, |dx| < 1e-9 m (summation order differs, contacts
// amplify round-off).
TEST(Restart, RestartAcrossRankCounts) { check_restart(2, 1, 1e-9); }

// The restart file written during a run (periodic `restart`) holds the bond
// history of that step. Tolerance: equal counts, |dx| < 1e-12 m.
TEST(Restart, RestartWrittenDuringRunMatchesStraightRun) { check_restart(1, 1, 1e-12, true); }

namespace {

// A bonded simple-cubic ball (~300 elements) hitting a wall at 10 m/s; the
// processor split (x) runs through the ball. Returns {bonds at start, broken
// at end, fragments at end}.
const char *kImpactFix =
    "fix bonds all bond/breakable modulus 1e10 stiffness_ratio 2.5 tensile_strength 4e6 "
    "cohesion 4e6 friction_angle 30 gap 0.2 max_bonds 16 dump_bonds bonds.txt\n";

std::array<double, 3> run_impact(int nprocs, const std::string &fix = kImpactFix) {
  const std::string dir =
      make_run_dir("impact" + std::to_string(nprocs) + (fix == kImpactFix ? "" : "fj"));
  std::ostringstream d;
  d.precision(17);
  d << bonded_ball_head(0.02, 0.03)
    << "velocity all set 0 0 -10 units box\n"
    << "fix wall all wall/gran model hertz tangential history primitive type 1 zplane 0.0\n"
    << "fix integr all nve/sphere\n"
    << fix << "timestep 5e-8\n"
    << "variable n0 equal f_bonds[1]\nvariable na equal atoms\n"
    << "thermo_style custom step atoms f_bonds[1] f_bonds[2] f_bonds[3] f_bonds[4]\n"
    << "thermo 500\nrun 0\n"
    << "print \"START ${n0} ${na}\" file start.txt\n"
    << "run 6000\n"
    << "variable nb equal f_bonds[2]\nvariable ni equal f_bonds[1]\n"
    << "print \"END ${nb} ${ni}\" file end.txt\n"
    << "write_dump all custom atoms_end.dump id f_bonds\n";
  const auto r = run_deck(dir, d.str(), nprocs);
  EXPECT_EQ(r.exit_code, 0) << r.screen;
  std::ifstream s(dir + "/start.txt"), e(dir + "/end.txt");
  std::string w;
  double n0 = -1, na = -1, nb = -1, ni = -1;
  s >> w >> n0 >> na;
  e >> w >> nb >> ni;
  const auto bonds = read_bonds(dir + "/bonds.txt");
  const int frags = count_fragments(static_cast<int>(na), bonds);
  std::printf(
      "impact on %d rank(s): %g atoms, %g bonds, %g broken, %zu intact in dump, %d "
      "fragments\n",
      nprocs, na, n0, nb, bonds.size(), frags);
  EXPECT_EQ(static_cast<double>(bonds.size()), ni) << "dump disagrees with the intact count";
  // Parallel bonds break whole: broken + intact = created. (A flat joint
  // counts broken elements.)
  if (fix == kImpactFix) {
    EXPECT_EQ(ni, n0 - nb) << "counters disagree";
  }
  // Per-atom intact-bond counts (f_ID in dump custom) sum to twice the bonds.
  double count_sum = 0.0;
  int lines = 0;
  {
    std::ifstream in(dir + "/atoms_end.dump");
    std::string line;
    bool atoms = false;
    while (std::getline(in, line)) {
      if (line.rfind("ITEM:", 0) == 0) {
        atoms = line.rfind("ITEM: ATOMS", 0) == 0;
        continue;
      }
      std::istringstream ls(line);
      double id, c;
      if (atoms && (ls >> id >> c)) {
        count_sum += c;
        ++lines;
      }
    }
  }
  EXPECT_EQ(lines, static_cast<int>(na));
  EXPECT_EQ(count_sum, 2.0 * bonds.size()) << "per-atom bond counts disagree with the dump";
  return {n0, nb, static_cast<double>(frags)};
}

}  // namespace

// Same impact on 1 and 2 ranks: identical initial bond count; broken fraction
// and fragment count within 2 % (relative).
TEST(Mpi, ImpactOneVersusTwoRanks) {
  const auto one = run_impact(1);
  const auto two = run_impact(2);
  ASSERT_GT(one[0], 0.0);
  EXPECT_EQ(one[0], two[0]) << "bond counts before impact differ";
  const double f1 = one[1] / one[0], f2 = two[1] / two[0];
  std::printf(
      "impact: broken fraction %.4f (1 rank) vs %.4f (2 ranks); fragments %g vs %g "
      "(tol 2%%)\n",
      f1, f2, one[2], two[2]);
  EXPECT_GT(f1, 0.01) << "impact breaks almost nothing: test would be vacuous";
  EXPECT_NEAR(f2 / f1, 1.0, 0.02);
  EXPECT_NEAR(two[2] / one[2], 1.0, 0.02);
}

namespace {

// A vibrating bonded 4x3x3 block that flies across the x = 0 processor
// boundary (atoms migrate with their bonds). Returns final "id x y z" text and
// the last (intact, energy) values.
std::pair<std::map<int, std::array<double, 3>>, std::vector<double>> run_migration(int nprocs) {
  const std::string dir = make_run_dir("migrate" + std::to_string(nprocs));
  std::ostringstream d;
  d.precision(17);
  d << head_split_x(0.02);
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 4; ++i)
        d << "create_atoms 1 single " << -0.009 + i * kL0 << " " << j * kL0 << " " << k * kL0
          << " units box\n";
  d << "set group all diameter " << 2 * kR << " density " << kRho << "\n"
    << "variable vx atom 50.0+200*(y-0.0021)\nvariable vy atom -150*(z-0.0021)\n"
    << "variable vz atom 100*(x+0.0058)\n"
    << "velocity all set v_vx v_vy v_vz units box\n"
    << "fix integr all nve/sphere\n"
    << bond_fix() << "timestep 2e-8\n"
    << "variable n equal f_bonds[1]\nvariable e equal f_bonds[5]\n"
    << "thermo 2000\nrun 12000\n"
    << "print \"${n} ${e}\" file end.txt\n"
    << "write_dump all custom final.dump id x y z modify format \"%d %.17g %.17g %.17g\"\n";
  const auto r = run_deck(dir, d.str(), nprocs);
  EXPECT_EQ(r.exit_code, 0) << r.screen;
  return {read_positions(dir + "/final.dump"), last_row(dir + "/end.txt")};
}

}  // namespace

// Atoms carry their bonds when they change rank (pack/unpack_exchange): a
// block crossing the processor boundary on 2 ranks matches the 1-rank run.
// Tolerance: equal intact count, |dx| < 1e-12 m, bond energy within 1e-9.
TEST(Mpi, BondsMigrateWithAtoms) {
  const auto one = run_migration(1);
  const auto two = run_migration(2);
  ASSERT_EQ(one.first.size(), 36u);
  ASSERT_EQ(two.first.size(), 36u);
  ASSERT_EQ(one.second.size(), 2u);
  ASSERT_EQ(two.second.size(), 2u);
  double worst = 0.0, xmin = 1.0;
  for (const auto &kv : one.first) {
    xmin = std::min(xmin, kv.second[0]);
    for (int c = 0; c < 3; ++c)
      worst = std::max(worst, std::fabs(kv.second[c] - two.first.at(kv.first)[c]));
  }
  std::printf(
      "migration: intact %g vs %g, bond energy %.9e vs %.9e J, max |dx| %.3e m, "
      "min x at end %.4f m (tol 1e-12 m)\n",
      one.second[0], two.second[0], one.second[1], two.second[1], worst, xmin);
  EXPECT_GT(xmin, 0.0) << "block did not cross the processor boundary";
  EXPECT_GT(one.second[1], 0.0) << "block does not vibrate";
  EXPECT_EQ(one.second[0], two.second[0]);
  EXPECT_NEAR(two.second[1] / one.second[1], 1.0, 1e-9);
  EXPECT_LT(worst, 1e-12);
}

// The fix prints the bond critical time step and warns when dt exceeds it.
// For the test pair the bound is about 5e-7 s (the rotational one), so
// dt = 1e-6 s must warn and dt = 1e-8 s must not.
TEST(BondTimeStep, WarnsWhenDeckStepExceedsBondStep) {
  for (const double dt : {1e-6, 1e-8}) {
    const std::string dir = make_run_dir("dtwarn");
    std::ostringstream d;
    d << deck_head(0.01) << pair_atoms() << bond_fix() << "fix integr all nve/sphere\n"
      << "timestep " << dt << "\nrun 0\n";
    const auto r = run_deck(dir, d.str());
    ASSERT_EQ(r.exit_code, 0) << r.screen;
    EXPECT_NE(r.screen.find("fix bond/breakable: critical time step of bond springs"),
              std::string::npos);
    const bool warned =
        r.screen.find("WARNING: fix bond/breakable: time step") != std::string::npos;
    EXPECT_EQ(warned, dt > 1e-7) << "dt " << dt << "\n" << r.screen;
  }
}

// A bond whose partner has vanished is an error naming both atoms, never a
// silent break.
TEST(BondErrors, MissingPartnerIsAnError) {
  const std::string dir = make_run_dir("err_partner");
  const auto r = run_deck(dir, deck_head(0.01) + pair_atoms() + bond_fix() +
                                   "fix integr all nve/sphere\ntimestep 1e-8\nrun 0\n"
                                   "delete_atoms group a2\nrun 10\n");
  EXPECT_NE(r.screen.find("fix bond/breakable: bond partner 2 of atom 1 is neither owned nor a "
                          "ghost"),
            std::string::npos)
      << r.screen;
  EXPECT_NE(r.exit_code, 0);
}

// A plain LIGGGHTS deck (no project style) gives bitwise the same trajectory
// with liggghts-mill as with Debian's stock `liggghts`, with the same command
// line (-var, -echo). Tolerance: identical output.
TEST(Executable, PlainDeckMatchesStockLiggghts) {
  const std::string stock = MILL_LIGGGHTS_STOCK_EXE;
  if (stock.empty() || stock.find("NOTFOUND") != std::string::npos)
    GTEST_SKIP() << "stock liggghts not installed";
  std::ostringstream d;
  d.precision(17);
  d << deck_head(0.01) << "create_atoms 1 single 0 0 0 units box\n"
    << "create_atoms 1 single 0.00205 0.0004 0 units box\n"
    << "set group all diameter " << 2 * kR << " density " << kRho << "\n"
    << "group a2 id 2\nvelocity a2 set ${speed} 0 0 units box\n"
    << "fix integr all nve/sphere\ntimestep 1e-8\nrun 3000\n"
    << "write_dump all custom final.dump id x y z vx vy vz omegaz modify format \"%d %.17g "
       "%.17g %.17g %.17g %.17g %.17g %.17g\"\n";
  const std::string dir_mill = make_run_dir("plain_mill"), dir_stock = make_run_dir("plain_stock");
  const auto rm = run_deck(dir_mill, d.str(), 1, "", "-var speed -2.0 -echo screen");
  const auto rs = run_deck(dir_stock, d.str(), 1, stock, "-var speed -2.0 -echo screen");
  ASSERT_EQ(rm.exit_code, 0) << rm.screen;
  ASSERT_EQ(rs.exit_code, 0) << rs.screen;
  EXPECT_NE(rm.screen.find("velocity a2 set ${speed}"), std::string::npos) << "-echo ignored";
  std::ifstream fm(dir_mill + "/final.dump"), fs(dir_stock + "/final.dump");
  std::stringstream sm, ss;
  sm << fm.rdbuf();
  ss << fs.rdbuf();
  ASSERT_FALSE(sm.str().empty());
  EXPECT_EQ(sm.str(), ss.str());
  const auto rows = read_table(dir_mill + "/final.dump");
  ASSERT_FALSE(rows.empty());
  EXPECT_LT(rows.back()[4], 0.0) << "-var speed not applied / no collision";
}

// User errors name the keyword and the value (house style).
struct BadDeck {
  const char *name;
  std::string fix_or_setup;
  const char *expected;
  const char *drop_from_head;  // a head line to leave out, or ""
};

// Prints a bad deck by its name in test listings.
void PrintTo(const BadDeck &bad, std::ostream *os) { *os << bad.name; }

class BondErrors : public ::testing::TestWithParam<BadDeck> {};

TEST_P(BondErrors, MessageNamesKeyAndValue) {
  const BadDeck &bad = GetParam();
  const std::string dir = make_run_dir(std::string("err_") + bad.name);
  std::string head = deck_head(0.01);
  const std::string drop = bad.drop_from_head;
  if (!drop.empty()) head.erase(head.find(drop), drop.size());
  const auto r = run_deck(dir, head + pair_atoms() + bad.fix_or_setup + "run 1\n");
  EXPECT_NE(r.screen.find(bad.expected), std::string::npos)
      << "expected message: " << bad.expected << "\ngot:\n"
      << r.screen;
  EXPECT_EQ(r.screen.find("Loop time"), std::string::npos) << "run went ahead";
}

INSTANTIATE_TEST_SUITE_P(
    Keywords, BondErrors,
    ::testing::Values(
        BadDeck{"ratio",
                "fix bonds all bond/breakable modulus 2e10 stiffness_ratio 0 "
                "tensile_strength 2e7 cohesion 2e7\n",
                "fix bond/breakable: stiffness_ratio must be > 0, got 0", ""},
        BadDeck{"unknown",
                "fix bonds all bond/breakable modulus 2e10 stiffness_ratio 2 "
                "tensile_strength 2e7 cohesion 2e7 frction_angle 30\n",
                "fix bond/breakable: unknown keyword 'frction_angle'", ""},
        BadDeck{"number",
                "fix bonds all bond/breakable modulus 2x10 stiffness_ratio 2 "
                "tensile_strength 2e7 cohesion 2e7\n",
                "fix bond/breakable: modulus expects a number, got '2x10'", ""},
        BadDeck{"missing",
                "fix bonds all bond/breakable modulus 2e10 stiffness_ratio 2 cohesion 2e7\n",
                "fix bond/breakable: keyword 'tensile_strength' is required", ""},
        BadDeck{"maxbonds",
                "fix bonds all bond/breakable modulus 2e10 stiffness_ratio 2 "
                "tensile_strength 2e7 cohesion 2e7 max_bonds 0\n",
                "fix bond/breakable: max_bonds must be an integer in [1, 64], got 0", ""},
        BadDeck{"nomap",
                "fix bonds all bond/breakable modulus 2e10 stiffness_ratio 2 "
                "tensile_strength 2e7 cohesion 2e7\n",
                "fix bond/breakable: needs the atom map", "atom_modify map array\n"}),
    [](const ::testing::TestParamInfo<BadDeck> &info) { return std::string(info.param.name); });

// fix bond/flatjoint through the same runs: the pair's break loads, restart
// and the 1- against 2-rank impact (the interface's closed forms are in
// test_flat_joint.cpp).

// Slow pull of a flat-jointed pair (2 x 4 elements): every element reaches
// sigma_t together, |F| = sigma_t A at the break (1 %); the counters count
// elements, the break log one line per step with breaks.
TEST(FlatJointPair, SlowPullBreaksAtTensileStrength) {
  const std::string dir = make_run_dir("fj_pull");
  const auto rows = run_prescribed_pair(
      dir, 0.2, 0.0, 2000, 1e-8, flat_joint_fix("break_log breaks.txt dump_bonds bonds.txt"));
  expect_peak_force(rows, kSigmaT * kArea, "flat joint pull");
  // Output 5, the elastic energy in the elements, at the peak: a pure stretch
  // stores F^2 / (2 kn A) (1e-6: the same step's force and energy).
  size_t peak = 0;
  for (size_t k = 0; k < rows.size(); ++k)
    if (rows[k][1] > rows[peak][1]) peak = k;
  const double f = rows[peak][1];
  EXPECT_NEAR(rows[peak][5] / (f * f / (2.0 * kKnA)), 1.0, 1e-6) << "f_bonds[5] at the peak";
  EXPECT_EQ(rows.back()[5], 0.0) << "energy left in an open interface";
  EXPECT_EQ(rows.back()[2], 0.0) << "interface still bonded at the end";
  EXPECT_EQ(rows.back()[3], 8.0) << "not all 8 elements broke in tension";
  EXPECT_EQ(rows.back()[4], 0.0);
  EXPECT_EQ(rows.back()[1], 0.0) << "an open interface must carry nothing";
  EXPECT_TRUE(read_bonds(dir + "/bonds.txt").empty());
}

// Slow shear without rotation: uniform shear on every element, which break
// together at tau = c: |F| = c A (1 %); afterwards the open pair (no
// compression) carries no friction.
TEST(FlatJointPair, SlowShearBreaksAtCohesion) {
  const std::string dir = make_run_dir("fj_shear");
  const auto rows = run_prescribed_pair(dir, 0.0, 0.5, 2000, 1e-8, flat_joint_fix());
  expect_peak_force(rows, kCohesion * kArea, "flat joint shear");
  EXPECT_EQ(rows.back()[2], 0.0);
  EXPECT_EQ(rows.back()[4], 8.0) << "not all 8 elements broke in shear";
  EXPECT_LT(rows.back()[1], 1e-6 * kCohesion * kArea);
}

namespace {
const std::string kBurstFlatJoint =
    "fix bonds all bond/flatjoint modulus 2e10 stiffness_ratio 2.5 tensile_strength 5e6 "
    "cohesion 5e6 friction_angle 30 gap 0.2 max_bonds 16 elements 1 3 dump_bonds bonds.txt\n";
}  // namespace

// The interfaces' element histories go through restart files (written
// between runs, and on 2 ranks read on 1). Tolerances as for the parallel bond.
TEST(FlatJointRestart, RestartedRunMatchesStraightRun) {
  check_restart(1, 1, 1e-12, false, kBurstFlatJoint);
}
TEST(FlatJointRestart, RestartAcrossRankCounts) { check_restart(2, 1, 1e-9, false, kBurstFlatJoint); }

// The bonded ball's impact with flat joints on 1 and 2 ranks: the same bond
// count; broken elements and fragments within 2 %.
TEST(FlatJointMpi, ImpactOneVersusTwoRanks) {
  const std::string fix =
      "fix bonds all bond/flatjoint modulus 1e10 stiffness_ratio 2.5 tensile_strength 4e6 "
      "cohesion 4e6 friction_angle 30 gap 0.2 max_bonds 16 elements 1 3 dump_bonds bonds.txt\n";
  const auto one = run_impact(1, fix);
  const auto two = run_impact(2, fix);
  ASSERT_GT(one[0], 0.0);
  EXPECT_EQ(one[0], two[0]) << "bond counts before impact differ";
  std::printf("flat joint impact: broken elements %g (1 rank) vs %g (2 ranks); fragments %g vs %g\n",
              one[1], two[1], one[2], two[2]);
  EXPECT_GT(one[1], 0.01 * 3 * one[0]) << "impact breaks almost nothing: test would be vacuous";
  EXPECT_NEAR(two[1] / one[1], 1.0, 0.02);
  EXPECT_NEAR(two[2] / one[2], 1.0, 0.02);
}
