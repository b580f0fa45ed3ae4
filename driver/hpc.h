// Scheduler scripts for a stage: a job array with one task per job of the
// stage (`--task $SLURM_ARRAY_TASK_ID`) and a dependent merge job that runs
// the stage once more (every task done: it only merges) and the report.
#pragma once

#include <filesystem>
#include <string>

#include "config/case_config.h"

namespace mill {

struct HpcOptions {
  std::string scheduler = "slurm";
  std::string stage;
  std::filesystem::path output;  // run folder
  int np = 1;                    // MPI ranks per array task
  std::string partition;         // optional
  std::string account;           // optional
  std::string time = "02:00:00"; // wall-time limit per task
  std::string mem;               // e.g. 4G, optional
  int max_parallel = 0;          // %N throttle of the array, 0 = none
};

// Throws a ConfigError naming the option when a value cannot go into an
// #SBATCH line as given: Slurm time and memory formats, names without
// blanks or control characters, counts in range, a run folder on one line.
void check_hpc_options(const HpcOptions& opt);

// Write <output>/hpc/<stage>.array.sh, <stage>.merge.sh and submit_<stage>.sh;
// returns a short text for the user. Throws ConfigError on bad options.
std::string write_hpc_scripts(const config::CaseConfig& cfg, const HpcOptions& opt, int n_tasks,
                              const std::string& orchestrate_exe);

}  // namespace mill
