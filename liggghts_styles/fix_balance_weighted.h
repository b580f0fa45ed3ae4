// fix balance/weighted: the processor grid's cuts kept where they split the
// work in equal parts, for LIGGGHTS 3.8 (which has no `balance` command). See
// docs/styles/fix_balance_weighted.md.
//
// LIGGGHTS cuts the box into equal slabs. A bonded lump in a shrink-wrapped
// box is not uniform: fragments flung off stretch the box, the slabs' middle
// cut leaves the lump, and one rank gets most of its elements and bonds. At
// each re-neighbouring (every N-th with `every N`), before atoms are
// exchanged, this fix moves each cut of each split dimension to the weighted
// median of the atoms along it (weight 1 per atom plus bond_weight per intact
// bond of a bond fix's per-atom count), as LAMMPS's `balance ... shift` does
// per dimension, and lets the ordinary exchange move the atoms. A cut moves no
// further than next to its neighbouring cuts per call, so that exchange
// suffices.
#ifndef MILL_FIX_BALANCE_WEIGHTED_H
#define MILL_FIX_BALANCE_WEIGHTED_H

#include <string>

#include "fix.h"

namespace LAMMPS_NS {

class FixBalanceWeighted : public Fix {
 public:
  FixBalanceWeighted(class LAMMPS *lmp, int narg, char **arg);

  static const char *style_name() { return "balance/weighted"; }

  int setmask() override;
  void init() override;
  void setup_pre_exchange() override;
  void pre_exchange() override;
  double compute_vector(int n) override;

 private:
  // Measures the ranks' weights, then moves the cuts (collective).
  void rebalance();

  std::string bonds_id_;  // fix with the per-atom intact-bond count ("" = none)
  Fix *bonds_ = nullptr;
  double bond_weight_ = 0.5;    // weight of one intact bond end, relative to one atom
  int every_ = 1;               // re-balance at every this many re-neighbourings
  long calls_ = 0;              // re-neighbourings seen
  double imbalance_ = 1.0;      // max / mean rank weight found at the last re-balance
  double imbalance_max_ = 1.0;  // the largest found
  double balances_ = 0.0;       // re-balances done
};

}  // namespace LAMMPS_NS

#endif
