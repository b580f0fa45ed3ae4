// fix bond/flatjoint: the style's name on fix bond/breakable's machinery;
// the keywords and the interface are read and evaluated there (the
// flat-joint branches of fix_bond_breakable.cpp, flat_joint.cpp).
#include "fix_bond_flatjoint.h"

using namespace LAMMPS_NS;

// The base reads `style` (arg[2] = bond/flatjoint) and switches to flat joints.
FixBondFlatJoint::FixBondFlatJoint(LAMMPS *lmp, int narg, char **arg)
    : FixBondBreakable(lmp, narg, arg) {}
