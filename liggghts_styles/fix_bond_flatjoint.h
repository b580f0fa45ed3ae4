// fix bond/flatjoint: bonds that are flat-joint interfaces (Potyondy 2012)
// between granular spheres, for LIGGGHTS 3.8. See
// docs/styles/fix_bond_flatjoint.md.
//
// The bookkeeping (bond creation, slots that move with the atoms, the bond
// list, restart, the energy ledger's terms, break log and bond dump) is
// fix bond/breakable's; this style stores a flat-joint interface
// (flat_joint.h) in each slot instead of a parallel bond's history and
// evaluates it element by element.
#ifndef MILL_FIX_BOND_FLATJOINT_H
#define MILL_FIX_BOND_FLATJOINT_H

#include "fix_bond_breakable.h"

namespace LAMMPS_NS {

class FixBondFlatJoint : public FixBondBreakable {
 public:
  FixBondFlatJoint(class LAMMPS *lmp, int narg, char **arg);
  static const char *style_name() { return "bond/flatjoint"; }
};

}  // namespace LAMMPS_NS

#endif
