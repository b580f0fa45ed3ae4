// Stage 'flow': mesh the mill and solve the steady MRF gas flow (OpenFOAM).
//
// One job per rotor speed. Work happens in <run>/flow/jobs/<rpm label>/case;
// on success the declared outputs appear at once (rename of a temp folder):
//   <run>/flow/<rpm label>/case/              the solved OpenFOAM case (case.foam inside)
//   <run>/flow/<rpm label>/geometry/*.stl     housing, flywheel, inlet, outlet (m)
//   <run>/flow/<rpm label>/flow_report.json   mass flows, y+, rim speed, cells, iterations
// docs/flow.md describes the case and the report; the job's steps live in
// stages/flow/ (writing the case, running OpenFOAM, reading its results, the report).
#pragma once

#include <filesystem>
#include <string>

#include "stages/stage.h"

namespace mill {

class FlowStage : public Stage {
 public:
  std::string name() const override { return "flow"; }
  std::string description() const override {
    return "mesh the mill and solve the steady MRF gas flow (OpenFOAM)";
  }
  Plan plan(const StageContext& ctx) const override;
  void run_job(StageContext& ctx, const JobSpec& job,
               const std::filesystem::path& job_dir) override;
  void finalize(StageContext& ctx, const std::vector<JobSpec>& jobs) override;
  std::string damaged_outputs(const StageContext& ctx, const JobSpec& job) const override;
  std::string damaged_merged_outputs(const StageContext& ctx,
                                     const std::vector<JobSpec>& jobs) const override;
};

namespace flow {

// Declared output folder of one rotor speed: <run>/flow/<label>.
std::filesystem::path output_dir(const std::filesystem::path& run_dir, const std::string& label);

}  // namespace flow
}  // namespace mill
