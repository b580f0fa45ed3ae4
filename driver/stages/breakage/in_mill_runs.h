// In-mill breakage (breakage.in_mill): for K lumps per rotor speed, the
// bonded lump is run in the turning mill from `lead_time` before its first
// flywheel strike in stage 1 (liggghts_inputs/in_mill.in.tmpl): the strike,
// the fragments' flight and their housing impacts. Jobs of the breakage stage
// beside its single impacts; the product of the lumps of lump.diameter goes
// into breakage/product.json (an `in_mill` object per rotor speed) and
// breakage/in_mill.csv; with a feed, each feed class's lumps run too and make
// its column of the breakage matrix (breakage_matrix.h).
#pragma once

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "config/feed_classes.h"
#include "stages/stage.h"

namespace mill::breakage {

// True for the jobs plan_in_mill makes.
bool is_in_mill_job(const JobSpec& job);

// The feed class of an in-mill job; none for the lumps of lump.diameter.
std::optional<std::size_t> in_mill_class(const JobSpec& job);

// Appends the in-mill jobs of one rotor speed, chosen from that speed's
// transport impacts: the lumps of lump.diameter from transport/<rpm>/
// impacts.csv (which must exist), or with `cls` the lumps of that feed class
// (its diameter and element count) from its own stage-1 run,
// transport/class_<k>/<rpm>/impacts.csv (MissingInput naming the command
// that makes it when absent).
void plan_in_mill(const StageContext& ctx, double rpm, Plan& plan,
                  const config::FeedClassRuns* cls = nullptr);

// Runs one in-mill job into out_dir; returns its summary line.
std::string run_in_mill(StageContext& ctx, const JobSpec& job,
                        const std::filesystem::path& out_dir);

// The outputs run_in_mill writes for `job` exist and parse: "" or the reason.
std::string damaged_in_mill_outputs(const JobSpec& job, const std::filesystem::path& dir);

// breakage/in_mill.csv (one row per run) and, per rotor speed, the in-mill
// product object of product.json (averaged over the runs); `jobs` are the
// runs of lump.diameter's lumps or, with a feed whose class of lump.diameter
// has runs of its own, that class's runs (plan_in_mill does not plan both):
// the sizes in mm are d/D x the runs' lump diameter (their `lump.diameter`
// input, else the case's).
std::map<double, nlohmann::json> write_in_mill_results(StageContext& ctx,
                                                       const std::vector<JobSpec>& jobs);

}  // namespace mill::breakage
