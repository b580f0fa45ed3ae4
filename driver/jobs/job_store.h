// Hash-keyed jobs with a STATUS file each, written by write-then-rename.
// A job folder holds job.json (label, id, inputs) and STATUS:
//   pending | running (pid, host, process start) | done | failed (reason),
//   with the scheduler job and its log when a scheduler ran it.
// A rerun skips done jobs whose id matches, reruns failed and stale-running
// jobs and jobs whose inputs changed. Success is never inferred from a log.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <ostream>
#include <string>

namespace mill::jobs {

enum class State { None, Pending, Running, Done, Failed };
std::string state_name(State s);

struct Status {
  State state = State::None;
  std::string id;      // job id the status belongs to
  long pid = 0;        // running: process that runs it
  std::string host;    // running: host of that process
  unsigned long long start_ticks = 0;  // running: process start (from /proc), guards pid reuse
  std::string reason;  // failed: why
  std::string time;    // UTC time of the change
  std::string scheduler_job;  // the scheduler job that ran it (e.g. Slurm "1234_5"), if any
  std::string log;            // that scheduler job's output file, if any
};

// What to do with a job on this run.
enum class Decision { Run, Skip, Busy };
struct Verdict {
  Decision decision;
  std::string why;  // "new", "done", "inputs changed", "failed before: ...", "stale (pid 12 gone)", ...
};

// Job id: 16 hex digits of a 64-bit FNV-1a hash of the canonical JSON.
std::string job_id(const nlohmann::json& inputs);

// Write `content` to `file` atomically: FILE.tmp.<pid>, fsync, rename.
// The time now, UTC, ISO 8601 to the second (2026-01-01T00:00:00Z).
std::string utc_now();

void atomic_write(const std::filesystem::path& file, const std::string& content);
// Stream into FILE.tmp.<pid>, then rename: for outputs written piece by piece.
void atomic_write_with(const std::filesystem::path& file, const std::function<void(std::ostream&)>& writer);

class JobStore {
 public:
  explicit JobStore(std::filesystem::path stage_dir);
  // A folder that is itself the job's folder (job.json and STATUS beside
  // its outputs), e.g. the output of `orchestrate impact`.
  static JobStore single(std::filesystem::path job_dir);

  std::filesystem::path job_dir(const std::string& label) const;
  Status read_status(const std::string& label) const;
  // Decide whether to run a job whose canonical inputs are `inputs`.
  Verdict decide(const std::string& label, const nlohmann::json& inputs, bool force) const;

  // Create the folder, write job.json and STATUS=running (this process, and
  // the scheduler job and log it runs in, when given; they stay in STATUS).
  void mark_running(const std::string& label, const nlohmann::json& inputs, const std::string& scheduler_job = "",
                    const std::string& log = "") const;
  void mark_done(const std::string& label) const;
  void mark_failed(const std::string& label, const std::string& reason) const;

  // True if process `pid` on this host is alive and started at `start_ticks`.
  static bool process_alive(long pid, unsigned long long start_ticks);
  static unsigned long long process_start_ticks(long pid);
  static std::string hostname();

 private:
  void write_status(const std::string& label, const Status& s) const;
  std::filesystem::path stage_dir_;
  bool single_ = false;  // job_dir(label) is stage_dir_ itself
};

}  // namespace mill::jobs
