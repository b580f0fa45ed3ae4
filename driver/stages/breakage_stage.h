// Stage 'breakage': one bonded-lump impact per (velocity, angle, repeat),
// each followed by the fragment analysis; finalize merges the campaign into
// breakage/summary.csv, fractions.csv, breakage.h5, plots, the critical
// velocity and the comminution efficiency.
#pragma once

#include <map>

#include "stages/stage.h"

namespace mill {

class BreakageStage : public Stage {
 public:
  std::string name() const override { return "breakage"; }
  std::string description() const override {
    return "impact of one bonded ore lump per condition, fragment analysis";
  }
  Plan plan(const StageContext& ctx) const override;
  void run_job(StageContext& ctx, const JobSpec& job, const std::filesystem::path& job_dir) override;
  void finalize(StageContext& ctx, const std::vector<JobSpec>& jobs) override;
  std::string damaged_outputs(const StageContext& ctx, const JobSpec& job) const override;
  // The calibrated bonds; with breakage.conditions = transport also the
  // transport's impacts, which decide the jobs (one per binned condition).
  std::vector<std::string> reads(const config::CaseConfig& cfg) const override;
  std::vector<std::string> jobs_from(const config::CaseConfig& cfg) const override;

 private:
  // breakage/product.csv and product.json: the mill product per rotor speed
  // when the conditions came from the transport stage.
  // With in-mill runs, each rotor speed's entry also holds their product
  // (`in_mill`, from write_in_mill_results).
  void write_mill_product(StageContext& ctx, const std::vector<JobSpec>& jobs,
                          const std::map<double, nlohmann::json>& in_mill);
};

// The canonical inputs of one impact (the job id is their hash): case keys of
// the lump and the run, the ore, the bond parameters, the condition.
nlohmann::json impact_inputs(const StageContext& ctx, double velocity, double angle, int repeat);

// The outputs run_impact writes into `dir` exist and parse: "" or the reason.
std::string damaged_impact_outputs(const std::filesystem::path& dir);

// The one-line summary of an impact from its result.json.
std::string impact_line(const nlohmann::json& result);

// One impact into `out_dir` (used by run_job and by `orchestrate impact`):
// runs the deck, analyses the fragments and the energy ledger, writes
// summary.csv, fractions.csv, impact.h5, energy_ledger.csv, energy_ledger.png,
// fragments.vtp and result.json there. Returns the summary line.
std::string run_impact(StageContext& ctx, double velocity, double angle, int repeat,
                       const std::filesystem::path& out_dir, const std::string& label);

}  // namespace mill
