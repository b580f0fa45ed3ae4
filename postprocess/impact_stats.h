// Impact statistics of the transport stage: reading the impact/recorder CSV
// and the trajectory dump, the per-surface and per-particle statistics, and
// the results file transport.h5 (units as attributes). No driver/ includes.
#pragma once

#include <array>
#include <map>
#include <string>
#include <vector>

namespace mill::post {

// One contact onset as written by fix impact/recorder.
struct ImpactRecord {
  double time_s = 0;
  long long particle_id = 0;
  std::string surface;                        // "flywheel", "housing"
  std::array<double, 3> position{};           // particle centre, m
  std::array<double, 3> contact{};            // contact point, m
  std::array<double, 3> normal{};             // surface normal towards the particle
  std::array<double, 3> relative_velocity{};  // particle minus surface velocity, m/s
  double speed_m_s = 0;                       // |relative velocity|
  double normal_speed_m_s = 0;                // approach speed along the normal (> 0)
  double tangential_speed_m_s = 0;
  double angle_deg = 0;           // to the surface plane, 90 = normal
  double surface_speed_m_s = 0;   // |Omega x r| at the contact point
  double particle_speed_m_s = 0;  // lab-frame particle speed
  double axis_distance_m = 0;     // contact point to the rotor axis
};

// Reads impacts.csv (columns found by name). Throws PostError naming file and line.
std::vector<ImpactRecord> ReadImpactsCsv(const std::string& path);

// Trajectory samples from a `dump custom` text file with id x y z vx vy vz.
struct Trajectories {
  std::vector<double> time_s;  // per sample
  std::vector<long long> particle_id;
  std::vector<std::array<double, 3>> position;  // m
  std::vector<std::array<double, 3>> velocity;  // m/s
};
// dt converts the dump's timesteps to seconds. Throws PostError on bad input.
Trajectories ReadTrajectoryDump(const std::string& path, double dt);

// Mean and (sample) standard deviation of a list; zero for empty lists.
struct MeanStd {
  double mean = 0, std = 0;
  long long n = 0;
};
MeanStd mean_std(const std::vector<double>& v);

// Statistics of the impacts on one surface.
struct SurfaceStats {
  long long n = 0;
  MeanStd speed, normal_speed, tangential_speed, angle, particle_speed, axis_distance;
};

// Everything summary.json reports.
struct TransportStats {
  long long n_particles = 0;  // lumps inserted
  std::map<std::string, SurfaceStats> surfaces;
  std::vector<long long> ids;                            // 1..n_particles
  std::vector<long long> impacts_per_particle;           // all surfaces, per id
  std::vector<long long> flywheel_impacts_per_particle;  // per id
  std::vector<double> first_impact_time_s;               // since insertion, per id; NaN if none
  double impacts_per_particle_mean = 0;
  double flywheel_impacts_per_particle_mean = 0;
  double first_impact_time_mean_s = 0;  // over particles with an impact
  long long particles_with_impact = 0;
};

// Statistics over the records; insert_time_s[k] is the insertion time of
// particle id k + 1 (ids 1..n). Records of unknown ids throw PostError.
TransportStats ComputeTransportStats(const std::vector<ImpactRecord>& records,
                                     const std::vector<double>& insert_time_s);

// Scalars and geometry for the root/geometry attributes of transport.h5.
struct TransportMeta {
  std::map<std::string, double> scalars;     // e.g. "rpm", "rim_speed_m_s"
  std::map<std::string, std::string> units;  // unit per scalar ("" if none)
  std::map<std::string, double> geometry;    // housing_height, tip_radius, ... (m)
};

// Writes transport.h5 (temp file, then rename): /impacts/*, /particles/*,
// /trajectories/*, /geometry attributes, root attributes from meta.
void WriteTransportH5(const std::string& path, const std::vector<ImpactRecord>& records,
                      const TransportStats& stats, const std::vector<double>& insert_time_s,
                      const Trajectories& traj, const TransportMeta& meta);

}  // namespace mill::post
