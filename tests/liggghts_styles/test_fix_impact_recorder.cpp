// Tests of fix impact/recorder through real liggghts-mill runs: a throw at a
// fixed plane and a particle struck by a rotating plate, against the analytic
// relative velocity. Each test states its tolerance next to the assertion.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include "deck_runner.h"

using namespace mill_test;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Rows of the recorder CSV as column name -> text.
std::vector<std::map<std::string, std::string>> read_csv(const std::string &path) {
  std::vector<std::map<std::string, std::string>> rows;
  std::ifstream in(path);
  std::string line;
  std::vector<std::string> head;
  auto split = [](const std::string &l) {
    std::vector<std::string> out;
    std::stringstream ss(l);
    std::string c;
    while (std::getline(ss, c, ',')) out.push_back(c);
    return out;
  };
  if (std::getline(in, line)) head = split(line);
  while (std::getline(in, line)) {
    const auto cells = split(line);
    std::map<std::string, std::string> r;
    for (size_t i = 0; i < cells.size() && i < head.size(); ++i) r[head[i]] = cells[i];
    rows.push_back(r);
  }
  return rows;
}

double num(const std::map<std::string, std::string> &r, const std::string &k) {
  const auto it = r.find(k);
  return it == r.end() ? NAN : std::stod(it->second);
}

// Writes a rectangle (two triangles) spanned by corner p0 and edges e1, e2.
void write_rect_stl(const std::string &path, const double *p0, const double *e1, const double *e2) {
  std::ofstream o(path);
  o.precision(17);
  double p[4][3];
  for (int k = 0; k < 3; ++k) {
    p[0][k] = p0[k];
    p[1][k] = p0[k] + e1[k];
    p[2][k] = p0[k] + e1[k] + e2[k];
    p[3][k] = p0[k] + e2[k];
  }
  const int tri[2][3] = {{0, 1, 2}, {0, 2, 3}};
  o << "solid rect\n";
  for (const auto &t : tri) {
    o << "facet normal 0 0 0\nouter loop\n";
    for (int v : t) o << "vertex " << p[v][0] << " " << p[v][1] << " " << p[v][2] << "\n";
    o << "endloop\nendfacet\n";
  }
  o << "endsolid rect\n";
}

}  // namespace

// A sphere thrown at 10 m/s, 30 deg to a fixed plane y = 0: one record with
// speed 10 m/s, angle 30 deg, normal 5 m/s, tangential 8.66 m/s. Tolerance 1 %.
TEST(ImpactRecorder, FixedPlaneSpeedAndAngle) {
  const std::string dir = make_run_dir("plane");
  const double p0[3] = {-0.5, 0, 0.5}, e1[3] = {1, 0, 0}, e2[3] = {0, 0, -1};
  write_rect_stl(dir + "/plane.stl", p0, e1, e2);
  const double v = 10.0, angle = 30.0, a = angle * kPi / 180.0;
  std::ostringstream s;
  s.precision(17);
  s << deck_head(0.6) << "fix plane all mesh/surface file plane.stl type 1\n"
    << "fix wall all wall/gran model hertz tangential history mesh n_meshes 1 meshes plane\n"
    << "create_atoms 1 single 0 0.012 0 units box\n"
    << "set group all diameter 0.02 density 2500\n"
    << "velocity all set " << v * std::cos(a) << " " << -v * std::sin(a) << " 0 units box\n"
    << "fix integr all nve/sphere\n"
    << "fix rec all impact/recorder file impacts.csv surface floor mesh plane\n"
    << "timestep 1e-6\nthermo 500\nrun 3000\n";
  const auto r = run_deck(dir, s.str());
  ASSERT_EQ(r.exit_code, 0) << r.screen;
  const auto rows = read_csv(dir + "/impacts.csv");
  ASSERT_EQ(rows.size(), 1u) << r.screen;
  const auto &e = rows[0];
  EXPECT_EQ(e.at("surface"), "floor");
  std::printf(
      "fixed plane: speed %.5f m/s (10), angle %.4f deg (30), normal %.5f (5), tangential %.5f "
      "(8.660)\n",
      num(e, "speed_m_s"), num(e, "angle_deg"), num(e, "normal_speed_m_s"),
      num(e, "tangential_speed_m_s"));
  EXPECT_NEAR(num(e, "speed_m_s") / v, 1.0, 0.01);
  EXPECT_NEAR(num(e, "angle_deg") / angle, 1.0, 0.01);
  EXPECT_NEAR(num(e, "normal_speed_m_s") / (v * std::sin(a)), 1.0, 0.01);
  EXPECT_NEAR(num(e, "tangential_speed_m_s") / (v * std::cos(a)), 1.0, 0.01);
  EXPECT_NEAR(num(e, "normal_y"), 1.0, 1e-6);
  EXPECT_NEAR(num(e, "surface_speed_m_s"), 0.0, 1e-12);
}

// A plate in the plane through the z axis, spinning at omega = 100 rad/s,
// sweeps into a sphere moving at 2 m/s along z, centre at r_p = 0.3 m. The
// contact point is the foot of the perpendicular, at r_c = sqrt(r_p^2 - R^2)
// from the axis; relative to the plate the sphere approaches normally at
// omega r_c and slides at 2 m/s. Tolerance 1 %.
TEST(ImpactRecorder, RotatingPlateSurfaceVelocitySubtracted) {
  const std::string dir = make_run_dir("rotplate");
  const double p0[3] = {0, 0.1, -0.1}, e1[3] = {0, 0.4, 0}, e2[3] = {0, 0, 0.2};
  write_rect_stl(dir + "/plate.stl", p0, e1, e2);
  const double omega = 100.0, rp = 0.3, R = 0.01, vz = 2.0;
  const double phi = 100.0 * kPi / 180.0;  // plate starts at 90 deg, turns towards 180 deg
  std::ostringstream s;
  s.precision(17);
  s << deck_head(0.6) << "fix plate all mesh/surface file plate.stl type 1\n"
    << "fix rot all move/mesh mesh plate rotate origin 0 0 0 axis 0 0 1 period " << 2 * kPi / omega
    << "\n"
    << "fix wall all wall/gran model hertz tangential history mesh n_meshes 1 meshes plate\n"
    << "create_atoms 1 single " << rp * std::cos(phi) << " " << rp * std::sin(phi)
    << " 0 units box\n"
    << "set group all diameter " << 2 * R << " density 2500\n"
    << "velocity all set 0 0 " << vz << " units box\n"
    << "fix integr all nve/sphere\n"
    << "fix rec all impact/recorder file impacts.csv surface beater mesh plate omega " << omega
    << " origin 0 0 0 axis 0 0 1\n"
    << "timestep 1e-6\nthermo 500\nrun 3000\n";
  const auto r = run_deck(dir, s.str());
  ASSERT_EQ(r.exit_code, 0) << r.screen;
  const auto rows = read_csv(dir + "/impacts.csv");
  ASSERT_GE(rows.size(), 1u) << r.screen;
  const auto &e = rows[0];
  const double rc = std::sqrt(rp * rp - R * R), wn = omega * rc;
  const double speed = std::hypot(wn, vz), angle = std::atan2(wn, vz) * 180.0 / kPi;
  std::printf(
      "rotating plate: speed %.5f (%.5f) m/s, normal %.5f (%.5f), tangential %.5f (%.5f), angle "
      "%.4f "
      "(%.4f) deg, surface %.5f m/s, lab speed %.5f m/s\n",
      num(e, "speed_m_s"), speed, num(e, "normal_speed_m_s"), wn, num(e, "tangential_speed_m_s"),
      vz, num(e, "angle_deg"), angle, num(e, "surface_speed_m_s"), num(e, "particle_speed_m_s"));
  EXPECT_NEAR(num(e, "speed_m_s") / speed, 1.0, 0.01);
  EXPECT_NEAR(num(e, "normal_speed_m_s") / wn, 1.0, 0.01);
  EXPECT_NEAR(num(e, "tangential_speed_m_s") / vz, 1.0, 0.01);
  EXPECT_NEAR(num(e, "angle_deg") / angle, 1.0, 0.01);
  EXPECT_NEAR(num(e, "axis_distance_m") / rc, 1.0, 0.01);
  EXPECT_NEAR(num(e, "particle_speed_m_s"), vz, 0.01 * vz);  // the lab-frame speed is only 2 m/s
}

// Two ranks (box split at x = 0): the sphere crosses from rank 0 to rank 1
// before it hits the plane, so its contact bits travel with it; exactly one
// record, gathered to rank 0, with speed sqrt(10^2 + 3^2). Tolerance 1 %.
TEST(ImpactRecorder, TwoRanksOneRecordAfterMigration) {
  const std::string dir = make_run_dir("plane2");
  const double p0[3] = {-0.5, 0, 0.5}, e1[3] = {1, 0, 0}, e2[3] = {0, 0, -1};
  write_rect_stl(dir + "/plane.stl", p0, e1, e2);
  std::ostringstream s;
  s.precision(17);
  std::string head = deck_head(0.6);
  head.insert(head.find("region box"), "processors 2 1 1\n");
  s << head << "fix plane all mesh/surface file plane.stl type 1\n"
    << "fix wall all wall/gran model hertz tangential history mesh n_meshes 1 meshes plane\n"
    << "create_atoms 1 single -0.05 0.05 0 units box\n"
    << "set group all diameter 0.02 density 2500\n"
    << "velocity all set 10 -3 0 units box\n"
    << "fix integr all nve/sphere\n"
    << "fix rec all impact/recorder file impacts.csv surface floor mesh plane\n"
    << "timestep 1e-5\nthermo 500\nrun 1600\n";
  const auto r = run_deck(dir, s.str(), 2);
  ASSERT_EQ(r.exit_code, 0) << r.screen;
  const auto rows = read_csv(dir + "/impacts.csv");
  ASSERT_EQ(rows.size(), 1u) << r.screen;
  EXPECT_GT(num(rows[0], "x_m"), 0.0);  // hit on rank 1's side
  std::printf("two ranks: speed %.5f m/s (%.5f), angle %.4f deg (%.4f)\n",
              num(rows[0], "speed_m_s"), std::sqrt(109.0), num(rows[0], "angle_deg"),
              std::atan2(3.0, 10.0) * 180.0 / kPi);
  EXPECT_NEAR(num(rows[0], "speed_m_s") / std::sqrt(109.0), 1.0, 0.01);
  EXPECT_NEAR(num(rows[0], "angle_deg") / (std::atan2(3.0, 10.0) * 180.0 / kPi), 1.0, 0.01);
}

// A user error names the keyword.
TEST(ImpactRecorder, MissingFileIsNamed) {
  const std::string dir = make_run_dir("recerr");
  const double p0[3] = {-0.05, 0, 0.05}, e1[3] = {0.1, 0, 0}, e2[3] = {0, 0, -0.1};
  write_rect_stl(dir + "/plane.stl", p0, e1, e2);
  const auto r =
      run_deck(dir, deck_head(0.1) + "fix plane all mesh/surface file plane.stl type 1\n" +
                        "fix rec all impact/recorder surface floor mesh plane\nrun 0\n");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.screen.find("'file'"), std::string::npos) << r.screen;
}
