// Tests of postprocess/impact_stats: the impact CSV and trajectory readers,
// the statistics on hand-made impact lists, and transport.h5 units.
#include "postprocess/impact_stats.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "postprocess/flow_field_io.h"
#include "postprocess/fragments.h"

namespace fs = std::filesystem;
using namespace mill::post;

namespace {

const char* kHeader =
    "time_s,particle_id,surface,x_m,y_m,z_m,contact_x_m,contact_y_m,contact_z_m,normal_x,normal_y,"
    "normal_z,"
    "vrel_x_m_s,vrel_y_m_s,vrel_z_m_s,speed_m_s,normal_speed_m_s,tangential_speed_m_s,angle_deg,"
    "surface_speed_m_s,particle_speed_m_s,axis_distance_m\n";

fs::path temp_file(const std::string& name, const std::string& text) {
  const fs::path p = fs::temp_directory_path() / (name + "_" + std::to_string(getpid()));
  std::ofstream(p) << text;
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
  const std::vector<ImpactRecord> r = {rec(1, "flywheel", 0.3, 90, 80, 60)};
  Trajectories tr;
  tr.time_s = {0.0};
  tr.particle_id = {1};
  tr.position = {{0, 1, 0}};
  tr.velocity = {{3, 4, 0}};
  TransportMeta meta;
  meta.scalars = {{"rpm", 2000}};
  meta.units = {{"rpm", "1/min"}};
  meta.geometry = {{"tip_radius", 0.5}};
  const fs::path p = fs::temp_directory_path() / ("transport_" + std::to_string(getpid()) + ".h5");
  WriteTransportH5(p.string(), r, ComputeTransportStats(r, insert), insert, tr, meta);
  EXPECT_EQ(dataset_unit(p, "impacts/speed"), "m/s");
  EXPECT_EQ(dataset_unit(p, "impacts/angle"), "deg");
  EXPECT_EQ(dataset_unit(p, "particles/first_impact_time"), "s");
  EXPECT_EQ(dataset_unit(p, "trajectories/speed"), "m/s");
  fs::remove(p);
}
