// Impact statistics of the transport stage: reading the impact/recorder CSVs
// (onsets and contact ends) and the trajectory dump, the struck part of each
// contact, first and later beater strikes, sliding contacts, the
// strike-to-housing chain, and the per-surface and per-particle statistics
// (postprocess/transport_h5 writes them to transport.h5). No driver/ includes.
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
  // Labels (LabelImpacts; read back from an annotated impacts.csv):
  std::string part;      // struck part (PartNames()), "" if not classified
  bool sliding = false;  // normal speed below the sliding threshold: not an impact
  int strike = 0;        // flywheel impacts: 1 the lump's first strike, 2 a later one
};

// Reads impacts.csv (columns found by name; the label columns part, sliding,
// strike if present). Throws PostError naming file and line.
std::vector<ImpactRecord> ReadImpactsCsv(const std::string& path);
// Writes the records with their labels (impacts.csv of the transport stage:
// the recorder's columns, then part, sliding, strike); temp file, then rename.
void WriteImpactsCsv(const std::string& path, const std::vector<ImpactRecord>& records);

// One contact end as written by fix impact/recorder (keyword ends).
struct ContactEnd {
  double time_s = 0;  // end of the contact
  long long particle_id = 0;
  std::string surface;
  double start_time_s = 0;  // time_s of its onset record
  double duration_s = 0;
  std::array<double, 3> position{};           // m
  std::array<double, 3> velocity{};           // lab velocity after the contact, m/s
  double speed_m_s = 0;                       // its magnitude
  std::array<double, 3> relative_velocity{};  // relative to the surface, m/s
  double relative_speed_m_s = 0;
  double normal_speed_m_s = 0;  // rebound speed along the normal (> 0 away)
  double tangential_speed_m_s = 0;
  double surface_speed_m_s = 0;
};
// Reads contact_ends.csv (columns by name). Throws PostError naming file and line.
std::vector<ContactEnd> ReadContactEndsCsv(const std::string& path);

// The mill as the part classification sees it: housing box x in [-w/2, w/2],
// y in [0, h], z in [-d/2, d/2]; flywheel about the axis (axis_x, axis_y, z).
struct MillShape {
  double height = 4.0, width = 1.6, depth = 0.5;  // m
  double axis_x = 0.0, axis_y = 1.2;              // m
  double hub_radius = 0.15, tip_radius = 0.5;     // m
};

// The parts a contact can strike: flywheel plate_face, plate_tip, hub,
// side_cap; housing side_wall, floor, roof, front_back; other.
const std::vector<std::string>& PartNames();
// The struck part of one contact, from its contact point and normal: on the
// flywheel, the normal's direction against the radial direction at the
// contact point (along the axis: side cap; across the radius: plate face;
// along the radius: plate tip beyond the middle of hub and tip radius, hub
// within); on the housing, the normal's main direction. Both are unchanged by
// the flywheel's rotation, so no rotor angle is needed.
std::string ClassifyPart(const ImpactRecord& r, const MillShape& m);

// Labels the records (any order): part, sliding (normal speed below
// sliding_threshold_m_s) and, for flywheel impacts that are not sliding,
// first or later strike of their lump (by time).
void LabelImpacts(std::vector<ImpactRecord>& records, const MillShape& m,
                  double sliding_threshold_m_s);

// A beater strike (a labelled flywheel impact) and what follows it: the end
// of its contact and the lump's next housing impact (not sliding), after the
// lump left the beater and before its next strike.
struct Strike {
  size_t record = 0;         // index of the strike in the records
  long end = -1;             // index of its contact end, -1 if none
  long housing = -1;         // index of the next housing impact, -1 if none
  double flight_time_s = 0;  // contact end (the onset if no end) to that housing impact
};
// One Strike per labelled strike, in the order of the records.
std::vector<Strike> StrikeChains(const std::vector<ImpactRecord>& records,
                                 const std::vector<ContactEnd>& ends);

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

// The beater strikes and the housing impacts that follow them.
struct StrikeStats {
  long long n_first = 0, n_later = 0;  // strikes
  MeanStd first_speed, later_speed;    // impact speed relative to the beater
  long long n_with_end = 0;            // strikes with a contact-end record
  MeanStd rebound_speed_lab;           // lab speed leaving the beater
  MeanStd rebound_normal_speed;        // normal speed away from the beater, relative
  MeanStd contact_duration;            // s
  long long n_to_housing = 0;          // strikes followed by a housing impact
  MeanStd housing_speed, housing_angle, flight_time;
};

// Everything summary.json reports. Sliding contacts are left out of every
// impact statistic and counted apart.
struct TransportStats {
  long long n_particles = 0;  // lumps inserted
  std::map<std::string, SurfaceStats> surfaces;
  std::map<std::string, long long> sliding;           // sliding contacts per surface
  long long sliding_contacts = 0;                     // all surfaces
  std::map<std::string, long long> impacts_per_part;  // impacts (not sliding) per part
  StrikeStats strikes;
  std::vector<Strike> chains;
  std::vector<long long> ids;                            // 1..n_particles
  std::vector<long long> impacts_per_particle;           // all surfaces, per id
  std::vector<long long> flywheel_impacts_per_particle;  // per id
  std::vector<double> first_impact_time_s;               // since insertion, per id; NaN if none
  double impacts_per_particle_mean = 0;
  double flywheel_impacts_per_particle_mean = 0;
  double first_impact_time_mean_s = 0;  // over particles with an impact
  long long particles_with_impact = 0;
};

// Statistics over the (labelled) records and their contact ends;
// insert_time_s[k] is the insertion time of particle id k + 1 (ids 1..n).
// Records of unknown ids throw PostError.
TransportStats ComputeTransportStats(const std::vector<ImpactRecord>& records,
                                     const std::vector<double>& insert_time_s,
                                     const std::vector<ContactEnd>& ends = {});

}  // namespace mill::post
