// fix energy/ledger: the energy of a bonded-lump run, term by term over time,
// and the checks that stop a run in which energy is created
// (docs/styles/fix_energy_ledger.md).
#include "fix_energy_ledger.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "fix_bond_breakable.h"
#include "fix_energy_work.h"
#include "fix_property_global.h"
#include "fix_wall_halfspace.h"
#include "force.h"
#include "group.h"
#include "lmptype.h"
#include "modify.h"
#include "neigh_list.h"
#include "pair.h"
#include "style_args.h"
#include "update.h"

using namespace LAMMPS_NS;
using namespace FixConst;

namespace {

constexpr const char *kColumnNames =
    "step,time_s,ke_trans_J,ke_rot_J,numerical_J,bond_elastic_J,bond_released_J,bond_damping_J,"
    "bond_friction_J,wall_elastic_J,wall_damping_J,wall_friction_J,contact_elastic_J,"
    "contact_damping_J,contact_friction_J,work_other_J,input_J,residual_J,max_speed_m_s,wall_"
    "overlap,residual_"
    "bonds_J,"
    "residual_wall_J";

constexpr double kPi = 3.14159265358979323846;

// Styles that add forces in post_force: the ledger must come before them.
constexpr const char *kForceStyles[] = {"bond/breakable", "bond/flatjoint", "wall/halfspace",
                                        "wall/gran",      "fluid/drag",     "gravity",
                                        "addforce",       "setforce"};

}  // namespace

FixEnergyLedger::FixEnergyLedger(LAMMPS *lmp, int narg, char **arg) : Fix(lmp, narg, arg) {
  parse_args(narg, arg);
  vector_flag = 1;
  size_vector = NCOLUMN;  // and one per fix energy/work, known at init
  global_freq = every_;
  extvector = 0;
}

FixEnergyLedger::~FixEnergyLedger() {
  if (out_) fclose(out_);
}

// Reads `fix ID group energy/ledger (every N | interval T) file F youngs E poisson NU [bonds ID]
// [wall ID] [speed_bound V] [residual_bound R] [residual_floor J]`.
void FixEnergyLedger::parse_args(int narg, char **arg) {
  auto fail = [this](const std::string &msg) {
    const std::string m = "fix energy/ledger: " + msg;
    error->all(FLERR, m.c_str());
  };
  const mill::StyleArgs args(error, "energy/ledger");
  bool have_e = false, have_nu = false;
  int iarg = 3;
  while (iarg < narg) {
    const std::string key = arg[iarg];
    if (iarg + 1 >= narg) fail("keyword '" + key + "' needs a value");
    const char *val = arg[iarg + 1];
    if (key == "every") {
      every_ = args.integer("every", val, 1, 1000000000);
      interval_ = 0.0;
    } else if (key == "interval") {
      interval_ = args.positive("interval", val, "s");
    } else if (key == "file") {
      file_ = val;
    } else if (key == "youngs") {
      youngs_ = args.positive("youngs", val, "Pa");
      have_e = true;
    } else if (key == "poisson") {
      poisson_ = args.real("poisson", val);
      if (!(poisson_ > -1.0 && poisson_ < 0.5))
        fail(std::string("poisson must be in (-1, 0.5), got ") + val);
      have_nu = true;
    } else if (key == "integrated") {
      integrated_ = val;
    } else if (key == "bonds") {
      bond_id_ = val;
    } else if (key == "wall") {
      wall_id_ = val;
    } else if (key == "speed_bound") {
      speed_bound_ = args.real("speed_bound", val);
      if (!(speed_bound_ >= 0.0))
        fail(std::string("speed_bound must be >= 0 m/s (0: no check), got ") + val);
    } else if (key == "residual_bound") {
      residual_bound_ = args.real("residual_bound", val);
      if (!(residual_bound_ >= 0.0))
        fail(std::string("residual_bound must be >= 0 (0: no check), got ") + val);
    } else if (key == "residual_floor") {
      residual_floor_ = args.real("residual_floor", val);
      if (!(residual_floor_ >= 0.0)) fail(std::string("residual_floor must be >= 0 J, got ") + val);
    } else {
      fail("unknown keyword '" + key +
           "' (expected every, interval, file, youngs, poisson, integrated, bonds, wall, "
           "speed_bound, "
           "residual_bound, residual_floor)");
    }
    iarg += 2;
  }
  if (!have_e || !have_nu)
    fail("youngs E and poisson NU of the elements are required (Hertz energy of contacts)");
}

int FixEnergyLedger::setmask() { return POST_FORCE | END_OF_STEP | POST_RUN; }

// Finds the fixes whose terms are read and checks that this fix sees the
// pair forces before any fix adds its own.
void FixEnergyLedger::init() {
  if (!atom->sphere_flag || !atom->rmass_flag)
    error->all(FLERR, "fix energy/ledger: needs atom_style sphere (radius, rmass, omega, torque)");
  bonds_ = nullptr;
  wall_ = nullptr;
  // The integrated group may be made after this fix (a lab deck separates the
  // platens after the bonds are made): until it exists, the fix's group.
  moved_ = groupbit;
  if (!integrated_.empty()) {
    const int ig = group->find(integrated_.c_str());
    if (ig >= 0) moved_ = group->bitmask[ig];
  }
  if (!bond_id_.empty()) {
    bonds_ = dynamic_cast<FixBondBreakable *>(modify->find_fix_id(bond_id_.c_str()));
    if (!bonds_)
      error->all(FLERR,
                 ("fix energy/ledger: bonds " + bond_id_ +
                  ": no fix bond/breakable or bond/flatjoint with that ID")
                     .c_str());
  }
  if (!wall_id_.empty()) {
    wall_ = dynamic_cast<FixWallHalfspace *>(modify->find_fix_id(wall_id_.c_str()));
    if (!wall_)
      error->all(
          FLERR,
          ("fix energy/ledger: wall " + wall_id_ + ": no fix wall/halfspace with that ID").c_str());
  }
  check_order();
  find_parts();
  find_restitution();
  if (interval_ > 0.0) every_ = std::max(1, static_cast<int>(std::lround(interval_ / update->dt)));
  global_freq = every_;
  // A `timestep` command between runs changed the step: bank as reset_dt does
  // (the forces are still those of the last step).
  bank_step_change();
  if (!force->pair)
    error->all(FLERR, "fix energy/ledger: needs a pair style (the element contacts)");
  if (comm->me == 0 && !out_ && !file_.empty()) {
    out_ = fopen(file_.c_str(), started_ ? "a" : "w");
    if (!out_) error->one(FLERR, ("fix energy/ledger: cannot open file '" + file_ + "'").c_str());
    if (!started_) {
      std::string header = kColumnNames;
      for (const FixEnergyWork *w : parts_) header += ",work_" + w->part_name() + "_J";
      fprintf(out_,
              "# fix energy/ledger: energy of the run [J] (docs/styles/fix_energy_ledger.md)\n%s\n",
              header.c_str());
      fflush(out_);
    }
  }
}

// Every fix that adds forces must come after this one in the deck.
void FixEnergyLedger::check_order() const {
  int me = -1;
  for (int k = 0; k < modify->nfix; ++k)
    if (modify->fix[k] == this) me = k;
  for (int k = 0; k < me; ++k)
    for (const char *s : kForceStyles)
      if (modify->fix[k]->style && std::strcmp(modify->fix[k]->style, s) == 0) {
        const std::string m =
            std::string("fix energy/ledger: must be defined before fix ") + modify->fix[k]->id +
            " (" + s + "): it reads the element contacts' forces before any fix adds its own";
        error->all(FLERR, m.c_str());
      }
}

// The fixes energy/work after this one, in deck order: each measures the
// forces added between the snapshot before it (this fix's, or the previous
// part's) and its own. One before this fix has no snapshot to start from.
void FixEnergyLedger::find_parts() {
  std::vector<FixEnergyWork *> found;
  bool after = false;
  for (int k = 0; k < modify->nfix; ++k) {
    if (modify->fix[k] == this) {
      after = true;
      continue;
    }
    auto *w = dynamic_cast<FixEnergyWork *>(modify->fix[k]);
    if (!w) continue;
    if (!after)
      error->all(FLERR, ("fix energy/ledger: fix energy/work " + std::string(w->id) +
                         " is defined before the ledger; define it after the force fixes whose "
                         "work it measures, and after the ledger")
                            .c_str());
    found.push_back(w);
  }
  if (started_ && found.size() != parts_.size())
    error->all(FLERR,
               "fix energy/ledger: a fix energy/work was added or removed between runs; the "
               "ledger's columns are fixed at the first run");
  parts_ = found;
  // Each part: the snapshot before it, and the fixes in between whose forces
  // the ledger books itself (bonds, the rigid surface).
  auto index_of = [this](const Fix *f) {
    for (int k = 0; k < modify->nfix; ++k)
      if (modify->fix[k] == f) return k;
    return -1;
  };
  const std::vector<double> *previous = &fpair_;
  int from = index_of(this);
  for (FixEnergyWork *w : parts_) {
    if (w->measures_mesh()) continue;
    const int to = index_of(w);
    const int ib = bonds_ ? index_of(bonds_) : -1, iw = wall_ ? index_of(wall_) : -1;
    w->set_previous(previous);
    w->set_booked(ib > from && ib < to ? bonds_ : nullptr, iw > from && iw < to ? wall_ : nullptr);
    previous = &w->snapshot();
    from = to;
  }
  size_vector = NCOLUMN + static_cast<int>(parts_.size());
  part_row_.assign(parts_.size(), 0.0);
}

// The normal dashpot of the pair style's Hertz contacts (LIGGGHTS
// normal_model_hertz): gamma_n = -2 sqrt(5/6) beta sqrt(S_n m*), S_n =
// 2 Y* sqrt(R* delta), beta = ln e / sqrt(ln^2 e + pi^2), with e the pair's
// coefficientRestitution (property/global) of the two elements' types
// (Tsuji et al. 1992). Read at each init.
void FixEnergyLedger::find_restitution() {
  ntypes_ = atom->ntypes;
  beta_.assign(static_cast<size_t>(ntypes_ + 1) * (ntypes_ + 1), 0.0);
  auto *cor = static_cast<FixPropertyGlobal *>(modify->find_fix_property(
      "coefficientRestitution", "property/global", "peratomtypepair", ntypes_, ntypes_, style));
  for (int i = 1; i <= ntypes_; ++i)
    for (int j = 1; j <= ntypes_; ++j) {
      const double e = cor->compute_array(i - 1, j - 1);
      if (!(e > 0.0 && e <= 1.0))
        error->all(FLERR, "fix energy/ledger: coefficientRestitution must be in (0, 1]");
      const double le = std::log(e);
      beta_[static_cast<size_t>(i) * (ntypes_ + 1) + j] = le / std::sqrt(le * le + kPi * kPi);
    }
}

// First run: the energy at the start. Every run: the pair forces (the fixes
// after this one add theirs to the same arrays right after).
void FixEnergyLedger::setup(int vflag) {
  post_force(vflag);
  if (started_) {
    // Between runs no force acts: kinetic energy that changed since the last
    // step (a `velocity` or `set` command) came from nowhere. It goes into
    // the residual, not into the other forces' work.
    double t = 0.0, r = 0.0, s = 0.0;
    local_kinetic(t, r, s);
    injected_ += t + r - ke_last_;
    ke_last_ = t + r;
    return;
  }
  pair_work_.start(local_pair_power(), update->dt);
  damp_work_.start(local_damping_power(), update->dt);
  started_ = true;
  double t = 0.0, r = 0.0, s = 0.0;
  local_kinetic(t, r, s);
  ke_last_ = t + r;
  double loc[2] = {t + r + s, local_contact_elastic()}, glob[2] = {0.0, 0.0};
  MPI_Allreduce(loc, glob, 2, MPI_DOUBLE, MPI_SUM, world);
  kinetic0_ = glob[0];
  contact_elastic0_ = glob[1];
}

// The pair forces and torques of this step, before any fix adds its own.
void FixEnergyLedger::post_force(int /*vflag*/) {
  double **f = atom->f, **torque = atom->torque;
  const int nlocal = atom->nlocal;
  fpair_.resize(6 * static_cast<size_t>(nlocal));
  for (int i = 0; i < nlocal; ++i) {
    double *p = &fpair_[6 * i];
    p[0] = f[i][0], p[1] = f[i][1], p[2] = f[i][2];
    p[3] = torque[i][0], p[4] = torque[i][1], p[5] = torque[i][2];
  }
  contact_damping_forces();
}

// The normal-dashpot part of this step's pair forces, per owned atom: the
// law of find_restitution at this step's positions and half-step velocities,
// the values the pair style used. A pair with a ghost is listed on both
// ranks (newton off): each adds the force on its own atom.
void FixEnergyLedger::contact_damping_forces() {
  const int nlocal = atom->nlocal;
  fdamp_.assign(3 * static_cast<size_t>(nlocal), 0.0);
  const NeighList *list = force->pair->list;
  if (!list || !list->ilist) return;
  double **x = atom->x, **v = atom->v;
  const double *radius = atom->radius, *rmass = atom->rmass;
  const int *type = atom->type;
  const double yeff = FixWallHalfspace::effective_youngs(youngs_, poisson_, youngs_, poisson_);
  const double sqrt56 = std::sqrt(5.0 / 6.0);
  for (int ii = 0; ii < list->inum; ++ii) {
    const int i = list->ilist[ii];
    const int *jlist = list->firstneigh[i];
    for (int jj = 0; jj < list->numneigh[i]; ++jj) {
      const int j = jlist[jj] & NEIGHMASK;
      const double d[3] = {x[i][0] - x[j][0], x[i][1] - x[j][1], x[i][2] - x[j][2]};
      const double rsum = radius[i] + radius[j];
      const double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
      if (r2 >= rsum * rsum || r2 == 0.0) continue;
      const double r = std::sqrt(r2), delta = rsum - r;
      const double beta = beta_[static_cast<size_t>(type[i]) * (ntypes_ + 1) + type[j]];
      if (beta == 0.0) continue;
      const double n[3] = {d[0] / r, d[1] / r, d[2] / r};
      const double vn =
          (v[i][0] - v[j][0]) * n[0] + (v[i][1] - v[j][1]) * n[1] + (v[i][2] - v[j][2]) * n[2];
      const double reff = radius[i] * radius[j] / rsum;
      const double meff = rmass[i] * rmass[j] / (rmass[i] + rmass[j]);
      const double sn = 2.0 * yeff * std::sqrt(reff * delta);
      const double gamman = -2.0 * sqrt56 * beta * std::sqrt(sn * meff);
      const double fd = -gamman * vn;  // on i along n; on j the opposite
      for (int c = 0; c < 3; ++c) {
        fdamp_[3 * i + c] += fd * n[c];
        if (j < nlocal) fdamp_[3 * j + c] -= fd * n[c];
      }
    }
  }
}

// Power of the contacts' normal dashpots on the owned atoms at the full-step
// velocities [W].
double FixEnergyLedger::local_damping_power() const {
  double **v = atom->v;
  const int n = std::min(atom->nlocal, static_cast<int>(fdamp_.size() / 3));
  double p = 0.0;
  for (int i = 0; i < n; ++i)
    p += fdamp_[3 * i] * v[i][0] + fdamp_[3 * i + 1] * v[i][1] + fdamp_[3 * i + 2] * v[i][2];
  return p;
}

// Power of the pair forces on the owned atoms at the full-step velocities [W].
double FixEnergyLedger::local_pair_power() const {
  const int n = std::min(atom->nlocal, static_cast<int>(fpair_.size() / 6));
  return mill::power6(fpair_.data(), n, atom->v, atom->omega);
}

// Kinetic energy of the group's owned elements (translation, rotation with
// I = 2/5 m r^2) and velocity Verlet's shadow term sum |F|^2 dt^2 / (8 m) +
// |T|^2 dt^2 / (8 I): with it, the trapezoidal work of all forces equals the
// change of kinetic energy exactly (docs/styles/fix_energy_ledger.md).
void FixEnergyLedger::local_kinetic(double &trans, double &rot, double &shadow) const {
  double **v = atom->v, **omega = atom->omega, **f = atom->f, **torque = atom->torque;
  const double *rmass = atom->rmass, *radius = atom->radius;
  const int *mask = atom->mask;
  const double dt2 = update->dt * update->dt;
  trans = rot = shadow = 0.0;
  for (int i = 0; i < atom->nlocal; ++i) {
    if (!(mask[i] & moved_)) continue;
    const double m = rmass[i], inertia = 0.4 * m * radius[i] * radius[i];
    trans += 0.5 * m * (v[i][0] * v[i][0] + v[i][1] * v[i][1] + v[i][2] * v[i][2]);
    rot += 0.5 * inertia *
           (omega[i][0] * omega[i][0] + omega[i][1] * omega[i][1] + omega[i][2] * omega[i][2]);
    shadow -=
        dt2 / 8.0 *
        ((f[i][0] * f[i][0] + f[i][1] * f[i][1] + f[i][2] * f[i][2]) / m +
         (torque[i][0] * torque[i][0] + torque[i][1] * torque[i][1] + torque[i][2] * torque[i][2]) /
             inertia);
  }
}

// Elastic energy in the normal springs of the touching element pairs of the
// pair style's neighbour list: 8/15 Y* sqrt(R*) delta^(5/2) per pair (the
// integral of Hertz's 4/3 Y* sqrt(R*) delta^(3/2); Johnson 1985, eq. 4.23),
// Y* = E / (2 (1 - nu^2)) for two elements of the same ore. A pair with a
// ghost is listed on both ranks (newton off): half each.
double FixEnergyLedger::local_contact_elastic() const {
  const NeighList *list = force->pair->list;
  if (!list || !list->ilist) return 0.0;
  double **x = atom->x;
  const double *radius = atom->radius;
  const int nlocal = atom->nlocal;
  const double yeff = FixWallHalfspace::effective_youngs(youngs_, poisson_, youngs_, poisson_);
  double e = 0.0;
  for (int ii = 0; ii < list->inum; ++ii) {
    const int i = list->ilist[ii];
    const int *jlist = list->firstneigh[i];
    for (int jj = 0; jj < list->numneigh[i]; ++jj) {
      const int j = jlist[jj] & NEIGHMASK;
      const double dx = x[i][0] - x[j][0], dy = x[i][1] - x[j][1], dz = x[i][2] - x[j][2];
      const double rsum = radius[i] + radius[j];
      const double r2 = dx * dx + dy * dy + dz * dz;
      if (r2 >= rsum * rsum) continue;
      const double delta = rsum - std::sqrt(r2);
      const double reff = radius[i] * radius[j] / rsum;
      e += (j < nlocal ? 1.0 : 0.5) * 8.0 / 15.0 * yeff * std::sqrt(reff) * delta * delta *
           std::sqrt(delta);
    }
  }
  return e;
}

// Full-step velocities: the contacts' work of this step; the speed bound;
// a sample every `every` steps.
void FixEnergyLedger::end_of_step() {
  pair_work_.add(local_pair_power(), update->dt);
  damp_work_.add(local_damping_power(), update->dt);
  double **v = atom->v, **omega = atom->omega;
  const double *rmass = atom->rmass, *radius = atom->radius;
  const int *mask = atom->mask;
  const double bound_sq = speed_bound_ * speed_bound_;
  ke_last_ = 0.0;
  for (int i = 0; i < atom->nlocal; ++i) {
    if (!(mask[i] & moved_)) continue;
    const double s2 = v[i][0] * v[i][0] + v[i][1] * v[i][1] + v[i][2] * v[i][2];
    const double w2 =
        omega[i][0] * omega[i][0] + omega[i][1] * omega[i][1] + omega[i][2] * omega[i][2];
    ke_last_ += 0.5 * rmass[i] * (s2 + 0.4 * radius[i] * radius[i] * w2);
    vmax_sq_ = std::max(vmax_sq_, s2);
    if (speed_bound_ > 0.0 && s2 > bound_sq) {
      char m[640];
      snprintf(
          m, sizeof(m),
          "fix energy/ledger: element %d moves at %.4g m/s at step " BIGINT_FORMAT
          " (t = %.6g s), above the speed bound %.4g m/s that the run's inputs allow: energy was "
          "created, the run is invalid (the ledger so far: %s)",
          atom->tag[i], std::sqrt(s2), update->ntimestep, update->get_cur_time(), speed_bound_,
          file_.empty() ? "no file" : file_.c_str());
      // Also on stderr: error->one aborts before the log file is flushed.
      fprintf(stderr, "ERROR on proc %d: %s\n", comm->me, m);
      fflush(stderr);
      error->one(FLERR, m);
    }
  }
  if (update->ntimestep % every_ == 0) sample(true);
}

// The last state of every run is a row, unless it is one already.
void FixEnergyLedger::post_run() {
  if (last_sample_ != update->ntimestep) sample(true);
}

// Sums the terms over ranks (one reduction), closes the balance, checks the
// residual, writes a row (rank 0).
void FixEnergyLedger::sample(bool write) {
  const size_t nsum = NSUM + parts_.size();
  std::vector<double> loc(nsum, 0.0), glob(nsum, 0.0);
  local_kinetic(loc[T], loc[R], loc[S]);
  loc[CE] = local_contact_elastic();
  loc[INJ] = injected_;
  // Exact velocity-Verlet work of each family: the trapezoid less its end
  // term dt^2/4 sum f.F/m (+ torques), energy_terms.h, over the group's atoms
  // (atoms moved at a set speed, such as platens, need no end term).
  const double q = 0.25 * update->dt * update->dt;
  double pair_end = 0.0, damp_end = 0.0;
  const double no_torque[3] = {0.0, 0.0, 0.0};
  const int np = std::min(atom->nlocal, static_cast<int>(fpair_.size() / 6));
  const int nd = std::min(atom->nlocal, static_cast<int>(fdamp_.size() / 3));
  for (int i = 0; i < np; ++i)
    if (atom->mask[i] & moved_)
      pair_end += mill::end_term(&fpair_[6 * i], &fpair_[6 * i + 3], atom->f[i], atom->torque[i],
                                 atom->rmass[i], atom->radius[i]);
  for (int i = 0; i < nd; ++i)
    if (atom->mask[i] & moved_)
      damp_end += mill::end_term(&fdamp_[3 * i], no_torque, atom->f[i], atom->torque[i],
                                 atom->rmass[i], atom->radius[i]);
  loc[WP] = pair_work_.value() - q * pair_end;
  loc[WDP] = damp_work_.value() - q * damp_end;
  for (size_t k = 0; k < parts_.size(); ++k)
    loc[NSUM + k] = parts_[k]->local_work_now() - q * parts_[k]->local_end_term(moved_);
  if (bonds_) {
    const auto &b = bonds_->local_energy();
    loc[WB] = bonds_->local_work_now() - q * bonds_->local_end_term(moved_);
    loc[BE] = b.elastic;
    loc[BE0] = b.elastic0;
    loc[BR] = b.released;
    loc[BD] = bonds_->local_damping_now();
    loc[BF] = b.friction;
  }
  if (wall_) {
    const auto &w = wall_->local_energy();
    wall_->local_work_now(loc[WW], loc[WD]);
    loc[WW] -= q * wall_->local_end_term(moved_);
    loc[WE] = w.elastic;
    loc[WE0] = w.elastic0;
    loc[WF] = w.friction;
  }
  for (size_t k = 0; k < dt_offset_.size() && k < nsum; ++k) loc[k] += dt_offset_[k];
  MPI_Allreduce(loc.data(), glob.data(), static_cast<int>(nsum), MPI_DOUBLE, MPI_SUM, world);
  const double lmax[2] = {vmax_sq_, wall_ ? wall_->local_energy().max_overlap : 0.0};
  double gmax[2] = {0.0, 0.0};
  MPI_Allreduce(lmax, gmax, 2, MPI_DOUBLE, MPI_MAX, world);
  vmax_sq_ = 0.0;

  double *r = row_;
  r[KE_TRANS] = glob[T];
  r[KE_ROT] = glob[R];
  r[NUMERICAL] = glob[S];
  r[BOND_ELASTIC] = glob[BE];
  r[BOND_RELEASED] = glob[BR];
  r[BOND_DAMPING] = glob[BD];
  r[BOND_FRICTION] = glob[BF];
  r[WALL_ELASTIC] = glob[WE];
  r[WALL_DAMPING] = glob[WD];
  r[WALL_FRICTION] = glob[WF];
  r[CONTACT_ELASTIC] = glob[CE];
  // What the element contacts took and do not store: their normal dashpots,
  // and the rest (tangential: slip, dashpot, rolling resistance).
  r[CONTACT_DAMPING] = -glob[WDP];
  r[CONTACT_FRICTION] = -glob[WP] - (glob[CE] - contact_elastic0_) - r[CONTACT_DAMPING];
  // The kinetic theorem: every other force did the rest of the work.
  // (less what changed between runs, which no force did).
  r[WORK_OTHER] =
      (glob[T] + glob[R] + glob[S] - kinetic0_) - glob[WP] - glob[WB] - glob[WW] - glob[INJ];
  r[INPUT] = kinetic0_ + contact_elastic0_ + glob[BE0] + glob[WE0];
  double held = 0.0;
  for (int c = KE_TRANS; c <= CONTACT_FRICTION; ++c) held += r[c];
  r[RESIDUAL] = r[INPUT] + r[WORK_OTHER] - held;
  r[MAX_SPEED] = std::sqrt(gmax[0]);
  r[WALL_OVERLAP] = gmax[1];
  r[RESIDUAL_BONDS] = -(glob[WB] + glob[BE] - glob[BE0] + glob[BR] + glob[BD] + glob[BF]);
  r[RESIDUAL_WALL] = -(glob[WW] + glob[WE] - glob[WE0] + glob[WD] + glob[WF]);
  for (size_t k = 0; k < parts_.size(); ++k) part_row_[k] = glob[NSUM + k];
  last_sample_ = update->ntimestep;

  if (write && out_) {
    fprintf(out_, BIGINT_FORMAT ",%.10g", update->ntimestep, update->get_cur_time());
    for (double c : row_) fprintf(out_, ",%.10g", c);
    for (double c : part_row_) fprintf(out_, ",%.10g", c);
    fputc('\n', out_);
    fflush(out_);
  }
  const double scale = r[INPUT] + std::fabs(r[WORK_OTHER]);
  if (residual_bound_ > 0.0 && std::fabs(r[RESIDUAL]) > residual_floor_ &&
      std::fabs(r[RESIDUAL]) > residual_bound_ * scale) {
    char m[640];
    snprintf(
        m, sizeof(m),
        "fix energy/ledger: the energy balance does not close at step " BIGINT_FORMAT
        " (t = %.6g s): residual %.4g J is %.3g%% of the energy put in (%.4g J), above the bound "
        "%.3g%%: energy was created or lost by the integration, the run is invalid (ledger: %s)",
        update->ntimestep, update->get_cur_time(), r[RESIDUAL],
        100.0 * std::fabs(r[RESIDUAL]) / scale, scale, 100.0 * residual_bound_,
        file_.empty() ? "no file" : file_.c_str());
    if (comm->me == 0) {
      fprintf(stderr, "ERROR: %s\n", m);
      fflush(stderr);
    }
    error->all(FLERR, m);
  }
}

// The step changed from books_dt_ to update->dt at the end of step K (the
// forces are F_K). Each step's work is exact with that step's own length
// (trapezoid less end term, energy_terms.h), but the shadow term
// -dt^2/8 |F_K|^2/m and the end terms -dt^2/4 f_K.F_K/m that the books hold
// at step K were taken with the old step: their difference to the same terms
// with the new step is banked, so the row of step K reads the same with
// either. The interval between samples is kept in time.
void FixEnergyLedger::reset_dt() {
  if (interval_ > 0.0) {
    every_ = std::max(1, static_cast<int>(std::lround(interval_ / update->dt)));
    global_freq = every_;
  }
  bank_step_change();
}

void FixEnergyLedger::bank_step_change() {
  const double a = books_dt_, b = update->dt;
  books_dt_ = b;
  if (!started_ || a == b || a == 0.0) return;
  const std::vector<double> sums = local_step_sums();
  if (dt_offset_.size() < sums.size()) dt_offset_.resize(sums.size(), 0.0);
  dt_offset_[S] += (b * b - a * a) / 8.0 * sums[S];
  for (size_t k = 0; k < sums.size(); ++k)
    if (k != S) dt_offset_[k] += (b * b - a * a) / 4.0 * sums[k];
}

std::vector<double> FixEnergyLedger::local_step_sums() const {
  std::vector<double> e(NSUM + parts_.size(), 0.0);
  double **f = atom->f, **torque = atom->torque;
  const double *rmass = atom->rmass, *radius = atom->radius;
  const int *mask = atom->mask;
  for (int i = 0; i < atom->nlocal; ++i) {
    if (!(mask[i] & moved_)) continue;
    e[S] += mill::end_term(f[i], torque[i], f[i], torque[i], rmass[i], radius[i]);
  }
  const double no_torque[3] = {0.0, 0.0, 0.0};
  const int np = std::min(atom->nlocal, static_cast<int>(fpair_.size() / 6));
  const int nd = std::min(atom->nlocal, static_cast<int>(fdamp_.size() / 3));
  for (int i = 0; i < np; ++i)
    if (mask[i] & moved_)
      e[WP] +=
          mill::end_term(&fpair_[6 * i], &fpair_[6 * i + 3], f[i], torque[i], rmass[i], radius[i]);
  for (int i = 0; i < nd; ++i)
    if (mask[i] & moved_)
      e[WDP] += mill::end_term(&fdamp_[3 * i], no_torque, f[i], torque[i], rmass[i], radius[i]);
  for (size_t k = 0; k < parts_.size(); ++k) e[NSUM + k] = parts_[k]->local_end_term(moved_);
  if (bonds_) e[WB] = bonds_->local_end_term(moved_);
  if (wall_) e[WW] = wall_->local_end_term(moved_);
  return e;
}

// Global outputs 1..NCOLUMN + parts: the last sample's columns (cached).
double FixEnergyLedger::compute_vector(int n) {
  if (n >= 0 && n < NCOLUMN) return row_[n];
  const size_t k = static_cast<size_t>(n - NCOLUMN);
  return (n >= NCOLUMN && k < part_row_.size()) ? part_row_[k] : 0.0;
}
