// In-mill breakage (breakage.in_mill): for K lumps per rotor speed, the
// bonded lump is run in the turning mill from `lead_time` before its first
// flywheel strike in stage 1 (liggghts_inputs/in_mill.in.tmpl): the strike,
// the fragments' flight and their housing impacts. Jobs of the breakage stage
// beside its single impacts; their product goes into breakage/product.json
// (an `in_mill` object per rotor speed) and breakage/in_mill.csv.
#pragma once

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "stages/stage.h"

namespace mill::breakage {

// True for the jobs plan_in_mill makes.
bool is_in_mill_job(const JobSpec& job);

// Appends the in-mill jobs of one rotor speed, chosen from that speed's
// transport impacts (transport/<rpm>/impacts.csv, which must exist).
void plan_in_mill(const StageContext& ctx, double rpm, Plan& plan);

// Runs one in-mill job into out_dir; returns its summary line.
std::string run_in_mill(StageContext& ctx, const JobSpec& job,
                        const std::filesystem::path& out_dir);

// The outputs run_in_mill writes for `job` exist and parse: "" or the reason.
std::string damaged_in_mill_outputs(const JobSpec& job, const std::filesystem::path& dir);

// breakage/in_mill.csv (one row per run), breakage/animation/ (the animated
// run's, in_mill_animation.h) and, per rotor speed, the in-mill product
// object of product.json (averaged over the runs).
std::map<double, nlohmann::json> write_in_mill_results(StageContext& ctx,
                                                       const std::vector<JobSpec>& jobs);

}  // namespace mill::breakage
