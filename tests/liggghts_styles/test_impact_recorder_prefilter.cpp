// Tests of fix impact/recorder's pre-filter (the grid of bins that lets a
// particle be tested only against the triangles near it): the same real
// liggghts-mill run with `prefilter yes` and `prefilter no` must write the
// same impact and contact-end CSVs, byte for byte.
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
std::string first_difference(const std::string &a, const std::string &b) {
  std::istringstream ia(a), ib(b);
  std::string la, lb;
  for (int line = 1;; ++line) {
    const bool ga = static_cast<bool>(std::getline(ia, la));
    const bool gb = static_cast<bool>(std::getline(ib, lb));
    if (!ga && !gb) return "none";
    if (!ga || !gb || la != lb)
      return "line " + std::to_string(line) + ":\n  prefilter yes: " + (ga ? la : "(end)") +
             "\n  prefilter no:  " + (gb ? lb : "(end)");
  }
}

struct Outputs {
  std::string impacts, ends;
};

// Runs `deck` (whose recorder line holds PREFILTER) with the pre-filter on and
// off on nprocs ranks; files are written to the run directories.
void run_both(const std::string &name, const std::string &deck, int nprocs,
              void (*write_inputs)(const std::string &dir), Outputs out[2]) {
  const char *value[2] = {"yes", "no"};
  for (int k = 0; k < 2; ++k) {
    const std::string dir = make_run_dir(name + "_" + value[k]);
    write_inputs(dir);
    std::string d = deck;
    d.replace(d.find("PREFILTER"), 9, value[k]);
    const auto r = run_deck(dir, d, nprocs);
    ASSERT_EQ(r.exit_code, 0) << r.screen;
    out[k].impacts = slurp(dir + "/impacts.csv");
    out[k].ends = slurp(dir + "/contact_ends.csv");
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
std::string mill_deck(int nprocs) {
  const double omega = 2000 * 2 * kPi / 60;
  std::string head = deck_head(0.65);
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
    << "timestep 2e-6\nthermo 1000\nthermo_modify lost ignore\nrun 9000\n";
  return s.str();
}

}  // namespace

// Spheres falling into the tiny mill's turning flywheel (fix move/mesh, as in
// the in-mill deck) and flung into its housing: onsets and contact ends on
// the flywheel and the housing, identical as text with and without the
// pre-filter, on one rank and on two (the triangles of owned and ghost
// elements on each rank).
TEST(ImpactRecorderPrefilter, SameRecordsInTurningMill) {
  for (int np = 1; np <= 2; ++np) {
    Outputs out[2];
    run_both("prefilter_mill" + std::to_string(np), mill_deck(np), np, write_mill, out);
    if (HasFatalFailure()) return;
    const int fw = count_rows(out[0].impacts, "flywheel"),
              hs = count_rows(out[0].impacts, "housing");
    const int ends = count_rows(out[0].ends, "flywheel") + count_rows(out[0].ends, "housing");
    std::printf("%d rank(s): %d flywheel and %d housing onsets, %d contact ends\n", np, fw, hs,
                ends);
    EXPECT_GE(fw, 20) << "too few flywheel strikes to compare";
    EXPECT_GE(hs, 10) << "too few housing impacts to compare";
    EXPECT_GE(ends, 40) << "too few contact ends to compare";
    EXPECT_TRUE(out[0].impacts == out[1].impacts)
        << np << " rank(s), impacts.csv: " << first_difference(out[0].impacts, out[1].impacts);
    EXPECT_TRUE(out[0].ends == out[1].ends)
        << np << " rank(s), contact_ends.csv: " << first_difference(out[0].ends, out[1].ends);
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
    << "timestep 1e-6\nthermo 1000\nrun 3000\n";
  Outputs out[2];
  run_both("prefilter_bins", s.str(), 1, write_square_and_strip, out);
  if (HasFatalFailure()) return;
  const int on[2] = {count_rows(out[0].impacts, "floor"), count_rows(out[1].impacts, "floor")};
  const int off[2] = {count_rows(out[0].ends, "floor"), count_rows(out[1].ends, "floor")};
  std::printf("onsets %d (yes) %d (no), ends %d (yes) %d (no), of 81 spheres\n", on[0], on[1],
              off[0], off[1]);
  EXPECT_EQ(on[1], 81);
  EXPECT_EQ(off[1], 81);
  EXPECT_EQ(on[0], 81);
  EXPECT_EQ(off[0], 81);
  EXPECT_TRUE(out[0].impacts == out[1].impacts)
      << "impacts.csv: " << first_difference(out[0].impacts, out[1].impacts);
  EXPECT_TRUE(out[0].ends == out[1].ends)
      << "contact_ends.csv: " << first_difference(out[0].ends, out[1].ends);
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
  EXPECT_NE(r.screen.find("prefilter must be yes or no, got 'maybe'"), std::string::npos)
      << r.screen;
}
