// Stage 'calibrate': bond parameters from the ore card's macro properties (issue 5).
#include "stages/calibrate_stage.h"

#include <fmt/format.h>

#include "stages/stage_util.h"

namespace mill {

Plan CalibrateStage::plan(const StageContext& ctx) const {
  Plan p;
  nlohmann::json in = case_keys(ctx.cfg.doc, {"calibrate.", "lump."});
  in["ore"] = ore_keys(ctx.cfg.ore);
  p.jobs.push_back({"calibration", in,
                    fmt::format("UCS + Brazilian tests on {} elements, fit to {}", ctx.cfg.doc.integer("calibrate.n_elements"),
                                ctx.cfg.ore.str("name"))});
  return p;
}

void CalibrateStage::run_job(StageContext&, const JobSpec&, const std::filesystem::path&) {
  throw NotImplemented("stage 'calibrate' is not implemented yet (issue 5: virtual lab tests and fitting)");
}

}  // namespace mill
