// flow_report.json of a solved flow case and the job's closing progress
// lines (docs/flow.md, "flow_report.json").
#pragma once

#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "stages/flow/case_files.h"
#include "stages/flow/foam_runs.h"
#include "stages/stage.h"

namespace mill::flow {

// Wall times of a job: when it started, how long meshing and solving took.
struct WallTimes {
  std::chrono::steady_clock::time_point start;
  double mesh_seconds = 0;
  double solve_seconds = 0;
};

// The report of the solved case in `work` (mass flows, backflow, shaft power,
// temperatures, y+, rim speed, residuals, times); warns when the start-up
// temperature guard still clips at the end.
nlohmann::json flow_report(StageContext& ctx, const JobSettings& s,
                           const std::filesystem::path& work, long cells, const Solution& sol,
                           const WallTimes& times);

// The job's summary line from its report, and a warning when it did not
// converge (naming the published solver log, `solver_log`).
void announce_result(StageContext& ctx, const JobSettings& s, const nlohmann::json& rep,
                     const Solution& sol, const std::filesystem::path& solver_log);

}  // namespace mill::flow
