// fix fluid/drag: gas drag (Schiller & Naumann 1933 / Newton regime) and
// buoyancy on granular spheres, one-way coupled, for LIGGGHTS 3.8. The
// equations are those of docs/method.md (stage 1); see the doc page
// docs/styles/fix_fluid_drag.md for keywords and units.
#include "fix_fluid_drag.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>

#include "atom.h"
#include "comm.h"
#include "error.h"
#include "postprocess/flow_field_io.h"
#include "style_args.h"
#include "update.h"

using namespace LAMMPS_NS;
using namespace FixConst;

namespace {

constexpr double kPi = 3.14159265358979323846;

}  // namespace

/* ---------------------------------------------------------------------- */

// Parses keywords and, for `field`, reads the gas field once for the whole run.
FixFluidDrag::FixFluidDrag(LAMMPS *lmp, int narg, char **arg) : Fix(lmp, narg, arg) {
  parse_args(narg, arg);
  vector_flag = 1;
  size_vector = 5;
  global_freq = 1;
  extvector = 0;
  if (!uniform_) {
    try {
      field_ = std::make_unique<mill::post::FlowField>(mill::post::read_flow_field(field_path_));
    } catch (const std::exception &e) {
      const std::string msg =
          std::string("fix fluid/drag: cannot read field '") + field_path_ + "': " + e.what();
      error->one(FLERR, msg.c_str());
    }
    // The field is the gas of one rotor speed: a deck that turns the
    // flywheel at another speed would drag lumps with the wrong gas.
    if (have_omega_) {
      const double field_omega = field_->rpm * 2.0 * kPi / 60.0;
      // 1e-4 relative: a hand-typed omega (209.44 for 2000 rpm) passes, another speed does not.
      const double tol = 1e-4 * std::max(std::fabs(omega_), std::fabs(field_omega));
      if (!(std::fabs(field_omega - omega_) <= tol)) {
        char m[512];
        snprintf(m, sizeof(m),
                 "fix fluid/drag: field '%s' was sampled at %.10g rpm (omega %.10g rad/s) but "
                 "the deck's omega is %.10g rad/s (%.10g rpm); sample the flow at this rotor "
                 "speed or give the field's omega",
                 field_path_.c_str(), field_->rpm, field_omega, omega_, omega_ * 60.0 / (2.0 * kPi));
        error->all(FLERR, m);
      }
    }
    if (comm->me == 0) {
      char line[512];
      snprintf(line, sizeof(line),
               "fix fluid/drag: field %s: %d x %d x %d points, spacing %g m, rpm %g\n",
               field_path_.c_str(), field_->dims[0], field_->dims[1], field_->dims[2],
               field_->spacing[0], field_->rpm);
      if (screen) fputs(line, screen);
      if (logfile) fputs(line, logfile);
    }
  }
}

FixFluidDrag::~FixFluidDrag() = default;

// Reads `fix ID group fluid/drag viscosity mu (field FILE | uniform ux uy uz rho)
// [buoyancy gx gy gz]`; errors name the keyword and the bad value.
void FixFluidDrag::parse_args(int narg, char **arg) {
  auto fail = [this](const std::string &msg) {
    const std::string m = "fix fluid/drag: " + msg;
    error->all(FLERR, m.c_str());
  };
  auto need = [&](int iarg, int n, const std::string &key) {
    if (iarg + n >= narg) fail("keyword '" + key + "' needs " + std::to_string(n) + " value(s)");
  };
  const mill::StyleArgs args(error, "fluid/drag");
  bool have_viscosity = false, have_field = false;
  int iarg = 3;
  while (iarg < narg) {
    const std::string key = arg[iarg];
    if (key == "viscosity") {
      need(iarg, 1, key);
      viscosity_ = args.positive(arg[iarg], arg[iarg + 1], "Pa s");
      have_viscosity = true;
      iarg += 2;
    } else if (key == "field") {
      need(iarg, 1, key);
      field_path_ = arg[iarg + 1];
      have_field = true;
      iarg += 2;
    } else if (key == "uniform") {
      need(iarg, 4, key);
      for (int d = 0; d < 3; ++d) u_uniform_[d] = args.real("uniform", arg[iarg + 1 + d]);
      rho_uniform_ = args.real("uniform (gas density)", arg[iarg + 4]);
      if (!(rho_uniform_ > 0.0))
        fail("uniform gas density must be > 0 kg/m^3, got " + std::string(arg[iarg + 4]));
      uniform_ = true;
      iarg += 5;
    } else if (key == "omega") {
      need(iarg, 1, key);
      omega_ = args.real("omega", arg[iarg + 1]);
      have_omega_ = true;
      iarg += 2;
    } else if (key == "buoyancy") {
      need(iarg, 3, key);
      for (int d = 0; d < 3; ++d) gravity_[d] = args.real("buoyancy", arg[iarg + 1 + d]);
      iarg += 4;
    } else {
      fail("unknown keyword '" + key + "' (expected viscosity, field, uniform, omega, buoyancy)");
    }
  }
  if (!have_viscosity) fail("keyword 'viscosity' (gas dynamic viscosity, Pa s) is required");
  if (have_field == uniform_)
    fail("give exactly one of 'field FILE' (sampled gas field, HDF5) or 'uniform ux uy uz rho'");
  if (have_omega_ && uniform_)
    fail("'omega' checks the rotor speed of a sampled field; it needs 'field FILE', not 'uniform'");
}

int FixFluidDrag::setmask() {
  int mask = 0;
  mask |= POST_FORCE;
  mask |= POST_RUN;
  return mask;
}

// Needs per-atom radius and mass (atom_style granular/sphere).
void FixFluidDrag::init() {
  if (!atom->radius_flag || !atom->rmass_flag)
    error->all(FLERR,
               "fix fluid/drag: needs per-atom radius and mass (atom_style granular or sphere)");
}

// Applies the forces once before the first step, like every post_force fix.
void FixFluidDrag::setup(int /*vflag*/) { post_force(0); }

// Gas velocity u and density rho at x; false when x is off the grid or next to
// a point outside the gas (then the particle feels no drag).
bool FixFluidDrag::gas_at(const double *x, double *u, double &rho) const {
  if (uniform_) {
    for (int d = 0; d < 3; ++d) u[d] = u_uniform_[d];
    rho = rho_uniform_;
    return true;
  }
  // Velocity and density with the same trilinear weights, in one pass.
  std::array<double, 3> ua{};
  if (!field_->gas_at({x[0], x[1], x[2]}, ua, rho)) return false;
  for (int d = 0; d < 3; ++d) u[d] = ua[d];
  return true;
}

// Adds drag and buoyancy to every particle of the group, then reduces the
// step's counters once (masked particles, largest Re).
void FixFluidDrag::post_force(int /*vflag*/) {
  double **x = atom->x, **v = atom->v, **f = atom->f;
  const double *radius = atom->radius, *rmass = atom->rmass;
  const int *mask = atom->mask;
  const int nlocal = atom->nlocal;
  double local[2] = {0.0, 0.0};  // masked, dragged
  double re_local = 0.0;
  for (int i = 0; i < nlocal; ++i) {
    if (!(mask[i] & groupbit)) continue;
    double u[3], rho = 0.0;
    if (!gas_at(x[i], u, rho)) {
      local[0] += 1.0;
      continue;
    }
    const double d = 2.0 * radius[i];
    const double m = rmass[i];
    const double rho_s = m / (kPi * d * d * d / 6.0);
    const double du[3] = {u[0] - v[i][0], u[1] - v[i][1], u[2] - v[i][2]};
    const double slip = std::sqrt(du[0] * du[0] + du[1] * du[1] + du[2] * du[2]);
    const double re = rho * d * slip / viscosity_;  // method.md: Re = rho d |u_s - u| / mu
    // method.md: F_drag = 3 mu C_d Re / (4 rho_s d^2), force m F_drag (u - u_s).
    const double fdrag = 3.0 * viscosity_ * drag_coefficient_times_re(re) / (4.0 * rho_s * d * d);
    // method.md: the g (rho_s - rho)/rho_s term; fix gravity supplies g, this the -g rho/rho_s
    // part.
    const double buoy = -rho / rho_s;
    for (int k = 0; k < 3; ++k) f[i][k] += m * (fdrag * du[k] + buoy * gravity_[k]);
    if (re > re_local) re_local = re;
    local[1] += 1.0;
  }
  double global[2] = {0.0, 0.0};
  MPI_Allreduce(local, global, 2, MPI_DOUBLE, MPI_SUM, world);
  MPI_Allreduce(&re_local, &re_max_, 1, MPI_DOUBLE, MPI_MAX, world);
  masked_now_ = global[0];
  dragged_now_ = global[1];
  masked_total_ += masked_now_;
  if (masked_now_ > masked_max_) masked_max_ = masked_now_;
}

// Warns when particles sat where the field has no gas velocity: the first
// time, then whenever the count has doubled (a deck of many short runs gets a
// few lines, not one per run). The total is f_ID[2].
void FixFluidDrag::post_run() {
  if (masked_total_ > 0.0 && masked_total_ >= 2.0 * masked_warned_) {
    masked_warned_ = masked_total_;
    if (comm->me == 0) {
      char line[400];
      snprintf(line, sizeof(line),
               "fix fluid/drag: %.0f particle-steps so far (at most %.0f particles at once) were "
               "off the "
               "field grid or next to a point outside the gas; they felt no drag there",
               masked_total_, masked_max_);
      error->warning(FLERR, line);
    }
  }
}

// 1: particles without gas velocity this step, 2: particle-steps without gas
// velocity this run, 3: most at once, 4: largest Re this step, 5: particles
// dragged this step. Cached values only.
double FixFluidDrag::compute_vector(int n) {
  switch (n) {
    case 0:
      return masked_now_;
    case 1:
      return masked_total_;
    case 2:
      return masked_max_;
    case 3:
      return re_max_;
    case 4:
      return dragged_now_;
    default:
      return 0.0;
  }
}
