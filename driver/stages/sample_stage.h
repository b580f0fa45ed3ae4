// Stage 'sample': resample the gas velocity on a uniform grid (field.h5, field.vti)
#pragma once

#include "stages/stage.h"

namespace mill {

class SampleStage : public Stage {
 public:
  std::string name() const override { return "sample"; }
  std::string description() const override { return "resample the gas velocity on a uniform grid (field.h5, field.vti)"; }
  bool implemented() const override { return false; }
  Plan plan(const StageContext& ctx) const override;
  void run_job(StageContext& ctx, const JobSpec& job, const std::filesystem::path& job_dir) override;
};

}  // namespace mill
