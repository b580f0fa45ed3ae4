// The breakage matrix of the feed's population balance per rotor speed, from
// the in-mill runs (breakage.in_mill) of a case with a feed: each feed
// class's runs (its own lumps, config/feed_classes.h) binned on
// feed.sizes_mm into its column, mass-weighted over the runs; the class of
// lump.diameter from the runs of lump.diameter's lumps when it has none of
// its own; the other classes scaled from a measured one
// (docs/population_balance.md, "Breakage matrix from the in-mill runs").
// Writes breakage/breakage_matrix.json and .csv; called from finalize.
#pragma once

#include <cstddef>
#include <map>
#include <vector>

#include "postprocess/breakage_matrix.h"
#include "stages/stage.h"

namespace mill::breakage {

// Per rotor speed, the assembled matrix of the in-mill runs: `in_mill` the
// runs of lump.diameter's lumps, `class_runs` those of the feed classes;
// writes breakage/breakage_matrix.json and .csv. The case must have a feed.
// Empty (and nothing written) without in-mill runs.
std::map<double, post::AssembledMatrix> write_breakage_matrices(
    StageContext& ctx, const std::vector<JobSpec>& in_mill, const std::vector<JobSpec>& class_runs);

}  // namespace mill::breakage
