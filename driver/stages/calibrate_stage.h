// Stage 'calibrate': fit the bond (micro) parameters to the ore card's macro
// properties with virtual UCS and Brazilian tests on a bonded specimen packed
// like the lump; writes calibrate/calibrated.yaml (read by the breakage
// stage), report.md, report.json, curves.csv and plots/. See docs/calibration.md.
#pragma once

#include "stages/stage.h"

namespace mill {

class CalibrateStage : public Stage {
 public:
  std::string name() const override { return "calibrate"; }
  std::string description() const override {
    return "fit bond parameters to the ore card (virtual UCS and Brazilian or direct tension "
           "tests)";
  }
  Plan plan(const StageContext& ctx) const override;
  void run_job(StageContext& ctx, const JobSpec& job,
               const std::filesystem::path& job_dir) override;
  void finalize(StageContext& ctx, const std::vector<JobSpec>& jobs) override;
  std::string damaged_outputs(const StageContext& ctx, const JobSpec& job) const override;
  std::string damaged_merged_outputs(const StageContext& ctx,
                                     const std::vector<JobSpec>& jobs) const override;
  // The fits (calibrate.starts) run side by side, their lab runs drawing on
  // resources.jobs engine runs in the order they ask.
  bool jobs_share_engine_runs() const override { return true; }
};

}  // namespace mill
