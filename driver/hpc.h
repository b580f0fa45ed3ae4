// Scheduler scripts for one stage or a contiguous range of stages. Each stage
// becomes a Slurm job array (one task per job of the stage) and a merge job,
// or one job for the small stages (sample, calibrate, report); a submit script
// chains them with --dependency=afterok along the stages' declared inputs.
// Where a stage's job count comes from an earlier stage's output (breakage at
// the transport's conditions), a planning job runs after that stage, counts
// the jobs with `orchestrate --list-tasks` and submits the array of that size
// and the stages after it. Every script comes from one template (header()).
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "config/case_config.h"

namespace mill {

struct HpcOptions {
  std::string scheduler = "slurm";
  std::string stage;  // as given: a stage, FIRST-LAST or all (names the submit script)
  std::vector<std::string> stages;  // the stages it stands for, in pipeline order
  std::filesystem::path output;     // run folder
  int np = 0;  // --np: ranks per flow task (and per task of a stage scripted alone); 0: not given
  std::string partition;  // every job's; "": resources.<stage>.partition
  std::string account;    // optional
  std::string time;       // every job's wall-time limit; "": resources.<stage>.time
  std::string mem;        // every job's memory, e.g. 4G; "": resources.<stage>.mem
  int max_parallel = 0;   // %N throttle of the arrays, 0 = none
};

// Throws a ConfigError naming the option when a value cannot go into an
// #SBATCH line as given: Slurm time and memory formats, names without
// blanks or control characters, counts in range, a run folder on one line.
void check_hpc_options(const HpcOptions& opt);

// What the jobs of one stage ask of Slurm; each value with where it came from
// (an option or a case-file key), for error messages.
struct StageResources {
  int np = 1;  // MPI ranks per task (--ntasks)
  std::string time, time_from;
  std::string mem, mem_from;  // "" = the partition's default
  std::string partition, partition_from;
  std::string merge_time, merge_time_from;  // the stage's merge and planning jobs
};

// Resources of `stage`: options, else the case's resources.<stage>.*, else the
// stage's default (the flow takes --np or resources.np ranks; the other MPI
// stages one rank unless resources.<stage>.np says otherwise, or --np is given
// for a stage scripted alone).
StageResources stage_resources(const config::CaseConfig& cfg, const HpcOptions& opt,
                               const std::string& stage);

// One "#SBATCH --option=value" line: the one place values enter #SBATCH lines.
// The value must be one printable line without '"' or '\'; it is double-quoted
// when it holds a blank or '#'. Otherwise a ConfigError names `source`.
std::string sbatch_directive(const std::string& option, const std::string& value,
                             const std::string& source);

// Write the scripts into <output>/hpc/ and return a short text for the user.
// n_tasks(stage) is the stage's job count now (0: none yet); `exe` is the
// orchestrate the jobs run. Throws ConfigError on bad options.
std::string write_hpc_scripts(const config::CaseConfig& cfg, const HpcOptions& opt,
                              const std::function<int(const std::string&)>& n_tasks,
                              const std::string& exe);

}  // namespace mill
