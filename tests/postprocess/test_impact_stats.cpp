// Tests of postprocess/impact_stats: the impact CSV and trajectory readers,
// the statistics on hand-made impact lists; and of postprocess/transport_h5:
// transport.h5 units.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "postprocess/flow_field_io.h"
#include "postprocess/fragments.h"
#include "postprocess/impact_stats.h"
#include "postprocess/transport_h5.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using namespace mill::post;

namespace {

const char* kHeader =
    "time_s,particle_id,surface,x_m,y_m,z_m,contact_x_m,contact_y_m,contact_z_m,normal_x,normal_y,"
    "normal_z,"
    "vrel_x_m_s,vrel_y_m_s,vrel_z_m_s,speed_m_s,normal_speed_m_s,tangential_speed_m_s,angle_deg,"
    "surface_speed_m_s,particle_speed_m_s,axis_distance_m\n";

// A file holding `text`, removed when the test passes.
mill::test::TempPath temp_file(const std::string& name, const std::string& text) {
  mill::test::TempPath p(name + "_" + std::to_string(getpid()));
  std::ofstream(p.path()) << text;
  return p;
}

ImpactRecord rec(long long id, const std::string& surface, double t, double speed, double vn,
                 double angle) {
  ImpactRecord r;
  r.particle_id = id;
  r.surface = surface;
  r.time_s = t;
  r.speed_m_s = speed;
  r.normal_speed_m_s = vn;
  r.tangential_speed_m_s = std::sqrt(std::max(0.0, speed * speed - vn * vn));
  r.angle_deg = angle;
  return r;
}

}  // namespace

TEST(ImpactCsv, ReadsColumnsByName) {
  const auto p = temp_file(
      "impacts.csv",
      std::string(kHeader) + "0.5,3,flywheel,1,2,3,4,5,6,0,1,0,-3,-4,0,5,4,3,53.13,100,101,0.45\n");
  const auto r = ReadImpactsCsv(p.string());
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].particle_id, 3);
  EXPECT_EQ(r[0].surface, "flywheel");
  EXPECT_DOUBLE_EQ(r[0].contact[2], 6.0);
  EXPECT_DOUBLE_EQ(r[0].relative_velocity[1], -4.0);
  EXPECT_DOUBLE_EQ(r[0].normal_speed_m_s, 4.0);
  EXPECT_DOUBLE_EQ(r[0].axis_distance_m, 0.45);
}

TEST(ImpactCsv, BadCellNamesFileLineAndColumn) {
  const auto p = temp_file(
      "bad_impacts.csv",
      std::string(kHeader) + "0.5,3,flywheel,1,2,3,4,5,6,0,1,0,-3,-4,0,fast,4,3,53,100,101,0.4\n");
  try {
    ReadImpactsCsv(p.string());
    FAIL() << "no error";
  } catch (const PostError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(":2:"), std::string::npos) << m;
    EXPECT_NE(m.find("speed_m_s"), std::string::npos) << m;
  }
}

// Hand-made impacts: means, sample standard deviation, per-particle counts,
// first-impact time since insertion.
TEST(TransportStats, MeansCountsAndFirstImpact) {
  const std::vector<double> insert = {0.0, 0.1, 0.2};
  const std::vector<ImpactRecord> r = {
      rec(1, "flywheel", 0.3, 90, 80, 60), rec(1, "housing", 0.35, 20, 10, 30),
      rec(2, "flywheel", 0.25, 110, 100, 70), rec(1, "flywheel", 0.5, 100, 90, 50)};
  const auto s = ComputeTransportStats(r, insert);
  EXPECT_EQ(s.n_particles, 3);
  const auto& f = s.surfaces.at("flywheel");
  EXPECT_EQ(f.n, 3);
  EXPECT_NEAR(f.speed.mean, 100.0, 1e-12);
  EXPECT_NEAR(f.speed.std, 10.0, 1e-12);  // sample std of 90, 110, 100
  EXPECT_NEAR(f.normal_speed.mean, 90.0, 1e-12);
  EXPECT_NEAR(f.angle.mean, 60.0, 1e-12);
  EXPECT_EQ(s.surfaces.at("housing").n, 1);
  EXPECT_EQ(s.impacts_per_particle, (std::vector<long long>{3, 1, 0}));
  EXPECT_EQ(s.flywheel_impacts_per_particle, (std::vector<long long>{2, 1, 0}));
  EXPECT_NEAR(s.impacts_per_particle_mean, 4.0 / 3.0, 1e-12);
  EXPECT_NEAR(s.first_impact_time_s[0], 0.3, 1e-12);
  EXPECT_NEAR(s.first_impact_time_s[1], 0.15, 1e-12);
  EXPECT_TRUE(std::isnan(s.first_impact_time_s[2]));
  EXPECT_NEAR(s.first_impact_time_mean_s, 0.225, 1e-12);
  EXPECT_EQ(s.particles_with_impact, 2);
}

TEST(TransportStats, EmptyListGivesZerosAndBothSurfaces) {
  const auto s = ComputeTransportStats({}, {0.0, 0.1});
  EXPECT_EQ(s.surfaces.at("flywheel").n, 0);
  EXPECT_EQ(s.surfaces.at("housing").n, 0);
  EXPECT_EQ(s.impacts_per_particle_mean, 0.0);
  EXPECT_EQ(s.first_impact_time_mean_s, 0.0);
}

TEST(TransportStats, UnknownParticleIsAnError) {
  EXPECT_THROW(ComputeTransportStats({rec(5, "flywheel", 0.1, 1, 1, 90)}, {0.0, 0.1}), PostError);
}

// Snapshots repeated at a run boundary are read once; columns by name.
TEST(TrajectoryDump, ReadsSnapshotsOnce) {
  const std::string snap =
      "ITEM: TIMESTEP\n100\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS ff ff ff\n0 1\n0 1\n0 1\n"
      "ITEM: ATOMS id x y z vx vy vz\n7 0.1 0.2 0.3 1 2 3\n";
  const std::string snap2 =
      "ITEM: TIMESTEP\n200\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS ff ff ff\n0 1\n0 1\n0 1\n"
      "ITEM: ATOMS id vx vy vz x y z\n7 4 5 6 0.4 0.5 0.6\n";
  const auto p = temp_file("traj.dump", snap + snap + snap2);
  const auto t = ReadTrajectoryDump(p.string(), 1e-3);
  ASSERT_EQ(t.time_s.size(), 2u);
  EXPECT_DOUBLE_EQ(t.time_s[1], 0.2);
  EXPECT_EQ(t.particle_id[1], 7);
  EXPECT_DOUBLE_EQ(t.position[1][2], 0.6);
  EXPECT_DOUBLE_EQ(t.velocity[1][0], 4.0);
}

TEST(TransportH5, DatasetsCarryUnits) {
  const std::vector<double> insert = {0.0};
  std::vector<ImpactRecord> r = {rec(1, "flywheel", 0.3, 90, 80, 60)};
  LabelImpacts(r, MillShape{}, 1.0);
  ContactEnd e;
  e.particle_id = 1;
  e.surface = "flywheel";
  e.start_time_s = 0.3;
  e.time_s = 0.30006;
  e.speed_m_s = 120;
  const std::vector<ContactEnd> ends = {e};
  Trajectories tr;
  tr.time_s = {0.0};
  tr.particle_id = {1};
  tr.position = {{0, 1, 0}};
  tr.velocity = {{3, 4, 0}};
  TransportMeta meta;
  meta.scalars = {{"rpm", 2000}};
  meta.units = {{"rpm", "1/min"}};
  meta.geometry = {{"tip_radius", 0.5}};
  const mill::test::TempPath p("transport_" + std::to_string(getpid()) + ".h5");
  WriteTransportH5(p.string(), r, ComputeTransportStats(r, insert, ends), insert, tr, meta, ends);
  EXPECT_EQ(dataset_unit(p, "impacts/speed"), "m/s");
  EXPECT_EQ(dataset_unit(p, "impacts/angle"), "deg");
  EXPECT_EQ(dataset_unit(p, "particles/first_impact_time"), "s");
  EXPECT_EQ(dataset_unit(p, "trajectories/speed"), "m/s");
  EXPECT_EQ(dataset_unit(p, "strikes/rebound_speed_lab"), "m/s");
  EXPECT_EQ(dataset_unit(p, "strikes/flight_time"), "s");
  EXPECT_EQ(dataset_unit(p, "strikes/housing_angle"), "deg");
  EXPECT_EQ(dataset_unit(p, "contact_ends/velocity"), "m/s");
  EXPECT_EQ(dataset_unit(p, "impacts/part"), "1");
}

namespace {

// A contact on the flywheel at plate-local coordinates (a along plate k, b
// across it, z along the axis) with a plate-local normal, turned to the lab
// frame at angle `turn` (rotor angle + omega t) about the axis (ax, ay).
ImpactRecord flywheel_contact(double ax, double ay, double turn, int k, int n_plates, double a,
                              double b, double z, double na, double nb, double nz) {
  const double th = turn + 2 * kPi * k / n_plates, c = std::cos(th), s = std::sin(th);
  ImpactRecord r;
  r.surface = "flywheel";
  r.contact = {ax + a * c - b * s, ay + a * s + b * c, z};
  r.normal = {na * c - nb * s, na * s + nb * c, nz};
  return r;
}

ImpactRecord housing_contact(double x, double y, double z, double nx, double ny, double nz) {
  ImpactRecord r;
  r.surface = "housing";
  r.contact = {x, y, z};
  r.normal = {nx, ny, nz};
  return r;
}

}  // namespace

// A hand-built mill (axis off centre at (0.1, 1.2), hub radius 0.15, tip 0.5,
// six 20 mm plates 0.3 m wide) caught at an arbitrary turn: contacts on each
// part of each plate, on the hub between plates, on both caps and on every
// housing wall, with the normals the surfaces have there, are named exactly.
TEST(ImpactParts, HandBuiltFlywheelAndHousing) {
  MillShape m;
  m.axis_x = 0.1;
  m.axis_y = 1.2;
  m.hub_radius = 0.15;
  m.tip_radius = 0.5;
  const double t2 = 0.01, xtip = std::sqrt(0.25 - t2 * t2), root = std::sqrt(0.0225 - t2 * t2);
  const int n = 6;
  for (double turn : {0.0, 0.3 + 209.44 * 0.0123, -2.0}) {
    for (int k = 0; k < n; ++k) {
      auto check = [&](const ImpactRecord& r, const char* want, const char* where) {
        EXPECT_EQ(ClassifyPart(r, m), want) << where << ", plate " << k << ", turn " << turn;
      };
      check(flywheel_contact(0.1, 1.2, turn, k, n, 0.3, t2, 0.05, 0, 1, 0), "plate_face",
            "leading face");
      check(flywheel_contact(0.1, 1.2, turn, k, n, 0.45, -t2, -0.1, 0, -1, 0), "plate_face",
            "trailing face");
      check(flywheel_contact(0.1, 1.2, turn, k, n, root + 0.005, t2, 0, 0, 1, 0), "plate_face",
            "face at the root");
      check(flywheel_contact(0.1, 1.2, turn, k, n, xtip, 0.004, 0.1, 1, 0, 0), "plate_tip", "tip");
      // Edge of tip and face, normal 30 deg off the radius: still the tip.
      check(flywheel_contact(0.1, 1.2, turn, k, n, xtip, t2, 0, std::cos(0.52), std::sin(0.52), 0),
            "plate_tip", "tip edge");
      // The hub midway to the next plate (radial normal), and near the root.
      const double mid = kPi / n;
      check(flywheel_contact(0.1, 1.2, turn, k, n, 0.15 * std::cos(mid), 0.15 * std::sin(mid), 0.02,
                             std::cos(mid), std::sin(mid), 0),
            "hub", "hub between plates");
      check(flywheel_contact(0.1, 1.2, turn, k, n, 0.15 * std::cos(0.1), 0.15 * std::sin(0.1), 0,
                             std::cos(0.1), std::sin(0.1), 0),
            "hub", "hub at the root");
      check(flywheel_contact(0.1, 1.2, turn, k, n, 0.3, 0.0, 0.15, 0, 0, 1), "side_cap",
            "cap +z on the plate");
      check(flywheel_contact(0.1, 1.2, turn, k, n, 0.08, 0.03, -0.15, 0, 0, -1), "side_cap",
            "cap -z on the hub");
    }
  }
  EXPECT_EQ(ClassifyPart(housing_contact(0.3, 0, 0.1, 0, 1, 0), m), "floor");
  EXPECT_EQ(ClassifyPart(housing_contact(-0.2, 4, 0, 0, -1, 0), m), "roof");
  EXPECT_EQ(ClassifyPart(housing_contact(0.8, 2, 0, -1, 0, 0), m), "side_wall");
  EXPECT_EQ(ClassifyPart(housing_contact(-0.8, 0.5, 0.1, 1, 0, 0), m), "side_wall");
  EXPECT_EQ(ClassifyPart(housing_contact(0, 2, 0.25, 0, 0, -1), m), "front_back");
  EXPECT_EQ(ClassifyPart(housing_contact(0, 2, -0.25, 0, 0, 1), m), "front_back");
  EXPECT_EQ(ClassifyPart(housing_contact(0.79, 0.01, 0, -0.6, 0.8, 0), m),
            "floor");  // edge, mostly floor
  ImpactRecord other;
  other.surface = "chute";
  EXPECT_EQ(ClassifyPart(other, m), "other");
}

namespace {

ContactEnd end_of(const ImpactRecord& r, double duration, const std::array<double, 3>& v) {
  ContactEnd e;
  e.particle_id = r.particle_id;
  e.surface = r.surface;
  e.start_time_s = r.time_s;
  e.time_s = r.time_s + duration;
  e.duration_s = duration;
  e.velocity = v;
  e.speed_m_s = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  return e;
}

}  // namespace

// A scripted trajectory: lump 1 is struck (t = 0.100 s), leaves the beater
// 60 us later at (30, 40, 0) m/s, flies ballistically (g = 9.81 along -y) to
// the side wall 0.6 m away, slides briefly on the floor on the way (0.4 m/s
// normal: not an impact), hits the wall, is struck again and then leaves the
// mill without touching the housing. Lump 2, listed interleaved and out of
// order, is struck once, touches the housing during its beater contact (not
// a flight) and hits the roof later. The chain must pick, per strike, the
// next housing impact after the lump left the beater and before its next
// strike: speed, angle and time of flight as scripted.
TEST(StrikeChain, ScriptedTrajectory) {
  const double g = 9.81, vx = 30, vy = 40, dist = 0.6;
  const double t_strike = 0.100, contact = 60e-6, t_leave = t_strike + contact;
  const double flight = dist / vx;  // horizontal speed is constant
  const double vy_hit = vy - g * flight;
  const double hit_speed = std::hypot(vx, vy_hit),
               hit_angle = std::atan2(vx, std::abs(vy_hit)) * 180 / kPi;
  MillShape m;
  auto rec_at = [](long long id, const std::string& surf, double t, double speed, double vn,
                   double angle, std::array<double, 3> normal, std::array<double, 3> contact_pt) {
    ImpactRecord r = rec(id, surf, t, speed, vn, angle);
    r.normal = normal;
    r.contact = contact_pt;
    return r;
  };
  // Flywheel contact points on a plate face of the default shape (axis 0, 1.2).
  const std::array<double, 3> face{0.3, 1.21, 0}, face_n{0, 1, 0};
  std::vector<ImpactRecord> r = {
      rec_at(2, "housing", 0.2001, 3, 2.5, 50, {0, -1, 0},
             {0, 4, 0}),                                          // 0: lump 2 on the roof, later
      rec_at(1, "flywheel", t_strike, 90, 80, 60, face_n, face),  // 1: lump 1 strike
      rec_at(1, "housing", 0.105, 5, 0.4, 5, {0, 1, 0}, {0.2, 0, 0}),  // 2: sliding on the floor
      rec_at(1, "housing", t_leave + flight, hit_speed, vx, hit_angle, {-1, 0, 0},
             {0.8, 1.5, 0}),                                 // 3: wall
      rec_at(2, "flywheel", 0.2, 70, 60, 60, face_n, face),  // 4: lump 2 strike
      rec_at(2, "housing", 0.20002, 20, 15, 40, {1, 0, 0},
             {-0.8, 1.2, 0}),                                // 5: during lump 2's contact
      rec_at(1, "flywheel", 0.3, 95, 85, 62, face_n, face),  // 6: lump 1 struck again
  };
  LabelImpacts(r, m, 1.0);
  EXPECT_TRUE(r[2].sliding);
  EXPECT_FALSE(r[3].sliding);
  EXPECT_EQ(r[1].strike, 1);
  EXPECT_EQ(r[6].strike, 2);
  EXPECT_EQ(r[4].strike, 1);
  EXPECT_EQ(r[3].part, "side_wall");
  EXPECT_EQ(r[0].part, "roof");
  EXPECT_EQ(r[1].part, "plate_face");
  const std::vector<ContactEnd> ends = {end_of(r[4], 50e-6, {0, 20, 0}),
                                        end_of(r[1], contact, {vx, vy, 0}),
                                        end_of(r[6], 55e-6, {-60, 80, 0})};
  const auto chains = StrikeChains(r, ends);
  ASSERT_EQ(chains.size(), 3u);
  // In record order: lump 1's first strike, lump 2's strike, lump 1's second.
  EXPECT_EQ(chains[0].record, 1u);
  EXPECT_EQ(chains[0].end, 1);
  EXPECT_EQ(chains[0].housing, 3);
  EXPECT_NEAR(chains[0].flight_time_s, flight, 1e-12);
  EXPECT_EQ(chains[1].record, 4u);
  EXPECT_EQ(chains[1].end, 0);
  EXPECT_EQ(chains[1].housing, 0);  // the roof, not the wall touched while on the beater
  EXPECT_NEAR(chains[1].flight_time_s, 0.2001 - 0.20005, 1e-12);
  EXPECT_EQ(chains[2].record, 6u);
  EXPECT_EQ(chains[2].housing, -1);  // left the mill
  const auto s = ComputeTransportStats(r, {0.0, 0.1}, ends);
  EXPECT_EQ(s.sliding_contacts, 1);
  EXPECT_EQ(s.sliding.at("housing"), 1);
  EXPECT_EQ(s.surfaces.at("housing").n, 3);  // the slide is not an impact
  EXPECT_EQ(s.strikes.n_first, 2);
  EXPECT_EQ(s.strikes.n_later, 1);
  EXPECT_NEAR(s.strikes.first_speed.mean, 80.0, 1e-12);
  EXPECT_NEAR(s.strikes.later_speed.mean, 95.0, 1e-12);
  EXPECT_EQ(s.strikes.n_with_end, 3);
  EXPECT_NEAR(s.strikes.rebound_speed_lab.mean, (50.0 + 20.0 + 100.0) / 3, 1e-12);
  EXPECT_EQ(s.strikes.n_to_housing, 2);
  EXPECT_NEAR(s.strikes.housing_speed.mean, 0.5 * (hit_speed + 3.0), 1e-12);
  EXPECT_NEAR(s.strikes.housing_angle.mean, 0.5 * (hit_angle + 50.0), 1e-12);
  EXPECT_NEAR(s.strikes.flight_time.mean, 0.5 * (flight + 0.00005), 1e-12);
  EXPECT_EQ(s.impacts_per_part.at("side_wall"), 2);
  EXPECT_EQ(s.impacts_per_part.at("plate_face"), 3);
  EXPECT_EQ(s.impacts_per_part.count("floor"), 0u);  // only the slide touched the floor
  std::printf("strike chain: housing speed %.4f m/s, angle %.3f deg, flight %.4f ms\n", hit_speed,
              hit_angle, 1e3 * flight);
}

// The contact-end CSV is read by column name; a bad cell names file, line and column.
TEST(ContactEndsCsv, ReadsColumnsByName) {
  const auto p = temp_file(
      "contact_ends.csv",
      "time_s,particle_id,surface,start_time_s,duration_s,x_m,y_m,z_m,vx_m_s,vy_m_s,vz_m_s,"
      "speed_m_s,vrel_x_m_s,vrel_y_m_s,vrel_z_m_s,relative_speed_m_s,normal_speed_m_s,"
      "tangential_speed_m_s,surface_speed_m_s\n"
      "0.10006,4,flywheel,0.1,6e-05,1,2,3,30,40,0,50,1,2,3,3.74,15,2,30\n"
      "0.2,5,housing,0.19,0.01,1,2,3,0,0,0,0,nan,nan,nan,nan,nan,nan,nan\n");
  const auto e = ReadContactEndsCsv(p.string());
  ASSERT_EQ(e.size(), 2u);
  EXPECT_EQ(e[0].particle_id, 4);
  EXPECT_EQ(e[0].surface, "flywheel");
  EXPECT_DOUBLE_EQ(e[0].start_time_s, 0.1);
  EXPECT_DOUBLE_EQ(e[0].velocity[1], 40.0);
  EXPECT_DOUBLE_EQ(e[0].speed_m_s, 50.0);
  EXPECT_DOUBLE_EQ(e[0].normal_speed_m_s, 15.0);
  EXPECT_TRUE(std::isnan(e[1].normal_speed_m_s));
  std::ofstream(p.path(), std::ios::app) << "0.3,5,housing,0.29,fast,1,2,3,0,0,0,0,0,0,0,0,0,0,0\n";
  try {
    ReadContactEndsCsv(p.string());
    FAIL() << "no error";
  } catch (const PostError& err) {
    const std::string msg = err.what();
    EXPECT_NE(msg.find(":4:"), std::string::npos) << msg;
    EXPECT_NE(msg.find("duration_s"), std::string::npos) << msg;
  }
}

// The labelled impacts.csv reads back with its labels.
TEST(ImpactCsv, LabelsRoundTrip) {
  std::vector<ImpactRecord> r = {rec(1, "flywheel", 0.1, 90, 80, 60),
                                 rec(1, "housing", 0.2, 5, 0.5, 6)};
  r[0].normal = {0, 1, 0};
  r[0].contact = {0.3, 1.21, 0};
  r[1].normal = {0, 1, 0};
  LabelImpacts(r, MillShape{}, 1.0);
  const mill::test::TempPath p("labelled_" + std::to_string(getpid()) + ".csv");
  WriteImpactsCsv(p.string(), r);
  const auto back = ReadImpactsCsv(p.string());
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].part, "plate_face");
  EXPECT_EQ(back[0].strike, 1);
  EXPECT_FALSE(back[0].sliding);
  EXPECT_EQ(back[1].part, "floor");
  EXPECT_TRUE(back[1].sliding);
  EXPECT_DOUBLE_EQ(back[0].speed_m_s, 90.0);
}
