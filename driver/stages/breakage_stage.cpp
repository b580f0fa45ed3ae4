// Stage 'breakage': one bonded-lump impact per condition (issue 4).
#include "stages/breakage_stage.h"

#include <fmt/format.h>

#include "stages/stage_util.h"

namespace mill {

Plan BreakageStage::plan(const StageContext& ctx) const {
  Plan p;
  const auto& d = ctx.cfg.doc;
  if (d.str("breakage.conditions") == "transport") {
    p.note = "impact conditions come from transport/ (binned flywheel impacts); they are known after that stage";
    return p;
  }
  nlohmann::json base = case_keys(d, {"lump.", "breakage.duration_after_contact", "breakage.timestep", "breakage.dump_interval"});
  base["ore"] = ore_keys(ctx.cfg.ore);
  for (double v : d.reals("breakage.velocities"))
    for (double a : d.reals("breakage.angles"))
      for (long r = 0; r < d.integer("breakage.repeats"); ++r) {
        nlohmann::json in = base;
        in["velocity"] = v;
        in["angle"] = a;
        in["repeat"] = r;
        p.jobs.push_back({impact_label(v, a, static_cast<int>(r)), in,
                          fmt::format("{}-element lump at {:g} m/s, {:g} deg, repeat {}", d.integer("lump.n_elements"), v,
                                      a, r)});
      }
  return p;
}

void BreakageStage::run_job(StageContext&, const JobSpec&, const std::filesystem::path&) {
  throw NotImplemented("stage 'breakage' is not implemented yet (issue 4: bonded lump impacts)");
}

}  // namespace mill
