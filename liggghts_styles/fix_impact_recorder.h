// fix impact/recorder: records every contact onset between a particle and a
// wall mesh (fix mesh/surface), with the velocity relative to the struck
// surface, and optionally every contact end, with the lab velocity after the
// contact and its duration, for LIGGGHTS 3.8. See
// docs/styles/fix_impact_recorder.md.
//
// Contact is decided geometrically, with the criterion fix wall/gran uses for
// meshes: the distance from the particle centre to the nearest triangle is
// below the radius. A per-atom bit per surface remembers "in contact" so that
// only onsets are recorded, and the onset time per surface lets the end
// record name its contact; both travel with the atom between ranks. With
// `pending FROM TO` a per-atom flag is 1 while the atom's latest onset on
// FROM is later than its latest onset on TO (struck, not yet arrived).
#ifndef MILL_FIX_IMPACT_RECORDER_H
#define MILL_FIX_IMPACT_RECORDER_H

#include <array>
#include <cstdio>
#include <string>
#include <vector>

#include "fix.h"

namespace LAMMPS_NS {

class FixImpactRecorder : public Fix {
 public:
  FixImpactRecorder(class LAMMPS *lmp, int narg, char **arg);
  ~FixImpactRecorder() override;

  static const char *style_name() { return "impact/recorder"; }

  int setmask() override;
  void init() override;
  void setup(int vflag) override;
  void end_of_step() override;
  double compute_vector(int n) override;

  void grow_arrays(int nmax) override;
  void copy_arrays(int i, int j, int delflag) override;
  void set_arrays(int i) override;
  int pack_exchange(int i, double *buf) override;
  int unpack_exchange(int nlocal, double *buf) override;
  double memory_usage() override;

  // Columns of one impact record (also the CSV columns after time and id).
  enum Column {
    TIME = 0,
    TAG,
    SURFACE,
    X,
    Y,
    Z,
    CX,
    CY,
    CZ,
    NX,
    NY,
    NZ,
    VRX,
    VRY,
    VRZ,
    SPEED,
    VN,
    VT,
    ANGLE,
    WSPEED,
    VABS,
    RAXIS,
    NCOL
  };

  // Columns of one contact-end record (also the contact_ends.csv columns).
  enum EndColumn {
    E_TIME = 0,
    E_TAG,
    E_SURFACE,
    E_START,
    E_DURATION,
    E_X,
    E_Y,
    E_Z,
    E_VX,
    E_VY,
    E_VZ,
    E_SPEED,
    E_VRX,
    E_VRY,
    E_VRZ,
    E_RSPEED,
    E_VN,
    E_VT,
    E_WSPEED,
    NEND
  };

 private:
  struct Surface {
    std::string name;     // label written to the CSV ("flywheel")
    std::string mesh_id;  // ID of its fix mesh/surface
    class FixMesh *mesh = nullptr;
    bool rotating = false;
    double omega = 0.0;                     // angular speed about axis [rad/s]
    std::array<double, 3> origin{0, 0, 0};  // a point on the axis        [m]
    std::array<double, 3> axis{0, 0, 1};    // unit axis (right-hand rule)
    std::vector<double> tri;                // 9 doubles per triangle, this step
    std::vector<double> normal;             // 3 doubles per triangle (unit)
    std::array<double, 6> box{};            // bounding box of the triangles
    std::array<double, 4> bound{};  // sphere holding the surface at any angle: centre, radius
    bool loaded = false;            // tri, normal, box (and grid) are this step's
    // The pre-filter: a uniform grid of bins over the triangles' boxes grown
    // by `reach`; bin b holds the triangles whose grown box meets it, in
    // ascending index order, in cell_tri[cell_start[b] .. cell_start[b + 1]).
    std::array<double, 3> grid_lo{};  // corner of bin (0, 0, 0)       [m]
    std::array<int, 3> grid_n{0, 0, 0};
    double grid_h = 0.0;       // bin edge                          [m]
    double grid_reach = -1.0;  // largest radius the grid answers (< 0: no grid)
    std::vector<int> cell_start;
    std::vector<int> cell_tri;
    // The triangles the grid was built from, and how far their nodes may
    // move from there before it must be built again (its boxes were grown
    // by this slack too): a turning or static mesh keeps its grid for many
    // steps instead of rebuilding it at each.
    std::vector<double> grid_tri;
    double grid_slack = 0.0;  // [m]
  };
  std::vector<Surface> surfaces_;
  std::string file_path_;
  FILE *file_ = nullptr;                     // rank 0 only
  std::string ends_path_;                    // contact_ends CSV ("" = no end records)
  FILE *ends_file_ = nullptr;                // rank 0 only
  bool prefilter_ = true;                    // test only the triangles of the particle's bin
  bool neighfilter_ = true;                  // skip particles in no mesh neighbour list
  double tests_[2] = {0.0, 0.0};             // this rank's particle-surface tests: made, skipped
  std::string pending_names_[2];             // `pending FROM TO` ("" = none)
  int pending_from_ = -1, pending_to_ = -1;  // their surface indices
  double query_reach_ = 0.0;                 // largest query radius this step on this rank [m]

  // Cached counts (read by compute_vector): total, then one per surface.
  std::vector<double> counts_;

  // Per atom: column 0 holds bit s set while in contact with surface s;
  // column 1 + s the onset time of that contact (-1: no onset recorded, e.g.
  // already touching when the run started).
  int nmax_ = 0;
  int ncols_ = 1;
  double **state_ = nullptr;
  double *pending_ = nullptr;   // per atom, with `pending`: the flag (the per-atom output)
  std::vector<double> events_;  // this step's onsets on this rank, NCOL per event
  std::vector<double> ends_;    // this step's contact ends on this rank, NEND per event

  void parse_args(int narg, char **arg);
  void load_triangles(Surface &s);
  void set_query_reach();
  void build_grid(Surface &s);
  bool grid_holds(const Surface &s) const;
  void set_bound(Surface &s);
  Fix *mesh_neighbour_counts(const Surface &s, int *wall_groupbit) const;
  bool nearest_point(Surface &s, const double *x, double radius, double *c);
  bool grid_candidates(const Surface &s, const double *x, const int **first,
                       const int **last) const;
  void surface_velocity(const Surface &s, const double *c, double *w, double *raxis) const;
  void record(const Surface &s, int is, int i, const double *c);
  void record_end(Surface &s, int is, int i, double start);
  std::vector<double> gather(std::vector<double> &local, int ncol, int ntotal);
  void flush_events();
};

}  // namespace LAMMPS_NS

#endif
