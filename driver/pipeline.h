// Running stages in order: planning, dry runs, task lists, single tasks
// (HPC array units) and full runs with J jobs at once, resuming done jobs.
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "config/case_config.h"
#include "stages/stage.h"

namespace mill {

// Exit statuses of orchestrate.
enum ExitCode : int {
  kExitOk = 0,
  kExitFailed = 1,          // a job or engine run failed
  kExitBadInput = 2,        // bad case file, ore card or command line
  kExitNotImplemented = 3,  // a requested stage is not implemented yet
};

struct Invocation {
  std::vector<std::string> stages;  // in pipeline order
  RunOptions opts;
  bool np_given = false;  // --np on the command line: every stage's ranks (else
                          // resources.<stage>.np when the case sets it, else resources.np)
  bool dry_run = false;
  bool list_tasks = false;
  std::optional<int> task;  // run only job I of the (single) stage
  bool merge_only = false;  // run no job: merge if every job is done, else name those that are not
};

// Run the invocation; returns an ExitCode (or 128+signal when interrupted).
int run_pipeline(const config::CaseConfig& cfg, const Invocation& inv, std::ostream& out);

// `orchestrate impact`: one impact into opts.output, the folder being the
// job's own (job.json, STATUS); `dry_run` prints what it would do.
int run_single_impact(const config::CaseConfig& cfg, const RunOptions& opts, double velocity, double angle,
                      int repeat, bool dry_run, std::ostream& out);

// Number of jobs the (single) stage of `inv` has for this case.
int count_tasks(const config::CaseConfig& cfg, const Invocation& inv);

// Expand "all" or a range FIRST-LAST ("transport-breakage") to its stages in
// pipeline order; validate names (ConfigError naming --stage).
std::vector<std::string> resolve_stages(const std::string& stage);

}  // namespace mill
