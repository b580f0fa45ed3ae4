// fix bond/breakable's packed kernel (`lanes`, liggghts_styles/bond_lanes.h):
// evaluating 2 or 4 intact bonds per instruction stream must give bitwise the
// results of one bond at a time, since each lane does the same IEEE
// operations in the same order. Checked on a bonded ball that strikes a
// wall hard enough to break bonds in tension and shear (the rare one-bond
// tail of a pack), with every option of the law that the pack evaluates.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "bond_test_util.h"
#include "deck_runner.h"

using namespace mill_test;

namespace {

struct LaneRun {
  std::string atoms;   // final x, v, omega, f, torque of every atom, %.17g
  std::string bonds;   // intact bonds at the end (dump_bonds)
  std::string breaks;  // every break event (break_log)
  double packed = -1;  // output 7: share of evaluations in packs
  double broken = -1;  // output 2
  double intact = -1;  // output 1
};

std::string slurp(const std::string &path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A simple-cubic ball of about 300 elements, spinning and moving at 12 m/s
// onto a wall at z = 0, 4000 steps; `keys` are added to the fix line.
// `style`: bond/breakable (parallel bonds) or bond/flatjoint (interfaces).
LaneRun run_ball(const std::string &name, int lanes, const std::string &keys, int nprocs = 1,
                 const std::string &style = "bond/breakable") {
  const std::string dir =
      make_run_dir("lanes_" + name + "_" + std::to_string(lanes) + "_np" + std::to_string(nprocs));
  std::ostringstream d;
  d.precision(17);
  d << bonded_ball_head(0.03, 0.04)
    // 12 m/s down, spinning at 800 rad/s about y through the centre
    << "variable vx atom 800*(z-0.0105)\nvariable vz atom -12-800*x\n"
    << "velocity all set v_vx 0 v_vz units box\n"
    << "fix wall all wall/gran model hertz tangential history primitive type 1 zplane 0.0\n"
    << "fix integr all nve/sphere\n"
    << "fix bonds all " << style << " modulus 1e10 stiffness_ratio 2.5 tensile_strength 4e6 "
    << "cohesion 6e6 friction_angle 30 gap 0.2 max_bonds 16 lanes " << lanes << " " << keys
    << " break_log breaks.txt dump_bonds bonds.txt\n"
    << "timestep 5e-8\nthermo 1000\nthermo_style custom step f_bonds[1] f_bonds[2] f_bonds[7]\n"
    << "run 4000\n"
    << "variable ni equal f_bonds[1]\nvariable nb equal f_bonds[2]\n"
    << "variable pk equal f_bonds[7]\n"
    << "print \"${ni} ${nb} ${pk}\" file end.txt\n"
    << "write_dump all custom atoms.dump id x y z vx vy vz omegax omegay omegaz fx fy fz tqx "
       "tqy tqz modify sort id format \"%d";
  for (int k = 0; k < 15; ++k) d << " %.17g";  // id, then 15 values at full precision
  d << "\"\n";
  const std::string deck = d.str();
  const auto r = run_deck(dir, deck, nprocs);
  EXPECT_EQ(r.exit_code, 0) << r.screen;
  LaneRun out;
  out.atoms = slurp(dir + "/atoms.dump");
  out.bonds = slurp(dir + "/bonds.txt");
  out.breaks = slurp(dir + "/breaks.txt");
  std::ifstream end(dir + "/end.txt");
  end >> out.intact >> out.broken >> out.packed;
  return out;
}

// Runs lanes 1, 2 and 4 with the same keywords and expects identical files.
void expect_lanes_agree(const std::string &name, const std::string &keys, int nprocs = 1,
                        const std::string &style = "bond/breakable") {
  const LaneRun one = run_ball(name, 1, keys, nprocs, style);
  ASSERT_FALSE(one.atoms.empty());
  // Not vacuous: the ball breaks bonds (the packs' one-bond tail runs) and
  // keeps most of them (the packs run).
  EXPECT_GT(one.broken, 20.0) << name << ": too few breaks to exercise the tail";
  EXPECT_GT(one.intact, 100.0) << name;
  EXPECT_EQ(one.packed, 0.0) << "lanes 1 evaluates one bond at a time";
  std::printf("%s: %g intact, %g broken at the end\n", name.c_str(), one.intact, one.broken);
  for (const int lanes : {2, 4}) {
    const LaneRun many = run_ball(name, lanes, keys, nprocs, style);
    EXPECT_GT(many.packed, 0.5) << name << ", lanes " << lanes
                                << ": most intact bonds should go through packs";
    EXPECT_EQ(many.atoms, one.atoms) << name << ", lanes " << lanes << ": atoms differ";
    EXPECT_EQ(many.bonds, one.bonds) << name << ", lanes " << lanes << ": intact bonds differ";
    EXPECT_EQ(many.breaks, one.breaks) << name << ", lanes " << lanes << ": breaks differ";
  }
}

}  // namespace

// The plain parallel bond (moment factor 1, no dashpots, broken bonds removed).
TEST(BondKernel, LanesGiveBitwiseTheOneBondResults) { expect_lanes_agree("plain", ""); }

// Dashpots (the relative motion at the end of the step: pair_motion in the
// packs) and a moment factor below 1.
TEST(BondKernel, LanesAgreeWithDampingAndMomentFactor) {
  expect_lanes_agree("damped", "damping 0.2 moment_factor 0.5");
}

// Broken bonds kept as contacts beside the packs, with moments, and pairs
// left unbonded from the start: the packs skip the contacts in the list.
TEST(BondKernel, LanesAgreeBesideContacts) {
  expect_lanes_agree("contacts",
                     "broken_contact yes contact_moment yes unbonded_fraction 0.2 unbonded_seed 7");
}

// Two ranks (ghost partners: a bond whose partner is not owned is computed
// on both ranks), the same bitwise agreement.
TEST(BondKernel, LanesAgreeOnTwoRanks) { expect_lanes_agree("np2", "damping 0.1", 2); }

// lanes takes 1, 2 or 4.
TEST(BondKernel, BadLanesAreNamed) {
  const std::string head = deck_head(0.01);
  const std::string atoms =
      "create_atoms 1 single 0 0 0 units box\ncreate_atoms 1 single 0.0021 0 0 units box\n"
      "set group all diameter 0.002 density 2500\n";
  const auto r3 =
      run_deck(make_run_dir("lanes_bad3"), head + atoms + bond_fix("lanes 3") + "run 1\n");
  EXPECT_NE(r3.screen.find("lanes must be 1, 2 or 4"), std::string::npos) << r3.screen;
  EXPECT_NE(r3.exit_code, 0);
  const auto rfj =
      run_deck(make_run_dir("lanes_badfj"), head + atoms + flat_joint_fix("lanes 3") + "run 1\n");
  EXPECT_NE(rfj.screen.find("lanes must be 1, 2 or 4"), std::string::npos) << rfj.screen;
  EXPECT_NE(rfj.exit_code, 0);
}

// bond/flatjoint's packed kernel (flat_joint::update_intact): runs of intact
// interfaces, every element bonded and undamaged, two or four at a time;
// a lane whose element breaks or starts to soften goes through update().
// The same bitwise agreement with one interface at a time, on the same
// ball, which breaks elements in tension and shear.
TEST(FlatJointKernel, LanesGiveBitwiseTheOneInterfaceResults) {
  expect_lanes_agree("fj_plain", "", 1, "bond/flatjoint");
}

// Tension softening (the lanes that reach u_t go through update(), which
// damages them; a damaged interface is not packed again), two rings of four
// sectors and dashpots (pair_motion at the end of the step in the packs).
TEST(FlatJointKernel, LanesAgreeWithSofteningRingsAndDashpots) {
  expect_lanes_agree("fj_soft", "elements 2 4 softening 5 damping 0.2", 1, "bond/flatjoint");
}

// Two ranks: interfaces whose partner is a ghost are computed on both.
TEST(FlatJointKernel, LanesAgreeOnTwoRanks) {
  expect_lanes_agree("fj_np2", "damping 0.1", 2, "bond/flatjoint");
}
