// fix balance/weighted (docs/styles/fix_balance_weighted.md) on 2 ranks: a
// bonded block that LIGGGHTS's equal slabs leave on one rank is shared out,
// and the run is the one-rank run.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "bond_test_util.h"

using namespace mill_test;

namespace {

struct BalanceRun {
  std::map<int, std::array<double, 3>> x;                      // id -> position at the end
  double nlocal_max = 0, nlocal_min = 0;                       // the ranks' atoms at the end
  double imbalance_last = 0, imbalance_max = 0, balances = 0;  // f_lb[1..3]
  double intact = 0;
};

// A bonded 6 x 3 x 3 block drifting at 5 m/s along x and vibrating, in the
// +x half of the box (x from 1 to 11.5 mm), on `nprocs` ranks cut along x
// (`processors * 1 1`: LIGGGHTS's equal slabs cut at the box's middle, x = 0
// in the fixed box, left of the block); with `balance` the cut follows the
// block (bond_weight 0.25). `boundary` "f f f" (a fixed box: the fix sets
// up the communication itself) or "m m m" (shrink-wrapped, as the impact
// deck; an unbonded element far off along -x stretches the box).
BalanceRun run_block(int nprocs, bool balance, const std::string &boundary) {
  const std::string dir = make_run_dir("balance" + std::to_string(nprocs) + (balance ? "b" : "u"));
  std::ostringstream d;
  d.precision(17);
  std::string head = deck_head(0.02, 5e9, boundary);
  const std::string comm_line = "communicate single vel yes\n";
  head.insert(head.find(comm_line) + comm_line.size(), "processors * 1 1\n");
  d << head;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 6; ++i)
        d << "create_atoms 1 single " << 0.001 + i * kL0 << " " << j * kL0 << " " << k * kL0
          << " units box\n";
  if (boundary == "m m m") d << "create_atoms 1 single -0.018 0.0 0.0 units box\n";
  d << "set group all diameter " << 2 * kR << " density " << kRho << "\n"
    << "variable vx atom 5.0+200*(y-0.0021)\nvariable vy atom -150*(z-0.0021)\n"
    << "variable vz atom 100*(x-0.006)\n"
    << "velocity all set v_vx v_vy v_vz units box\n"
    << "fix integr all nve/sphere\n"
    << bond_fix();
  if (balance) d << "fix lb all balance/weighted bonds bonds bond_weight 0.25\n";
  d << "timestep 2e-8\n"
    << "thermo 1000\n"
    << "run 6000\n"
    << "variable n equal f_bonds[1]\n";
  if (balance)
    d << "variable i1 equal f_lb[1]\nvariable i2 equal f_lb[2]\nvariable i3 equal f_lb[3]\n"
      << "print \"${n} ${i1} ${i2} ${i3}\" file end.txt\n";
  else
    d << "print \"${n} 0 0 0\" file end.txt\n";
  d << "write_dump all custom final.dump id x y z modify format \"%d %.17g %.17g %.17g\"\n";
  const auto r = run_deck(dir, d.str(), nprocs);
  EXPECT_EQ(r.exit_code, 0) << r.screen;
  BalanceRun out;
  out.x = read_positions(dir + "/final.dump");
  // The run statistics' last "Nlocal: AVE ave MAX max MIN min".
  const auto at = r.screen.rfind("Nlocal:");
  if (at != std::string::npos) {
    std::istringstream ls(r.screen.substr(at + 7));
    std::string w;
    double ave;
    ls >> ave >> w >> out.nlocal_max >> w >> out.nlocal_min;
  }
  std::ifstream e(dir + "/end.txt");
  e >> out.intact >> out.imbalance_last >> out.imbalance_max >> out.balances;
  return out;
}

}  // namespace

// On LIGGGHTS's equal slabs the block is on one rank (the other owns nothing
// but, shrink-wrapped, the lone element). With fix balance/weighted the first
// re-balance (at the setup) finds all the weight on one rank (max / mean 2)
// and moves the cut into the block: at the end the ranks own 27 +- 6 elements
// each, and each later re-balance found them within 25 % of the mean. The
// run is the one-rank run to 1e-12 m (only the order of sums differs).
TEST(Mpi, BalanceWeightedSharesOutABlockAndKeepsTheRun) {
  for (const std::string boundary : {"f f f", "m m m"}) {
    SCOPED_TRACE(boundary);
    const BalanceRun one = run_block(1, false, boundary);
    const BalanceRun slabs = run_block(2, false, boundary);
    const BalanceRun balanced = run_block(2, true, boundary);
    const std::size_t n = boundary == "m m m" ? 55 : 54;
    ASSERT_EQ(one.x.size(), n);
    ASSERT_EQ(balanced.x.size(), n);
    std::printf(
        "%s: atoms per rank at the end: equal slabs %g / %g, balanced %g / %g; imbalance at the "
        "last re-balance %.3f, largest %.3f, %g re-balances\n",
        boundary.c_str(), slabs.nlocal_max, slabs.nlocal_min, balanced.nlocal_max,
        balanced.nlocal_min, balanced.imbalance_last, balanced.imbalance_max, balanced.balances);
    EXPECT_GE(slabs.nlocal_max, 54) << "the block was not on one rank: the test is vacuous";
    EXPECT_LE(balanced.nlocal_max, n / 2.0 + 6) << "the cut did not follow the block";
    EXPECT_GE(balanced.nlocal_min, n / 2.0 - 6);
    EXPECT_NEAR(balanced.imbalance_max, 2.0, 0.05);
    EXPECT_LE(balanced.imbalance_last, 1.25);
    EXPECT_GE(balanced.balances, 3);  // the setup and re-neighbourings
    EXPECT_EQ(balanced.intact, one.intact);
    double worst = 0.0, moved = 0.0;
    for (const auto &[id, p] : one.x) {
      ASSERT_TRUE(balanced.x.count(id)) << id;
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::fabs(p[c] - balanced.x.at(id)[c]));
    }
    moved = one.x.at(1)[0] - 0.001;
    EXPECT_GT(moved, 2e-4) << "the block hardly moved: no re-neighbouring to re-balance at";
    EXPECT_LT(worst, 1e-12);
  }
}
