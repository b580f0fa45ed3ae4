// Stage 'transport': ore lumps through the mill in the sampled gas flow
// (LIGGGHTS, one-way coupled), one job per rotor speed, and with a feed one
// more per rotor speed and feed class (config/feed_classes.h). Each job
// writes transport/<rpm label>/ (transport/class_<k>/<rpm label>/ for a
// class) {impacts.csv, contact_ends.csv, transport.h5, summary.json,
// plots/*.png} and keeps its LIGGGHTS run (VTK dumps, log) in
// transport/jobs/<label>/run; finalize gathers the classes' statistics in
// transport/feed_classes.{json,csv}.
#pragma once

#include "stages/stage.h"

namespace mill {

class TransportStage : public Stage {
 public:
  std::string name() const override { return "transport"; }
  std::string description() const override {
    return "track ore lumps through the sampled flow (LIGGGHTS, one-way coupled)";
  }
  Plan plan(const StageContext& ctx) const override;
  std::vector<std::string> reads(const config::CaseConfig&) const override { return {"sample"}; }
  void run_job(StageContext& ctx, const JobSpec& job,
               const std::filesystem::path& job_dir) override;
  std::string damaged_outputs(const StageContext& ctx, const JobSpec& job) const override;
  void finalize(StageContext& ctx, const std::vector<JobSpec>& jobs) override;
  std::string damaged_merged_outputs(const StageContext& ctx,
                                     const std::vector<JobSpec>& jobs) const override;
};

}  // namespace mill
