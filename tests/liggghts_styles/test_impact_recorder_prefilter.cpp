// Tests of fix impact/recorder's pre-filters (the mesh neighbour lists that
// spare particles far from a surface, and the grid of bins that lets a
// particle be tested only against the triangles near it): the same real
// liggghts-mill run with `prefilter yes` (both), `grid` (the grid only) and
// `no` (every triangle) must write the same impact and contact-end CSVs, byte
// for byte.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "deck_runner.h"
#include "geometry/mill_geometry.h"

using namespace mill_test;

namespace {

constexpr double kPi = 3.14159265358979323846;

// The whole text of a file ("" if it cannot be read).
std::string slurp(const std::string &path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Rows of a recorder CSV (after the header) whose surface column is `surface`.
int count_rows(const std::string &text, const std::string &surface) {
  std::istringstream in(text);
  std::string line;
  int n = 0;
  std::getline(in, line);
  while (std::getline(in, line)) {
    const size_t a = line.find(',');
    const size_t b = line.find(',', a + 1);
    if (a != std::string::npos && b != std::string::npos &&
        line.substr(b + 1).rfind(surface, 0) == 0)
      ++n;
  }
  return n;
}

// The first line where two texts differ, for the failure message.
std::string first_difference(const std::string &a, const std::string &b, const std::string &name_a,
                             const std::string &name_b) {
  std::istringstream ia(a), ib(b);
  std::string la, lb;
  for (int line = 1;; ++line) {
    const bool ga = static_cast<bool>(std::getline(ia, la));
    const bool gb = static_cast<bool>(std::getline(ib, lb));
    if (!ga && !gb) return "none";
    if (!ga || !gb || la != lb)
      return "line " + std::to_string(line) + ":\n  prefilter " + name_a + ": " +
             (ga ? la : "(end)") + "\n  prefilter " + name_b + ": " + (gb ? lb : "(end)");
  }
}

constexpr int kModes = 3;
const char *const kMode[kModes] = {"yes", "grid", "no"};

struct Outputs {
  std::string impacts, ends;
  double spared = -1.0;  // the recorder's last output: share of tests the lists spared
};

// Runs `deck` (whose recorder line holds PREFILTER, and which ends by printing
// "spared <f_rec's last element>") with each pre-filter on nprocs ranks;
// files are written to the run directories.
void run_modes(const std::string &name, const std::string &deck, int nprocs,
               void (*write_inputs)(const std::string &dir), Outputs out[kModes]) {
  for (int k = 0; k < kModes; ++k) {
    const std::string dir = make_run_dir(name + "_" + kMode[k]);
    write_inputs(dir);
    std::string d = deck;
    d.replace(d.find("PREFILTER"), 9, kMode[k]);
    const auto r = run_deck(dir, d, nprocs);
    ASSERT_EQ(r.exit_code, 0) << r.screen;
    out[k].impacts = slurp(dir + "/impacts.csv");
    out[k].ends = slurp(dir + "/contact_ends.csv");
    const size_t at = r.screen.rfind("spared ");
    ASSERT_NE(at, std::string::npos) << r.screen;
    out[k].spared = std::stod(r.screen.substr(at + 7));
  }
}

// Every mode's CSVs equal those of `prefilter no` (the last).
void expect_same_records(const Outputs out[kModes], const std::string &what) {
  for (int k = 0; k + 1 < kModes; ++k) {
    EXPECT_TRUE(out[k].impacts == out[kModes - 1].impacts)
        << what << ", impacts.csv: "
        << first_difference(out[k].impacts, out[kModes - 1].impacts, kMode[k], "no");
    EXPECT_TRUE(out[k].ends == out[kModes - 1].ends)
        << what << ", contact_ends.csv: "
        << first_difference(out[k].ends, out[kModes - 1].ends, kMode[k], "no");
  }
}

// The tiny mill of tests/data/tiny_in_mill.yaml (1.2 m housing, 0.5 m
// flywheel of 4 plates at 2000 rpm, hub of 24 facets).
mill::geometry::MillGeometry tiny_mill() {
  mill::geometry::MillGeometry g;
  g.height = 1.2;
  g.width = 0.8;
  g.depth = 0.3;
  g.tip_diameter = 0.5;
  g.hub_diameter = 0.15;
  g.n_plates = 4;
  g.plate_width = 0.2;
  g.plate_thickness = 0.02;
  g.axis_height = 0.45;
  g.arc_segments = 24;
  return g;
}

void write_mill(const std::string &dir) {
  const auto g = tiny_mill();
  mill::geometry::write_stl(dir + "/flywheel.stl", "flywheel", mill::geometry::flywheel_surface(g));
  mill::geometry::write_stl(dir + "/housing.stl", "housing", mill::geometry::housing_surface(g));
}

// A cloud of spheres falling into the turning flywheel of the tiny mill and
// flung into its housing.
std::string mill_deck(int nprocs, const std::string &boundary) {
  const double omega = 2000 * 2 * kPi / 60;
  std::string head = deck_head(0.65, 5e9, boundary);
  const size_t r0 = head.find("region box"), r1 = head.find('\n', r0);
  head.replace(r0, r1 - r0, "region box block -0.45 0.45 -0.05 1.25 -0.2 0.2 units box");
  if (nprocs == 2) head.insert(head.find("region box"), "processors 2 1 1\n");
  std::ostringstream s;
  s.precision(17);
  s << head << "neigh_modify delay 0 binsize 0.02\n"
    << "fix fw all mesh/surface file flywheel.stl type 1\n"
    << "fix hs all mesh/surface file housing.stl type 1\n"
    << "fix rot all move/mesh mesh fw rotate origin 0 0.45 0 axis 0 0 1 period " << 2 * kPi / omega
    << "\n"
    << "fix walls all wall/gran model hertz tangential history mesh n_meshes 2 meshes fw hs\n";
  // 7 x 2 x 2 spheres just above the tips, falling at 8 m/s, and 8 in the
  // plates' path (radius 0.15-0.22 m), at rest.
  for (int i = 0; i < 7; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k)
        s << "create_atoms 1 single " << -0.15 + 0.05 * i << " " << 0.72 + 0.03 * j << " "
          << -0.05 + 0.1 * k << " units box\n";
  for (int a = 0; a < 8; ++a) {
    const double phi = (22.5 + 45 * a) * kPi / 180, r = 0.15 + 0.01 * a;
    s << "create_atoms 1 single " << r * std::cos(phi) << " " << 0.45 + r * std::sin(phi) << " "
      << 0.09 * ((a % 3) - 1) << " units box\n";
  }
  s << "set group all diameter 0.01 density 2500\n"
    << "group falling id <= 28\nvelocity falling set 0 -8 0 units box\n"
    << "fix grav all gravity 9.81 vector 0 -1 0\n"
    << "fix integr all nve/sphere\n"
    << "fix rec all impact/recorder file impacts.csv ends contact_ends.csv prefilter PREFILTER "
    << "surface flywheel mesh fw omega " << omega << " origin 0 0.45 0 axis 0 0 1 "
    << "surface housing mesh hs\n"
    << "timestep 2e-6\nthermo 1000\nthermo_modify lost ignore\nrun 9000\n"
    << "variable spared equal f_rec[4]\nprint \"spared ${spared}\"\n";
  return s.str();
}

}  // namespace

// Spheres falling into the tiny mill's turning flywheel (fix move/mesh, as in
// the in-mill deck) and flung into its housing: onsets and contact ends on
// the flywheel and the housing, identical as text with each pre-filter, on
// one rank and on two (the triangles of owned and ghost elements on each
// rank), in a fixed box (the housing's neighbour lists from precomputed bins,
// half the skin) and a shrink-wrapped one as the in-mill deck's (every
// triangle's box of bins, the whole skin). The neighbour lists must spare
// most tests, or the comparison says nothing about them.
TEST(ImpactRecorderPrefilter, SameRecordsInTurningMill) {
  const struct {
    int np;
    const char *boundary;
  } runs[] = {{1, "f f f"}, {2, "f f f"}, {1, "m m m"}};
  for (const auto &run : runs) {
    const std::string what = std::to_string(run.np) + " rank(s), boundary " + run.boundary;
    Outputs out[kModes];
    run_modes("prefilter_mill" + std::to_string(run.np) + run.boundary[0],
              mill_deck(run.np, run.boundary), run.np, write_mill, out);
    if (HasFatalFailure()) return;
    const int fw = count_rows(out[0].impacts, "flywheel"),
              hs = count_rows(out[0].impacts, "housing");
    const int ends = count_rows(out[0].ends, "flywheel") + count_rows(out[0].ends, "housing");
    std::printf("%s: %d flywheel and %d housing onsets, %d contact ends; the lists spared %.3f\n",
                what.c_str(), fw, hs, ends, out[0].spared);
    EXPECT_GE(fw, 20) << what << ": too few flywheel strikes to compare";
    EXPECT_GE(hs, 10) << what << ": too few housing impacts to compare";
    EXPECT_GE(ends, 40) << what << ": too few contact ends to compare";
    EXPECT_GT(out[0].spared, 0.5) << what;
    EXPECT_EQ(out[1].spared, 0.0) << what << ": prefilter grid uses no lists";
    EXPECT_EQ(out[2].spared, 0.0) << what << ": prefilter no uses no lists";
    expect_same_records(out, what);
  }
}

namespace {

// A 1 m x 1 m square in the plane y = 0 (two triangles) beside a strip of
// 400 small triangles (z from 0.5 to 0.6 m): the grid gets bins sized for the
// small triangles (about 4 per triangle, some 5 cm), so each large triangle
// spans hundreds of bins.
void write_square_and_strip(const std::string &dir) {
  std::ofstream o(dir + "/plane.stl");
  o.precision(17);
  auto facet = [&o](const double *a, const double *b, const double *c) {
    o << "facet normal 0 0 0\nouter loop\n";
    for (const double *p : {a, b, c}) o << "vertex " << p[0] << " " << p[1] << " " << p[2] << "\n";
    o << "endloop\nendfacet\n";
  };
  o << "solid plane\n";
  const double p0[3] = {-0.5, 0, 0.5}, p1[3] = {0.5, 0, 0.5}, p2[3] = {0.5, 0, -0.5},
               p3[3] = {-0.5, 0, -0.5};
  facet(p0, p1, p2);
  facet(p0, p2, p3);
  for (int i = 0; i < 200; ++i) {
    const double x0 = -0.5 + 0.005 * i, x1 = x0 + 0.005;
    const double a[3] = {x0, 0, 0.6}, b[3] = {x1, 0, 0.6}, c[3] = {x1, 0, 0.5}, d[3] = {x0, 0, 0.5};
    facet(a, b, c);
    facet(a, c, d);
  }
  o << "endsolid plane\n";
}

}  // namespace

// 81 spheres (a 9 x 9 lattice over the whole square, 2 cm from its edges)
// fall onto the two large triangles, which each span hundreds of bins:
// every sphere touches once, rebounds and leaves, and both runs write the
// same 81 onsets and 81 ends. A bin left out of a large triangle's list
// (its first or last along any axis included) loses the spheres over it.
TEST(ImpactRecorderPrefilter, TriangleOverManyBins) {
  std::ostringstream s;
  s.precision(17);
  s << deck_head(0.7) << "fix plane all mesh/surface file plane.stl type 1\n"
    << "fix wall all wall/gran model hertz tangential history mesh n_meshes 1 meshes plane\n";
  for (int i = 0; i < 9; ++i)
    for (int k = 0; k < 9; ++k)
      s << "create_atoms 1 single " << -0.48 + 0.12 * i << " 0.011 " << -0.48 + 0.12 * k
        << " units box\n";
  s << "set group all diameter 0.02 density 2500\n"
    << "velocity all set 0.3 -2 0.1 units box\n"
    << "fix integr all nve/sphere\n"
    << "fix rec all impact/recorder file impacts.csv ends contact_ends.csv prefilter PREFILTER "
       "surface floor mesh plane\n"
    << "timestep 1e-6\nthermo 1000\nrun 3000\n"
    << "variable spared equal f_rec[3]\nprint \"spared ${spared}\"\n";
  Outputs out[kModes];
  run_modes("prefilter_bins", s.str(), 1, write_square_and_strip, out);
  if (HasFatalFailure()) return;
  for (int k = 0; k < kModes; ++k) {
    std::printf("prefilter %s: onsets %d, ends %d of 81 spheres\n", kMode[k],
                count_rows(out[k].impacts, "floor"), count_rows(out[k].ends, "floor"));
    EXPECT_EQ(count_rows(out[k].impacts, "floor"), 81) << kMode[k];
    EXPECT_EQ(count_rows(out[k].ends, "floor"), 81) << kMode[k];
  }
  expect_same_records(out, "square and strip");
}

// A wrong value of the keyword is named with what it accepts.
TEST(ImpactRecorderPrefilter, BadValueIsNamed) {
  const std::string dir = make_run_dir("prefilter_err");
  write_square_and_strip(dir);
  const auto r = run_deck(
      dir, deck_head(0.7) + "fix plane all mesh/surface file plane.stl type 1\n" +
               "fix rec all impact/recorder file impacts.csv prefilter maybe surface floor mesh "
               "plane\nrun 0\n");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.screen.find("prefilter must be yes, grid or no, got 'maybe'"), std::string::npos)
      << r.screen;
}
