// Stage 'transport': track ore lumps through the sampled flow (LIGGGHTS, one-way coupled)
#pragma once

#include "stages/stage.h"

namespace mill {

class TransportStage : public Stage {
 public:
  std::string name() const override { return "transport"; }
  std::string description() const override { return "track ore lumps through the sampled flow (LIGGGHTS, one-way coupled)"; }
  bool implemented() const override { return false; }
  Plan plan(const StageContext& ctx) const override;
  void run_job(StageContext& ctx, const JobSpec& job, const std::filesystem::path& job_dir) override;
};

}  // namespace mill
