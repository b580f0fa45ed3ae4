// fix impact/recorder: contact onsets between particles and wall meshes, with
// the impact velocity relative to the (possibly rotating) struck surface, and
// contact ends with the lab velocity after the contact and its duration.
// See docs/styles/fix_impact_recorder.md for keywords, columns and units.
#include "fix_impact_recorder.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>

#include "abstract_mesh.h"
#include "atom.h"
#include "comm.h"
#include "error.h"
#include "fix_mesh.h"
#include "fix_mesh_surface.h"
#include "fix_neighlist_mesh.h"
#include "fix_property_atom.h"
#include "memory.h"
#include "modify.h"
#include "postprocess/closest_point.h"
#include "style_args.h"
#include "update.h"

using namespace LAMMPS_NS;
using namespace FixConst;

namespace {

constexpr double kRadToDeg = 57.295779513082320876;
constexpr int kMaxSurfaces = 16;
// The pre-filter's grid: at most this many bins per triangle, and at most
// this many bin entries (triangle indices) per triangle; the bins grow until
// both hold.
constexpr double kBinsPerTriangle = 4.0;
constexpr double kEntriesPerTriangle = 32.0;
// The grid's boxes are grown by this many bin edges (of the triangles' own
// box at kBinsPerTriangle), and it is kept while no node has moved farther.
constexpr double kGridSlackBins = 0.25;

// Small 3-vector helpers: dot product, difference, cross product c = a x b.
inline double dot3(const double *a, const double *b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline void sub3(const double *a, const double *b, double *c) {
  for (int k = 0; k < 3; ++k) c[k] = a[k] - b[k];
}
inline void cross3(const double *a, const double *b, double *c) {
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}

}  // namespace

/* ---------------------------------------------------------------------- */

// Parses keywords, opens the CSVs (rank 0) and registers the per-atom state.
FixImpactRecorder::FixImpactRecorder(LAMMPS *lmp, int narg, char **arg) : Fix(lmp, narg, arg) {
  parse_args(narg, arg);
  vector_flag = 1;
  size_vector = 2 + static_cast<int>(surfaces_.size());
  global_freq = 1;
  extvector = 0;
  create_attribute = 1;
  counts_.assign(1 + surfaces_.size(), 0.0);  // the last output is computed

  ncols_ = 1 + static_cast<int>(surfaces_.size());
  if (pending_from_ >= 0) {
    peratom_flag = 1;
    size_peratom_cols = 0;
    peratom_freq = 1;
  }
  grow_arrays(atom->nmax);
  atom->add_callback(0);

  if (comm->me == 0) {
    auto open = [this](const std::string &path) {
      FILE *f = fopen(path.c_str(), "w");
      if (!f) {
        const std::string msg = "fix impact/recorder: cannot open file '" + path + "'";
        error->one(FLERR, msg.c_str());
      }
      return f;
    };
    file_ = open(file_path_);
    fputs(
        "time_s,particle_id,surface,x_m,y_m,z_m,contact_x_m,contact_y_m,contact_z_m,"
        "normal_x,normal_y,normal_z,vrel_x_m_s,vrel_y_m_s,vrel_z_m_s,speed_m_s,"
        "normal_speed_m_s,tangential_speed_m_s,angle_deg,surface_speed_m_s,"
        "particle_speed_m_s,axis_distance_m\n",
        file_);
    fflush(file_);
    if (!ends_path_.empty()) {
      ends_file_ = open(ends_path_);
      fputs(
          "time_s,particle_id,surface,start_time_s,duration_s,x_m,y_m,z_m,vx_m_s,vy_m_s,vz_m_s,"
          "speed_m_s,vrel_x_m_s,vrel_y_m_s,vrel_z_m_s,relative_speed_m_s,normal_speed_m_s,"
          "tangential_speed_m_s,surface_speed_m_s\n",
          ends_file_);
      fflush(ends_file_);
    }
  }
}

// Unregisters the callback, frees storage and closes the CSVs.
FixImpactRecorder::~FixImpactRecorder() {
  atom->delete_callback(id, 0);
  memory->destroy(state_);
  memory->destroy(pending_);
  if (file_) fclose(file_);
  if (ends_file_) fclose(ends_file_);
}

// Reads `fix ID group impact/recorder file F [ends F2] [prefilter yes|no]
// [pending FROM TO] surface NAME mesh MESHID [omega w origin x y z axis x y z]
// [surface ...]`; errors name key and value.
void FixImpactRecorder::parse_args(int narg, char **arg) {
  auto fail = [this](const std::string &msg) {
    const std::string m = "fix impact/recorder: " + msg;
    error->all(FLERR, m.c_str());
  };
  auto need = [&](int iarg, int n, const std::string &key) {
    if (iarg + n >= narg) fail("keyword '" + key + "' needs " + std::to_string(n) + " value(s)");
  };
  const mill::StyleArgs args(error, "impact/recorder");
  int iarg = 3;
  while (iarg < narg) {
    const std::string key = arg[iarg];
    if (key == "file") {
      need(iarg, 1, key);
      file_path_ = arg[iarg + 1];
      iarg += 2;
    } else if (key == "ends") {
      need(iarg, 1, key);
      ends_path_ = arg[iarg + 1];
      iarg += 2;
    } else if (key == "prefilter") {
      need(iarg, 1, key);
      const std::string v = arg[iarg + 1];
      if (v != "yes" && v != "grid" && v != "no")
        fail("prefilter must be yes, grid or no, got '" + v + "'");
      prefilter_ = v != "no";
      neighfilter_ = v == "yes";
      iarg += 2;
    } else if (key == "pending") {
      need(iarg, 2, key);
      pending_names_[0] = arg[iarg + 1];
      pending_names_[1] = arg[iarg + 2];
      iarg += 3;
    } else if (key == "surface") {
      need(iarg, 3, key);
      if (std::strcmp(arg[iarg + 2], "mesh") != 0)
        fail("surface " + std::string(arg[iarg + 1]) + ": expected 'mesh MESH_FIX_ID', got '" +
             arg[iarg + 2] + "'");
      Surface s;
      s.name = arg[iarg + 1];
      s.mesh_id = arg[iarg + 3];
      iarg += 4;
      bool have_omega = false, have_origin = false, have_axis = false;
      while (iarg < narg && std::strcmp(arg[iarg], "surface") != 0 &&
             std::strcmp(arg[iarg], "file") != 0 && std::strcmp(arg[iarg], "ends") != 0 &&
             std::strcmp(arg[iarg], "prefilter") != 0 && std::strcmp(arg[iarg], "pending") != 0) {
        const std::string sub = arg[iarg];
        if (sub == "omega") {
          need(iarg, 1, sub);
          s.omega = args.real("omega", arg[iarg + 1]);
          have_omega = true;
          iarg += 2;
        } else if (sub == "origin" || sub == "axis") {
          need(iarg, 3, sub);
          auto &v = sub == "origin" ? s.origin : s.axis;
          for (int d = 0; d < 3; ++d) v[d] = args.real(sub.c_str(), arg[iarg + 1 + d]);
          (sub == "origin" ? have_origin : have_axis) = true;
          iarg += 4;
        } else {
          fail("surface " + s.name + ": unknown keyword '" + sub +
               "' (expected omega, origin, axis, surface, file, ends, prefilter, pending)");
        }
      }
      if (have_omega || have_origin || have_axis) {
        if (!(have_omega && have_origin && have_axis))
          fail("surface " + s.name + ": a rotating surface needs all of omega, origin and axis");
        const double n =
            std::sqrt(s.axis[0] * s.axis[0] + s.axis[1] * s.axis[1] + s.axis[2] * s.axis[2]);
        if (!(n > 0.0)) fail("surface " + s.name + ": axis must not be the zero vector");
        for (auto &a : s.axis) a /= n;
        s.rotating = true;
      }
      surfaces_.push_back(s);
    } else {
      fail("unknown keyword '" + key + "' (expected file, ends, prefilter, pending, surface)");
    }
  }
  if (file_path_.empty()) fail("keyword 'file' (the impact CSV) is required");
  if (!ends_path_.empty() && ends_path_ == file_path_)
    fail("'ends' and 'file' name the same file '" + file_path_ +
         "'; give the contact ends their own");
  if (surfaces_.empty()) fail("at least one 'surface NAME mesh MESH_FIX_ID' is required");
  if (surfaces_.size() > static_cast<size_t>(kMaxSurfaces))
    fail("at most " + std::to_string(kMaxSurfaces) + " surfaces, got " +
         std::to_string(surfaces_.size()));
  if (!pending_names_[0].empty()) {
    std::string names;
    for (const auto &s : surfaces_) names += (names.empty() ? "" : ", ") + s.name;
    int *index[2] = {&pending_from_, &pending_to_};
    for (int k = 0; k < 2; ++k) {
      for (size_t is = 0; is < surfaces_.size(); ++is)
        if (surfaces_[is].name == pending_names_[k]) *index[k] = static_cast<int>(is);
      if (*index[k] < 0)
        fail("pending: no surface named '" + pending_names_[k] + "' (the surfaces: " + names + ")");
    }
    if (pending_from_ == pending_to_)
      fail("pending: FROM and TO must be two surfaces, got '" + pending_names_[0] + "' twice");
  }
}

int FixImpactRecorder::setmask() {
  int mask = 0;
  mask |= END_OF_STEP;
  return mask;
}

// Finds the mesh fixes (they may be defined after this fix) and checks atoms.
void FixImpactRecorder::init() {
  if (!atom->radius_flag || !atom->rmass_flag)
    error->all(FLERR, "fix impact/recorder: needs per-atom radius and mass (atom_style granular)");
  for (auto &s : surfaces_) {
    const int ifix = modify->find_fix(s.mesh_id.c_str());
    if (ifix < 0) {
      const std::string msg =
          "fix impact/recorder: surface " + s.name + ": no fix with ID '" + s.mesh_id + "'";
      error->all(FLERR, msg.c_str());
    }
    if (std::strncmp(modify->fix[ifix]->style, "mesh/surface", 12) != 0) {
      const std::string msg = "fix impact/recorder: surface " + s.name + ": fix '" + s.mesh_id +
                              "' is a " + modify->fix[ifix]->style + ", not a mesh/surface";
      error->all(FLERR, msg.c_str());
    }
    s.mesh = static_cast<FixMesh *>(modify->fix[ifix]);
  }
}

// Marks particles already touching a surface at the start as in contact
// (no record, and no end record later): only onsets during the run are
// impacts. Called at every `run`; contacts already known keep their state.
void FixImpactRecorder::setup(int /*vflag*/) {
  double **x = atom->x;
  const double *radius = atom->radius;
  const int *mask = atom->mask;
  set_query_reach();
  for (auto &s : surfaces_) {
    load_triangles(s);
    set_bound(s);
  }
  for (int i = 0; i < atom->nlocal; ++i) {
    if (!(mask[i] & groupbit)) continue;
    int bits = static_cast<int>(state_[i][0]);
    for (size_t is = 0; is < surfaces_.size(); ++is) {
      double c[3];
      if (!(bits & (1 << is)) && nearest_point(surfaces_[is], x[i], radius[i], c)) {
        bits |= 1 << is;
        state_[i][1 + is] = -1.0;
      }
    }
    state_[i][0] = bits;
  }
}

// Copies the current (moved) triangles of a mesh, owned and ghost, with their
// unit normals and bounding box, and bins them (with the pre-filter on).
void FixImpactRecorder::load_triangles(Surface &s) {
  AbstractMesh *m = s.mesh->mesh();
  const int n = m->size();
  s.tri.resize(9 * static_cast<size_t>(n));
  s.normal.resize(3 * static_cast<size_t>(n));
  s.box = {1e300, -1e300, 1e300, -1e300, 1e300, -1e300};
  for (int t = 0; t < n; ++t) {
    double *p = &s.tri[9 * static_cast<size_t>(t)];
    for (int j = 0; j < 3; ++j) {
      m->node_slow(t, j, p + 3 * j);
      for (int d = 0; d < 3; ++d) {
        s.box[2 * d] = std::min(s.box[2 * d], p[3 * j + d]);
        s.box[2 * d + 1] = std::max(s.box[2 * d + 1], p[3 * j + d]);
      }
    }
    double e1[3], e2[3], nrm[3];
    sub3(p + 3, p, e1);
    sub3(p + 6, p, e2);
    cross3(e1, e2, nrm);
    const double len = std::sqrt(dot3(nrm, nrm));
    for (int d = 0; d < 3; ++d) s.normal[3 * t + d] = len > 0.0 ? nrm[d] / len : 0.0;
  }
  s.loaded = true;
  if (prefilter_ && !grid_holds(s)) build_grid(s);
}

// Whether the grid still answers for the triangles just loaded: built for
// this step's query reach (or more), from as many triangles, none of whose
// nodes has moved farther than the grid's slack since. A triangle within r of
// a point lies then within r + slack of where its grid boxes were made, so
// the point's bin still lists it (a superset, in ascending order: the same
// nearest point as a new grid or the full loop).
bool FixImpactRecorder::grid_holds(const Surface &s) const {
  if (s.grid_reach < query_reach_ || s.grid_tri.size() != s.tri.size()) return false;
  const double slack2 = s.grid_slack * s.grid_slack;
  for (size_t v = 0; v < s.tri.size(); v += 3) {
    double d[3];
    sub3(&s.tri[v], &s.grid_tri[v], d);
    if (dot3(d, d) > slack2) return false;
  }
  return true;
}

// The largest radius nearest_point is asked for this step on this rank: the
// largest radius of the group's atoms, twice that with contact ends
// (record_end looks for the surface within two radii).
void FixImpactRecorder::set_query_reach() {
  const double *radius = atom->radius;
  const int *mask = atom->mask;
  double r = 0.0;
  for (int i = 0; i < atom->nlocal; ++i)
    if ((mask[i] & groupbit) && radius[i] > r) r = radius[i];
  query_reach_ = ends_path_.empty() ? r : 2.0 * r;
}

// Bins the triangles of s into a uniform grid: each triangle goes into every
// bin that its bounding box, grown by this step's query reach, the slack
// (grid_holds) and a margin far above rounding, meets, so that a triangle
// within the reach of a point is always among the triangles of the point's
// bin, until one of its nodes has moved farther than the slack. Bins are cubes sized for
// about kBinsPerTriangle bins per triangle, and grow while the entries pass
// kEntriesPerTriangle per triangle (large triangles over small bins).
void FixImpactRecorder::build_grid(Surface &s) {
  s.grid_reach = -1.0;  // no grid until this one is built
  s.grid_tri.clear();
  const int n = static_cast<int>(s.normal.size() / 3);
  if (n == 0) return;  // no triangles here: the box test already says no contact
  double ext[3], lo[3], widest = 0.0, far = 0.0;
  for (int d = 0; d < 3; ++d) {
    widest = std::max(widest, s.box[2 * d + 1] - s.box[2 * d]);
    far = std::max({far, std::fabs(s.box[2 * d]), std::fabs(s.box[2 * d + 1])});
  }
  // The slack: a quarter of the bin edge the triangles' own box would get,
  // so a turning mesh keeps its grid while its nodes move that far.
  double vol = 1.0;
  for (int d = 0; d < 3; ++d) vol *= s.box[2 * d + 1] - s.box[2 * d];
  const double slack = kGridSlackBins * std::cbrt(std::max(0.0, vol) / (kBinsPerTriangle * n));
  const double pad = query_reach_ * (1.0 + 1e-9) + slack + 1e-9 * (widest + far);
  for (int d = 0; d < 3; ++d) {
    lo[d] = s.box[2 * d] - pad;
    ext[d] = s.box[2 * d + 1] + pad - lo[d];
  }
  const double max_cells = std::max(1.0, kBinsPerTriangle * n);
  const double max_entries = kEntriesPerTriangle * n;
  double h = std::cbrt(ext[0] * ext[1] * ext[2] / max_cells);
  if (!(h > 0.0) || !std::isfinite(h)) return;  // a degenerate surface: test all triangles
  // Bins of the grown box of triangle t along d at bin size h: [i0, i1].
  auto range = [&](int t, int d, int nd, int &i0, int &i1) {
    const double *p = &s.tri[9 * static_cast<size_t>(t)];
    const double tlo = std::min({p[d], p[3 + d], p[6 + d]}) - pad;
    const double thi = std::max({p[d], p[3 + d], p[6 + d]}) + pad;
    i0 = std::clamp(static_cast<int>(std::floor((tlo - lo[d]) / h)), 0, nd - 1);
    i1 = std::clamp(static_cast<int>(std::floor((thi - lo[d]) / h)), 0, nd - 1);
  };
  int nb[3];
  for (;;) {
    double cells = 1.0;
    for (int d = 0; d < 3; ++d) {
      nb[d] = std::max(1, static_cast<int>(std::ceil(ext[d] / h)));
      cells *= nb[d];
    }
    if (cells > max_cells) {
      h *= 1.25;
      continue;
    }
    double entries = 0.0;
    for (int t = 0; t < n && entries <= max_entries; ++t) {
      double k = 1.0;
      for (int d = 0; d < 3; ++d) {
        int i0, i1;
        range(t, d, nb[d], i0, i1);
        k *= i1 - i0 + 1;
      }
      entries += k;
    }
    if (entries <= max_entries || cells <= 1.0) break;
    h *= 1.25;
  }
  const size_t ncell = static_cast<size_t>(nb[0]) * nb[1] * nb[2];
  s.cell_start.assign(ncell + 1, 0);
  // Two passes, count then fill, in ascending triangle order: every bin's
  // list comes out ascending, the order the full loop tests them in.
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<int> next;
    if (pass == 1) {
      for (size_t b = 0; b < ncell; ++b) s.cell_start[b + 1] += s.cell_start[b];
      s.cell_tri.resize(static_cast<size_t>(s.cell_start[ncell]));
      next.assign(s.cell_start.begin(), s.cell_start.end() - 1);
    }
    for (int t = 0; t < n; ++t) {
      int r0[3], r1[3];
      for (int d = 0; d < 3; ++d) range(t, d, nb[d], r0[d], r1[d]);
      for (int i = r0[0]; i <= r1[0]; ++i)
        for (int j = r0[1]; j <= r1[1]; ++j)
          for (int k = r0[2]; k <= r1[2]; ++k) {
            const size_t b = (static_cast<size_t>(k) * nb[1] + j) * nb[0] + i;
            if (pass == 0)
              ++s.cell_start[b + 1];
            else
              s.cell_tri[static_cast<size_t>(next[b]++)] = t;
          }
    }
  }
  for (int d = 0; d < 3; ++d) {
    s.grid_lo[d] = lo[d];
    s.grid_n[d] = nb[d];
  }
  s.grid_h = h;
  s.grid_reach = query_reach_;
  s.grid_slack = slack;
  s.grid_tri = s.tri;
}

// The triangles of the bin holding x, as [*first, *last); false if x lies
// outside the grid (then no triangle is within the grid's reach of it).
bool FixImpactRecorder::grid_candidates(const Surface &s, const double *x, const int **first,
                                        const int **last) const {
  int ib[3];
  for (int d = 0; d < 3; ++d) {
    const double f = std::floor((x[d] - s.grid_lo[d]) / s.grid_h);
    if (!(f >= 0.0 && f < s.grid_n[d])) return false;
    ib[d] = static_cast<int>(f);
  }
  const size_t b = (static_cast<size_t>(ib[2]) * s.grid_n[1] + ib[1]) * s.grid_n[0] + ib[0];
  *first = s.cell_tri.data() + s.cell_start[b];
  *last = s.cell_tri.data() + s.cell_start[b + 1];
  return true;
}

// A sphere that holds the whole surface at every rotation angle (about the
// axis for a rotating surface; around the box of a fixed one), from the
// triangles of all ranks (their elements migrate as the mesh turns).
// Particles outside it are not checked.
void FixImpactRecorder::set_bound(Surface &s) {
  const size_t n = s.tri.size() / 3;  // vertices on this rank
  if (!s.rotating) {
    double lo[3], hi[3], glo[3], ghi[3];
    for (int d = 0; d < 3; ++d) {
      lo[d] = s.box[2 * d];
      hi[d] = s.box[2 * d + 1];
    }
    MPI_Allreduce(lo, glo, 3, MPI_DOUBLE, MPI_MIN, world);
    MPI_Allreduce(hi, ghi, 3, MPI_DOUBLE, MPI_MAX, world);
    double r2 = 0.0;
    for (int d = 0; d < 3; ++d) {
      s.bound[d] = 0.5 * (glo[d] + ghi[d]);
      r2 += 0.25 * (ghi[d] - glo[d]) * (ghi[d] - glo[d]);
    }
    s.bound[3] = glo[0] <= ghi[0] ? std::sqrt(r2) : -1.0;
    return;
  }
  double mx[3] = {1e300, -1e300, 0.0};  // -min axial, max axial, max radius^2
  for (size_t v = 0; v < n; ++v) {
    double r[3];
    sub3(&s.tri[3 * v], s.origin.data(), r);
    const double along = dot3(r, s.axis.data());
    mx[0] = std::min(mx[0], along);
    mx[1] = std::max(mx[1], along);
    mx[2] = std::max(mx[2], dot3(r, r) - along * along);
  }
  mx[0] = -mx[0];
  double g[3];
  MPI_Allreduce(mx, g, 3, MPI_DOUBLE, MPI_MAX, world);
  const double amin = -g[0], amax = g[1];
  const double mid = 0.5 * (amin + amax), half = 0.5 * (amax - amin);
  for (int d = 0; d < 3; ++d) s.bound[d] = s.origin[d] + mid * s.axis[d];
  s.bound[3] = amin <= amax ? std::sqrt(g[2] + half * half) : -1.0;
}

// Nearest point c of the surface to x if closer than radius (contact); false
// otherwise. Only the triangles of x's bin are tested (with the pre-filter;
// all of them without), in ascending order, so the first of equally near
// triangles wins either way; triangles whose plane is farther than radius
// are skipped cheaply.
bool FixImpactRecorder::nearest_point(Surface &s, const double *x, double radius, double *c) {
  double dc[3];
  sub3(x, s.bound.data(), dc);
  const double reach = s.bound[3] + radius;
  if (s.bound[3] < 0.0 || dot3(dc, dc) > reach * reach) return false;
  if (!s.loaded) load_triangles(s);  // first particle near this surface this step
  for (int d = 0; d < 3; ++d)
    if (x[d] < s.box[2 * d] - radius || x[d] > s.box[2 * d + 1] + radius) return false;
  double best = radius * radius;
  bool found = false;
  auto test = [&](size_t t) {
    const double *p = &s.tri[9 * t];
    double ap[3];
    sub3(x, p, ap);
    if (std::fabs(dot3(ap, &s.normal[3 * t])) >= radius) return;
    double q[3];
    mill::post::closest_on_triangle(x, p, p + 3, p + 6, q);
    double dq[3];
    sub3(x, q, dq);
    const double d2 = dot3(dq, dq);
    if (d2 < best) {
      best = d2;
      for (int k = 0; k < 3; ++k) c[k] = q[k];
      found = true;
    }
  };
  if (s.grid_reach >= radius) {
    const int *first = nullptr, *last = nullptr;
    if (!grid_candidates(s, x, &first, &last)) return false;
    for (const int *t = first; t != last; ++t) test(static_cast<size_t>(*t));
    return found;
  }
  const size_t n = s.normal.size() / 3;  // no grid, or a radius beyond its reach
  for (size_t t = 0; t < n; ++t) test(t);
  return found;
}

// With the pre-filter `yes`: the per-atom count of the triangles of s whose
// neighbour list (LIGGGHTS' fix neighlist/mesh, the one fix wall/gran uses)
// holds the atom, and the group bit of the atoms those lists look at; null
// when the mesh has no such list (no wall/gran fix uses it). The lists are
// conservative: a particle in none of them is farther than its radius plus
// the neighbour skin from every triangle when they were built, and neither it
// nor the mesh has moved by more than half the skin since (LIGGGHTS rebuilds
// them then), so it touches no triangle now.
Fix *FixImpactRecorder::mesh_neighbour_counts(const Surface &s, int *wall_groupbit) const {
  auto *surface = dynamic_cast<FixMeshSurface *>(s.mesh);
  if (!surface || !surface->hasNeighList()) return nullptr;
  FixNeighlistMesh *list = surface->meshNeighlist();
  FixPropertyAtom *counts = list ? list->fix_nneighs() : nullptr;
  if (!counts || !counts->vector_atom) return nullptr;
  *wall_groupbit = list->groupbit_wall_mesh;
  return counts;
}

// Velocity w of surface s at point c (Omega x r, r from the axis to c; zero
// for a fixed surface) and the distance of c from the axis.
void FixImpactRecorder::surface_velocity(const Surface &s, const double *c, double *w,
                                         double *raxis) const {
  for (int k = 0; k < 3; ++k) w[k] = 0.0;
  *raxis = 0.0;
  if (!s.rotating) return;
  double r[3], om[3];
  sub3(c, s.origin.data(), r);
  const double along = dot3(r, s.axis.data());
  for (int k = 0; k < 3; ++k) {
    r[k] -= along * s.axis[k];  // radius vector from the axis
    om[k] = s.omega * s.axis[k];
  }
  *raxis = std::sqrt(dot3(r, r));
  cross3(om, r, w);
}

// Stores one onset of atom i on surface is at contact point c: velocity
// relative to the surface there (v - Omega x r for a rotating surface), its
// normal and tangential parts, and the impact angle to the surface plane.
void FixImpactRecorder::record(const Surface &s, int is, int i, const double *c) {
  double **x = atom->x, **v = atom->v, **f = atom->f;
  // The velocity before this step's contact force: velocity Verlet added
  // dt/2 f/m of the new force (contact included) in final_integrate.
  const double half_dt_m = 0.5 * update->dt / atom->rmass[i];
  const double vpre[3] = {v[i][0] - half_dt_m * f[i][0], v[i][1] - half_dt_m * f[i][1],
                          v[i][2] - half_dt_m * f[i][2]};
  double n[3];
  sub3(x[i], c, n);
  const double len = std::sqrt(dot3(n, n));
  for (int k = 0; k < 3; ++k) n[k] = len > 0.0 ? n[k] / len : 0.0;
  double w[3], raxis;
  surface_velocity(s, c, w, &raxis);
  double vr[3];
  sub3(vpre, w, vr);
  const double vn = -dot3(vr, n);  // approach speed along the normal (> 0 towards the surface)
  double vt_vec[3];
  for (int k = 0; k < 3; ++k) vt_vec[k] = vr[k] + vn * n[k];
  const double vt = std::sqrt(dot3(vt_vec, vt_vec));
  const double e[NCOL] = {update->get_cur_time(),
                          static_cast<double>(atom->tag[i]),
                          static_cast<double>(is),
                          x[i][0],
                          x[i][1],
                          x[i][2],
                          c[0],
                          c[1],
                          c[2],
                          n[0],
                          n[1],
                          n[2],
                          vr[0],
                          vr[1],
                          vr[2],
                          std::sqrt(dot3(vr, vr)),
                          vn,
                          vt,
                          std::atan2(vn, vt) * kRadToDeg,
                          std::sqrt(dot3(w, w)),
                          std::sqrt(dot3(vpre, vpre)),
                          raxis};
  events_.insert(events_.end(), e, e + NCOL);
}

// Stores the end of the contact of atom i with surface is that began at
// `start`: the lab velocity now (the first step without contact, so no
// contact force is in it) and, at the nearest surface point within two radii,
// the velocity relative to the surface with its normal (> 0 away from the
// surface) and tangential parts.
void FixImpactRecorder::record_end(Surface &s, int is, int i, double start) {
  double **x = atom->x, **v = atom->v;
  const double now = update->get_cur_time();
  double c[3], w[3] = {0, 0, 0}, raxis = 0.0, vr[3], n[3] = {0, 0, 0};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  double vn = nan, vt = nan, wspeed = nan;
  for (int k = 0; k < 3; ++k) vr[k] = nan;
  if (nearest_point(s, x[i], 2.0 * atom->radius[i], c)) {
    surface_velocity(s, c, w, &raxis);
    sub3(x[i], c, n);
    const double len = std::sqrt(dot3(n, n));
    for (int k = 0; k < 3; ++k) n[k] = len > 0.0 ? n[k] / len : 0.0;
    sub3(v[i], w, vr);
    vn = dot3(vr, n);
    double t[3];
    for (int k = 0; k < 3; ++k) t[k] = vr[k] - vn * n[k];
    vt = std::sqrt(dot3(t, t));
    wspeed = std::sqrt(dot3(w, w));
  }
  const double e[NEND] = {now,
                          static_cast<double>(atom->tag[i]),
                          static_cast<double>(is),
                          start,
                          now - start,
                          x[i][0],
                          x[i][1],
                          x[i][2],
                          v[i][0],
                          v[i][1],
                          v[i][2],
                          std::sqrt(dot3(v[i], v[i])),
                          vr[0],
                          vr[1],
                          vr[2],
                          std::sqrt(dot3(vr, vr)),
                          vn,
                          vt,
                          wspeed};
  ends_.insert(ends_.end(), e, e + NEND);
}

// Detects onsets and ends after the step's integration (particles and meshes
// at the same time), then gathers the step's records on rank 0 (one reduction).
void FixImpactRecorder::end_of_step() {
  double **x = atom->x;
  const double *radius = atom->radius;
  const int *mask = atom->mask;
  if (prefilter_) set_query_reach();
  for (auto &s : surfaces_) s.loaded = false;  // triangles are fetched lazily
  const size_t ns = surfaces_.size();
  Fix *nneigh[kMaxSurfaces] = {nullptr};
  int wallbit[kMaxSurfaces] = {0};
  if (neighfilter_)
    for (size_t is = 0; is < ns; ++is)
      nneigh[is] = mesh_neighbour_counts(surfaces_[is], &wallbit[is]);
  for (int i = 0; i < atom->nlocal; ++i) {
    if (!(mask[i] & groupbit)) continue;
    int bits = static_cast<int>(state_[i][0]), onsets = 0;
    for (size_t is = 0; is < ns; ++is) {
      double c[3];
      const int bit = 1 << is;
      // In no triangle's neighbour list of the mesh: farther than its radius
      // from every triangle (the lists hold every particle within radius +
      // skin, and are rebuilt before anything moves by half the skin).
      const bool listed =
          !nneigh[is] || !(mask[i] & wallbit[is]) || nneigh[is]->get_vector_atom_int(i) > 0;
      tests_[listed ? 0 : 1] += 1.0;
      if (listed && nearest_point(surfaces_[is], x[i], radius[i], c)) {
        if (!(bits & bit)) {
          record(surfaces_[is], static_cast<int>(is), i, c);
          state_[i][1 + is] = update->get_cur_time();
          onsets |= bit;
        }
        bits |= bit;
      } else {
        if ((bits & bit) && !ends_path_.empty() && state_[i][1 + is] >= 0.0)
          record_end(surfaces_[is], static_cast<int>(is), i, state_[i][1 + is]);
        bits &= ~bit;
        state_[i][1 + is] = -1.0;
      }
    }
    state_[i][0] = bits;
    if (pending_from_ >= 0) {  // an onset on TO in the same step as one on FROM: arrived
      if (onsets & (1 << pending_to_))
        pending_[i] = 0.0;
      else if (onsets & (1 << pending_from_))
        pending_[i] = 1.0;
    }
  }
  flush_events();
}

// Moves this step's records of every rank (ncol values each, ntotal in all)
// to rank 0; `local` is emptied.
std::vector<double> FixImpactRecorder::gather(std::vector<double> &local, int ncol, int ntotal) {
  std::vector<double> all;
  if (comm->nprocs == 1) {
    all.swap(local);
    return all;
  }
  const int nsend = static_cast<int>(local.size());
  std::vector<int> counts(comm->nprocs), displs(comm->nprocs);
  MPI_Gather(&nsend, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, world);
  if (comm->me == 0) {
    for (int p = 1; p < comm->nprocs; ++p) displs[p] = displs[p - 1] + counts[p - 1];
    all.resize(static_cast<size_t>(ntotal) * ncol);
  }
  MPI_Gatherv(local.data(), nsend, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE,
              0, world);
  local.clear();
  return all;
}

// Gathers this step's onsets and ends to rank 0, appends them to the CSVs and
// updates the cached counts (one reduction a step).
void FixImpactRecorder::flush_events() {
  const int nlocal[2] = {static_cast<int>(events_.size() / NCOL),
                         static_cast<int>(ends_.size() / NEND)};
  int ntotal[2] = {0, 0};
  MPI_Allreduce(nlocal, ntotal, 2, MPI_INT, MPI_SUM, world);
  if (ntotal[1] > 0) {
    const std::vector<double> all = gather(ends_, NEND, ntotal[1]);
    if (comm->me == 0) {
      for (size_t e = 0; e + NEND <= all.size(); e += NEND) {
        const double *r = &all[e];
        fprintf(ends_file_, "%.9g,%.0f,%s", r[E_TIME], r[E_TAG],
                surfaces_[static_cast<int>(r[E_SURFACE])].name.c_str());
        for (int k = E_START; k < NEND; ++k) fprintf(ends_file_, ",%.9g", r[k]);
        fputc('\n', ends_file_);
      }
      fflush(ends_file_);
    }
  }
  if (ntotal[0] == 0) return;
  const std::vector<double> all = gather(events_, NCOL, ntotal[0]);
  if (comm->me == 0) {
    for (size_t e = 0; e + NCOL <= all.size(); e += NCOL) {
      const double *r = &all[e];
      const int is = static_cast<int>(r[SURFACE]);
      fprintf(file_, "%.9g,%.0f,%s", r[TIME], r[TAG], surfaces_[is].name.c_str());
      for (int k = X; k < NCOL; ++k) fprintf(file_, ",%.9g", r[k]);
      fputc('\n', file_);
      counts_[0] += 1.0;
      counts_[1 + is] += 1.0;
    }
    fflush(file_);
  }
  MPI_Bcast(counts_.data(), static_cast<int>(counts_.size()), MPI_DOUBLE, 0, world);
}

// 1: impacts recorded so far, 1 + s: impacts on surface s (in keyword order),
// then the share of particle-surface tests since the fix was made that the
// mesh neighbour lists spared (all ranks; 0 before the first test).
double FixImpactRecorder::compute_vector(int n) {
  if (n == size_vector - 1) {
    double all[2] = {0.0, 0.0};
    MPI_Allreduce(tests_, all, 2, MPI_DOUBLE, MPI_SUM, world);
    return all[0] + all[1] > 0.0 ? all[1] / (all[0] + all[1]) : 0.0;
  }
  return n >= 0 && n < static_cast<int>(counts_.size()) ? counts_[n] : 0.0;
}

// Per-atom contact bits and onset times, then (with `pending`) the pending
// flag: grow, copy, set, pack and unpack list the same columns in the same
// order.
void FixImpactRecorder::grow_arrays(int nmax) {
  memory->grow(state_, nmax, ncols_, "impact/recorder:state");
  if (pending_from_ >= 0) {
    memory->grow(pending_, nmax, "impact/recorder:pending");
    vector_atom = pending_;
  }
  for (int i = nmax_; i < nmax; ++i) set_arrays(i);
  nmax_ = nmax;
}

void FixImpactRecorder::copy_arrays(int i, int j, int /*delflag*/) {
  for (int k = 0; k < ncols_; ++k) state_[j][k] = state_[i][k];
  if (pending_) pending_[j] = pending_[i];
}

// A new atom starts without contacts, not pending.
void FixImpactRecorder::set_arrays(int i) {
  state_[i][0] = 0.0;
  for (int k = 1; k < ncols_; ++k) state_[i][k] = -1.0;
  if (pending_) pending_[i] = 0.0;
}

int FixImpactRecorder::pack_exchange(int i, double *buf) {
  for (int k = 0; k < ncols_; ++k) buf[k] = state_[i][k];
  if (!pending_) return ncols_;
  buf[ncols_] = pending_[i];
  return ncols_ + 1;
}

int FixImpactRecorder::unpack_exchange(int nlocal, double *buf) {
  for (int k = 0; k < ncols_; ++k) state_[nlocal][k] = buf[k];
  if (!pending_) return ncols_;
  pending_[nlocal] = buf[ncols_];
  return ncols_ + 1;
}

double FixImpactRecorder::memory_usage() {
  double bytes = static_cast<double>(nmax_) * (ncols_ + (pending_ ? 1 : 0)) * sizeof(double);
  for (const auto &s : surfaces_)
    bytes += (s.tri.size() + s.normal.size()) * sizeof(double) +
             (s.cell_start.size() + s.cell_tri.size()) * sizeof(int);
  return bytes;
}
