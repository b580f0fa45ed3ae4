// The mill product of the breakage stage when its conditions came from the
// transport stage (breakage.conditions: transport): per rotor speed, each
// bin's impacts averaged over the repeats and the bins weighted by their
// share of impacts (postprocess/impact_conditions.h; docs/breakage.md,
// "Conditions from stage 1 and the mill product").
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <vector>

#include "stages/stage.h"

namespace mill::breakage {

// breakage/product.csv, product.json and plots/product_*.png from the single
// impacts `jobs`; each rotor speed's entry also holds `in_mill[rpm]` (the
// in-mill product, write_in_mill_results) when there is one.
void write_mill_product(StageContext& ctx, const std::vector<JobSpec>& jobs,
                        const std::map<double, nlohmann::json>& in_mill);

}  // namespace mill::breakage
