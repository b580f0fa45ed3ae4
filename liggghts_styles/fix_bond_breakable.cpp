// fix bond/breakable: parallel-bond model of Potyondy & Cundall (2004) as a
// LIGGGHTS 3.8 fix. Physics references are cited per line; see the doc page
// docs/styles/fix_bond_breakable.md for the equations and keywords.
#include "fix_bond_breakable.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <map>
#include <sstream>
#include <unordered_map>

#include "atom.h"
#include "bond_geometry.h"
#include "bond_lanes.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "memory.h"
#include "neighbor.h"
#include "network_step.h"
#include "step_limit.h"
#include "style_args.h"
#include "update.h"

using namespace LAMMPS_NS;
using namespace FixConst;
using namespace mill::bond_geometry;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kEventCols = 10;  // step time x y z mode tag_a tag_b sigma tau
constexpr int kMaxBondsLimit = 64;
// Intact bonds per evaluation unless `lanes` says otherwise: a pack of four
// where this file is built for AVX (MILL_AVX), else two (SSE2).
#if defined(__AVX__)
constexpr int kDefaultLanes = 4;
#else
constexpr int kDefaultLanes = 2;
#endif

// Formats a double the way users wrote it (shortest round-trip-ish form).
std::string fmt_num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

// Result of one bond evaluation in the canonical frame (a = lower tag).
struct FixBondBreakable::BondResult {
  Vec3 fa;          // total force on a (force on b is -fa)
  Vec3 ta;          // torque on a
  Vec3 tb;          // torque on b
  double sigma;     // max tensile stress [Pa]
  double tau;       // max shear stress [Pa]
  double strength;  // shear strength at this normal stress [Pa]
  double energy;    // elastic energy stored in the bond [J]
  double stretch;   // L - L0 [m] (< 0: compressed)
  double released;  // what a bond that breaks now takes with it [J] (advance only)
  Vec3 fdash;       // the dashpots' part of the force on b [N]
  double slipped;   // taken this step by Coulomb slip of a contact [J] (advance only)
  Vec3 centre;      // bond centre (contact point)
  int mode;         // 0 intact, 1 tension, 2 shear
  // bond/flatjoint: elements that broke this step, and bonded after it.
  int fj_tension = 0, fj_shear = 0, fj_bonded = 0;
};

// Per-atom arrays read by evaluate_bond, fetched once per step (LIGGGHTS's
// Pointers members are references to pointers: one load each, not per bond).
struct FixBondBreakable::AtomArrays {
  double **x, **v, **omega;
  double *radius, *rmass;
  double dt;
};

/* ---------------------------------------------------------------------- */

// Parses keywords, allocates per-atom storage and registers atom callbacks.
FixBondBreakable::FixBondBreakable(LAMMPS *lmp, int narg, char **arg) : Fix(lmp, narg, arg) {
  lanes_ = kDefaultLanes;
  parse_args(narg, arg);

  restart_global = 1;
  restart_peratom = 1;
  vector_flag = 1;
  size_vector = 8;
  global_freq = 1;
  extvector = 0;
  peratom_flag = 1;
  size_peratom_cols = 0;
  peratom_freq = 1;
  create_attribute = 1;  // atoms created later start without bonds

  grow_arrays(atom->nmax);
  atom->add_callback(0);  // grow / copy / exchange
  atom->add_callback(1);  // restart
  for (int i = 0; i < atom->nmax; ++i) {
    nbond_[i] = 0;
    count_[i] = 0.0;
  }
}

// Unregisters callbacks and frees storage; closes the break log.
FixBondBreakable::~FixBondBreakable() {
  atom->delete_callback(id, 0);
  atom->delete_callback(id, 1);
  memory->destroy(nbond_);
  memory->destroy(bonds_);
  memory->destroy(count_);
  if (break_log_) fclose(break_log_);
}

// Reads `fix ID group bond/breakable key value ...`; errors name key and value.
void FixBondBreakable::parse_args(int narg, char **arg) {
  bool have_modulus = false, have_ratio = false, have_tensile = false, have_cohesion = false;
  auto fail = [this](const std::string &msg) {
    std::string m = label() + msg;
    error->all(FLERR, m.c_str());
  };
  const mill::StyleArgs args(error, style);
  flat_joint_ = std::strcmp(style, "bond/flatjoint") == 0;
  int iarg = 3;
  while (iarg < narg) {
    const std::string key = arg[iarg];
    if (iarg + 1 >= narg) fail("keyword '" + key + "' needs a value");
    const char *val = arg[iarg + 1];
    const bool parallel_only =
        key == "moment_factor" || key == "broken_contact" || key == "contact_moment";
    if (flat_joint_ && parallel_only) {
      fail("keyword '" + key + "' is one of fix bond/breakable's parallel bonds; a flat joint " +
           "has none (its elements carry the moments, broken elements stay as frictional " +
           "contacts): remove it (docs/styles/fix_bond_flatjoint.md)");
    } else if ((key == "elements" || key == "joint_friction" || key == "softening") &&
               !flat_joint_) {
      fail("keyword '" + key + "' belongs to fix bond/flatjoint, not to " + style);
    } else if (key == "elements") {
      if (iarg + 2 >= narg) fail("keyword 'elements' needs two values: rings sectors");
      fj_rings_ = args.integer("elements (rings)", val, 1, mill::flat_joint::kMaxElements);
      fj_sectors_ = args.integer("elements (sectors)", arg[iarg + 2], 3,
                                 mill::flat_joint::kMaxElements);
      ++iarg;
    } else if (key == "joint_friction") {
      fj_friction_ = args.real(arg[iarg], val);
      if (!(fj_friction_ >= 0.0)) fail("joint_friction must be >= 0, got " + std::string(val));
    } else if (key == "softening") {
      fj_softening_ = args.real(arg[iarg], val);
      if (!(fj_softening_ >= 1.0))
        fail(
            "softening must be >= 1 (1: brittle elements; lambda > 1: tension falls to zero "
            "at lambda x the peak opening), got " +
            std::string(val));
    } else if (key == "radius_multiplier") {
      radius_multiplier_ = args.positive(arg[iarg], val);
    } else if (key == "modulus") {
      modulus_ = args.positive(arg[iarg], val, "Pa");
      have_modulus = true;
    } else if (key == "stiffness_ratio") {
      stiffness_ratio_ = args.positive(arg[iarg], val);
      have_ratio = true;
    } else if (key == "tensile_strength") {
      tensile_strength_ = args.positive(arg[iarg], val, "Pa");
      have_tensile = true;
    } else if (key == "cohesion") {
      cohesion_ = args.positive(arg[iarg], val, "Pa");
      have_cohesion = true;
    } else if (key == "friction_angle") {
      friction_angle_ = args.real(arg[iarg], val);
      if (!(friction_angle_ >= 0.0 && friction_angle_ < 90.0))
        fail("friction_angle must be in [0, 90) degrees, got " + std::string(val));
    } else if (key == "damping") {
      damping_ = args.real(arg[iarg], val);
      if (!(damping_ >= 0.0)) fail("damping must be >= 0, got " + std::string(val));
    } else if (key == "moment_factor") {
      moment_factor_ = args.real(arg[iarg], val);
      if (!(moment_factor_ >= 0.0 && moment_factor_ <= 1.0))
        fail("moment_factor must be in [0, 1], got " + std::string(val));
    } else if (key == "broken_contact") {
      const std::string v = val;
      if (v != "yes" && v != "no") fail("broken_contact must be yes or no, got '" + v + "'");
      broken_contact_ = v == "yes";
    } else if (key == "contact_moment") {
      const std::string v = val;
      if (v != "yes" && v != "no") fail("contact_moment must be yes or no, got '" + v + "'");
      contact_moment_ = v == "yes";
    } else if (key == "unbonded_fraction") {
      unbonded_fraction_ = args.real(arg[iarg], val);
      if (!(unbonded_fraction_ >= 0.0 && unbonded_fraction_ < 1.0))
        fail("unbonded_fraction must be in [0, 1), got " + std::string(val));
    } else if (key == "unbonded_seed") {
      unbonded_seed_ = args.integer(arg[iarg], val, 1, 2147483647);
    } else if (key == "gap") {
      gap_ = args.real(arg[iarg], val);
      if (!(gap_ >= 0.0)) fail("gap must be >= 0, got " + std::string(val));
    } else if (key == "max_bonds") {
      max_bonds_ = args.integer(arg[iarg], val, 1, kMaxBondsLimit);
    } else if (key == "lanes") {
      lanes_ = args.integer(arg[iarg], val, 1, 4);
      if (lanes_ == 3) fail("lanes must be 1, 2 or 4 (intact bonds per evaluation), got 3");
    } else if (key == "step_estimate") {
      if (std::strcmp(val, "sum") == 0)
        network_step_ = false;
      else if (std::strcmp(val, "network") == 0)
        network_step_ = true;
      else
        fail(
            "step_estimate must be sum (per-atom sum of the pairs' omega^2) or network "
            "(the whole network's largest eigenfrequency), got '" +
            std::string(val) + "'");
    } else if (key == "break_log") {
      break_log_path_ = val;
    } else if (key == "dump_bonds") {
      dump_bonds_path_ = val;
      if (iarg + 3 < narg && std::strcmp(arg[iarg + 2], "every") == 0) {
        const double v = args.real("every", arg[iarg + 3]);
        if (!(v >= 1.0 && v == std::floor(v)))
          fail("dump_bonds every must be an integer >= 1 step, got " + std::string(arg[iarg + 3]));
        dump_every_ = static_cast<int>(v);
        iarg += 2;
      }
    } else {
      fail("unknown keyword '" + key +
           (flat_joint_ ? "' (expected radius_multiplier, modulus, stiffness_ratio, "
                          "tensile_strength, cohesion, friction_angle, elements, joint_friction, "
                          "softening, unbonded_fraction, unbonded_seed, damping, gap, max_bonds, "
                          "step_estimate, break_log, dump_bonds)"
                        : "' (expected radius_multiplier, modulus, stiffness_ratio, "
                          "tensile_strength, cohesion, friction_angle, moment_factor, "
                          "broken_contact, contact_moment, unbonded_fraction, unbonded_seed, "
                          "damping, gap, max_bonds, lanes, step_estimate, break_log, dump_bonds)"));
    }
    iarg += 2;
  }
  if (!have_modulus) fail("keyword 'modulus' is required (bond Young's modulus, Pa)");
  if (!have_ratio) fail("keyword 'stiffness_ratio' is required (kn/ks, dimensionless)");
  if (!have_tensile) fail("keyword 'tensile_strength' is required (Pa)");
  if (!have_cohesion) fail("keyword 'cohesion' is required (Pa)");
  if (flat_joint_) {
    if (fj_rings_ * fj_sectors_ > mill::flat_joint::kMaxElements)
      fail("elements " + std::to_string(fj_rings_) + " x " + std::to_string(fj_sectors_) +
           " is more than " + std::to_string(mill::flat_joint::kMaxElements) +
           " elements per interface");
    fj_layout_ = mill::flat_joint::make_layout(fj_rings_, fj_sectors_);
    ncol_ = NCOL + mill::flat_joint::history_size(fj_layout_.elements());
  }
}

// Hooks: forces after the pair style; optional periodic bond dumps.
int FixBondBreakable::setmask() {
  int mask = 0;
  mask |= PRE_EXCHANGE;
  mask |= POST_FORCE;
  mask |= POST_RUN;
  mask |= END_OF_STEP;  // the ledger's work (and the periodic bond dump)
  return mask;
}

// Checks the atom style and communication settings; finds the radius range.
void FixBondBreakable::init() {
  if (!atom->radius_flag || !atom->rmass_flag || !atom->omega_flag || !atom->torque_flag)
    error->all(FLERR,
               (label() + "requires per-atom radius, mass, omega and torque "
                "(use 'atom_style sphere')").c_str());
  if (atom->map_style == 0)
    error->all(FLERR,
               (label() + "needs the atom map to find bond partners; add "
                "'atom_modify map array' before the box is created").c_str());
  if (!comm->ghost_velocity)
    error->all(FLERR,
               (label() + "ghost atoms need velocities; add 'communicate single vel yes' "
                "(LIGGGHTS's form of 'comm_modify vel yes')").c_str());

  double lo = 1e300, hi = 0.0;
  for (int i = 0; i < atom->nlocal; ++i)
    if (atom->mask[i] & groupbit) {
      lo = std::min(lo, atom->radius[i]);
      hi = std::max(hi, atom->radius[i]);
    }
  MPI_Allreduce(&hi, &rmax_, 1, MPI_DOUBLE, MPI_MAX, world);
  MPI_Allreduce(&lo, &rmin_, 1, MPI_DOUBLE, MPI_MIN, world);
  if (rmin_ > rmax_) rmin_ = rmax_;
  tan_friction_ = std::tan(friction_angle_ * kPi / 180.0);
  inv_ratio_ = 1.0 / stiffness_ratio_;
  inv_modulus_ = 1.0 / modulus_;

  double lm = 0.0;
  for (int i = 0; i < atom->nlocal; ++i)
    for (int k = 0; k < nbond_[i]; ++k) lm = std::max(lm, bonds_[i][k * ncol_ + L0]);
  MPI_Allreduce(&lm, &lmax_, 1, MPI_DOUBLE, MPI_MAX, world);

  if (break_log_path_.size() && comm->me == 0 && !break_log_) {
    break_log_ = fopen(break_log_path_.c_str(), bonds_created_ ? "a" : "w");
    if (!break_log_) {
      std::string m = label() + "cannot open break_log file '" + break_log_path_ + "'";
      fail_one(m);
    }
    if (!bonds_created_)
      fprintf(break_log_,
              "# fix %s break events\n"
              "# columns: step time[s] x[m] y[m] z[m] mode tag_i tag_j sigma[Pa] %s\n",
              style, flat_joint_ ? "tau/tau_c[-]" : "tau[Pa]");
  }
}

// Ghost cutoff that keeps every bond partner among the ghosts. LIGGGHTS's
// granular comm sends an atom as ghost when it lies within cutghost/2 + skin/2
// + radius of the sub-domain face (comm_I.h), so cutghost must reach ~2 L.
double FixBondBreakable::extend_cut_ghost() {
  double lbond = std::max(lmax_, (2.0 + gap_) * rmax_);
  if (contacts_on()) lbond += gap_ * rmax_;  // contacts live up to L0 + g min(Ri, Rj)
  lbond *= 1.05;  // bonds stretch before they break (strain at break << 5%)
  return std::max(0.0, 2.0 * lbond - 2.0 * rmin_);
}

// First run: creates the bonds. Every run: forces from the stored state.
void FixBondBreakable::setup(int /*vflag*/) {
  if (!bonds_created_) {
    create_bonds();
    bonds_created_ = 1;
  }
  list_valid_ = false;  // atoms may have moved between runs
  estimate_time_step();
  compute_bonds(false);
  if (!ledger_started_) {
    ledger_.work.start(bond_power(), update->dt);
    ledger_.damping.start(dashpot_power(), update->dt);
    ledger_.elastic0 = ledger_.elastic;
    ledger_started_ = true;
    ledger_step_ = update->ntimestep;
  }
}

// Each step: advances, checks and applies every bond.
void FixBondBreakable::post_force(int /*vflag*/) { compute_bonds(true); }

// Atoms are about to move between ranks (and be sorted): the slots they
// carry must hold the current history.
void FixBondBreakable::setup_pre_exchange() { store_history(); }
void FixBondBreakable::pre_exchange() { store_history(); }

// With the full-step velocities: the work of this step's bond forces
// (trapezoidal rule, energy_terms.h); the periodic bond dump.
void FixBondBreakable::end_of_step() {
  ledger_.work.add(bond_power(), update->dt);
  if (damping_ > 0.0) ledger_.damping.add(dashpot_power(), update->dt);
  ledger_step_ = update->ntimestep;
  if (dump_every_ > 0 && update->ntimestep % dump_every_ == 0) write_bond_dump();
}

double FixBondBreakable::local_damping_now() const {
  if (ledger_step_ == update->ntimestep || damping_ <= 0.0) return ledger_.damping.value();
  return ledger_.damping.value_with(dashpot_power(), update->dt);
}

// Power the dashpots take: -f_d . (relative velocity of the contact point) at
// the full-step velocities, each bond once [W].
double FixBondBreakable::dashpot_power() const {
  if (damping_ <= 0.0) return 0.0;
  double **x = atom->x, **v = atom->v, **omega = atom->omega;
  const double *radius = atom->radius;
  const size_t n = std::min(list_.size(), dash_.size() / 3);
  double p = 0.0;
  for (size_t e = 0; e < n; ++e) {
    const Vec3 fd = load3(&dash_[3 * e]);
    if (fd.x == 0.0 && fd.y == 0.0 && fd.z == 0.0) continue;
    const ListedBond &lb = list_[e];
    const Vec3 d = load3(x[lb.b]) - load3(x[lb.a]);
    const PairMotion m = pair_motion(d, std::sqrt(dot(d, d)), load3(v[lb.a]), load3(v[lb.b]),
                                     load3(omega[lb.a]), load3(omega[lb.b]), radius[lb.a], radius[lb.b]);
    p -= dot(fd, m.vn * m.n + m.vt);
  }
  return p;
}

double FixBondBreakable::local_work_now() const {
  if (ledger_step_ == update->ntimestep) return ledger_.work.value();
  return ledger_.work.value_with(bond_power(), update->dt);
}

double FixBondBreakable::local_end_term(int groupbit) const {
  const int n = std::min(atom->nlocal, static_cast<int>(fbond_.size() / 6));
  double s = 0.0;
  for (int i = 0; i < n; ++i)
    if (atom->mask[i] & groupbit)
      s += mill::end_term(&fbond_[6 * i], &fbond_[6 * i + 3], atom->f[i], atom->torque[i], atom->rmass[i],
                        atom->radius[i]);
  return s;
}

// Power of this step's bond forces and torques on the owned atoms [W].
double FixBondBreakable::bond_power() const {
  const int n = std::min(atom->nlocal, static_cast<int>(fbond_.size() / 6));
  return mill::power6(fbond_.data(), n, atom->v, atom->omega);
}

// Writes the bond dump at the end of every run.
void FixBondBreakable::post_run() {
  store_history();  // commands between runs may read or move the slots
  if (!dump_bonds_path_.empty()) write_bond_dump();
  if (break_log_) fflush(break_log_);
}

/* ---------------------------------------------------------------------- */

// Prints one line on screen and in the log file (rank 0).
void FixBondBreakable::message(const std::string &text) const {
  if (comm->me != 0) return;
  if (screen) fprintf(screen, "%s\n", text.c_str());
  if (logfile) fprintf(logfile, "%s\n", text.c_str());
}

// Stops the run from one rank. The message also goes to stderr first:
// Error::one aborts MPI, and a buffered screen file would lose the text.
void FixBondBreakable::fail_one(const std::string &text) const {
  fprintf(stderr, "ERROR on proc %d: %s\n", comm->me, text.c_str());
  fflush(stderr);
  if (logfile) {
    fprintf(logfile, "ERROR on proc %d: %s\n", comm->me, text.c_str());
    fflush(logfile);
  }
  error->one(FLERR, text.c_str());
  std::abort();  // not reached: Error::one does not return
}

// Bonds every pair of group atoms whose surface gap is below gap x min(Ri,Rj).
// Partners may be ghosts; the test is symmetric so both ends agree.
void FixBondBreakable::create_bonds() {
  double **x = atom->x;
  double *radius = atom->radius;
  int *tag = atom->tag;
  int *mask = atom->mask;
  const int nlocal = atom->nlocal;
  const int nall = nlocal + atom->nghost;

  // Cell list over owned + ghost atoms; cell edge = longest possible bond.
  const double h = std::max((2.0 + gap_) * rmax_, 1e-300);
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (int i = 0; i < nall; ++i)
    for (int d = 0; d < 3; ++d) {
      lo[d] = std::min(lo[d], x[i][d]);
      hi[d] = std::max(hi[d], x[i][d]);
    }
  int nc[3] = {1, 1, 1};
  if (nall > 0)
    for (int d = 0; d < 3; ++d)
      nc[d] = std::max(1, std::min(256, static_cast<int>((hi[d] - lo[d]) / h) + 1));
  std::vector<int> head(static_cast<size_t>(nc[0]) * nc[1] * nc[2], -1), next(nall, -1);
  auto cell_of = [&](const double *p, int *c) {
    for (int d = 0; d < 3; ++d)
      c[d] = std::min(nc[d] - 1, std::max(0, static_cast<int>((p[d] - lo[d]) / h)));
  };
  for (int i = 0; i < nall; ++i) {
    if (!(mask[i] & groupbit)) continue;
    int c[3];
    cell_of(x[i], c);
    const size_t id = (static_cast<size_t>(c[2]) * nc[1] + c[1]) * nc[0] + c[0];
    next[i] = head[id];
    head[id] = i;
  }

  struct Candidate {
    int tag;
    double dist;
    Vec3 d;  // lower tag -> higher tag (the flat joint's normal)
  };
  std::vector<Candidate> cand;
  for (int i = 0; i < nlocal; ++i) {
    nbond_[i] = 0;
    if (!(mask[i] & groupbit)) continue;
    cand.clear();
    int c[3];
    cell_of(x[i], c);
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int cx = c[0] + dx, cy = c[1] + dy, cz = c[2] + dz;
          if (cx < 0 || cy < 0 || cz < 0 || cx >= nc[0] || cy >= nc[1] || cz >= nc[2]) continue;
          for (int j = head[(static_cast<size_t>(cz) * nc[1] + cy) * nc[0] + cx]; j >= 0;
               j = next[j]) {
            if (tag[j] == tag[i]) continue;
            // Canonical difference (lower tag -> higher tag): same bits on both ends.
            const bool i_first = tag[i] < tag[j];
            const double *xa = i_first ? x[i] : x[j];
            const double *xb = i_first ? x[j] : x[i];
            const double d[3] = {xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2]};
            const double dist = norm3(d);
            const double rmin_ij = std::min(radius[i], radius[j]);
            if (dist - radius[i] - radius[j] < gap_ * rmin_ij) {
              bool dup = false;  // periodic images: keep the closest
              for (auto &cd : cand)
                if (cd.tag == tag[j]) {
                  if (dist < cd.dist) cd = {tag[j], dist, load3(d)};
                  dup = true;
                }
              if (!dup) cand.push_back({tag[j], dist, load3(d)});
            }
          }
        }
    if (static_cast<int>(cand.size()) > max_bonds_) {
      std::string m = label() + "atom " + std::to_string(tag[i]) + " has " +
                      std::to_string(cand.size()) + " bond candidates but max_bonds is " +
                      std::to_string(max_bonds_) + "; raise max_bonds or lower gap";
      fail_one(m);
    }
    std::sort(cand.begin(), cand.end(),
              [](const Candidate &p, const Candidate &q) { return p.tag < q.tag; });
    for (const auto &cd : cand) {
      double *s = &bonds_[i][nbond_[i] * ncol_];
      for (int k = 0; k < ncol_; ++k) s[k] = 0.0;
      s[PARTNER] = cd.tag;
      s[L0] = cd.dist;
      if (unbonded_fraction_ > 0.0 && starts_unbonded(tag[i], cd.tag)) s[STATE] = 1.0;
      // Both ends get bitwise the same history: the canonical normal.
      if (flat_joint_)
        mill::flat_joint::init_history(&s[NCOL], fj_layout_, (1.0 / cd.dist) * cd.d,
                                       s[STATE] == 0.0);
      ++nbond_[i];
    }
  }

  // Report: number of bonds and mean coordination of the group.
  double local[3] = {0.0, 0.0, 0.0}, global[3];
  double slots = 0.0;
  for (int i = 0; i < nlocal; ++i)
    if (mask[i] & groupbit) {
      local[0] += intact_bonds(i);
      slots += nbond_[i];
      local[1] += 1.0;
      for (int k = 0; k < nbond_[i]; ++k) local[2] = std::max(local[2], bonds_[i][k * ncol_ + L0]);
    }
  MPI_Allreduce(local, global, 2, MPI_DOUBLE, MPI_SUM, world);
  MPI_Allreduce(&local[2], &lmax_, 1, MPI_DOUBLE, MPI_MAX, world);
  double slots_all = 0.0;
  MPI_Allreduce(&slots, &slots_all, 1, MPI_DOUBLE, MPI_SUM, world);
  const double nb = 0.5 * global[0];
  const double coord = global[1] > 0.0 ? global[0] / global[1] : 0.0;
  char line[320];
  snprintf(line, sizeof(line),
           "%screated %.0f bonds among %.0f atoms, mean coordination %.3f "
           "(gap < %g x min radius)",
           label().c_str(), nb, global[1], coord, gap_);
  message(line);
  if (flat_joint_ && fj_softening_ > 1.0) {
    snprintf(line, sizeof(line),
             "%sthe interface elements soften in tension: softening %g (each element's "
             "fracture energy x %g at the same strength)",
             label().c_str(), fj_softening_, fj_softening_);
    message(line);
  }
  if (unbonded_fraction_ > 0.0) {
    snprintf(line, sizeof(line),
             "%s%.0f more pairs in bonding range left unbonded "
             "(unbonded_fraction %g): compression-only frictional contacts",
             label().c_str(), 0.5 * (slots_all - global[0]), unbonded_fraction_);
    message(line);
  }
}

// Index of the partner of local atom i for this step (closest periodic image),
// or an error: a missing partner is never treated as a broken bond.
int FixBondBreakable::partner_index(int i, int partner_tag) const {
  int j = atom->map(partner_tag);
  if (j >= 0 && atom->tag[j] != partner_tag) j = -1;  // stale map entry (deleted atom)
  if (j < 0) {
    std::string m = label() + "bond partner " + std::to_string(partner_tag) +
                    " of atom " + std::to_string(atom->tag[i]) +
                    " is neither owned nor a ghost on this rank (atom lost, or ghost cutoff too "
                    "short: raise 'communicate single cutoff')";
    fail_one(m);
  }
  if (domain->xperiodic || domain->yperiodic || domain->zperiodic) j = domain->closest_image(i, j);
  return j;
}

// Intact bonds of atom i (its slots less the broken bonds kept as contacts).
int FixBondBreakable::intact_bonds(int i) const {
  if (!contacts_on()) return nbond_[i];
  int n = 0;
  for (int k = 0; k < nbond_[i]; ++k) n += bonds_[i][k * ncol_ + STATE] == 0.0;
  return n;
}

// True for the pairs created as contacts, not bonds: a hash of the two tags
// and the seed (the same on both ends and any rank count) below the fraction.
bool FixBondBreakable::starts_unbonded(int tag_a, int tag_b) const {
  const uint64_t lo = static_cast<uint64_t>(std::min(tag_a, tag_b));
  const uint64_t hi = static_cast<uint64_t>(std::max(tag_a, tag_b));
  uint64_t z = (lo << 32 | hi) + 0x9e3779b97f4a7c15ULL * static_cast<uint64_t>(unbonded_seed_);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;  // splitmix64 finaliser (Steele et al. 2014)
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * 0x1.0p-53 < unbonded_fraction_;
}

// Slot of the bond to partner_tag in atom i's list, or -1.
int FixBondBreakable::find_slot(int i, int partner_tag) const {
  const double key = partner_tag;  // tags are stored exactly as doubles
  const double *row = bonds_[i];
  for (int k = 0; k < nbond_[i]; ++k)
    if (row[k * ncol_ + PARTNER] == key) return k;
  return -1;
}

// Removes slot k of atom i by moving the last slot into it.
void FixBondBreakable::remove_slot(int i, int k) {
  const int last = nbond_[i] - 1;
  if (k != last) std::memcpy(&bonds_[i][k * ncol_], &bonds_[i][last * ncol_], ncol_ * sizeof(double));
  nbond_[i] = last;
}

// The law's inputs for the bond in the canonical frame (a = lower tag).
inline void FixBondBreakable::load_bond(const AtomArrays &at, const ListedBond &bond,
                                        mill::parallel_bond::In<double> &in) const {
  const int a = bond.a, b = bond.b;
  in.xa = load3(at.x[a]);
  in.xb = load3(at.x[b]);
  in.va = load3(at.v[a]);
  in.vb = load3(at.v[b]);
  in.wa = load3(at.omega[a]);
  in.wb = load3(at.omega[b]);
  in.ra = at.radius[a];
  in.rb = at.radius[b];
  in.fs = load3(bond.fs);
  in.mb = load3(bond.mb);
  in.mt = bond.mt;
  in.l0 = bond.l0;
  in.kna = bond.kna;
  in.ksa = bond.ksa;
  in.kni = bond.kni;
  in.ksj = bond.ksj;
  in.inv_area = bond.inv_area;
  in.inv_inertia = bond.inv_inertia;
  in.rbond = bond.rbond;
  in.cn = bond.cn;
  in.cs = bond.cs;
}

// Fills out from the law's result of one bond: forces, stresses, the
// breakage verdict, and what a bond that breaks now releases.
inline void FixBondBreakable::bond_result(const mill::parallel_bond::Out<double> &o, Vec3 xa, double dt,
                                          bool advance, BondResult &out) const {
  out.fa = o.fa;
  out.ta = o.ta;
  out.tb = o.tb;
  out.sigma = o.sigma;
  out.tau = o.tau;
  out.strength = o.strength;
  out.energy = o.energy;
  out.stretch = o.stretch;
  out.fdash = o.fdash;
  out.slipped = 0.0;
  out.mode = 0;
  if (out.sigma > tensile_strength_)
    out.mode = 1;
  else if (out.tau > out.strength)
    out.mode = 2;
  if (out.mode == 0) return;
  out.centre = xa + o.m.ra;  // breaks now: exerts no force from this step on
  if (!advance) return;
  // Released: the energy held now plus the half step of work the bond
  // would still have done, f . dx / 2 with the half-step velocities (its
  // force ends between two steps; with this the ledger closes exactly for
  // a linear spring). A contact left behind keeps its normal push.
  const PairMotion &m = o.m;
  const bool keeps_push = broken_contact_ && o.stretch < 0.0;
  const Vec3 fgone = keeps_push ? o.fs : o.fb;
  const Vec3 tga = keeps_push ? cross(m.ra, -o.fs) - o.mom : out.ta;
  const Vec3 tgb = keeps_push ? cross(m.rb, o.fs) + o.mom : out.tb;
  const double p_half = dot(fgone, m.vrel_ab) + dot(tga, m.wa) + dot(tgb, m.wb);
  out.released = out.energy - (keeps_push ? 0.5 * o.fn * o.stretch : 0.0) + 0.5 * p_half * dt;
}

// Evaluates the bond between atoms a (lower tag) and b in the canonical frame:
// advances the history in bond when advance is true, then returns forces,
// torques, stresses and the breakage verdict.
inline void FixBondBreakable::evaluate_bond(const AtomArrays &at, ListedBond &bond, bool advance,
                                            BondResult &out) const {
  mill::parallel_bond::In<double> in;
  load_bond(at, bond, in);
  mill::parallel_bond::Out<double> o;
  mill::parallel_bond::law(in, at.dt, advance, coefficients(), o);
  if (advance) {
    store3(bond.fs, o.fs);
    store3(bond.mb, o.mb);
    bond.mt = o.mt;
  }
  bond_result(o, in.xa, at.dt, advance, out);
}

// evaluate_bond for kLanes<L> intact bonds at once, one per lane of a pack:
// the same results, bitwise, as one call per bond (tested: BondKernel.*).
template <class L>
inline void FixBondBreakable::evaluate_lanes(const AtomArrays &at, ListedBond *const *bonds,
                                             bool advance, BondResult *outs) const {
  constexpr int N = kLanes<L>;
  const double *xa[N], *xb[N], *va[N], *vb[N], *wa[N], *wb[N], *fs[N], *mb[N];
  mill::parallel_bond::In<L> in;
  for (int k = 0; k < N; ++k) {
    const ListedBond &lb = *bonds[k];
    xa[k] = at.x[lb.a], xb[k] = at.x[lb.b];
    va[k] = at.v[lb.a], vb[k] = at.v[lb.b];
    wa[k] = at.omega[lb.a], wb[k] = at.omega[lb.b];
    fs[k] = lb.fs, mb[k] = lb.mb;
    in.ra[k] = at.radius[lb.a], in.rb[k] = at.radius[lb.b];
    in.mt[k] = lb.mt;
    in.l0[k] = lb.l0, in.kna[k] = lb.kna, in.ksa[k] = lb.ksa, in.kni[k] = lb.kni;
    in.ksj[k] = lb.ksj, in.inv_area[k] = lb.inv_area, in.inv_inertia[k] = lb.inv_inertia;
    in.rbond[k] = lb.rbond, in.cn[k] = lb.cn, in.cs[k] = lb.cs;
  }
  in.xa = gather3<L>(xa), in.xb = gather3<L>(xb);
  in.va = gather3<L>(va), in.vb = gather3<L>(vb);
  in.wa = gather3<L>(wa), in.wb = gather3<L>(wb);
  in.fs = gather3<L>(fs), in.mb = gather3<L>(mb);
  mill::parallel_bond::Out<L> o;
  mill::parallel_bond::law(in, L{} + at.dt, advance, coefficients(), o);
  // The verdict in all lanes at once: the one-bond comparisons, lane by lane.
  const auto tension = o.sigma > tensile_strength_;
  const auto shear = o.tau > o.strength;
  for (int k = 0; k < N; ++k) {
    if (advance) {
      double *f = bonds[k]->fs, *m = bonds[k]->mb;
      f[0] = o.fs.x[k], f[1] = o.fs.y[k], f[2] = o.fs.z[k];
      m[0] = o.mb.x[k], m[1] = o.mb.y[k], m[2] = o.mb.z[k];
      bonds[k]->mt = o.mt[k];
    }
    BondResult &out = outs[k];
    if (tension[k] || shear[k]) {  // breaks now (rare): the one-bond tail
      bond_result(mill::parallel_bond::lane_of(o, k), lane(in.xa, k), at.dt, advance, out);
      continue;
    }
    // Intact: what finishing an intact bond reads.
    out.fa = lane(o.fa, k);
    out.ta = lane(o.ta, k);
    out.tb = lane(o.tb, k);
    out.sigma = o.sigma[k];
    out.tau = o.tau[k];
    out.strength = o.strength[k];
    out.energy = o.energy[k];
    out.stretch = o.stretch[k];
    out.fdash = lane(o.fdash, k);
    out.slipped = 0.0;
    out.mode = 0;
  }
}

// A contact: a broken bond kept (broken_contact yes) or a pair left unbonded
// at creation (unbonded_fraction). While the pair is closer than its bonding
// distance L0 it pushes back with the bond's normal stiffness,
// F_n = kn A (L - L0) < 0, and resists sliding with an incremental shear force
// ks A dU_s capped by Coulomb friction, |F_s| <= tan(phi) |F_n|; no tension,
// and moments only with contact_moment yes (capped, below): cement that bears
// load in compression only, like the
// unbonded (slit) interfaces of the flat-joint model (Potyondy 2012) and the
// linear contact left beside a broken parallel bond (Potyondy & Cundall 2004,
// sec. 2.2). Open (L >= L0) it carries nothing; returns false once the pair
// has separated past L0 + g min(Ri, Rj), when the contact is dropped.
inline bool FixBondBreakable::evaluate_contact(const AtomArrays &at, ListedBond &bond,
                                               bool advance, BondResult &out) const {
  const int a = bond.a, b = bond.b;
  const Vec3 d = load3(at.x[b]) - load3(at.x[a]);
  const double len = std::sqrt(dot(d, d));
  const double stretch = len - bond.l0;
  out.mode = 0;
  out.energy = 0.0;
  out.slipped = 0.0;
  out.fdash = {0.0, 0.0, 0.0};
  out.stretch = stretch;
  if (len > bond.drop_len) return false;
  if (stretch >= 0.0) {  // open: no force, no stored shear or moment (contact lost)
    out.fa = out.ta = out.tb = Vec3{0.0, 0.0, 0.0};
    if (advance) {
      store3(bond.fs, {0.0, 0.0, 0.0});
      store3(bond.mb, {0.0, 0.0, 0.0});
      bond.mt = 0.0;
    }
    return true;
  }
  const PairMotion m = pair_motion(d, len, load3(at.v[a]), load3(at.v[b]), load3(at.omega[a]),
                                   load3(at.omega[b]), at.radius[a], at.radius[b]);
  const Vec3 n = m.n;

  const double fn = bond.kna * stretch;  // < 0: compression
  Vec3 fs = load3(bond.fs);
  // Increments at the step's midpoint, as for a bond (evaluate_bond).
  const Vec3 dmid = d - (0.5 * at.dt) * m.vrel_ab;
  const PairMotion h = pair_motion(dmid, std::sqrt(dot(dmid, dmid)), load3(at.v[a]), load3(at.v[b]),
                                   m.wa, m.wb, at.radius[a], at.radius[b]);
  const double half_spin = 0.25 * (dot(m.wa, n) + dot(m.wb, n)) * at.dt;
  if (advance) {
    fs = rotate_onto_plane(fs, h.n, half_spin);
    fs = fs - (bond.ksa * at.dt) * h.vt;
    fs = rotate_onto_plane(fs, n, half_spin);
  }
  const double cap = tan_friction_ * (-fn), fs_mag = std::sqrt(dot(fs, fs));
  if (fs_mag > cap) {  // Coulomb slip: the stored force stays on the cone
    const double sc = fs_mag > 0.0 ? cap / fs_mag : 0.0;
    fs = sc * fs;
    if (advance) out.slipped += cap * (fs_mag - cap) / bond.ksa;  // cap x slip
  }
  if (advance) store3(bond.fs, fs);
  // Stored while pressed: F_n^2/(2 kn A) + |F_s|^2/(2 ks A) (+ the moments below).
  out.energy = 0.5 * fn * stretch + 0.5 * dot(fs, fs) / bond.ksa;

  // Normal push on b along n, with the optional dashpot; never a pull (a
  // pair separating fast must not stick through the dashpot).
  double push = -fn;
  if (damping_ > 0.0) {
    const double fd = std::min(bond.cn * m.vn, push);  // the dashpot's share, never a pull
    push -= fd;
    out.fdash = -fd * n;
  }
  const Vec3 fb = push * n + fs;
  out.fa = -fb;
  out.ta = cross(m.ra, out.fa);
  out.tb = cross(m.rb, fb);
  if (!contact_moment_) return true;

  // contact_moment yes: the pressed flat interface of radius R also resists
  // bending and twisting with the bond's stiffnesses (P&C 2004, eq. 6), up to
  // the moment at which its edge lifts off under the uniform pressure
  // F_n/A, |M_b| <= |F_n| I/(A R) = |F_n| R/4, and the friction torque of a
  // uniformly pressed flat disc (the uniform-pressure clutch),
  // |M_t| <= tan(phi) |F_n| 2R/3; beyond them the interface rocks or spins at
  // that moment.
  Vec3 mb = load3(bond.mb);
  double mt = bond.mt;
  if (advance) {
    mb = rotate_onto_plane(mb, h.n, half_spin);
    const Vec3 wrel = m.wb - m.wa;
    const double wn = dot(wrel, h.n);
    mb = mb - (bond.kni * at.dt) * (wrel - wn * h.n);
    mt -= bond.ksj * wn * at.dt;
    mb = rotate_onto_plane(mb, n, half_spin);
  }
  const double mb_cap = 0.25 * (-fn) * bond.rbond, mb_mag = std::sqrt(dot(mb, mb));
  if (mb_mag > mb_cap) {
    const double sc = mb_mag > 0.0 ? mb_cap / mb_mag : 0.0;
    mb = sc * mb;
    if (advance) out.slipped += mb_cap * (mb_mag - mb_cap) / bond.kni;
  }
  const double mt_cap = tan_friction_ * (-fn) * 2.0 * bond.rbond / 3.0;
  if (advance && std::fabs(mt) > mt_cap) out.slipped += mt_cap * (std::fabs(mt) - mt_cap) / bond.ksj;
  mt = std::max(-mt_cap, std::min(mt_cap, mt));
  out.energy += 0.5 * (dot(mb, mb) / bond.kni + mt * mt / bond.ksj);
  if (advance) {
    store3(bond.mb, mb);
    bond.mt = mt;
  }
  const Vec3 mom = mb + mt * n;
  out.ta = out.ta - mom;
  out.tb = out.tb + mom;
  return true;
}

// bond/flatjoint: the interface of a pair (flat_joint.h, Potyondy 2012), its
// step's increments taken at the midpoint as for a parallel bond
// (evaluate_bond): the normal and the contact point's relative motion at
// x - v dt/2, the frame's spin the mean spin of the two grains about n.
void FixBondBreakable::evaluate_flat_joint(const AtomArrays &at, ListedBond &bond, bool advance,
                                           BondResult &out) const {
  const int a = bond.a, b = bond.b;
  const Vec3 va = load3(at.v[a]), vb = load3(at.v[b]);
  const Vec3 wa = load3(at.omega[a]), wb = load3(at.omega[b]);
  const Vec3 d = load3(at.x[b]) - load3(at.x[a]);
  const double len = std::sqrt(dot(d, d));
  const bool dashpots = damping_ > 0.0 && bond.state == 0.0;
  const PairMotion m = dashpots ? pair_motion(d, len, va, vb, wa, wb, at.radius[a], at.radius[b])
                                : pair_geometry(d, len, va, vb, wa, wb, at.radius[a], at.radius[b]);
  const Vec3 dmid = d - (0.5 * at.dt) * m.vrel_ab;
  const PairMotion h =
      pair_motion(dmid, std::sqrt(dot(dmid, dmid)), va, vb, wa, wb, at.radius[a], at.radius[b]);
  mill::flat_joint::Step st;
  st.n_mid = h.n;
  st.n_end = m.n;
  st.du_shear = at.dt * h.vt;
  st.wrel = wb - wa;
  st.dtheta = at.dt * st.wrel;
  st.spin = 0.5 * (dot(wa, m.n) + dot(wb, m.n)) * at.dt;
  st.vrel = h.vt + h.vn * h.n;
  st.dt = at.dt;
  st.stretch = len - bond.l0;
  st.gap0 = bond.gap0;
  st.advance = advance;
  st.stresses = false;  // the largest stresses go to the break log only
  mill::flat_joint::Params p;
  p.kn = bond.kna * bond.inv_area;
  p.ks = bond.ksa * bond.inv_area;
  p.radius = bond.rbond;
  p.tensile = tensile_strength_;
  p.cohesion = cohesion_;
  p.tan_phi = tan_friction_;
  p.mu = fj_friction_ >= 0.0 ? fj_friction_ : tan_friction_;
  p.softening = fj_softening_;
  const mill::flat_joint::Result r = mill::flat_joint::update(bond.fj, fj_layout_, p, st);
  // Optional dashpots on the interface while it holds (as a parallel bond's:
  // on the contact point's relative velocity, not part of the stresses).
  out.fdash = {0.0, 0.0, 0.0};
  if (dashpots) out.fdash = -(bond.cn * m.vn * m.n + bond.cs * m.vt);
  const Vec3 fb = r.force_b + out.fdash;
  out.fa = -fb;
  out.ta = cross(m.ra, out.fa) - r.moment_b;
  out.tb = cross(m.rb, fb) + r.moment_b;
  out.energy = r.energy;
  out.slipped = r.slipped;
  out.released = r.released;
  out.stretch = st.stretch;
  out.sigma = r.sigma_max;
  out.tau = r.tau_ratio;
  out.strength = 1.0;
  out.centre = load3(at.x[a]) + m.ra;
  out.mode = 0;
  out.fj_tension = r.broke_tension;
  out.fj_shear = r.broke_shear;
  out.fj_bonded = r.bonded;
}

// True for an interface with every element bonded (intact, or softened to
// a damage below 1): what the packed kernel takes (flat_joint::update_intact).
bool FixBondBreakable::flat_joint_packable(const ListedBond &bond) const {
  const double *el = bond.fj + mill::flat_joint::kHistory + mill::flat_joint::kState;
  for (int e = 0; e < fj_layout_.elements(); ++e)
    if (!(el[3 * e] < 1.0)) return false;
  return bond.state == 0.0;
}

// evaluate_flat_joint for kLanes<L> bonded interfaces at once, one per lane
// of a pack (flat_joint::update_intact): the same expressions, so a lane's
// result is bitwise the one-interface result (tested: FlatJointKernel.*).
// Returns a bit per lane that held (history advanced, outs[k] written);
// the caller evaluates the others one at a time (their history untouched).
// Advancing steps only.
template <class L>
inline int FixBondBreakable::evaluate_flat_joint_lanes(const AtomArrays &at,
                                                       ListedBond *const *bonds,
                                                       BondResult *outs) const {
  constexpr int N = kLanes<L>;
  const double *xa[N], *xb[N], *va_p[N], *vb_p[N], *wa_p[N], *wb_p[N];
  double *hist[N];
  for (int k = 0; k < N; ++k) {
    const ListedBond &lb = *bonds[k];
    xa[k] = at.x[lb.a], xb[k] = at.x[lb.b];
    va_p[k] = at.v[lb.a], vb_p[k] = at.v[lb.b];
    wa_p[k] = at.omega[lb.a], wb_p[k] = at.omega[lb.b];
    hist[k] = lb.fj;
  }
  // Each constant as one pack (lanes_of: no lane-by-lane stores).
  const L ra = lanes_of<L>([&](int k) { return at.radius[bonds[k]->a]; });
  const L rb = lanes_of<L>([&](int k) { return at.radius[bonds[k]->b]; });
  const L l0 = lanes_of<L>([&](int k) { return bonds[k]->l0; });
  const L kna = lanes_of<L>([&](int k) { return bonds[k]->kna; });
  const L ksa = lanes_of<L>([&](int k) { return bonds[k]->ksa; });
  const L inv_area = lanes_of<L>([&](int k) { return bonds[k]->inv_area; });
  const L rbond = lanes_of<L>([&](int k) { return bonds[k]->rbond; });
  const L cn = lanes_of<L>([&](int k) { return bonds[k]->cn; });
  const L cs = lanes_of<L>([&](int k) { return bonds[k]->cs; });
  const V3<L> va = gather3<L>(va_p), vb = gather3<L>(vb_p);
  const V3<L> wa = gather3<L>(wa_p), wb = gather3<L>(wb_p);
  const V3<L> d = gather3<L>(xb) - gather3<L>(xa);
  const L len = vsqrt(dot(d, d));
  const bool dashpots = damping_ > 0.0;  // every lane's interface holds (state 0)
  const PairMotionT<L> m = dashpots ? pair_motion(d, len, va, vb, wa, wb, ra, rb)
                                    : pair_geometry(d, len, va, vb, wa, wb, ra, rb);
  const L dt = L{} + at.dt;
  const V3<L> dmid = d - (0.5 * dt) * m.vrel_ab;
  const PairMotionT<L> h = pair_motion(dmid, vsqrt(dot(dmid, dmid)), va, vb, wa, wb, ra, rb);
  mill::flat_joint::IntactStep<L> st;
  st.n_mid = h.n;
  st.n_end = m.n;
  st.du_shear = dt * h.vt;
  st.dtheta = dt * (wb - wa);
  st.spin = 0.5 * (dot(wa, m.n) + dot(wb, m.n)) * at.dt;
  st.stretch = len - l0;
  mill::flat_joint::IntactParams<L> mat;
  mat.kn = kna * inv_area;
  mat.ks = ksa * inv_area;
  mat.radius = rbond;
  mill::flat_joint::Params p;
  p.tensile = tensile_strength_;
  p.cohesion = cohesion_;
  p.tan_phi = tan_friction_;
  p.softening = fj_softening_;
  mill::flat_joint::IntactResult<L> r;
  const auto holds = mill::flat_joint::update_intact(hist, fj_layout_, mat, p, st, r);
  V3<L> fdash{L{}, L{}, L{}};
  if (dashpots) fdash = -(cn * m.vn * m.n + cs * m.vt);
  const V3<L> fb = r.force_b + fdash;
  const V3<L> fa = -fb;
  const V3<L> ta = cross(m.ra, fa) - r.moment_b;
  const V3<L> tb = cross(m.rb, fb) + r.moment_b;
  const int ne = fj_layout_.elements();
  const Spilled3<L> fdash_k(fdash), fa_k(fa), ta_k(ta), tb_k(tb);
  alignas(32) double energy_k[N], stretch_k[N];
  std::memcpy(energy_k, &r.energy, sizeof(L));
  std::memcpy(stretch_k, &st.stretch, sizeof(L));
  const int held = lane_bits(holds);
  for (int k = 0; k < N; ++k) {
    if (!(held >> k & 1)) continue;
    BondResult &out = outs[k];
    out.fdash = fdash_k[k];
    out.fa = fa_k[k];
    out.ta = ta_k[k];
    out.tb = tb_k[k];
    out.energy = energy_k[k];
    out.slipped = 0.0;
    out.released = 0.0;
    out.stretch = stretch_k[k];
    out.sigma = 0.0;
    out.tau = 0.0;
    out.strength = 1.0;
    out.mode = 0;
    out.fj_tension = 0;
    out.fj_shear = 0;
    out.fj_bonded = ne;
  }
  return held;
}

// A pair whose interface is fully broken has separated past its bonding
// range, L0 + g min(Ri, Rj): the interface is dropped.
bool FixBondBreakable::separated(const AtomArrays &at, const ListedBond &bond) const {
  const Vec3 d = load3(at.x[bond.b]) - load3(at.x[bond.a]);
  return dot(d, d) > bond.drop_len * bond.drop_len;
}

// True while the cached bond list still matches the atom arrays: no
// neighbour-list build (the only time LIGGGHTS exchanges, sorts or re-ghosts
// atoms), no break and no change of time step since it was built.
bool FixBondBreakable::list_current() const {
  if (!list_valid_) return false;
  if (domain->xperiodic || domain->yperiodic || domain->zperiodic) return false;  // images move
  return neighbor->ncalls == list_ncalls_ && atom->nlocal == list_nlocal_ &&
         atom->nghost == list_nghost_ && update->dt == list_dt_;
}

// Writes the history held by the bond list back to the slots of both ends.
// Called before anything reads the slots or moves atoms; a no-op when they
// are current. The list's slot indices stay valid until then: slots only
// move in remove_slot, exchange and sort, each after this.
void FixBondBreakable::store_history() {
  if (!history_dirty_) return;
  for (const ListedBond &lb : list_) {
    double *si = &bonds_[lb.i][lb.slot_i * ncol_];
    store3(&si[FS], load3(lb.fs));
    store3(&si[MB], load3(lb.mb));
    si[MT] = lb.mt;
    si[STATE] = lb.state;
    if (lb.fj) std::memcpy(&si[NCOL], lb.fj, (ncol_ - NCOL) * sizeof(double));
    if (lb.j >= 0) std::memcpy(&bonds_[lb.j][lb.slot_j * ncol_ + FS], &si[FS],
                               (ncol_ - FS) * sizeof(double));
  }
  history_dirty_ = false;
}

// Resolves every bond this rank computes to atom indices and history slots,
// in the order the per-atom slots are visited (owned atom ascending, slot
// descending), so that forces are summed in a fixed order; copies the
// history in and computes the bond's constants.
void FixBondBreakable::build_bond_list() {
  store_history();
  int *tag = atom->tag;
  const double *radius = atom->radius;
  const double *rmass = atom->rmass;
  const int nlocal = atom->nlocal;
  const bool periodic = domain->xperiodic || domain->yperiodic || domain->zperiodic;
  list_.clear();
  for (int i = 0; i < nlocal; ++i) {
    for (int k = nbond_[i] - 1; k >= 0; --k) {
      const double *slot = &bonds_[i][k * ncol_];
      const int ptag = static_cast<int>(slot[PARTNER]);
      int jloc = atom->map(ptag);
      if (jloc >= 0 && tag[jloc] != ptag) jloc = -1;  // stale map entry
      const bool partner_local = jloc >= 0 && jloc < nlocal;
      const bool i_lower = tag[i] < ptag;
      if (partner_local && !i_lower) continue;  // listed under the partner (lower tag)
      const int jimg = (jloc < 0 || periodic) ? partner_index(i, ptag) : jloc;

      int jslot = -1;
      if (partner_local) {
        jslot = find_slot(jloc, tag[i]);
        if (jslot < 0) {
          std::string m = label() + "internal error, bond " + std::to_string(tag[i]) +
                          "-" + std::to_string(ptag) + " stored on one end only";
          fail_one(m);
        }
      }
      ListedBond lb;
      lb.a = i_lower ? i : jimg;
      lb.b = i_lower ? jimg : i;
      lb.i = i;
      lb.j = partner_local ? jloc : -1;
      lb.slot_i = k;
      lb.slot_j = jslot;
      lb.i_lower = i_lower;
      store3(lb.fs, load3(&slot[FS]));
      store3(lb.mb, load3(&slot[MB]));
      lb.mt = slot[MT];
      lb.state = slot[STATE];
      lb.l0 = slot[L0];
      // Potyondy & Cundall 2004, eq. 5: parallel-bond disc of radius lambda min(Ri,Rj),
      // A = pi R^2, I = pi R^4 / 4, J = 2 I.
      lb.rbond = radius_multiplier_ * std::min(radius[lb.a], radius[lb.b]);
      const double area = kPi * lb.rbond * lb.rbond;
      const double inertia = 0.25 * area * lb.rbond * lb.rbond;
      const double polar = 2.0 * inertia;
      lb.inv_area = 1.0 / area;
      lb.inv_inertia = 4.0 * kPi * lb.inv_area * lb.inv_area;  // = 1 / (pi R^4 / 4)
      // Stiffness per unit area from the bond modulus over the initial length,
      // kn = E_b / L0, ks = kn / (kn/ks)  (Potyondy & Cundall 2004, sec. 2.2).
      const double kn = modulus_ / slot[L0];  // [Pa/m]
      const double ks = kn * inv_ratio_;      // [Pa/m]
      lb.kna = kn * area;
      lb.ksa = ks * area;
      lb.kni = kn * inertia;
      lb.ksj = ks * polar;
      // Dashpots: the fraction `damping` of critical damping of the two-body
      // normal oscillator, sqrt(ks/kn) of it in shear (masses are constant).
      const double ma = rmass[lb.a], mbm = rmass[lb.b];
      lb.cn = 2.0 * damping_ * std::sqrt(ma * mbm / (ma + mbm) * kn * area);
      lb.cs = lb.cn * std::sqrt(inv_ratio_);
      lb.drop_len = slot[L0] + gap_ * std::min(radius[lb.a], radius[lb.b]);
      lb.fj = nullptr;  // bond/flatjoint: set below
      lb.gap0 = std::max(0.0, slot[L0] - radius[lb.a] - radius[lb.b]);
      list_.push_back(lb);
    }
  }
  // bond/flatjoint: the interfaces' histories copied into one array in list
  // order, which the loop then reads as a stream. Read in their slots, each
  // interface's history sat in its atom's row of max_bonds slots (a row
  // longer than a page) and cost a cache miss: half of the flat joint's
  // time in perf.
  if (flat_joint_) {
    const size_t hs = static_cast<size_t>(ncol_ - NCOL);
    fj_history_.resize(list_.size() * hs);
    for (size_t e = 0; e < list_.size(); ++e) {
      ListedBond &lb = list_[e];
      lb.fj = &fj_history_[e * hs];
      std::memcpy(lb.fj, &bonds_[lb.i][lb.slot_i * ncol_ + NCOL], hs * sizeof(double));
    }
  }
  list_valid_ = true;
  list_ncalls_ = neighbor->ncalls;
  list_nlocal_ = nlocal;
  list_nghost_ = atom->nghost;
  list_dt_ = update->dt;
}

// Loops over the bonds of owned atoms: advances (if advance), breaks, applies
// forces, then does this step's single reduction of the global counters.
void FixBondBreakable::compute_bonds(bool advance) {
  double **f = atom->f, **torque = atom->torque;
  int *tag = atom->tag;
  const int nlocal = atom->nlocal;
  const AtomArrays at{atom->x, atom->v, atom->omega, atom->radius, atom->rmass, update->dt};

  if (atom->nmax > nmax_) grow_arrays(atom->nmax);
  // The list is rebuilt whenever the slots may have changed outside this
  // loop (a neighbour-list build: exchange, sort, new atoms; a new run); so
  // between rebuilds the per-atom counts change only by this loop's breaks.
  const bool rebuilt = !list_current();
  if (rebuilt) build_bond_list();
  events_.clear();
  broken_.clear();
  contact_.clear();
  double local[4] = {0.0, 0.0, 0.0, 0.0};  // intact, new tension, new shear, energy
  double stored = 0.0;                      // ledger: bonds and pressed contacts [J]
  BondResult r;
  if (damping_ > 0.0) dash_.assign(3 * list_.size(), 0.0);
  // The ledger's snapshot: forces and torques before the bonds add theirs.
  fbond_.resize(6 * static_cast<size_t>(nlocal));
  for (int i = 0; i < nlocal; ++i) {
    double *fb = &fbond_[6 * i];
    fb[0] = f[i][0], fb[1] = f[i][1], fb[2] = f[i][2];
    fb[3] = torque[i][0], fb[4] = torque[i][1], fb[5] = torque[i][2];
  }

  // Adds this rank's share of a bond's (or contact's) force and torques: both
  // ends if the partner is owned here.
  auto add3 = [](double *p, Vec3 v) {
    p[0] += v.x;
    p[1] += v.y;
    p[2] += v.z;
  };
  auto apply = [&](const ListedBond &lb, const BondResult &res) {
    const int i = lb.i;
    if (lb.i_lower) {
      add3(f[i], res.fa);
      add3(torque[i], res.ta);
    } else {
      add3(f[i], -res.fa);
      add3(torque[i], res.tb);
    }
    if (lb.j >= 0) {  // i is the lower tag here: the partner is b.
      add3(f[lb.j], -res.fa);
      add3(torque[lb.j], res.tb);
    }
  };
  // Queues the slots of list entry lb for removal after the loop (by tag).
  auto remove_later = [&](const ListedBond &lb) {
    const int ptag = static_cast<int>(bonds_[lb.i][lb.slot_i * ncol_ + PARTNER]);
    const int brk[4] = {lb.i, lb.j, tag[lb.i], ptag};
    broken_.insert(broken_.end(), brk, brk + 4);
  };

  const int nlisted = static_cast<int>(list_.size());
  // bond/flatjoint: an interface once evaluated: its force on the atoms, the
  // counters and its break events.
  auto finish_interface = [&](int e, ListedBond &lb, const BondResult &res) {
    apply(lb, res);
    if (lb.state == 0.0 && res.fj_bonded == 0) contact_.push_back(e);  // all elements broken
    if (!lb.i_lower) return;  // counted once: by the owner of the lower tag
    local[3] += res.energy;   // output 5: the energy in the elements, bonded or pressed
    ledger_.friction += res.slipped;
    ledger_.released += res.released;
    if (damping_ > 0.0) store3(&dash_[3 * e], res.fdash);
    local[1] += res.fj_tension;
    local[2] += res.fj_shear;
    if (lb.state == 0.0 && res.fj_bonded > 0) local[0] += 1.0;
    if (advance && res.fj_tension + res.fj_shear > 0) {
      const double ev[kEventCols] = {static_cast<double>(update->ntimestep),
                                     update->get_cur_time(),
                                     res.centre.x,
                                     res.centre.y,
                                     res.centre.z,
                                     res.fj_tension > 0 ? 1.0 : 2.0,
                                     static_cast<double>(tag[lb.i]),
                                     bonds_[lb.i][lb.slot_i * ncol_ + PARTNER],
                                     res.sigma,
                                     res.tau};
      events_.insert(events_.end(), ev, ev + kEventCols);
    }
  };
  BondResult fj_out[4];
  for (int e = 0; e < nlisted && flat_joint_; ++e) {
    // bond/flatjoint: every interface, bonded or not, through its elements;
    // one whose elements are all broken stays until the pair separates.
    ListedBond &lb = list_[e];
    if (lb.state != 0.0 && separated(at, lb)) {
      if (advance) remove_later(lb);
      continue;
    }
    // Interfaces in a row whose elements are all bonded (intact or
    // softened): two or four at a time, one per lane (none reads what
    // another's finish writes); a lane where an element breaks or softens
    // further this step goes through the one-interface code, from its
    // untouched history; then all are finished in list order.
    int run = 0;
    while (advance && run < lanes_ && e + run < nlisted && flat_joint_packable(list_[e + run]))
      ++run;
    if (run >= 2) {
      ListedBond *pack[4];
      const int n = run >= 4 ? 4 : 2;
      for (int k = 0; k < n; ++k) pack[k] = &list_[e + k];
      const int held = n == 4 ? evaluate_flat_joint_lanes<Lane4>(at, pack, fj_out)
                              : evaluate_flat_joint_lanes<Lane2>(at, pack, fj_out);
      for (int k = 0; k < n; ++k) {
        if (held >> k & 1) {
          evals_packed_ += 1.0;
          finish_interface(e + k, list_[e + k], fj_out[k]);
        } else {
          evaluate_flat_joint(at, list_[e + k], advance, r);
          evals_single_ += 1.0;
          finish_interface(e + k, list_[e + k], r);
        }
      }
      e += n - 1;
      continue;
    }
    evaluate_flat_joint(at, lb, advance, r);
    if (lb.state == 0.0) evals_single_ += 1.0;
    finish_interface(e, lb, r);
  }
  // An intact bond once evaluated: its break (counted, logged, turned into a
  // contact or removed) or its force on the atoms.
  auto finish_bond = [&](int e, ListedBond &lb, const BondResult &res) {
    if (advance && res.mode != 0) {
      if (lb.i_lower) {  // counted once: by the owner of the lower tag
        ledger_.released += res.released;
        local[res.mode] += 1.0;
        const double ev[kEventCols] = {
            static_cast<double>(update->ntimestep),
            update->get_cur_time(),
            res.centre.x,
            res.centre.y,
            res.centre.z,
            static_cast<double>(res.mode),
            static_cast<double>(tag[lb.i]),
            bonds_[lb.i][lb.slot_i * ncol_ + PARTNER],
            res.sigma,
            res.tau};
        events_.insert(events_.end(), ev, ev + kEventCols);
      }
      // A broken bond stays as a contact (broken_contact yes); otherwise it
      // is removed after the loop (list entries point at slots).
      if (broken_contact_)
        contact_.push_back(e);
      else
        remove_later(lb);
      return;
    }
    apply(lb, res);
    if (lb.i_lower) {
      local[0] += 1.0;
      local[3] += res.energy;
      if (damping_ > 0.0) store3(&dash_[3 * e], res.fdash);
    }
  };
  BondResult rs[4];
  for (int e = 0; e < nlisted && !flat_joint_; ++e) {
    ListedBond &lb = list_[e];
    if (lb.state != 0.0) {  // a broken bond kept as a contact
      if (evaluate_contact(at, lb, advance, r)) {
        apply(lb, r);
        if (lb.i_lower) {
          stored += r.energy;
          ledger_.friction += r.slipped;
          if (damping_ > 0.0) store3(&dash_[3 * e], r.fdash);
        }
      } else if (advance) {
        remove_later(lb);
      }
      continue;
    }
    // Intact bonds in a row: evaluated together, kLanes at a time (none
    // reads what another's finish writes: forces, the break lists), then
    // finished in list order.
    int run = 1;
    while (run < lanes_ && e + run < nlisted && list_[e + run].state == 0.0) ++run;
    if (run >= 2) {
      ListedBond *pack[4];
      const int n = run >= 4 ? 4 : 2;
      for (int k = 0; k < n; ++k) pack[k] = &list_[e + k];
      if (n == 4)
        evaluate_lanes<Lane4>(at, pack, advance, rs);
      else
        evaluate_lanes<Lane2>(at, pack, advance, rs);
      for (int k = 0; k < n; ++k) finish_bond(e + k, list_[e + k], rs[k]);
      evals_packed_ += n;
      e += n - 1;
      continue;
    }
    evaluate_bond(at, lb, advance, r);
    finish_bond(e, lb, r);
    evals_single_ += 1.0;
  }
  if (advance) history_dirty_ = true;
  ledger_.elastic = local[3] + stored;
  // The bonds' own forces and torques on the owned atoms (for the ledger's work).
  for (int i = 0; i < nlocal; ++i) {
    double *fb = &fbond_[6 * i];
    fb[0] = f[i][0] - fb[0], fb[1] = f[i][1] - fb[1], fb[2] = f[i][2] - fb[2];
    fb[3] = torque[i][0] - fb[3], fb[4] = torque[i][1] - fb[4], fb[5] = torque[i][2] - fb[5];
  }

  // Broken bonds become contacts (broken_contact yes): state 1, and the stored
  // shear force and moments start again from zero. (A flat joint whose
  // elements all broke keeps its history: state 1 only.)
  for (const int e : contact_) {
    ListedBond &lb = list_[e];
    if (flat_joint_) {
      lb.state = 1.0;
      continue;
    }
    store3(lb.fs, {0.0, 0.0, 0.0});
    store3(lb.mb, {0.0, 0.0, 0.0});
    lb.mt = 0.0;
    lb.state = 1.0;
  }

  // Remove the broken bonds from both ends, in list order (slots are found
  // by tag: a removal moves another slot of the same atom). The slots are
  // brought up to date first; the list is rebuilt next step.
  if (!contact_.empty() || !broken_.empty()) store_history();
  for (size_t e = 0; e + 4 <= broken_.size(); e += 4) {
    const int i = broken_[e], j = broken_[e + 1], itag = broken_[e + 2], ptag = broken_[e + 3];
    if (j >= 0) remove_slot(j, find_slot(j, itag));
    remove_slot(i, find_slot(i, ptag));
  }
  if (!broken_.empty()) list_valid_ = false;

  // Counting scans every slot of every atom (5 % of a flat-joint step in
  // perf): done only when a count can have changed (above).
  if (rebuilt || !contact_.empty() || !broken_.empty())
    for (int i = 0; i < nlocal; ++i) count_[i] = intact_bonds(i);
  vector_atom = count_;

  double global[4];
  MPI_Allreduce(local, global, 4, MPI_DOUBLE, MPI_SUM, world);
  intact_ = global[0];
  broken_tension_ += global[1];
  broken_shear_ += global[2];
  energy_ = global[3];
  if (global[1] + global[2] > 0.0 && !break_log_path_.empty()) write_break_events();
}

// Gathers this step's break events to rank 0 and appends them to the log.
void FixBondBreakable::write_break_events() {
  int n = static_cast<int>(events_.size());
  std::vector<int> counts(comm->nprocs), displs(comm->nprocs, 0);
  MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, world);
  std::vector<double> all;
  if (comm->me == 0) {
    int tot = 0;
    for (int p = 0; p < comm->nprocs; ++p) {
      displs[p] = tot;
      tot += counts[p];
    }
    all.resize(tot);
  }
  MPI_Gatherv(events_.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE,
              0, world);
  if (comm->me != 0 || !break_log_) return;
  for (size_t e = 0; e + kEventCols <= all.size(); e += kEventCols) {
    const double *ev = &all[e];
    fprintf(break_log_, "%.0f %.10g %.10g %.10g %.10g %s %.0f %.0f %.8g %.8g\n", ev[0], ev[1],
            ev[2], ev[3], ev[4], ev[5] == 1.0 ? "tension" : "shear", ev[6], ev[7], ev[8], ev[9]);
  }
  fflush(break_log_);
}

// Writes all intact bonds (tag_i < tag_j) to the dump file via FILE.tmp + rename.
void FixBondBreakable::write_bond_dump() {
  store_history();
  std::vector<int> mine;
  for (int i = 0; i < atom->nlocal; ++i)
    for (int k = 0; k < nbond_[i]; ++k) {
      const int p = static_cast<int>(bonds_[i][k * ncol_ + PARTNER]);
      if (bonds_[i][k * ncol_ + STATE] != 0.0) continue;  // a contact, not a bond
      if (atom->tag[i] < p) {
        mine.push_back(atom->tag[i]);
        mine.push_back(p);
      }
    }
  int n = static_cast<int>(mine.size());
  std::vector<int> counts(comm->nprocs), displs(comm->nprocs, 0);
  MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, world);
  std::vector<int> all;
  if (comm->me == 0) {
    int tot = 0;
    for (int p = 0; p < comm->nprocs; ++p) {
      displs[p] = tot;
      tot += counts[p];
    }
    all.resize(tot);
  }
  MPI_Gatherv(mine.data(), n, MPI_INT, all.data(), counts.data(), displs.data(), MPI_INT, 0, world);
  if (comm->me != 0) return;

  std::vector<std::pair<int, int>> pairs;
  for (size_t e = 0; e + 1 < all.size(); e += 2) pairs.emplace_back(all[e], all[e + 1]);
  std::sort(pairs.begin(), pairs.end());
  std::string path = dump_bonds_path_;
  const size_t star = path.find('*');
  if (star != std::string::npos) path.replace(star, 1, std::to_string(update->ntimestep));
  const std::string tmp = path + ".tmp";
  FILE *fp = fopen(tmp.c_str(), "w");
  if (!fp) {
    std::string m = label() + "cannot write dump_bonds file '" + tmp + "'";
    fail_one(m);
  }
  fprintf(fp, "# fix bond/breakable intact bonds\n# step " BIGINT_FORMAT "\n", update->ntimestep);
  fprintf(fp, "# bonds %zu\n# columns: tag_i tag_j\n", pairs.size());
  for (const auto &p : pairs) fprintf(fp, "%d %d\n", p.first, p.second);
  fclose(fp);
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::string m = label() + "cannot rename '" + tmp + "' to '" + path + "'";
    fail_one(m);
  }
}

// Critical time step of the bond springs over the bonds left now: per bond
// the exact largest squared eigenfrequency of the free bonded pair
// (step_limit.h, bond_omega2); an atom's estimate sums its bonds' values
// (exact for a pair and for the axial mode of a uniform chain), a bound of
// the network's omega_max^2; with step_estimate network, the smaller of that
// and the network's own largest eigenvalue (network_step.h). Velocity
// Verlet is stable for omega dt < 2. With dashpots (f_ID[8]) the step stays
// the per-atom estimate, each atom's sum with its damping, whatever
// step_estimate: the damping of the network's top mode is not known, and
// the network's step scaled by the strongest per-atom damping created
// energy in the lab decks (docs/styles/fix_bond_breakable.md). 0 when no
// bond is left. Collective; caches the value for f_ID[6].
double FixBondBreakable::critical_step() {
  double *radius = atom->radius, *rmass = atom->rmass;
  const mill::step_limit::BondSprings springs{modulus_, stiffness_ratio_, radius_multiplier_};
  // [0]: the largest per-atom sum of the bonds' omega^2; [1]: minus the
  // smallest per-atom step with the dashpots (one MAX reduction for both).
  double local[2] = {0.0, -HUGE_VAL};
  for (int i = 0; i < atom->nlocal; ++i) {
    double sum2 = 0.0, sum1 = 0.0;
    for (int k = 0; k < nbond_[i]; ++k) {
      const int j = partner_index(i, static_cast<int>(bonds_[i][k * ncol_ + PARTNER]));
      const double w2 = mill::step_limit::bond_omega2(
          springs, {radius[i], radius[j], rmass[i], rmass[j], bonds_[i][k * ncol_ + L0]});
      sum2 += w2;
      sum1 += std::sqrt(w2);
    }
    local[0] = std::max(local[0], sum2);
    if (sum2 > 0.0)
      local[1] = std::max(local[1], -mill::step_limit::damped_critical_step(sum2, sum1, damping_));
  }
  double global[2] = {0.0, 0.0};
  MPI_Allreduce(local, global, 2, MPI_DOUBLE, MPI_MAX, world);
  dt_crit_sum_ = mill::step_limit::critical_step(global[0]);
  network_iterations_ = 0;
  double omega2 = global[0];
  if (network_step_ && global[0] > 0.0) omega2 = std::min(omega2, network_omega2());
  dt_crit_ = mill::step_limit::critical_step(omega2);
  dt_crit_damped_ = global[0] > 0.0 ? -global[1] : 0.0;
  return dt_crit_;
}

// The network's largest omega^2 (network_step.h): every rank sends the bonds
// it counts (those of the lower tag's owner) to rank 0, which orders them by
// tags (the same estimate on any number of ranks), runs the Lanczos
// estimate and sends the value back. Springs as in step_limit.h.
double FixBondBreakable::network_omega2() {
  constexpr int kCols = 10;  // tag_a tag_b mass_a mass_b radius_a radius_b l0 n
  const int *tag = atom->tag;
  const double *radius = atom->radius, *rmass = atom->rmass;
  double **x = atom->x;
  std::vector<double> mine;
  for (int i = 0; i < atom->nlocal; ++i) {
    for (int k = 0; k < nbond_[i]; ++k) {
      const int ptag = static_cast<int>(bonds_[i][k * ncol_ + PARTNER]);
      if (tag[i] > ptag) continue;  // counted by the lower tag's owner
      const int j = partner_index(i, ptag);
      Vec3 d = load3(x[j]) - load3(x[i]);
      d = (1.0 / std::sqrt(dot(d, d))) * d;
      const double rec[kCols] = {static_cast<double>(tag[i]),
                                 static_cast<double>(ptag),
                                 rmass[i],
                                 rmass[j],
                                 radius[i],
                                 radius[j],
                                 bonds_[i][k * ncol_ + L0],
                                 d.x,
                                 d.y,
                                 d.z};
      mine.insert(mine.end(), rec, rec + kCols);
    }
  }
  const int nprocs = comm->nprocs;
  const int count = static_cast<int>(mine.size());
  std::vector<int> counts(nprocs), displs(nprocs, 0);
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, world);
  std::vector<double> all;
  if (comm->me == 0) {
    for (int p = 1; p < nprocs; ++p) displs[p] = displs[p - 1] + counts[p - 1];
    all.resize(static_cast<size_t>(displs[nprocs - 1]) + counts[nprocs - 1]);
  }
  MPI_Gatherv(mine.data(), count, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE,
              0, world);
  double result[2] = {0.0, 0.0};  // omega^2, Lanczos steps
  if (comm->me == 0) {
    const size_t nb = all.size() / kCols;
    std::vector<size_t> order(nb);
    for (size_t b = 0; b < nb; ++b) order[b] = b;
    std::sort(order.begin(), order.end(), [&](size_t p, size_t q) {
      const double *rp = &all[p * kCols], *rq = &all[q * kCols];
      return rp[0] != rq[0] ? rp[0] < rq[0] : rp[1] < rq[1];
    });
    std::map<int, int> index;  // tag -> atom of the network
    mill::network_step::Atoms atoms;
    auto atom_of = [&](double t, double m, double r) {
      const auto it = index.emplace(static_cast<int>(t), static_cast<int>(atoms.mass.size()));
      if (it.second) {
        atoms.mass.push_back(m);
        atoms.inertia.push_back(0.4 * m * r * r);
      }
      return it.first->second;
    };
    std::vector<mill::network_step::Bond> bonds(nb);
    for (size_t b = 0; b < nb; ++b) {
      const double *r = &all[order[b] * kCols];
      mill::network_step::Bond &bd = bonds[b];
      bd.a = atom_of(r[0], r[2], r[4]);
      bd.b = atom_of(r[1], r[3], r[5]);
      const double l0 = r[6], rb = radius_multiplier_ * std::min(r[4], r[5]);
      bd.n = {r[7], r[8], r[9]};
      bd.arm_a = l0 * r[4] / (r[4] + r[5]);
      bd.arm_b = l0 - bd.arm_a;
      const double kn = modulus_ / l0, ks = kn / stiffness_ratio_;
      const double area = mill::step_limit::kPi * rb * rb, inertia = 0.25 * area * rb * rb;
      bd.kna = kn * area;
      bd.ksa = ks * area;
      bd.kni = kn * inertia;
      bd.ksj = ks * 2.0 * inertia;
    }
    const mill::network_step::Estimate est = mill::network_step::largest_omega2(bonds, atoms);
    result[0] = est.omega2;
    result[1] = est.iterations;
  }
  MPI_Bcast(result, 2, MPI_DOUBLE, 0, world);
  network_iterations_ = static_cast<int>(result[1]);
  return result[0];
}

// At the setup of a run: the critical step, printed; warns if the deck's dt
// exceeds it.
void FixBondBreakable::estimate_time_step() {
  if (critical_step() <= 0.0) return;
  char line[256];
  if (network_step_) {
    snprintf(line, sizeof(line),
             "%sstep_estimate network: bonds' critical step %.4g s (%d Lanczos steps), the "
             "per-atom sum's %.4g s",
             label().c_str(), dt_crit_, network_iterations_, dt_crit_sum_);
    message(line);
  }
  if (damping_ > 0.0)
    snprintf(line, sizeof(line),
             "%scritical time step of bond springs %.4g s, %.4g s with their dashpots; time step "
             "%.4g s",
             label().c_str(), dt_crit_, dt_crit_damped_, update->dt);
  else
    snprintf(line, sizeof(line), "%scritical time step of bond springs %.4g s; time step %.4g s",
             label().c_str(), dt_crit_, update->dt);
  message(line);
  if (update->dt > dt_crit_damped_ && comm->me == 0) {
    snprintf(line, sizeof(line),
             "%stime step %g s exceeds the bond critical time step %g s",
             label().c_str(), update->dt, dt_crit_damped_);
    error->warning(FLERR, line);
  }
}

/* ---------------------------------------------------------------------- */

// Global outputs: 1 intact bonds, 2 broken, 3 broken by tension, 4 broken by
// shear, 5 bond elastic energy [J], 6 critical time step [s]. Cached values.
double FixBondBreakable::compute_vector(int n) {
  switch (n) {
    case 0:
      return intact_;
    case 1:
      return broken_tension_ + broken_shear_;
    case 2:
      return broken_tension_;
    case 3:
      return broken_shear_;
    case 4:
      return energy_;
    case 5:
      return dt_crit_;
    case 6: {  // share of the intact-bond evaluations made in packs (lanes)
      const double local[2] = {evals_packed_, evals_single_};
      double global[2];
      MPI_Allreduce(local, global, 2, MPI_DOUBLE, MPI_SUM, world);
      return global[0] + global[1] > 0.0 ? global[0] / (global[0] + global[1]) : 0.0;
    }
    case 7:
      return dt_crit_damped_;
    default:
      return 0.0;
  }
}

// Global restart state: all parameters and the cumulative counters.
void FixBondBreakable::write_restart(FILE *fp) {
  const double list[] = {radius_multiplier_,
                         modulus_,
                         stiffness_ratio_,
                         tensile_strength_,
                         cohesion_,
                         friction_angle_,
                         damping_,
                         gap_,
                         static_cast<double>(max_bonds_),
                         static_cast<double>(bonds_created_),
                         broken_tension_,
                         broken_shear_,
                         lmax_,
                         moment_factor_,
                         broken_contact_ ? 1.0 : 0.0,
                         unbonded_fraction_,
                         static_cast<double>(unbonded_seed_),
                         contact_moment_ ? 1.0 : 0.0,
                         static_cast<double>(ncol_)};
  const int n = sizeof(list) / sizeof(list[0]);
  if (comm->me == 0) {
    int size = n * sizeof(double);
    fwrite(&size, sizeof(int), 1, fp);
    fwrite(list, sizeof(double), n, fp);
  }
}

// Restores parameters and counters written by write_restart; keywords given
// again in the deck must agree (bonds created with other parameters would lie).
void FixBondBreakable::restart(char *buf) {
  const double *list = reinterpret_cast<double *>(buf);
  const char *names[] = {"radius_multiplier", "modulus",  "stiffness_ratio",
                         "tensile_strength",  "cohesion", "friction_angle",
                         "damping",           "gap",      "moment_factor"};
  double *mine[] = {&radius_multiplier_, &modulus_,        &stiffness_ratio_,
                    &tensile_strength_,  &cohesion_,       &friction_angle_,
                    &damping_,           &gap_,            &moment_factor_};
  const double theirs[] = {list[0], list[1], list[2], list[3], list[4],
                           list[5], list[6], list[7], list[13]};
  for (int k = 0; k < 9; ++k)
    if (*mine[k] != theirs[k] && comm->me == 0) {
      std::string m = label() + names[k] + " " + fmt_num(*mine[k]) +
                      " differs from the restart file (" + fmt_num(theirs[k]) +
                      "); using the deck's value";
      error->warning(FLERR, m.c_str());
    }
  if (static_cast<int>(list[8]) > max_bonds_) {
    std::string m = label() + "max_bonds " + std::to_string(max_bonds_) +
                    " is smaller than in the restart file (" + fmt_num(list[8]) + ")";
    error->all(FLERR, m.c_str());
  }
  if (static_cast<int>(list[18]) != ncol_) {
    // A slot's columns: the bond model and, for a flat joint, its elements.
    std::string m = label() + "the restart file holds bonds of " + fmt_num(list[18]) +
                    " columns, this fix " + std::to_string(ncol_) +
                    ": give the same style (and elements) as the run that wrote it";
    error->all(FLERR, m.c_str());
  }
  bonds_created_ = static_cast<int>(list[9]);
  broken_tension_ = list[10];
  broken_shear_ = list[11];
  lmax_ = list[12];
  if (list[15] != unbonded_fraction_ && comm->me == 0)
    error->warning(FLERR, (label() + "unbonded_fraction differs from the restart file; "
                                     "the pairs were chosen when the bonds were created and are kept")
                                        .c_str());
  if ((list[14] != 0.0) != broken_contact_) {
    // Contacts stored in the file would be read as bonds (or the reverse).
    std::string m = label() + "broken_contact " +
                    (broken_contact_ ? "yes" : "no") + " differs from the restart file (" +
                    (list[14] != 0.0 ? "yes" : "no") + "); give the same value";
    error->all(FLERR, m.c_str());
  }
}

// Grows per-atom storage to nmax atoms.
void FixBondBreakable::grow_arrays(int nmax) {
  store_history();  // the list's slot indices stay valid across the reallocation
  memory->grow(nbond_, nmax, "bond/breakable:nbond");
  memory->grow(bonds_, nmax, max_bonds_ * ncol_, "bond/breakable:bonds");
  memory->grow(count_, nmax, "bond/breakable:count");
  for (int i = nmax_; i < nmax; ++i) {
    nbond_[i] = 0;
    count_[i] = 0.0;
  }
  nmax_ = nmax;
  vector_atom = count_;
  list_valid_ = false;  // atoms were added or moved
}

// Copies atom i's bonds to slot j (atom sorting, deletion).
void FixBondBreakable::copy_arrays(int i, int j, int /*delflag*/) {
  store_history();  // normally a no-op: pre_exchange already stored it
  nbond_[j] = nbond_[i];
  count_[j] = count_[i];
  std::memcpy(bonds_[j], bonds_[i], nbond_[i] * ncol_ * sizeof(double));
}

// A newly created atom has no bonds.
void FixBondBreakable::set_arrays(int i) {
  if (i >= nmax_) grow_arrays(atom->nmax);
  nbond_[i] = 0;
  count_[i] = 0.0;
}

// Columns: nbond, then nbond x (PARTNER L0 FS[3] MB[3] MT STATE).
int FixBondBreakable::pack_exchange(int i, double *buf) {
  store_history();  // normally a no-op: pre_exchange already stored it
  buf[0] = nbond_[i];
  std::memcpy(&buf[1], bonds_[i], nbond_[i] * ncol_ * sizeof(double));
  return 1 + nbond_[i] * ncol_;
}

// Same columns as pack_exchange.
int FixBondBreakable::unpack_exchange(int nlocal, double *buf) {
  if (nlocal >= nmax_) grow_arrays(atom->nmax);
  nbond_[nlocal] = static_cast<int>(buf[0]);
  std::memcpy(bonds_[nlocal], &buf[1], nbond_[nlocal] * ncol_ * sizeof(double));
  count_[nlocal] = intact_bonds(nlocal);
  return 1 + nbond_[nlocal] * ncol_;
}

// Restart columns: size, nbond, then nbond x (PARTNER L0 FS[3] MB[3] MT STATE).
int FixBondBreakable::pack_restart(int i, double *buf) {
  store_history();  // a restart written during a run (output after post_force)
  buf[0] = 2 + nbond_[i] * ncol_;
  buf[1] = nbond_[i];
  std::memcpy(&buf[2], bonds_[i], nbond_[i] * ncol_ * sizeof(double));
  return 2 + nbond_[i] * ncol_;
}

// Reads this fix's columns of atom nlocal from atom->extra (same order).
void FixBondBreakable::unpack_restart(int nlocal, int nth) {
  double **extra = atom->extra;
  int m = 0;
  for (int i = 0; i < nth; ++i) m += static_cast<int>(extra[nlocal][m]);
  m++;
  const int nb = static_cast<int>(extra[nlocal][m++]);
  if (nb > max_bonds_) {
    std::string m2 = label() + "restart atom has " + std::to_string(nb) +
                     " bonds, more than max_bonds " + std::to_string(max_bonds_);
    fail_one(m2);
  }
  nbond_[nlocal] = nb;
  std::memcpy(bonds_[nlocal], &extra[nlocal][m], nb * ncol_ * sizeof(double));
  count_[nlocal] = intact_bonds(nlocal);
}

// Restart size of atom nlocal.
int FixBondBreakable::size_restart(int nlocal) { return 2 + nbond_[nlocal] * ncol_; }

// Largest restart size of any atom.
int FixBondBreakable::maxsize_restart() { return 2 + max_bonds_ * ncol_; }

// Bytes of per-atom storage and of the bond list.
double FixBondBreakable::memory_usage() {
  return static_cast<double>(nmax_) * (sizeof(int) + sizeof(double) * (1 + max_bonds_ * ncol_)) +
         static_cast<double>(list_.capacity()) * sizeof(ListedBond);
}
