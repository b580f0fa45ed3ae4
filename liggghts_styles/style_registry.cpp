#include "style_registry.h"

#include <map>

#include "fix_balance_weighted.h"
#include "fix_bond_breakable.h"
#include "fix_bond_flatjoint.h"
#include "fix_energy_ledger.h"
#include "fix_energy_work.h"
#include "fix_fluid_drag.h"
#include "fix_impact_recorder.h"
#include "fix_step_adaptive.h"
#include "fix_wall_halfspace.h"
#include "lammps.h"
#include "modify.h"

namespace mill {
namespace {

// Same signature as LIGGGHTS's private Modify::FixCreator.
using FixCreator = LAMMPS_NS::Fix *(*)(LAMMPS_NS::LAMMPS *, int, char **);
using FixMap = std::map<std::string, FixCreator>;

// Access to the private member Modify::fix_map without patching LIGGGHTS:
// access checking does not apply to the template arguments of an explicit
// instantiation ([temp.spec]/6 in C++17), so the instantiation below may name
// &Modify::fix_map and hand the pointer-to-member out through a friend.
struct FixMapTag {
  using type = FixMap *LAMMPS_NS::Modify::*;
  friend type member_of(FixMapTag);
};
template <typename Tag, typename Tag::type Member>
struct Grant {
  friend typename Tag::type member_of(Tag) { return Member; }
};
template struct Grant<FixMapTag, &LAMMPS_NS::Modify::fix_map>;

// Creates one fix of style T; stored in the registry.
template <typename T>
LAMMPS_NS::Fix *create_fix(LAMMPS_NS::LAMMPS *lmp, int narg, char **arg) {
  return new T(lmp, narg, arg);
}

}  // namespace

// Adds the project's fix styles to the registry of lmp (before the deck runs).
std::vector<std::string> register_mill_styles(LAMMPS_NS::LAMMPS *lmp) {
  FixMap *fix_map = lmp->modify->*member_of(FixMapTag{});
  std::vector<std::string> names;
  using LAMMPS_NS::FixBondBreakable;
  (*fix_map)[FixBondBreakable::style_name()] = &create_fix<FixBondBreakable>;
  names.emplace_back(LAMMPS_NS::FixBondBreakable::style_name());
  (*fix_map)[LAMMPS_NS::FixBondFlatJoint::style_name()] = &create_fix<LAMMPS_NS::FixBondFlatJoint>;
  names.emplace_back(LAMMPS_NS::FixBondFlatJoint::style_name());
  (*fix_map)[LAMMPS_NS::FixFluidDrag::style_name()] = &create_fix<LAMMPS_NS::FixFluidDrag>;
  names.emplace_back(LAMMPS_NS::FixFluidDrag::style_name());
  (*fix_map)[LAMMPS_NS::FixImpactRecorder::style_name()] =
      &create_fix<LAMMPS_NS::FixImpactRecorder>;
  names.emplace_back(LAMMPS_NS::FixImpactRecorder::style_name());
  (*fix_map)[LAMMPS_NS::FixWallHalfspace::style_name()] = &create_fix<LAMMPS_NS::FixWallHalfspace>;
  names.emplace_back(LAMMPS_NS::FixWallHalfspace::style_name());
  (*fix_map)[LAMMPS_NS::FixEnergyLedger::style_name()] = &create_fix<LAMMPS_NS::FixEnergyLedger>;
  names.emplace_back(LAMMPS_NS::FixEnergyLedger::style_name());
  (*fix_map)[LAMMPS_NS::FixEnergyWork::style_name()] = &create_fix<LAMMPS_NS::FixEnergyWork>;
  names.emplace_back(LAMMPS_NS::FixEnergyWork::style_name());
  (*fix_map)[LAMMPS_NS::FixStepAdaptive::style_name()] = &create_fix<LAMMPS_NS::FixStepAdaptive>;
  names.emplace_back(LAMMPS_NS::FixStepAdaptive::style_name());
  (*fix_map)[LAMMPS_NS::FixBalanceWeighted::style_name()] =
      &create_fix<LAMMPS_NS::FixBalanceWeighted>;
  names.emplace_back(LAMMPS_NS::FixBalanceWeighted::style_name());
  return names;
}

}  // namespace mill
