// Tests of fix impact/recorder through real liggghts-mill runs: a throw at a
// fixed plane and a particle struck by a rotating plate, against the analytic
// relative velocity. Each test states its tolerance next to the assertion.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include "deck_runner.h"
#include "geometry/mill_geometry.h"
#include "postprocess/impact_stats.h"

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

// Time, particle and surface of a CSV row, for sorting records of two runs.
std::vector<std::map<std::string, std::string>> sorted_rows(const std::string &path,
                                                            const std::string &surface) {
  auto rows = read_csv(path);
  std::vector<std::map<std::string, std::string>> out;
  for (auto &r : rows)
    if (r["surface"] == surface) out.push_back(r);
  std::sort(out.begin(), out.end(), [](const auto &a, const auto &b) {
    const double ta = std::stod(a.at("time_s")), tb = std::stod(b.at("time_s"));
    return ta != tb ? ta < tb : std::stol(a.at("particle_id")) < std::stol(b.at("particle_id"));
  });
  return out;
}

// A plate turning at omega = 100 rad/s about the z axis (fix move/mesh, as the
// transport deck spins the flywheel) strikes a sphere at rest whose centre is
// R = 10 mm in front of it at r = 0.3 m from the axis, with the plate
// pointing straight down at contact. Relative to the plate the sphere
// approaches normally at omega r = 30 m/s; a rigid plate returns it at
// e 30 m/s relative, so in the lab it leaves at (1 + e) 30 m/s along +x
// (e = 0.5, the contact's coefficient of restitution; the plate turns 0.3 deg
// during the contact). It then flies under gravity (9.81 m/s^2 along -y) to a
// fixed wall at x = 0.45 m: the strike-to-housing chain of postprocess must
// give the flight time and the speed at the wall that ballistics predicts
// from the contact-end record. Tolerances: 5 % against the rigid-plate
// rebound, 1 % against ballistics (onsets are resolved to one 1 us step).
TEST(ImpactRecorder, RotatingPlateReboundAndStrikeToHousing) {
  const std::string dir = make_run_dir("rebound");
  const double omega = 100.0, r = 0.3, R = 0.01, e = 0.5, g = 9.81, xw = 0.45;
  const double delta = 0.1;  // the plate starts 0.1 rad before contact
  const double phi0 = -0.5 * kPi - delta;
  const double u[3] = {std::cos(phi0), std::sin(phi0), 0};
  const double p0[3] = {0.1 * u[0], 0.1 * u[1], -0.1}, e1[3] = {0.25 * u[0], 0.25 * u[1], 0},
               e2[3] = {0, 0, 0.2};  // radial extent 0.1-0.35 m: the tip (35 m/s) stays behind
  write_rect_stl(dir + "/plate.stl", p0, e1, e2);
  const double w0[3] = {xw, -0.5, 0.2}, w1[3] = {0, 1, 0}, w2[3] = {0, 0, -0.4};
  write_rect_stl(dir + "/wall.stl", w0, w1, w2);
  std::ostringstream s;
  s.precision(17);
  s << deck_head(0.6) << "fix plate all mesh/surface file plate.stl type 1\n"
    << "fix wallm all mesh/surface file wall.stl type 1\n"
    << "fix rot all move/mesh mesh plate rotate origin 0 0 0 axis 0 0 1 period " << 2 * kPi / omega
    << "\n"
    << "fix walls all wall/gran model hertz tangential history mesh n_meshes 2 meshes plate wallm\n"
    << "create_atoms 1 single " << R << " " << -r << " 0 units box\n"
    << "set group all diameter " << 2 * R << " density 2500\n"
    << "fix grav all gravity " << g << " vector 0 -1 0\n"
    << "fix integr all nve/sphere\n"
    << "fix rec all impact/recorder file impacts.csv ends contact_ends.csv surface flywheel mesh "
       "plate omega "
    << omega << " origin 0 0 0 axis 0 0 1 surface housing mesh wallm\n"
    << "timestep 1e-6\nthermo 1000\nrun 12000\n";
  const auto res = run_deck(dir, s.str());
  ASSERT_EQ(res.exit_code, 0) << res.screen;
  auto records = mill::post::ReadImpactsCsv(dir + "/impacts.csv");
  const auto ends = mill::post::ReadContactEndsCsv(dir + "/contact_ends.csv");
  ASSERT_EQ(records.size(), 2u) << res.screen;
  ASSERT_GE(ends.size(), 1u) << res.screen;
  const auto &strike = records[0];
  const auto &leave = ends[0];
  ASSERT_EQ(strike.surface, "flywheel");
  ASSERT_EQ(leave.surface, "flywheel");
  EXPECT_EQ(leave.start_time_s, strike.time_s);  // the join key
  const double wn = omega * r, lab = (1 + e) * wn;
  std::printf(
      "rotating plate rebound: relative normal speed %.5f m/s (rigid plate %.5f), lab speed after "
      "%.5f m/s (%.5f), vx %.5f, rebound normal %.5f (e wn = %.5f), contact %.1f us\n",
      strike.normal_speed_m_s, wn, leave.speed_m_s, lab, leave.velocity[0], leave.normal_speed_m_s,
      e * wn, 1e6 * leave.duration_s);
  EXPECT_NEAR(strike.normal_speed_m_s / wn, 1.0, 0.05);
  EXPECT_NEAR(strike.speed_m_s / wn, 1.0, 0.05);
  EXPECT_NEAR(strike.particle_speed_m_s, 0.0, 0.05);  // at rest in the lab before the strike
  EXPECT_NEAR(leave.speed_m_s / lab, 1.0, 0.05);
  EXPECT_NEAR(leave.velocity[0] / lab, 1.0, 0.05);
  EXPECT_NEAR(leave.normal_speed_m_s / (e * wn), 1.0, 0.05);
  EXPECT_GT(leave.duration_s, 0.0);
  EXPECT_LT(leave.duration_s, 2e-4);

  // The chain: the next housing impact after the lump left the plate.
  mill::post::MillShape shape;
  shape.axis_x = shape.axis_y = 0;
  shape.hub_radius = 0.1;
  shape.tip_radius = 0.35;
  mill::post::LabelImpacts(records, shape, 1.0);
  EXPECT_EQ(records[0].part, "plate_face");
  EXPECT_EQ(records[1].part, "side_wall");
  const auto chains = mill::post::StrikeChains(records, ends);
  ASSERT_EQ(chains.size(), 1u);
  ASSERT_EQ(chains[0].housing, 1);
  const double t_fly = (xw - R - leave.position[0]) / leave.velocity[0];
  const double vy = leave.velocity[1] - g * t_fly;
  const double v_wall = std::hypot(leave.velocity[0], vy);
  const double angle = std::atan2(leave.velocity[0], std::abs(vy)) * 180.0 / kPi;
  const auto &hit = records[1];
  std::printf(
      "strike to housing: flight %.4f ms (ballistic %.4f), speed %.4f m/s (%.4f), angle %.3f deg "
      "(%.3f)\n",
      1e3 * chains[0].flight_time_s, 1e3 * t_fly, hit.speed_m_s, v_wall, hit.angle_deg, angle);
  EXPECT_NEAR(chains[0].flight_time_s / t_fly, 1.0, 0.01);
  EXPECT_NEAR(hit.speed_m_s / v_wall, 1.0, 0.01);
  EXPECT_NEAR(hit.angle_deg / angle, 1.0, 0.01);
}

// Lumps around the real flywheel (driver/geometry, 4 plates, turning at
// 2000 rpm) on both sides of the rank boundary x = 0, placed for plate faces,
// tips, hub and caps: the flywheel's onset and contact-end records, and the
// parts they are classified into, are the same on one and two ranks (lumps
// struck across the boundary carry their contact state with them).
// Tolerance: 1e-9 relative on every number (the two runs sum the same forces).
TEST(ImpactRecorder, FlywheelRecordsSameOnOneAndTwoRanks) {
  mill::geometry::MillGeometry g;
  g.height = 1.2;
  g.width = 0.8;
  g.depth = 0.3;
  g.tip_diameter = 0.5;
  g.hub_diameter = 0.15;
  g.n_plates = 4;
  g.plate_width = 0.2;
  g.axis_height = 0.0;  // the flywheel about the z axis, inside the test box
  g.arc_segments = 24;
  const double omega = 2000 * 2 * kPi / 60;
  std::string dirs[2];
  for (int np = 1; np <= 2; ++np) {
    const std::string dir = make_run_dir("ranks" + std::to_string(np));
    dirs[np - 1] = dir;
    mill::geometry::write_stl(dir + "/flywheel.stl", "flywheel",
                              mill::geometry::flywheel_surface(g));
    std::ostringstream s;
    s.precision(17);
    std::string head = deck_head(0.6);
    if (np == 2) head.insert(head.find("region box"), "processors 2 1 1\n");
    s << head << "fix fw all mesh/surface file flywheel.stl type 1\n"
      << "fix rot all move/mesh mesh fw rotate origin 0 0 0 axis 0 0 1 period " << 2 * kPi / omega
      << "\n"
      << "fix walls all wall/gran model hertz tangential history mesh n_meshes 1 meshes fw\n";
    // Lumps in the plates' path (plate faces), just outside the tips moving
    // in (tips), just outside the hub moving in (hub), and flying at the caps:
    // angle (deg), radius (m), z (m), radial and axial velocity (m/s).
    const double polar[][5] = {
        {30, 0.18, 0.0, 0, 0},  {120, 0.2, 0.05, 0, 0},   {210, 0.16, -0.05, 0, 0},
        {300, 0.22, 0.0, 0, 0}, {60, 0.2585, 0.0, 0, 0},  {240, 0.2585, 0.03, 0, 0},
        {45, 0.09, 0.0, -5, 0}, {10, 0.03, 0.12, 0, -12}, {190, 0.03, -0.12, 0, 12}};
    std::vector<std::array<double, 6>> lumps;  // x y z vx vy vz
    for (const auto &l : polar) {
      const double a = l[0] * kPi / 180, c = std::cos(a), sn = std::sin(a);
      lumps.push_back({l[1] * c, l[1] * sn, l[2], l[3] * c, l[3] * sn, l[4]});
    }
    // One more at a cap, crossing the rank boundary x = 0 while in contact.
    lumps.push_back({0.0085, 0.03, 0.12, -10, 0, -12});
    for (const auto &l : lumps)
      s << "create_atoms 1 single " << l[0] << " " << l[1] << " " << l[2] << " units box\n";
    s << "set group all diameter 0.02 density 2500\n";
    int id = 1;
    for (const auto &l : lumps)
      s << "group one id " << id++ << "\nvelocity one set " << l[3] << " " << l[4] << " " << l[5]
        << " units box\ngroup one delete\n";
    s << "fix integr all nve/sphere\n"
      << "fix rec all impact/recorder file impacts.csv ends contact_ends.csv surface flywheel mesh "
         "fw "
         "omega "
      << omega << " origin 0 0 0 axis 0 0 1\n"
      << "timestep 2e-6\nthermo 1000\nthermo_modify lost ignore\nrun 4000\n";
    const auto res = run_deck(dir, s.str(), np);
    ASSERT_EQ(res.exit_code, 0) << res.screen;
  }
  mill::post::MillShape shape;
  shape.axis_x = 0;
  shape.axis_y = 0.0;
  shape.hub_radius = 0.075;
  shape.tip_radius = 0.25;
  std::map<std::string, int> parts;
  for (const char *file : {"/impacts.csv", "/contact_ends.csv"}) {
    const auto one = sorted_rows(dirs[0] + file, "flywheel");
    const auto two = sorted_rows(dirs[1] + file, "flywheel");
    ASSERT_EQ(one.size(), two.size()) << file;
    ASSERT_GE(one.size(), 6u) << file;
    for (size_t k = 0; k < one.size(); ++k)
      for (const auto &[col, text] : one[k]) {
        if (col == "surface") continue;
        const double a = std::stod(text), b = std::stod(two[k].at(col));
        EXPECT_NEAR(a, b, 1e-9 * std::max(1.0, std::abs(a))) << file << " row " << k << " " << col;
      }
  }
  // Lump 10 touched the cap on the x > 0 rank and left it from the x < 0 one.
  const auto ends2 = mill::post::ReadContactEndsCsv(dirs[1] + "/contact_ends.csv");
  const auto crossing =
      std::find_if(ends2.begin(), ends2.end(), [](const auto &e) { return e.particle_id == 10; });
  ASSERT_NE(crossing, ends2.end());
  std::printf("lump 10: contact from %.6f s to %.6f s, leaving at x = %.5f m\n",
              crossing->start_time_s, crossing->time_s, crossing->position[0]);
  EXPECT_LT(crossing->position[0], 0.0);
  const auto rec2_all = mill::post::ReadImpactsCsv(dirs[1] + "/impacts.csv");
  const auto onset = std::find_if(rec2_all.begin(), rec2_all.end(),
                                  [](const auto &r) { return r.particle_id == 10; });
  ASSERT_NE(onset, rec2_all.end());
  EXPECT_GT(onset->position[0], 0.0);
  EXPECT_EQ(onset->time_s, crossing->start_time_s);
  auto rec1 = mill::post::ReadImpactsCsv(dirs[0] + "/impacts.csv");
  auto rec2 = mill::post::ReadImpactsCsv(dirs[1] + "/impacts.csv");
  mill::post::LabelImpacts(rec1, shape, 1.0);
  mill::post::LabelImpacts(rec2, shape, 1.0);
  auto key = [](const mill::post::ImpactRecord &r) {
    return std::to_string(r.time_s) + "/" + std::to_string(r.particle_id) + "/" + r.part;
  };
  std::vector<std::string> k1, k2;
  for (const auto &r : rec1) {
    k1.push_back(key(r));
    ++parts[r.part];
  }
  for (const auto &r : rec2) k2.push_back(key(r));
  std::sort(k1.begin(), k1.end());
  std::sort(k2.begin(), k2.end());
  EXPECT_EQ(k1, k2);
  std::string seen;
  for (const auto &[p, n] : parts) seen += p + " " + std::to_string(n) + ", ";
  std::printf("one and two ranks: %zu flywheel records, parts: %s\n", rec1.size(), seen.c_str());
  for (const char *p : {"plate_face", "plate_tip", "hub", "side_cap"})
    EXPECT_GT(parts[p], 0) << p << ": " << seen;
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

// `pending floor wall`: a sphere thrown down at a floor (y = 0) bounces off
// it and flies on to a wall (x = 0.05 m). The per-atom flag, summed by a
// compute, is 0 before the floor strike, 1 between the strike and the wall
// impact, and 0 after it; on two ranks (split at x = 0) the sphere crosses
// to rank 1 after the strike, so the flag must travel with it.
TEST(ImpactRecorder, PendingFromStrikeToWall) {
  for (int np = 1; np <= 2; ++np) {
    const std::string dir = make_run_dir("pending" + std::to_string(np));
    const double f0[3] = {-0.5, 0, 0.5}, f1[3] = {1, 0, 0}, f2[3] = {0, 0, -1};
    write_rect_stl(dir + "/floor.stl", f0, f1, f2);
    const double w0[3] = {0.05, -0.5, 0.5}, w1[3] = {0, 1, 0}, w2[3] = {0, 0, -1};
    write_rect_stl(dir + "/wall.stl", w0, w1, w2);
    std::string head = deck_head(0.6);
    if (np == 2) head.insert(head.find("region box"), "processors 2 1 1\n");
    std::ostringstream s;
    s.precision(17);
    s << head << "fix floor all mesh/surface file floor.stl type 1\n"
      << "fix wall all mesh/surface file wall.stl type 1\n"
      << "fix walls all wall/gran model hertz tangential history mesh n_meshes 2 meshes floor "
         "wall\n"
      << "create_atoms 1 single -0.008 0.012 0 units box\n"
      << "set group all diameter 0.02 density 2500\n"
      << "velocity all set 10 -3 0 units box\n"
      << "fix integr all nve/sphere\n"
      << "fix rec all impact/recorder file impacts.csv pending floor wall surface floor mesh "
         "floor surface wall mesh wall\n"
      << "variable p atom f_rec\ncompute np all reduce sum v_p\n"
      << "variable np_now equal c_np\nvariable x1 equal x[1]\n"
      << "thermo_style custom step c_np f_rec[2] f_rec[3]\n"
      << "timestep 1e-6\nthermo 1000\n"
      << "run 500\nprint \"pending: ${np_now} before\"\n"
      << "run 1000\nprint \"pending: ${np_now} between, x ${x1}\"\n"
      << "run 8000\nprint \"pending: ${np_now} after\"\n";
    const auto r = run_deck(dir, s.str(), np);
    ASSERT_EQ(r.exit_code, 0) << r.screen;
    for (const char *want : {"pending: 0 before", "pending: 1 between, x 0.0", "pending: 0 after"})
      EXPECT_NE(r.screen.find(want), std::string::npos) << np << " rank(s): " << want << "\n"
                                                        << r.screen;
  }
}

// `pending` must name two of the fix's surfaces.
TEST(ImpactRecorder, PendingUnknownSurfaceIsNamed) {
  const std::string dir = make_run_dir("pendingerr");
  const double p0[3] = {-0.05, 0, 0.05}, e1[3] = {0.1, 0, 0}, e2[3] = {0, 0, -0.1};
  write_rect_stl(dir + "/plane.stl", p0, e1, e2);
  const auto r = run_deck(
      dir, deck_head(0.1) + "fix plane all mesh/surface file plane.stl type 1\n" +
               "fix rec all impact/recorder file impacts.csv pending beater floor surface floor "
               "mesh plane\nrun 0\n");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.screen.find("pending: no surface named 'beater' (the surfaces: floor)"),
            std::string::npos)
      << r.screen;
}
