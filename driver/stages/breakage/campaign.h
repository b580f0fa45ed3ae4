// What BreakageStage::finalize makes of a finished sweep of single impacts:
// the merged tables (summary.csv, fractions.csv, breakage.h5), the critical
// velocity, the comminution efficiency and the plots (docs/breakage.md,
// "Outputs"). The JK fit and size distributions are in summaries.h, the mill
// product in mill_product.h.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <vector>

#include "postprocess/breakage_results.h"
#include "stages/stage.h"

namespace mill::breakage {

// The impacts of a sweep, merged: one summary row per impact, in job order.
struct Campaign {
  std::vector<post::ImpactSummary> rows;
  std::vector<std::filesystem::path> row_dirs;  // the job folder of each row
  std::vector<post::FractionRow> fractions;
};

// Reads every job's summary.csv, fractions.csv and impact.h5 and writes
// breakage/summary.csv, fractions.csv and breakage.h5.
Campaign merge_impacts(StageContext& ctx, const std::vector<JobSpec>& jobs);

// breakage/critical_velocity.json: per angle (all conditions pooled into one
// entry when `pooled`), the speed at which the largest piece falls below
// breakage.critical_largest_fraction. Returns what it wrote.
nlohmann::json write_critical_velocity(StageContext& ctx,
                                       const std::vector<post::ImpactSummary>& rows, bool pooled);

// breakage/comminution_efficiency.json: the comminution efficiency of the
// impacts of each entry of critical_velocity.json `crit`.
void write_comminution_efficiency(StageContext& ctx, const std::vector<post::ImpactSummary>& rows,
                                  const nlohmann::json& crit);

// breakage/plots/*.png from the merged CSVs (postprocess/plot_breakage.py)
// and plots/energy_ledger_fastest.png, the ledger of the fastest impact.
void plot_campaign(StageContext& ctx, const Campaign& c, bool pooled);

}  // namespace mill::breakage
