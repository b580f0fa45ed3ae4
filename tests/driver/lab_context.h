// The calibrate stage's context for tests that drive its lab tests
// (calibrate::LabBench, pack_specimen, run_checks) with real LIGGGHTS runs:
// the case file in `dir` loaded against `project`, the run folder `dir`, the
// engine runner, progress to dir/progress.log.
#pragma once

#include <stdlib.h>

#include <filesystem>
#include <fstream>

#include "config/case_config.h"
#include "engine/runner.h"
#include "progress.h"
#include "stages/stage.h"

namespace mill::test {

struct LabContext {
  LabContext(const std::filesystem::path& dir, const std::filesystem::path& project)
      : cfg((setenv("MILL_LIGGGHTS", LIGGGHTS_MILL_EXE, 1),
             config::load_case(dir / "case.yaml", project))),
        log(dir / "progress.log"),
        progress(log, false),
        ctx{cfg, opts, dir, dir / "calibrate", runner, progress} {
    opts.output = dir;
  }
  LabContext(const LabContext&) = delete;
  LabContext& operator=(const LabContext&) = delete;

  const config::CaseConfig cfg;
  RunOptions opts;
  engine::Runner runner;
  std::ofstream log;
  Progress progress;
  StageContext ctx;
};

}  // namespace mill::test
