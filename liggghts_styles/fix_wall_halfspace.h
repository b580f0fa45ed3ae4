// fix wall/halfspace: a rigid flat surface that is solid on one side, with the
// Hertz-Mindlin contact of LIGGGHTS's `wall/gran model hertz tangential
// history`, for LIGGGHTS 3.8. See docs/styles/fix_wall_halfspace.md.
//
// LIGGGHTS's primitive planes (wall/gran ... primitive zplane) are two-sided:
// an element whose centre is pressed past the plane is pushed out the far
// side with the energy of an overlap as large as its radius. Here the solid
// fills the half-space behind the plane, so the overlap is measured from the
// element's lowest point to the plane and the push always points out of the
// solid, whatever the overlap. The fix also keeps its own share of the
// energy ledger: work done on the elements, energy stored in the contacts,
// energy dissipated by the dashpots and by Coulomb sliding.
#ifndef MILL_FIX_WALL_HALFSPACE_H
#define MILL_FIX_WALL_HALFSPACE_H

#include <vector>

#include "energy_terms.h"
#include "fix.h"

namespace LAMMPS_NS {

class FixWallHalfspace : public Fix {
 public:
  FixWallHalfspace(class LAMMPS *lmp, int narg, char **arg);
  ~FixWallHalfspace() override;

  static const char *style_name() { return "wall/halfspace"; }

  int setmask() override;
  void init() override;
  void setup(int vflag) override;
  void post_force(int vflag) override;
  void end_of_step() override;

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

  // This rank's share of the wall's energy terms [J]; summed over ranks by
  // the reader (fix energy/ledger) in its own once-per-sample reduction.
  struct Energy {
    mill::PowerIntegral work;     // work done on the elements
    double elastic = 0.0;         // stored in the contacts now (normal + tangential springs)
    double elastic0 = 0.0;        // stored at the start of the first run
    mill::PowerIntegral damping;  // dissipated by the normal and tangential dashpots
    double friction =
        0.0;  // dissipated by Coulomb sliding and the spring's stiffness change, cumulative
    double max_overlap = 0.0;  // largest overlap / element radius so far [-]
  };
  const Energy &local_energy() const { return energy_; }
  // This rank's work on the elements and dashpot losses up to the current
  // step, whether or not this fix's end_of_step ran yet [J].
  void local_work_now(double &work, double &damping) const;
  // sum of end_term() over this step's wall forces on the atoms of groupbit,
  // the ones velocity Verlet integrates (energy_terms.h).
  double local_end_term(int groupbit) const;
  // Takes this step's forces and torques of the surface off a per-atom array
  // (6 per atom: force, torque), for fix energy/work.
  void subtract_forces(std::vector<double> &f6) const;

  // Contact law of one element on the wall (LIGGGHTS's hertz model; public
  // for the analytic tests). Effective Young's and shear moduli [Pa] and the
  // damping ratio beta = ln(e)/sqrt(ln^2 e + pi^2) of the pair.
  static double effective_youngs(double e1, double nu1, double e2, double nu2);
  static double effective_shear(double e1, double nu1, double e2, double nu2);
  static double damping_beta(double restitution);

 private:
  // Parameters (SI units, see the doc page).
  double z0_ = 0.0;            // plane height                                    [m]
  double side_ = 1.0;          // +1: solid below (z < z0), -1: solid above       [-]
  double youngs_ = 0.0;        // element Young's modulus                          [Pa]
  double poisson_ = 0.0;       // element Poisson's ratio                          [-]
  double wall_youngs_ = 0.0;   // wall Young's modulus                             [Pa]
  double wall_poisson_ = 0.0;  // wall Poisson's ratio                             [-]
  double restitution_ = 0.5;   // coefficient of restitution                       [-]
  double friction_ = 0.5;      // Coulomb friction coefficient                     [-]

  double yeff_ = 0.0, geff_ = 0.0, beta_ = 0.0;  // set in init()

  // Per-atom tangential spring: displacement (3 columns) and the stiffness
  // k_t it had at the last step (4th column), migrates with atoms.
  static constexpr int kCols = 4;
  double **shear_ = nullptr;
  int nmax_ = 0;

  // This step's forces and torques on the elements in contact, kept from
  // post_force to end_of_step, where the full-step velocities give the work.
  struct Touch {
    int i;
    double f[3], t[3];  // force and torque on the element [N], [N m]
    double fd[3];       // the dashpots' part of the force [N]
    double arm;         // centre to contact point, along -n [m]
  };
  std::vector<Touch> touches_;

  Energy energy_;
  bool started_ = false;  // the ledger's integrals began (first setup)
  bigint step_ = -1;      // the step whose power the integrals hold
  void step_power(double &p, double &pd) const;

  void parse_args(int narg, char **arg);
  void compute_contacts(bool advance);
  double contact_velocity_dot(const Touch &t, const double *fvec) const;
};

}  // namespace LAMMPS_NS

#endif
