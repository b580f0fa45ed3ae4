// fix bond/breakable: breakable parallel bonds between granular spheres
// (Potyondy & Cundall 2004) for LIGGGHTS 3.8. See docs/styles/fix_bond_breakable.md.
//
// Bonds live with the atoms: every atom stores, for each of its intact bonds,
// the partner's tag and the bond's history (initial length, shear force,
// bending moment, twisting moment). The history is mirrored on both atoms and
// always expressed in the canonical direction lower tag -> higher tag, so that
// two ranks that each own one end compute bitwise the same bond; the slots
// are what moves with an atom between ranks and what a restart file holds.
// During a run each rank works on one entry per bond it computes (atom
// indices, the history and the bond's constants, contiguous), rebuilt only
// when atoms are exchanged, sorted or re-ghosted and after a break, so that
// the per-step loop does no tag lookups and touches no per-atom slot; the
// history goes back to the slots of both ends before anything reads them.
#ifndef MILL_FIX_BOND_BREAKABLE_H
#define MILL_FIX_BOND_BREAKABLE_H

#include <cstdio>
#include <string>
#include <vector>

#include "energy_terms.h"
#include "fix.h"
#include "flat_joint.h"
#include "parallel_bond.h"

namespace LAMMPS_NS {

class FixBondBreakable : public Fix {
 public:
  FixBondBreakable(class LAMMPS *lmp, int narg, char **arg);
  ~FixBondBreakable() override;

  static const char *style_name() { return "bond/breakable"; }

  int setmask() override;
  void init() override;
  void setup(int vflag) override;
  void post_force(int vflag) override;
  void end_of_step() override;
  void setup_pre_exchange() override;
  void pre_exchange() override;
  void post_run() override;

  double compute_vector(int n) override;
  double extend_cut_ghost() override;

  void write_restart(FILE *fp) override;
  void restart(char *buf) override;

  void grow_arrays(int nmax) override;
  void copy_arrays(int i, int j, int delflag) override;
  void set_arrays(int i) override;
  int pack_exchange(int i, double *buf) override;
  int unpack_exchange(int nlocal, double *buf) override;
  int pack_restart(int i, double *buf) override;
  void unpack_restart(int nlocal, int nth) override;
  int size_restart(int nlocal) override;
  int maxsize_restart() override;
  double memory_usage() override;

  // Per-bond columns stored per atom and slot: partner tag, initial length L0,
  // shear force (3), bending moment (3), twisting moment (1), state (0 intact
  // bond, 1 broken bond kept as a compression-only contact). Canonical frame.
  // bond/flatjoint appends the interface's history (flat_joint.h) at NCOL;
  // a slot is then ncol_ columns wide, and its state is 1 once every element
  // of the interface is broken.
  enum Column { PARTNER = 0, L0, FS, MB = FS + 3, MT = MB + 3, STATE, NCOL };

  // This rank's share of the bonds' energy terms [J] (bonds computed here,
  // counted once); summed over ranks by fix energy/ledger at its samples.
  struct Energy {
    mill::PowerIntegral work;     // work the bonds and contacts did on the elements
    double elastic = 0.0;         // stored now: intact bonds and pressed contacts
    double elastic0 = 0.0;        // stored at the start of the first run
    double released = 0.0;        // stored in bonds at the step they broke, cumulative
    mill::PowerIntegral damping;  // taken by the dashpots (power at the full steps)
    double friction = 0.0;        // taken by Coulomb slip of contacts, cumulative
  };
  const Energy &local_energy() const { return ledger_; }
  // This rank's work of the bonds up to the current step, whether or not
  // this fix's end_of_step ran yet [J].
  double local_work_now() const;
  // This rank's dashpot losses up to the current step, likewise [J].
  double local_damping_now() const;
  // sum of end_term() over this step's bond forces on the atoms of groupbit,
  // the ones velocity Verlet integrates (energy_terms.h).
  double local_end_term(int groupbit) const;
  // This step's bond forces and torques on the owned atoms (6 per atom).
  const std::vector<double> &ledger_forces() const { return fbond_; }
  // The bond springs' critical time step over the bonds left now [s], 0
  // when none is left (step_limit.h); also what f_ID[6] reads from then on,
  // and f_ID[8] the same with the dashpots (damped_critical_step).
  // Collective: every rank calls it at the same step.
  double critical_step();
  // Lanczos steps the last network estimate took (0: step_estimate sum).
  int network_iterations() const { return network_iterations_; }

 private:
  // "fix <style>: ", the start of every message.
  std::string label() const { return std::string("fix ") + style + ": "; }

  // bond/flatjoint (docs/styles/fix_bond_flatjoint.md): each bond is a
  // flat-joint interface of elements instead of a parallel bond.
  bool flat_joint_ = false;
  int fj_rings_ = 1, fj_sectors_ = 3;  // elements: rings x sectors
  double fj_friction_ = -1.0;          // mu of broken elements (< 0: tan(friction_angle))
  double fj_softening_ = 1.0;          // tension softening lambda = u_s / u_t (1: brittle)
  mill::flat_joint::Layout fj_layout_;
  int ncol_ = NCOL;  // columns of a slot

  // Parameters (SI units, see the doc page).
  double radius_multiplier_ = 1.0;  // lambda, bond radius = lambda min(Ri,Rj)  [-]
  double modulus_ = 0.0;            // E_b, bond modulus                          [Pa]
  double stiffness_ratio_ = 0.0;    // kn/ks                                     [-]
  double tensile_strength_ = 0.0;   // sigma_c                                   [Pa]
  double cohesion_ = 0.0;           // c                                         [Pa]
  double friction_angle_ = 0.0;     // phi                                       [deg]
  double damping_ = 0.0;            // fraction of critical damping              [-]
  double moment_factor_ = 1.0;      // beta, moment share of the bond stresses   [-]
  bool broken_contact_ = false;     // keep broken bonds as compression contacts
  bool contact_moment_ = false;     // contacts also carry capped moments
  double unbonded_fraction_ = 0.0;  // share of bonding pairs made contacts only  [-]
  int unbonded_seed_ = 1;           // seed of the choice of those pairs
  double gap_ = 0.1;                // bonding tolerance, x min radius           [-]
  int max_bonds_ = 16;              // slots per atom
  std::string break_log_path_;
  std::string dump_bonds_path_;
  int dump_every_ = 0;
  int lanes_ = 2;  // intact bonds (interfaces) evaluated at once (1, 2, 4; bond_lanes.h)
  // step_estimate network: the critical step from the whole network's largest
  // eigenfrequency (network_step.h) instead of the per-atom sum alone.
  bool network_step_ = false;
  // Intact-bond evaluations on this rank since the fix was defined: in packs
  // of lanes, and one at a time (output 7).
  double evals_packed_ = 0.0, evals_single_ = 0.0;

  // Run state (global, written to restart).
  int bonds_created_ = 0;
  double broken_tension_ = 0.0;
  double broken_shear_ = 0.0;

  // Cached per-step reductions (read by compute_vector).
  double intact_ = 0.0;
  double energy_ = 0.0;
  double dt_crit_ = 0.0;
  double dt_crit_damped_ = 0.0;  // with the dashpots (f_ID[8]); dt_crit_ when damping is 0
  double dt_crit_sum_ = 0.0;     // the per-atom sum's step (dt_crit_ with step_estimate sum)
  int network_iterations_ = 0;
  // step_estimate network: this rank's bonds to rank 0, the estimate back
  // (collective); the largest omega^2 [1/s^2], 0 when no bond is left.
  double network_omega2();

  // Per-atom storage.
  int nmax_ = 0;
  int *nbond_ = nullptr;      // intact bonds of each atom
  double **bonds_ = nullptr;  // [atom][slot * NCOL + column]
  double *count_ = nullptr;   // intact-bond count exposed as vector_atom

  double tan_friction_ = 0.0;   // tan(phi), set in init()
  double inv_ratio_ = 0.0;      // ks/kn, set in init()
  double inv_modulus_ = 0.0;    // 1/E_b, set in init()
  double rmax_ = 0.0;           // largest radius in the group
  double rmin_ = 0.0;           // smallest radius in the group
  double lmax_ = 0.0;           // longest bond length (initial)
  FILE *break_log_ = nullptr;   // rank 0 only
  std::vector<double> events_;  // break events of this step (local)

  // One entry per bond this rank computes, in the order of the per-atom slots
  // (owned atom i ascending, slot descending; a bond with both ends owned
  // here is listed once, under its lower tag). While the list is current the
  // entry's history is the bond's state and the per-atom slots are stale
  // (history_dirty_); store_history() writes it back to the slots of both
  // ends before anything reads or moves them (exchange, sort, restart, dump,
  // a break, storage growth, the end of a run). Valid until atoms are
  // exchanged, sorted or re-ghosted (a neighbour-list build), a bond breaks,
  // storage grows or the time step changes.
  struct ListedBond {
    int a, b;      // atom indices, a = lower tag (b may be a ghost image)
    int i;         // owned atom whose slot holds the history
    int j;         // the partner if it is owned here, else -1
    int slot_i;    // slot of the bond on i
    int slot_j;    // slot on j (j >= 0), else -1
    bool i_lower;  // tag[i] < partner tag
    // History, canonical frame (columns FS, MB, MT, STATE of the slots):
    double fs[3], mb[3], mt, state;
    // Constants of the bond (radii, masses and L0 do not change during a run):
    double l0;                            // initial length [m]
    double rbond, inv_area, inv_inertia;  // disc radius [m], 1/A [1/m^2], 1/I [1/m^4]
    double kna, ksa;                      // kn A, ks A [N/m]
    double kni, ksj;                      // kn I, ks J [N m]
    double cn, cs;                        // dashpots (damping > 0) [N s/m]
    double drop_len;                      // a contact is dropped beyond this length [m]
    double gap0;                          // flat joint: installation gap, >= 0 [m]
    double *fj;  // bond/flatjoint: the interface's history, in fj_history_ (written
                 // back to the slots by store_history)
  };
  std::vector<ListedBond> list_;
  std::vector<double> fj_history_;  // bond/flatjoint: the listed interfaces' histories
  bool list_valid_ = false;
  bool history_dirty_ = false;  // list_ holds history not yet in the slots
  bigint list_ncalls_ = -1;     // neighbor->ncalls when the list was built
  int list_nlocal_ = -1, list_nghost_ = -1;
  double list_dt_ = 0.0;  // update->dt when the list was built
  // Energy ledger: this step's bond forces and torques on the owned atoms
  // (6 per atom, f then torque), kept from post_force to end_of_step.
  Energy ledger_;
  std::vector<double> fbond_;
  bool ledger_started_ = false;
  bigint ledger_step_ = -1;   // the step whose power the work holds
  double bond_power() const;  // sum of F.v + T.omega of fbond_ [W]
  // With damping: each listed bond's dashpot force on b this step (3 per
  // entry, zero for bonds counted elsewhere), and the power they take at the
  // full-step velocities [W].
  std::vector<double> dash_;
  double dashpot_power() const;

  std::vector<int> broken_;   // slots to remove this step: i, j, tag i, partner tag
  std::vector<int> contact_;  // bonds that became contacts this step: list entries

  struct BondResult;
  struct AtomArrays;
  bool list_current() const;
  void build_bond_list();
  void parse_args(int narg, char **arg);
  void create_bonds();
  void compute_bonds(bool advance);
  void evaluate_bond(const AtomArrays &at, ListedBond &bond, bool advance, BondResult &out) const;
  template <class L>
  void evaluate_lanes(const AtomArrays &at, ListedBond *const *bonds, bool advance,
                      BondResult *outs) const;
  void load_bond(const AtomArrays &at, const ListedBond &bond,
                 mill::parallel_bond::In<double> &in) const;
  void bond_result(const mill::parallel_bond::Out<double> &o, mill::bond_geometry::Vec3 xa,
                   double dt, bool advance, BondResult &out) const;
  // The coefficients of the parallel bond's law (parallel_bond.h).
  mill::parallel_bond::Coefficients coefficients() const {
    return {damping_ > 0.0, moment_factor_, cohesion_, tan_friction_, inv_modulus_,
            stiffness_ratio_};
  }
  bool evaluate_contact(const AtomArrays &at, ListedBond &bond, bool advance,
                        BondResult &out) const;
  void evaluate_flat_joint(const AtomArrays &at, ListedBond &bond, bool advance,
                           BondResult &out) const;
  template <class L>
  int evaluate_flat_joint_lanes(const AtomArrays &at, ListedBond *const *bonds,
                                BondResult *outs) const;
  bool flat_joint_packable(const ListedBond &bond) const;
  bool separated(const AtomArrays &at, const ListedBond &bond) const;
  void store_history();
  void remove_slot(int i, int slot);
  int find_slot(int i, int partner_tag) const;
  int intact_bonds(int i) const;
  bool contacts_on() const { return flat_joint_ || broken_contact_ || unbonded_fraction_ > 0.0; }
  bool starts_unbonded(int tag_a, int tag_b) const;
  int partner_index(int i, int partner_tag) const;
  void estimate_time_step();
  void write_bond_dump();
  void write_break_events();
  void message(const std::string &text) const;
  [[noreturn]] void fail_one(const std::string &text) const;
};

}  // namespace LAMMPS_NS

#endif
