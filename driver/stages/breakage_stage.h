// Stage 'breakage': impact of one bonded ore lump per condition, fragment analysis
#pragma once

#include "stages/stage.h"

namespace mill {

class BreakageStage : public Stage {
 public:
  std::string name() const override { return "breakage"; }
  std::string description() const override { return "impact of one bonded ore lump per condition, fragment analysis"; }
  bool implemented() const override { return false; }
  Plan plan(const StageContext& ctx) const override;
  void run_job(StageContext& ctx, const JobSpec& job, const std::filesystem::path& job_dir) override;
};

}  // namespace mill
