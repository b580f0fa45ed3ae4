// Stage 'breakage': one bonded-lump impact per (velocity, angle, repeat),
// each followed by the fragment analysis, and optionally lumps run in the
// turning mill; finalize merges the campaign into breakage/summary.csv,
// fractions.csv, breakage.h5, plots, the critical velocity and the
// comminution efficiency. The steps live in stages/breakage/ (single
// impacts, in-mill runs, what both share, the campaign's summaries, the mill
// product); the lump itself in lump/. See docs/breakage.md.
#pragma once

#include "stages/stage.h"

namespace mill {

class BreakageStage : public Stage {
 public:
  std::string name() const override { return "breakage"; }
  std::string description() const override {
    return "impact of one bonded ore lump per condition, fragment analysis";
  }
  Plan plan(const StageContext& ctx) const override;
  void run_job(StageContext& ctx, const JobSpec& job,
               const std::filesystem::path& job_dir) override;
  void finalize(StageContext& ctx, const std::vector<JobSpec>& jobs) override;
  std::string damaged_outputs(const StageContext& ctx, const JobSpec& job) const override;
  std::string damaged_merged_outputs(const StageContext& ctx,
                                     const std::vector<JobSpec>& jobs) const override;
  // The calibrated bonds; with breakage.conditions = transport also the
  // transport's impacts, which decide the jobs (one per binned condition).
  std::vector<std::string> reads(const config::CaseConfig& cfg) const override;
  std::vector<std::string> jobs_from(const config::CaseConfig& cfg) const override;
};

}  // namespace mill
