// The contract every stage implements. A stage splits its work into jobs
// (plan), runs one job into its own folder (run_job), and after all jobs are
// done merges them into the stage's declared outputs (finalize). A stage reads
// only the declared outputs of earlier stages (files under the run folder),
// never another stage's internals.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "config/case_config.h"

namespace mill {

namespace engine {
class Runner;
}
class Progress;

// Options of one orchestrate invocation that stages may need.
struct RunOptions {
  std::filesystem::path output;  // run folder: runs/<case name> by default
  int np = 1;                    // MPI ranks per engine run
  int jobs = 1;                  // engine runs at once
  bool force = false;            // redo done jobs
  // Set when running under a scheduler (the Slurm scripts of `orchestrate hpc`
  // export MILL_SCHEDULER_JOB and MILL_SCHEDULER_LOG): kept in each job's STATUS.
  std::string scheduler_job;  // e.g. "1234_5" (array job 1234, task 5)
  std::string scheduler_log;  // that scheduler job's output file
};

// One unit of work: the unit of an HPC job-array task.
struct JobSpec {
  std::string label;      // folder name, readable and unique in the stage: "v150_a90_r0"
  nlohmann::json inputs;  // canonical inputs; the job id is their hash
  std::string summary;    // one line shown by --list-tasks and --dry-run
};

// What a stage will do: its jobs, and a note (e.g. "waits for transport").
struct Plan {
  std::vector<JobSpec> jobs;
  std::string note;
  // Said as warnings when the stage runs (not in --dry-run, where an
  // earlier stage of the same command may still change them).
  std::vector<std::string> warnings;
};

// Everything a stage may touch while running.
struct StageContext {
  const config::CaseConfig& cfg;
  const RunOptions& opts;
  std::filesystem::path run_dir;    // opts.output
  std::filesystem::path stage_dir;  // run_dir / stage name
  engine::Runner& runner;
  Progress& progress;
};

// Thrown by a stage whose work is not implemented yet: exit status 3.
struct NotImplemented : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Thrown when a stage needs an earlier stage's output that is missing.
struct MissingInput : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class Stage {
 public:
  virtual ~Stage() = default;
  virtual std::string name() const = 0;
  virtual std::string description() const = 0;
  // False for stages a later issue implements: run() then says so plainly.
  virtual bool implemented() const { return true; }
  // The jobs of this stage for this case (cheap; no engine runs).
  virtual Plan plan(const StageContext& ctx) const = 0;
  // Run one job; write its outputs into job_dir (atomically); throw on failure.
  virtual void run_job(StageContext& ctx, const JobSpec& job, const std::filesystem::path& job_dir) = 0;
  // After every job is done: merge into the stage's declared outputs.
  virtual void finalize(StageContext& /*ctx*/, const std::vector<JobSpec>& /*jobs*/) {}
  // A job is done only if its declared outputs exist and parse: "" when they
  // do, else what is missing or damaged (the job is then run again).
  virtual std::string damaged_outputs(const StageContext& /*ctx*/, const JobSpec& /*job*/) const { return ""; }
  // The same for the merged outputs that finalize makes from `jobs` and
  // later stages read: "" when they exist and parse, else what is damaged
  // (rebuilt by finalize when the jobs are done).
  virtual std::string damaged_merged_outputs(const StageContext& /*ctx*/, const std::vector<JobSpec>& /*jobs*/) const {
    return "";
  }
  // Earlier stages whose declared outputs this stage reads (what a scheduler
  // chain makes it wait for), and those of them whose outputs decide how many
  // jobs it has (its plan can only be made once they have run).
  virtual std::vector<std::string> reads(const config::CaseConfig& /*cfg*/) const { return {}; }
  virtual std::vector<std::string> jobs_from(const config::CaseConfig& /*cfg*/) const { return {}; }
  // True for a stage whose jobs each start several engine runs of their own
  // (the calibrate stage's fits): the pipeline then runs all its jobs at
  // once and limits the engine runs, not the jobs, to RunOptions::jobs
  // (engine::Runner::limit_runs), so that no core idles while one job waits
  // for its own runs. Each job may then ask for up to RunOptions::jobs runs
  // at once.
  virtual bool jobs_share_engine_runs() const { return false; }
};

// The stages in pipeline order: flow, sample, transport, calibrate, breakage, report.
std::vector<std::unique_ptr<Stage>> make_stages();
const std::vector<std::string>& stage_names();

}  // namespace mill
