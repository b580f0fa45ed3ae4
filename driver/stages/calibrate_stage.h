// Stage 'calibrate': fit bond parameters to the ore card (virtual UCS and Brazilian tests)
#pragma once

#include "stages/stage.h"

namespace mill {

class CalibrateStage : public Stage {
 public:
  std::string name() const override { return "calibrate"; }
  std::string description() const override { return "fit bond parameters to the ore card (virtual UCS and Brazilian tests)"; }
  bool implemented() const override { return false; }
  Plan plan(const StageContext& ctx) const override;
  void run_job(StageContext& ctx, const JobSpec& job, const std::filesystem::path& job_dir) override;
};

}  // namespace mill
