// The breakage matrix of the feed's population balance per rotor speed, from
// the in-mill runs (breakage.in_mill) of a case with a feed: each run's
// pieces binned on feed.sizes_mm into the column of its lump's class,
// mass-weighted over the runs, the other classes scaled from a measured one
// (docs/population_balance.md, "Breakage matrix from the in-mill runs").
// Writes breakage/breakage_matrix.json and .csv; called from finalize.
#pragma once

#include <cstddef>
#include <map>
#include <vector>

#include "postprocess/breakage_matrix.h"
#include "stages/stage.h"

namespace mill::breakage {

// Per rotor speed, the assembled matrix of the in-mill runs among `jobs`
// (others are skipped); writes breakage/breakage_matrix.json and .csv. The
// case must have a feed. Empty (and nothing written) without in-mill runs.
std::map<double, post::AssembledMatrix> write_breakage_matrices(StageContext& ctx,
                                                                const std::vector<JobSpec>& jobs);

}  // namespace mill::breakage
