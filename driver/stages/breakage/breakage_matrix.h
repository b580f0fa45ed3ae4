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
#include "postprocess/circuit_bootstrap.h"
#include "stages/stage.h"

namespace mill::breakage {

// What the runs that measure one class at one rotor speed gave.
struct ClassRuns {
  std::vector<post::LumpRun> lumps;  // pieces (mm, kg) and beater work per run
  double mass_kg = 0;                // the pieces' mass, summed over the runs
  double lump_mm = 0;                // the lumps' diameter
  long elements = 0;                 // per lump
  bool own = false;                  // the class's own runs; else those of lump.diameter
};

// Per rotor speed and class (coarsest first), the runs that measure it.
using MeasuringRuns = std::map<double, std::map<std::size_t, ClassRuns>>;

// The in-mill runs that measure each class: `class_runs` (the feed
// classes') measure their own class; `in_mill` (lump.diameter's lumps)
// measure lump.diameter's class where it has no runs of its own. Reads each
// run's impact.h5 (pieces) and in_mill.json (beater work, lump mass). The
// case must have a feed.
MeasuringRuns collect_measuring_runs(const StageContext& ctx, const std::vector<JobSpec>& in_mill,
                                     const std::vector<JobSpec>& class_runs);

// Per rotor speed, the assembled matrix of the measuring runs; writes
// breakage/breakage_matrix.json and .csv. Empty (and nothing written)
// without runs.
std::map<double, post::AssembledMatrix> write_breakage_matrices(StageContext& ctx,
                                                                const MeasuringRuns& runs);

}  // namespace mill::breakage
