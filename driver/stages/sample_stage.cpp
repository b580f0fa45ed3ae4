// Stage 'sample': resample each flow solution on a uniform grid (issue 6).
#include "stages/sample_stage.h"

#include "stages/stage_util.h"

namespace mill {

Plan SampleStage::plan(const StageContext& ctx) const {
  Plan p;
  for (double rpm : ctx.cfg.doc.reals("rotor.rpm")) {
    nlohmann::json in = case_keys(ctx.cfg.doc, {"mill.", "gas.", "flow.", "sample."});
    in["rotor.rpm"] = rpm;
    p.jobs.push_back({rpm_label(rpm), in, "sample flow/" + rpm_label(rpm) + " on a uniform grid"});
  }
  return p;
}

void SampleStage::run_job(StageContext&, const JobSpec&, const std::filesystem::path&) {
  throw NotImplemented("stage 'sample' is not implemented yet (issue 6: sampled velocity field)");
}

}  // namespace mill
