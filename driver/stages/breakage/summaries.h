// What the breakage stage derives from a finished campaign in a mill
// engineer's terms: the JK breakage parameters (t10 against the specific
// impact energy) and size distributions as cumulative percent passing against
// size in millimetres with P50 and P80. Called from BreakageStage::finalize.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "postprocess/breakage_results.h"
#include "stages/stage.h"

namespace mill::breakage {

// Sieve sizes in mm of a list of relative fraction edges: the edges above 0
// times the lump size in mm (sizes are d/D x lump.diameter, docs/breakage.md).
std::vector<double> sieves_mm(const std::vector<double>& edges_rel, double lump_diameter_mm);

// A passing curve as JSON: sieves_mm, passing_percent, p50_mm and p80_mm
// (null when finer than the finest sieve), from the mass per size fraction.
nlohmann::json passing_json(const std::vector<double>& sieves,
                            const std::vector<double>& fraction_mass);

// breakage/jk_fit.json, jk_points.csv, /jk_fit in breakage.h5 and
// plots/jk_t10_vs_ecs.png: t10 = A (1 - exp(-b Ecs)) fitted per impact angle
// (all conditions pooled when `pooled`) to the impacts whose t10 is resolved.
void write_jk_fit(StageContext& ctx, const std::vector<post::ImpactSummary>& rows, bool pooled);

// breakage/size_distributions.csv and .json: per condition (speed, angle),
// the passing curve averaged over repeats, its min-max band, P50 and P80
// (and P80's range over the repeats).
void write_size_distributions(StageContext& ctx, const std::vector<post::FractionRow>& fractions);

}  // namespace mill::breakage
