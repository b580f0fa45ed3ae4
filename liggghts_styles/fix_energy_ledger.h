// fix energy/ledger: where the energy of a bonded-lump run goes, sampled over
// time, and the checks that stop a run in which energy is created. For
// LIGGGHTS 3.8; see docs/styles/fix_energy_ledger.md.
//
// The ledger integrates the power of each force family (element contacts of
// `pair gran`, the bonds of fix bond/breakable, the rigid surface of fix
// wall/halfspace, everything else) with the trapezoidal rule at full steps,
// which adds up exactly to the change of the kinetic energy under velocity
// Verlet (plus its shadow term). Each family's work is then compared with the
// energy the family's own law says it stores and dissipates; what does not
// close is the residual.
#ifndef MILL_FIX_ENERGY_LEDGER_H
#define MILL_FIX_ENERGY_LEDGER_H

#include <cstdio>
#include <string>
#include <vector>

#include "energy_terms.h"
#include "fix.h"

namespace LAMMPS_NS {

class FixBondBreakable;
class FixWallHalfspace;
class FixEnergyWork;

class FixEnergyLedger : public Fix {
 public:
  FixEnergyLedger(class LAMMPS *lmp, int narg, char **arg);
  ~FixEnergyLedger() override;

  static const char *style_name() { return "energy/ledger"; }

  int setmask() override;
  void init() override;
  void setup(int vflag) override;
  void post_force(int vflag) override;
  void end_of_step() override;
  void post_run() override;
  double compute_vector(int n) override;

  // The ledger's columns, in file order (docs/styles/fix_energy_ledger.md).
  enum Column {
    KE_TRANS = 0,      // translational kinetic energy now
    KE_ROT,            // rotational kinetic energy now
    NUMERICAL,         // velocity Verlet's shadow term, sum |F|^2 dt^2/(8m) + |T|^2 dt^2/(8I)
    BOND_ELASTIC,      // stored in intact bonds (and pressed contacts of broken bonds)
    BOND_RELEASED,     // stored in bonds when they broke, cumulative
    BOND_DAMPING,      // taken by bond dashpots, cumulative
    BOND_FRICTION,     // taken by Coulomb slip of broken-bond contacts, cumulative
    WALL_ELASTIC,      // stored in the rigid surface's contacts now
    WALL_DAMPING,      // taken by its dashpots, cumulative
    WALL_FRICTION,     // taken by sliding on it, cumulative
    CONTACT_ELASTIC,   // stored in the normal springs of element contacts now (Hertz)
    CONTACT_DAMPING,   // taken by the normal dashpots of element contacts, cumulative
    CONTACT_FRICTION,  // taken tangentially: Coulomb slip, tangential dashpot, rolling resistance
    WORK_OTHER,        // work of every other force (moving walls, gas, gravity, platens);
                       // its parts measured by fix energy/work follow the last column
    INPUT,             // energy at the start: kinetic + stored
    RESIDUAL,          // input + other work - everything above
    MAX_SPEED,         // fastest element since the last sample [m/s]
    WALL_OVERLAP,      // largest overlap on the rigid surface / element radius so far
    RESIDUAL_BONDS,    // the bonds' share of the residual: work + stored change + released + taken
    RESIDUAL_WALL,     // the rigid surface's share, likewise
    NCOLUMN
  };

 private:
  int every_ = 1000;                     // steps between samples
  double interval_ = 0.0;                // time between samples [s]; sets every_ at init
  std::string file_;                     // the ledger file (CSV), rank 0
  std::string bond_id_, wall_id_;        // fixes whose terms are read
  std::string integrated_;               // group velocity Verlet moves (default: the fix's)
  int moved_ = 0;                        // its bit, found at each init
  double youngs_ = 0.0, poisson_ = 0.0;  // element E [Pa], nu (Hertz energy of contacts)
  double speed_bound_ = 0.0;             // fastest element allowed [m/s]; 0 = no check
  double residual_bound_ = 0.0;          // |residual| / (input + |other work|) allowed; 0 = none
  double residual_floor_ = 0.0;          // J below which the residual is not checked

  FixBondBreakable *bonds_ = nullptr;
  FixWallHalfspace *wall_ = nullptr;
  std::vector<FixEnergyWork *> parts_;  // fix energy/work after this one, in deck order
  FILE *out_ = nullptr;

  std::vector<double> fpair_;      // this step's pair forces and torques, 6 per atom
  mill::PowerIntegral pair_work_;  // work of the element contacts
  std::vector<double> fdamp_;      // this step's normal-dashpot forces of the contacts, 3 per atom
  mill::PowerIntegral damp_work_;  // their work
  std::vector<double> beta_;       // ln e / sqrt(ln^2 e + pi^2) per type pair (row-major, 1-based)
  int ntypes_ = 0;
  double input_ = 0.0;  // input energy (first setup) [J]
  double contact_elastic0_ = 0.0, bond_elastic0_ = 0.0, wall_elastic0_ = 0.0;
  double kinetic0_ = 0.0;  // kinetic energy incl. shadow term at the start [J]
  bool started_ = false;
  double vmax_sq_ = 0.0;   // fastest element since the last sample, squared
  double ke_last_ = 0.0;   // this rank's kinetic energy at the last step's end [J]
  double injected_ = 0.0;  // this rank's kinetic energy changed between runs [J]
  bigint last_sample_ = -1;
  double row_[NCOLUMN] = {};      // the last sample (global values)
  std::vector<double> part_row_;  // and its work_NAME_J columns

  void parse_args(int narg, char **arg);
  double local_pair_power() const;
  double local_damping_power() const;
  void find_restitution();
  void find_parts();
  void contact_damping_forces();
  double local_contact_elastic() const;
  void local_kinetic(double &trans, double &rot, double &shadow) const;
  void sample(bool write);
  void check_order() const;

  // The terms sample() sums over ranks, in this order (then one per part).
  enum Sum { T = 0, R, S, CE, WP, WDP, WB, BE, BE0, BR, BD, BF, WW, WE, WE0, WD, WF, INJ, NSUM };
  // The step changed (fix step/adaptive, fix dt/reset): velocity Verlet's
  // shadow and end terms, taken with the step of the sample, are banked so
  // that the books stay continuous across the change (fix_energy_ledger.md,
  // "A changing step").
  void reset_dt() override;
  void bank_step_change();  // the banking of reset_dt, also at init (a `timestep` between runs)
  double books_dt_ = 0.0;   // the step of the shadow and end terms [s]
  std::vector<double> dt_offset_;  // this rank's banked differences, per Sum [J]
  // This rank's sums of the dt-dependent terms in Sum order: S the shadow
  // term's sum |F|^2/m + |T|^2/I (times -dt^2/8), WP, WDP, WB, WW and the
  // parts their end terms' sums (times -dt^2/4); 0 elsewhere.
  std::vector<double> local_step_sums() const;
};

}  // namespace LAMMPS_NS

#endif
