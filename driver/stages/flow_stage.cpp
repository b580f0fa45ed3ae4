// Stage 'flow': one OpenFOAM run per rotor speed (issue 6 implements the run).
#include "stages/flow_stage.h"

#include "stages/stage_util.h"

namespace mill {

Plan FlowStage::plan(const StageContext& ctx) const {
  Plan p;
  for (double rpm : ctx.cfg.doc.reals("rotor.rpm")) {
    nlohmann::json in = case_keys(ctx.cfg.doc, {"mill.", "gas.", "flow."});
    in["rotor.rpm"] = rpm;
    p.jobs.push_back({rpm_label(rpm), in,
                      "mesh (" + ctx.cfg.doc.str("flow.mesh_preset") + " preset) and solve at " + rpm_label(rpm)});
  }
  return p;
}

void FlowStage::run_job(StageContext&, const JobSpec&, const std::filesystem::path&) {
  throw NotImplemented("stage 'flow' is not implemented yet (issue 6: OpenFOAM flow case)");
}

}  // namespace mill
