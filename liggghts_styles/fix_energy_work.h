// fix energy/work: the work of the force fixes just before it in the deck, a
// named part of fix energy/ledger's "other work" (the beater, the housing,
// gravity, the gas). For LIGGGHTS 3.8; see docs/styles/fix_energy_work.md.
//
// Fixes add their forces to the same per-atom arrays one after another in
// deck order. fix energy/ledger keeps the arrays as the pair style left them;
// each fix energy/work after it keeps them as they are at its own place, so
// the difference to the snapshot before it is the force of the fixes in
// between. Its work is integrated like the ledger's families (trapezoid at
// full steps, less velocity Verlet's end term), and the ledger writes it as a
// column work_NAME_J.
//
// With `mesh ID omega W axis AX AY AZ origin OX OY OZ` it measures instead the
// work a rotating mesh wall does on the elements: -omega . T, T the torque on
// the mesh (fix mesh/surface/stress, reference_point on the axis) from the
// contact forces of this step. One wall/gran fix serves every mesh of a deck
// (LIGGGHTS allows one), so this is how the beater's work is told from the
// housing's.
#ifndef MILL_FIX_ENERGY_WORK_H
#define MILL_FIX_ENERGY_WORK_H

#include <string>
#include <vector>

#include "energy_terms.h"
#include "fix.h"

namespace LAMMPS_NS {

class FixBondBreakable;
class FixWallHalfspace;

class FixEnergyWork : public Fix {
 public:
  FixEnergyWork(class LAMMPS *lmp, int narg, char **arg);

  static const char *style_name() { return "energy/work"; }

  int setmask() override;
  void setup(int vflag) override;
  void post_force(int vflag) override;
  void end_of_step() override;
  double compute_scalar() override;

  void init() override;

  // The name of the part (column work_NAME_J).
  const std::string &part_name() const { return name_; }
  // A rotating mesh's work (keyword mesh): not a link of the snapshot chain.
  bool measures_mesh() const { return !mesh_id_.empty(); }
  // The ledger sets, at each init, the snapshot taken just before this fix
  // (6 per atom: forces, torques); nullptr until then.
  void set_previous(const std::vector<double> *previous) { previous_ = previous; }
  // Fixes between that snapshot and this fix whose forces the ledger books
  // itself (nullptr: none); their forces are not part of this one's.
  void set_booked(const FixBondBreakable *bonds, const FixWallHalfspace *wall) {
    booked_bonds_ = bonds;
    booked_wall_ = wall;
  }
  // The snapshot this fix takes, for the next fix energy/work.
  const std::vector<double> &snapshot() const { return snapshot_; }
  // This rank's work of the part so far [J], velocity Verlet's end term not
  // yet taken (the ledger takes it with local_end_term).
  double local_work_now() const;
  // Sum over the owned atoms in groupbit of f.F/m + t.T/I for the part's
  // forces f, torques t, against the total F, T (energy_terms.h).
  double local_end_term(int groupbit) const;

 private:
  std::string name_;
  std::string mesh_id_;                 // mesh mode: the fix mesh/surface/stress
  class Fix *mesh_ = nullptr;           // found at each init
  double omega_[3] = {0.0, 0.0, 0.0};   // its angular velocity [rad/s]
  double origin_[3] = {0.0, 0.0, 0.0};  // a point of its axis [m]
  const std::vector<double> *previous_ = nullptr;
  const FixBondBreakable *booked_bonds_ = nullptr;
  const FixWallHalfspace *booked_wall_ = nullptr;
  std::vector<double> snapshot_;  // forces and torques at this fix's place, 6 per atom
  std::vector<double> part_;      // this step's forces and torques of the part, 6 per atom
  mill::PowerIntegral work_;
  bigint added_step_ = -1;  // the step whose power work_ last added
  bool started_ = false;

  double local_power() const;
};

}  // namespace LAMMPS_NS

#endif
