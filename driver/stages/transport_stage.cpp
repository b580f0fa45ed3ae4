// Stage 'transport': ore lumps through the sampled flow (issue 7).
#include "stages/transport_stage.h"

#include <fmt/format.h>

#include "stages/stage_util.h"

namespace mill {

Plan TransportStage::plan(const StageContext& ctx) const {
  Plan p;
  for (double rpm : ctx.cfg.doc.reals("rotor.rpm")) {
    nlohmann::json in = case_keys(ctx.cfg.doc, {"mill.", "gas.", "flow.", "sample.", "injection."});
    in["rotor.rpm"] = rpm;
    in["ore"] = ore_keys(ctx.cfg.ore);
    p.jobs.push_back({rpm_label(rpm), in,
                      fmt::format("{} lumps of {:g} mm through the mill at {}", ctx.cfg.doc.integer("injection.n_lumps"),
                                  ctx.cfg.doc.real("injection.lump_diameter") * 1e3, rpm_label(rpm))});
  }
  return p;
}

void TransportStage::run_job(StageContext&, const JobSpec&, const std::filesystem::path&) {
  throw NotImplemented("stage 'transport' is not implemented yet (issue 7: one-way coupled lump transport)");
}

}  // namespace mill
