// The results file of the transport stage, transport.h5: the labelled
// impacts, contact ends, beater strikes, per-particle counts and trajectories,
// one group each, every dataset with its unit as an attribute. No driver/
// includes.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "postprocess/impact_stats.h"

namespace mill::post {

// Scalars and geometry for the root/geometry attributes of transport.h5.
struct TransportMeta {
  std::map<std::string, double> scalars;     // e.g. "rpm", "rim_speed_m_s"
  std::map<std::string, std::string> units;  // unit per scalar ("" if none)
  std::map<std::string, double> geometry;    // housing_height, tip_radius, ... (m)
};

// Writes transport.h5 (temp file, then rename): /impacts/*, /contact_ends/*,
// /strikes/*, /particles/*, /trajectories/*, /geometry attributes, root
// attributes from meta.
void WriteTransportH5(const std::string& path, const std::vector<ImpactRecord>& records,
                      const TransportStats& stats, const std::vector<double>& insert_time_s,
                      const Trajectories& traj, const TransportMeta& meta,
                      const std::vector<ContactEnd>& ends = {});

}  // namespace mill::post
