// fix energy/work: the work of the force fixes just before it, a named part
// of the energy ledger's other work (docs/styles/fix_energy_work.md).
#include "fix_energy_work.h"

#include <mpi.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "fix_bond_breakable.h"
#include "fix_wall_halfspace.h"
#include "modify.h"
#include "style_args.h"
#include "update.h"

using namespace LAMMPS_NS;
using namespace FixConst;

// Reads `fix ID group energy/work NAME [mesh ID omega W axis AX AY AZ origin OX OY OZ]`.
FixEnergyWork::FixEnergyWork(LAMMPS *lmp, int narg, char **arg) : Fix(lmp, narg, arg) {
  if (narg != 4 && narg != 16)
    error->all(FLERR,
               "fix energy/work: expected `fix ID group energy/work NAME` (NAME: the part's "
               "column work_NAME_J in the energy ledger, e.g. gravity) or `... NAME mesh ID "
               "omega W axis AX AY AZ origin OX OY OZ` (a rotating mesh wall)");
  name_ = arg[3];
  if (narg == 16) {
    const mill::StyleArgs args(error, "energy/work");
    const char *expect[] = {"mesh", "omega", "axis", "origin"};
    const int at[] = {4, 6, 8, 12};
    for (int k = 0; k < 4; ++k)
      if (std::strcmp(arg[at[k]], expect[k]) != 0)
        error->all(FLERR, (std::string("fix energy/work: expected keyword '") + expect[k] +
                           "' at argument " + std::to_string(at[k]) + ", got '" + arg[at[k]] + "'")
                              .c_str());
    mesh_id_ = arg[5];
    const double w = args.real("omega", arg[7]);
    double a[3], len = 0.0;
    for (int c = 0; c < 3; ++c) {
      a[c] = args.real("axis", arg[9 + c]);
      origin_[c] = args.real("origin", arg[13 + c]);
      len += a[c] * a[c];
    }
    if (!(len > 0.0)) error->all(FLERR, "fix energy/work: axis must not be the zero vector");
    for (int c = 0; c < 3; ++c) omega_[c] = w * a[c] / std::sqrt(len);
  }
  const bool ok = !name_.empty() && std::all_of(name_.begin(), name_.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
  if (!ok)
    error->all(FLERR, ("fix energy/work: NAME '" + name_ +
                       "' must be letters, digits and '_' (it names a CSV column)")
                          .c_str());
  scalar_flag = 1;
  global_freq = 1;
  extscalar = 1;
}

int FixEnergyWork::setmask() { return POST_FORCE | END_OF_STEP; }

// Mesh mode: the mesh fix, tracking stress, with its reference point on the axis.
void FixEnergyWork::init() {
  if (!measures_mesh()) return;
  mesh_ = modify->find_fix_id(mesh_id_.c_str());
  if (!mesh_ || std::strncmp(mesh_->style, "mesh/surface/stress", 19) != 0)
    error->all(FLERR, ("fix energy/work: mesh " + mesh_id_ +
                       ": needs a fix mesh/surface/stress with that ID (it sums the torque on "
                       "the mesh)")
                          .c_str());
  // The reference point (outputs 7-9) must lie on the axis.
  double d[3], w2 = 0.0, dw = 0.0, d2 = 0.0;
  for (int c = 0; c < 3; ++c) {
    d[c] = mesh_->compute_vector(6 + c) - origin_[c];
    w2 += omega_[c] * omega_[c];
    dw += d[c] * omega_[c];
    d2 += d[c] * d[c];
  }
  const double off2 = w2 > 0.0 ? d2 - dw * dw / w2 : 0.0;
  if (off2 > 1e-18)
    error->all(FLERR, ("fix energy/work: the reference_point of fix " + mesh_id_ +
                       " is not on the axis through origin: give it reference_point on the axis "
                       "(the torque is taken about it)")
                          .c_str());
}

// The part's forces of the setup; the integral starts with the first run.
void FixEnergyWork::setup(int vflag) {
  post_force(vflag);
  if (started_) return;
  work_.start(local_power(), update->dt);
  added_step_ = update->ntimestep;
  started_ = true;
}

// The arrays at this fix's place, less the snapshot before it.
void FixEnergyWork::post_force(int /*vflag*/) {
  if (measures_mesh()) return;
  if (!previous_)
    error->all(FLERR, ("fix energy/work " + std::string(id) +
                       ": needs a fix energy/ledger defined before it (the ledger reads it)")
                          .c_str());
  double **f = atom->f, **torque = atom->torque;
  const int nlocal = atom->nlocal;
  snapshot_.resize(6 * static_cast<size_t>(nlocal));
  part_.resize(6 * static_cast<size_t>(nlocal));
  const int nprev = static_cast<int>(previous_->size() / 6);
  for (int i = 0; i < nlocal; ++i) {
    double *s = &snapshot_[6 * i], *p = &part_[6 * i];
    s[0] = f[i][0], s[1] = f[i][1], s[2] = f[i][2];
    s[3] = torque[i][0], s[4] = torque[i][1], s[5] = torque[i][2];
    for (int c = 0; c < 6; ++c) p[c] = s[c] - (i < nprev ? (*previous_)[6 * i + c] : 0.0);
  }
  if (booked_bonds_) {
    const std::vector<double> &fb = booked_bonds_->ledger_forces();
    const size_t n = std::min(fb.size(), part_.size());
    for (size_t k = 0; k < n; ++k) part_[k] -= fb[k];
  }
  if (booked_wall_) booked_wall_->subtract_forces(part_);
}

void FixEnergyWork::end_of_step() {
  work_.add(local_power(), update->dt);
  added_step_ = update->ntimestep;
}

// Power of the part's forces and torques on the owned atoms at the full-step
// velocities [W].
double FixEnergyWork::local_power() const {
  if (measures_mesh()) {
    // The mesh's summed torque is global: rank 0 counts it.
    if (comm->me != 0 || !mesh_) return 0.0;
    double p = 0.0;
    for (int c = 0; c < 3; ++c) p -= omega_[c] * mesh_->compute_vector(3 + c);
    return p;
  }
  const int n = std::min(atom->nlocal, static_cast<int>(part_.size() / 6));
  return mill::power6(part_.data(), n, atom->v, atom->omega);
}

// The ledger samples in its own end_of_step, which runs before this fix's.
double FixEnergyWork::local_work_now() const {
  if (added_step_ == update->ntimestep) return work_.value();
  return work_.value_with(local_power(), update->dt);
}

double FixEnergyWork::local_end_term(int groupbit) const {
  if (measures_mesh()) return 0.0;  // its per-atom forces are not known
  const int n = std::min(atom->nlocal, static_cast<int>(part_.size() / 6));
  double s = 0.0;
  for (int i = 0; i < n; ++i)
    if (atom->mask[i] & groupbit)
      s += mill::end_term(&part_[6 * i], &part_[6 * i + 3], atom->f[i], atom->torque[i],
                          atom->rmass[i], atom->radius[i]);
  return s;
}

// The trapezoidal work of the part over all ranks so far [J] (without the
// end term; the ledger's column is exact).
double FixEnergyWork::compute_scalar() {
  double loc = local_work_now(), glob = 0.0;
  MPI_Allreduce(&loc, &glob, 1, MPI_DOUBLE, MPI_SUM, world);
  return glob;
}
