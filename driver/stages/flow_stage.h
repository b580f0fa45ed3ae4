// Stage 'flow': mesh the mill and solve the steady MRF gas flow (OpenFOAM)
#pragma once

#include "stages/stage.h"

namespace mill {

class FlowStage : public Stage {
 public:
  std::string name() const override { return "flow"; }
  std::string description() const override { return "mesh the mill and solve the steady MRF gas flow (OpenFOAM)"; }
  bool implemented() const override { return false; }
  Plan plan(const StageContext& ctx) const override;
  void run_job(StageContext& ctx, const JobSpec& job, const std::filesystem::path& job_dir) override;
};

}  // namespace mill
