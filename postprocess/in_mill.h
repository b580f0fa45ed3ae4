// In-mill breakage (breakage.in_mill): where each bonded-lump run starts
// (stage 1's first flywheel strikes, backed off by a lead time) and what the
// run's records say afterwards: bonds broken at the beater strike or later,
// the contacts the elements made, and where the mass ended up.
// No driver/ includes.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "postprocess/fragments.h"
#include "postprocess/impact_stats.h"

namespace mill::post {

// The turning flywheel of the transport run: angle omega t about the axis
// through `origin` along +z (right-hand rule), angle 0 at t = 0.
struct RotorMotion {
  double omega_rad_s = 0;
  std::array<double, 3> origin{};  // a point on the rotor axis, m
  double gravity_m_s2 = 9.81;      // along -y
};

// The state of a transport lump `lead_time_s` before its first flywheel strike.
struct StrikeStart {
  long long particle_id = 0;
  double strike_time_s = 0;            // time of the first flywheel contact
  double start_time_s = 0;             // strike_time_s - lead_time_s
  std::array<double, 3> position{};    // lump centre at start_time_s, m
  std::array<double, 3> velocity{};    // lab-frame velocity at start_time_s, m/s
  double rotor_angle_rad = 0;          // flywheel angle at start_time_s, in [0, 2 pi)
  double strike_speed_m_s = 0;         // speed relative to the beater at the strike
  double strike_normal_speed_m_s = 0;  // its normal part
  double strike_angle_deg = 0;         // to the beater surface, 90 = normal
};

// Each particle's first flywheel contact (earliest record on "flywheel" with
// a normal speed of at least min_normal_m_s: resting contacts are not
// strikes); of those particles, `k` are chosen spread over the range of
// strike normal speeds (the (i + 1/2)/k quantiles, ties to the earlier
// strike), then backed off ballistically by lead_time_s (gravity only: drag
// changes a 40 mm lump's velocity by well under 1 % in a few milliseconds).
// The lab velocity at the strike is the recorded relative velocity plus the
// beater's Omega x r at the contact point. Sorted by particle id. Throws
// PostError when no particle struck the flywheel or when the records lack
// the contact point (an old impacts.csv).
std::vector<StrikeStart> SelectStrikeStarts(const std::vector<ImpactRecord>& records, int k,
                                            double lead_time_s, const RotorMotion& rotor,
                                            double min_normal_m_s = 0.5);

// One break event of fix bond/breakable's break log.
struct BreakEvent {
  double time_s = 0;
  long long i = 0, j = 0;
};
// Reads the break log (`step time x y z mode tag_i tag_j sigma tau`, lines
// with # are comments). Throws PostError naming file and line.
std::vector<BreakEvent> ReadBreakLog(const std::string& path);

// Bonds broken at the beater strike and later. The strike lasts from the
// lump's first element contact with the flywheel until the first element
// contact with the housing (or the end of the run): what breaks then is the
// beater's work; what breaks after is the housing's and the later strikes'.
// A lump that never touches the flywheel breaks nothing at the strike.
struct BreakSplit {
  long long at_strike = 0, later = 0;
  double first_flywheel_contact_s = -1;  // -1: none
  double first_housing_contact_s = -1;   // -1: none
};
BreakSplit SplitBreaks(const std::vector<BreakEvent>& breaks,
                       const std::vector<ImpactRecord>& contacts);

// The element contacts of one surface in one run.
struct ContactTally {
  long long n = 0;                   // contact onsets
  long long n_elements = 0;          // distinct elements that touched it
  double normal_speed_mean_m_s = 0;  // over onsets
  double normal_speed_max_m_s = 0;
};
ContactTally TallyContacts(const std::vector<ImpactRecord>& contacts, const std::string& surface);

// Where the mass is at the end of a run, as shares of the element mass:
// in the rotor region (within the flywheel's tip radius of the axis and
// within its width along z), below the floor (left through the outlet
// opening), above the roof (out through the inlet opening), and elsewhere in
// the housing.
struct MillRegions {
  double axis_x = 0, axis_y = 0;
  double tip_radius = 0, half_width_z = 0;
  double floor_y = 0, roof_y = 0;
};
struct MassPlaces {
  double rotor = 0, housing = 0, outlet = 0, inlet = 0;
};
MassPlaces LocateMass(const std::vector<Element>& elements, const MillRegions& regions);

// How an in-mill run ended, from the deck's last line
// "in_mill: stopped at t = T s (REASON)" in its LIGGGHTS log: REASON is
// "work_done" (the early stop's conditions held at the end of a chunk) or
// "t_end" (the run lasted its duration). Throws PostError naming the log
// when it holds no such line.
struct InMillStop {
  double time_s = 0;
  std::string reason;
};
InMillStop ReadInMillStop(const std::string& log_path);

}  // namespace mill::post
