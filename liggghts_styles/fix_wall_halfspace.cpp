// fix wall/halfspace: a rigid surface that is solid on one side, with the
// Hertz-Mindlin contact of LIGGGHTS's `model hertz tangential history`
// (docs/styles/fix_wall_halfspace.md), and its terms of the energy ledger.
#include "fix_wall_halfspace.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "atom.h"
#include "error.h"
#include "memory.h"
#include "style_args.h"
#include "update.h"

using namespace LAMMPS_NS;
using namespace FixConst;

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kSqrtFiveSixths = 0.91287092917527685576;  // sqrt(5/6)
}  // namespace

// Reduced Young's modulus of two bodies, Y* = 1 / ((1-nu1^2)/E1 + (1-nu2^2)/E2)
// (Johnson 1985, Contact Mechanics, eq. 4.22; LIGGGHTS's Yeff).
double FixWallHalfspace::effective_youngs(double e1, double nu1, double e2, double nu2) {
  return 1.0 / ((1.0 - nu1 * nu1) / e1 + (1.0 - nu2 * nu2) / e2);
}

// Reduced shear modulus, G* = 1 / (2(2-nu1)(1+nu1)/E1 + 2(2-nu2)(1+nu2)/E2)
// (Mindlin 1949; Di Renzo & Di Maio 2004, eq. 12; LIGGGHTS's Geff).
double FixWallHalfspace::effective_shear(double e1, double nu1, double e2, double nu2) {
  return 1.0 / (2.0 * (2.0 - nu1) * (1.0 + nu1) / e1 + 2.0 * (2.0 - nu2) * (1.0 + nu2) / e2);
}

// beta = ln(e) / sqrt(ln^2(e) + pi^2) (Tsuji et al. 1992; LIGGGHTS's betaeff).
double FixWallHalfspace::damping_beta(double restitution) {
  const double l = std::log(restitution);
  return l / std::sqrt(l * l + kPi * kPi);
}

FixWallHalfspace::FixWallHalfspace(LAMMPS *lmp, int narg, char **arg) : Fix(lmp, narg, arg) {
  parse_args(narg, arg);
  restart_peratom = 1;
  create_attribute = 1;
  grow_arrays(atom->nmax);
  atom->add_callback(0);  // grow, copy, exchange
  atom->add_callback(1);  // restart
}

FixWallHalfspace::~FixWallHalfspace() {
  atom->delete_callback(id, 0);
  atom->delete_callback(id, 1);
  memory->destroy(shear_);
}

// Reads `fix ID group wall/halfspace zplane Z [side lo|hi] youngs E poisson NU
// wall_youngs EW wall_poisson NUW restitution e friction mu`.
void FixWallHalfspace::parse_args(int narg, char **arg) {
  auto fail = [this](const std::string &msg) {
    const std::string m = "fix wall/halfspace: " + msg;
    error->all(FLERR, m.c_str());
  };
  const mill::StyleArgs args(error, "wall/halfspace");
  bool have_plane = false, have_e = false, have_nu = false, have_ew = false, have_nuw = false;
  int iarg = 3;
  while (iarg < narg) {
    const std::string key = arg[iarg];
    if (iarg + 1 >= narg) fail("keyword '" + key + "' needs a value");
    const char *val = arg[iarg + 1];
    if (key == "zplane") {
      z0_ = args.real("zplane", val);
      have_plane = true;
    } else if (key == "side") {
      if (std::strcmp(val, "lo") == 0)
        side_ = 1.0;
      else if (std::strcmp(val, "hi") == 0)
        side_ = -1.0;
      else
        fail(std::string("side must be 'lo' (solid below the plane) or 'hi', got '") + val + "'");
    } else if (key == "youngs") {
      youngs_ = args.positive("youngs", val, "Pa");
      have_e = true;
    } else if (key == "poisson") {
      poisson_ = args.real("poisson", val);
      have_nu = true;
    } else if (key == "wall_youngs") {
      wall_youngs_ = args.positive("wall_youngs", val, "Pa");
      have_ew = true;
    } else if (key == "wall_poisson") {
      wall_poisson_ = args.real("wall_poisson", val);
      have_nuw = true;
    } else if (key == "restitution") {
      restitution_ = args.real("restitution", val);
      if (!(restitution_ > 0.05 && restitution_ <= 1.0))
        fail(std::string("restitution must be in (0.05, 1] (as LIGGGHTS's), got ") + val);
    } else if (key == "friction") {
      friction_ = args.real("friction", val);
      if (!(friction_ >= 0.0)) fail(std::string("friction must be >= 0, got ") + val);
    } else {
      fail("unknown keyword '" + key +
           "' (expected zplane, side, youngs, poisson, wall_youngs, wall_poisson, restitution, "
           "friction)");
    }
    iarg += 2;
  }
  if (!have_plane) fail("zplane Z is required (height of the surface, m)");
  if (!have_e || !have_ew) fail("youngs and wall_youngs are required (Pa)");
  if (!have_nu || !have_nuw) fail("poisson and wall_poisson are required");
  for (double nu : {poisson_, wall_poisson_})
    if (!(nu > -1.0 && nu < 0.5))
      fail("a Poisson's ratio must be in (-1, 0.5), got " + std::to_string(nu));
}

int FixWallHalfspace::setmask() { return POST_FORCE | END_OF_STEP; }

void FixWallHalfspace::init() {
  if (!atom->sphere_flag || !atom->rmass_flag)
    error->all(FLERR, "fix wall/halfspace: needs atom_style sphere (radius, rmass, omega, torque)");
  yeff_ = effective_youngs(youngs_, poisson_, wall_youngs_, wall_poisson_);
  geff_ = effective_shear(youngs_, poisson_, wall_youngs_, wall_poisson_);
  beta_ = damping_beta(restitution_);
}

// Forces at the start of each run (the integrator cleared them); the history
// is not advanced. The ledger's integrals start at the first run.
void FixWallHalfspace::setup(int /*vflag*/) {
  compute_contacts(false);
  if (!started_) {
    double p = 0.0, pd = 0.0;
    step_power(p, pd);
    step_ = update->ntimestep;
    energy_.work.start(p, update->dt);
    energy_.damping.start(pd, update->dt);
    energy_.elastic0 = energy_.elastic;
    started_ = true;
  }
}

void FixWallHalfspace::post_force(int /*vflag*/) { compute_contacts(true); }

// Hertz-Mindlin contact of every group element that reaches into the solid.
// With n the outward normal (+z for side lo) and s the height of the centre
// above the plane, the overlap is delta = r - s, for any s (also s < 0).
void FixWallHalfspace::compute_contacts(bool advance) {
  double **x = atom->x, **v = atom->v, **f = atom->f, **omega = atom->omega,
         **torque = atom->torque;
  const double *radius = atom->radius, *rmass = atom->rmass;
  const int *mask = atom->mask;
  const int nlocal = atom->nlocal;
  const double dt = update->dt;
  const double n = side_;  // outward normal: (0, 0, n)
  touches_.clear();
  energy_.elastic = 0.0;
  for (int i = 0; i < nlocal; ++i) {
    if (!(mask[i] & groupbit)) continue;
    const double s = n * (x[i][2] - z0_);
    const double delta = radius[i] - s;
    double *sh = shear_[i];
    if (delta <= 0.0) {  // no contact: the tangential spring is released
      if (advance) {
        // What it still held is lost with it (the ledger counts it as friction).
        energy_.friction += 0.5 * sh[3] * (sh[0] * sh[0] + sh[1] * sh[1]);
        sh[0] = sh[1] = sh[2] = sh[3] = 0.0;
      }
      continue;
    }
    const double r = radius[i], m = rmass[i];
    energy_.max_overlap = std::max(energy_.max_overlap, delta / r);
    // LIGGGHTS's hertz model (normal_model_hertz.h) with R* = r, m* = m:
    // S_n = 2 Y* sqrt(R delta), S_t = 8 G* sqrt(R delta), k_n = 4/3 Y* sqrt(R delta),
    // k_t = S_t, gamma = -2 sqrt(5/6) beta sqrt(S m) (Tsuji et al. 1992).
    const double sq = std::sqrt(r * delta);
    const double sn = 2.0 * yeff_ * sq, st = 8.0 * geff_ * sq;
    const double kn = 4.0 / 3.0 * yeff_ * sq, kt = st;
    const double gn = -2.0 * kSqrtFiveSixths * beta_ * std::sqrt(sn * m);
    const double gt = -2.0 * kSqrtFiveSixths * beta_ * std::sqrt(st * m);
    // Contact point at arm = r - delta/2 below the centre (LIGGGHTS's c_r);
    // its velocity is v + omega x (-arm n). Normal part vn along n (< 0 when
    // approaching), tangential part vt (z = 0).
    const double arm = std::max(r - 0.5 * delta, 0.0);
    const double vn = n * v[i][2];
    const double vt[3] = {v[i][0] - arm * n * omega[i][1], v[i][1] + arm * n * omega[i][0], 0.0};
    const double fn_el = kn * delta, fn_damp = -gn * vn;
    const double fn = fn_el + fn_damp;  // may turn negative while separating, as in LIGGGHTS
    // Mindlin tangential spring with Coulomb's cap (tangential_model_history.h).
    double trial[3] = {sh[0], sh[1], 0.0};
    if (advance) {
      // The Mindlin spring keeps its displacement while its stiffness follows
      // the overlap, so k_t |s|^2 / 2 changes with no work done: energy the
      // incremental law makes (loading) or loses (unloading). The ledger
      // counts it with the tangential losses; a new contact starts at k_t.
      if (sh[3] > 0.0) energy_.friction -= 0.5 * (kt - sh[3]) * (sh[0] * sh[0] + sh[1] * sh[1]);
      sh[3] = kt;
      trial[0] += vt[0] * dt;
      trial[1] += vt[1] * dt;
    }
    const double smag = std::sqrt(trial[0] * trial[0] + trial[1] * trial[1]);
    const double cap = friction_ * std::fabs(fn), ft_el = kt * smag;
    double ft[3] = {-kt * trial[0], -kt * trial[1], 0.0}, fd[3] = {0.0, 0.0, n * fn_damp};
    if (ft_el > cap) {  // slides: the spring is set back onto the cone
      const double ratio = smag > 0.0 ? cap / ft_el : 0.0;
      ft[0] *= ratio;
      ft[1] *= ratio;
      if (advance) {
        energy_.friction += cap * (ft_el - cap) / kt;  // cap x slip, slip = (F_trial - cap)/k_t
        trial[0] = -ft[0] / kt;
        trial[1] = -ft[1] / kt;
      }
    } else {  // sticks: the tangential dashpot acts
      ft[0] -= gt * vt[0];
      ft[1] -= gt * vt[1];
      fd[0] = -gt * vt[0];
      fd[1] = -gt * vt[1];
    }
    if (advance) {
      sh[0] = trial[0];
      sh[1] = trial[1];
    }
    // Stored: 8/15 Y* sqrt(R) delta^(5/2) (integral of 4/3 Y* sqrt(R) delta^(3/2))
    // plus the tangential spring's k_t |s|^2 / 2.
    energy_.elastic += 8.0 / 15.0 * yeff_ * sq * delta * delta +
                       0.5 * kt * (trial[0] * trial[0] + trial[1] * trial[1]);
    Touch t;
    t.i = i;
    t.f[0] = ft[0];
    t.f[1] = ft[1];
    t.f[2] = n * fn;
    // Torque of the tangential force at the contact point (-arm n) x F_t.
    t.t[0] = arm * n * ft[1];
    t.t[1] = -arm * n * ft[0];
    t.t[2] = 0.0;
    std::copy(fd, fd + 3, t.fd);
    t.arm = arm;
    for (int d = 0; d < 3; ++d) {
      f[i][d] += t.f[d];
      torque[i][d] += t.t[d];
    }
    touches_.push_back(t);
  }
}

// F . (velocity of the contact point) with the current v and omega, for a
// force F acting at the contact point of touch t.
double FixWallHalfspace::contact_velocity_dot(const Touch &t, const double *fvec) const {
  const double *v = atom->v[t.i], *w = atom->omega[t.i];
  const double a = t.arm * side_;  // contact point at (0, 0, -a) from the centre
  const double vc[3] = {v[0] - a * w[1], v[1] + a * w[0], v[2]};
  return fvec[0] * vc[0] + fvec[1] * vc[1] + fvec[2] * vc[2];
}

// Full-step velocities: the work of this step's wall forces and the power the
// dashpots took (trapezoidal rule, see energy_terms.h).
void FixWallHalfspace::end_of_step() {
  double p = 0.0, pd = 0.0;
  step_power(p, pd);
  energy_.work.add(p, update->dt);
  energy_.damping.add(pd, update->dt);
  step_ = update->ntimestep;
}

// Power of this step's wall forces on the elements and taken by the dashpots [W].
void FixWallHalfspace::step_power(double &p, double &pd) const {
  p = pd = 0.0;
  for (const Touch &t : touches_) {
    p += contact_velocity_dot(t, t.f);
    pd -= contact_velocity_dot(t, t.fd);
  }
}

double FixWallHalfspace::local_end_term(int groupbit) const {
  double s = 0.0;
  for (const Touch &t : touches_)
    if (atom->mask[t.i] & groupbit)
      s += mill::end_term(t.f, t.t, atom->f[t.i], atom->torque[t.i], atom->rmass[t.i],
                          atom->radius[t.i]);
  return s;
}

void FixWallHalfspace::subtract_forces(std::vector<double> &f6) const {
  const int n = static_cast<int>(f6.size() / 6);
  for (const Touch &t : touches_)
    if (t.i < n)
      for (int c = 0; c < 3; ++c) {
        f6[6 * t.i + c] -= t.f[c];
        f6[6 * t.i + 3 + c] -= t.t[c];
      }
}

void FixWallHalfspace::local_work_now(double &work, double &damping) const {
  if (step_ == update->ntimestep) {
    work = energy_.work.value();
    damping = energy_.damping.value();
    return;
  }
  double p = 0.0, pd = 0.0;
  step_power(p, pd);
  work = energy_.work.value_with(p, update->dt);
  damping = energy_.damping.value_with(pd, update->dt);
}

// ---- per-atom tangential spring: 3 columns, same order everywhere ----

void FixWallHalfspace::grow_arrays(int nmax) {
  memory->grow(shear_, nmax, kCols, "wall/halfspace:shear");
  for (int i = nmax_; i < nmax; ++i)
    for (int d = 0; d < kCols; ++d) shear_[i][d] = 0.0;
  nmax_ = nmax;
}

void FixWallHalfspace::copy_arrays(int i, int j, int /*delflag*/) {
  for (int d = 0; d < kCols; ++d) shear_[j][d] = shear_[i][d];
}

void FixWallHalfspace::set_arrays(int i) {
  for (int d = 0; d < kCols; ++d) shear_[i][d] = 0.0;
}

int FixWallHalfspace::pack_exchange(int i, double *buf) {
  for (int d = 0; d < kCols; ++d) buf[d] = shear_[i][d];
  return kCols;
}

int FixWallHalfspace::unpack_exchange(int nlocal, double *buf) {
  for (int d = 0; d < kCols; ++d) shear_[nlocal][d] = buf[d];
  return kCols;
}

int FixWallHalfspace::pack_restart(int i, double *buf) {
  buf[0] = kCols + 1;  // values of this fix, this one included (LAMMPS convention)
  for (int d = 0; d < kCols; ++d) buf[1 + d] = shear_[i][d];
  return kCols + 1;
}

void FixWallHalfspace::unpack_restart(int nlocal, int nth) {
  double **extra = atom->extra;
  int m = 0;
  for (int k = 0; k < nth; ++k) m += static_cast<int>(extra[nlocal][m]);
  for (int d = 0; d < kCols; ++d) shear_[nlocal][d] = extra[nlocal][m + 1 + d];
}

int FixWallHalfspace::size_restart(int /*nlocal*/) { return kCols + 1; }
int FixWallHalfspace::maxsize_restart() { return kCols + 1; }

double FixWallHalfspace::memory_usage() {
  return static_cast<double>(nmax_) * kCols * sizeof(double) +
         static_cast<double>(touches_.capacity()) * sizeof(Touch);
}
