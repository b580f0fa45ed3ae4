// The band of critical impact speeds over the calibration's parameter sets
// (calibrate.starts; docs/breakage.md, "Critical speed over the parameter
// sets"): the impacts of the sweep repeated with every further set, and
// breakage/calibration_sets.json with each set's critical speed.
#pragma once

#include <nlohmann/json.hpp>
#include <vector>

#include "postprocess/breakage_results.h"
#include "stages/stage.h"

namespace mill::breakage {

// The calibration set of a breakage job: 1 for the primary set, k for the
// impacts of set k (their label begins with "set<k>_").
int calibration_set_of(const JobSpec& job);

// Adds to `p` a copy of each of its single impacts (not the in-mill runs)
// for every further set k = 2..calibrate.starts, with that set's bond
// parameters; a set the calibrate stage has not made yet is noted in the
// plan, not planned.
void plan_calibration_sets(const StageContext& ctx, Plan& p);

// One set's sweep: its number and the summary rows of its impacts.
struct SetRows {
  int set = 1;
  std::vector<post::ImpactSummary> rows;
};

// calibration_sets.json's content from the primary set's critical_velocity.json
// entries `primary_crit`, every set's rows (the primary's included, set 1)
// and calibrate/sets.json (`calib_sets`, null when absent): per entry (an
// angle, or all pooled) each set's critical speed, the band (min, max)
// over all sets and over the sets that meet the ore card, and whether the
// band is within +-15 % of the primary set's speed.
nlohmann::json calibration_sets_json(const nlohmann::json& primary_crit,
                                     const std::vector<SetRows>& sets,
                                     const nlohmann::json& calib_sets, double threshold,
                                     bool pooled);

// Writes breakage/calibration_sets.json from the finished jobs (removes it
// when the case has one set) and logs the band.
void write_calibration_sets(StageContext& ctx, const std::vector<JobSpec>& set_jobs,
                            const std::vector<post::ImpactSummary>& primary_rows,
                            const nlohmann::json& primary_crit, bool pooled);

}  // namespace mill::breakage
