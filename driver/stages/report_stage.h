// Stage 'report': report/index.html (self-contained, opens offline) and
// report/summary.json, from the declared outputs of the stages that ran.
#pragma once

#include "stages/stage.h"

namespace mill {

class ReportStage : public Stage {
 public:
  std::string name() const override { return "report"; }
  std::string description() const override { return "the HTML report and headline numbers"; }
  Plan plan(const StageContext& ctx) const override;
  void run_job(StageContext& ctx, const JobSpec& job, const std::filesystem::path& job_dir) override;
  std::string damaged_outputs(const StageContext& ctx, const JobSpec& job) const override;
};

}  // namespace mill
