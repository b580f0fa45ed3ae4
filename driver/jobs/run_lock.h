// The run-folder lock: one command writes into a stage of a run folder (or
// an impact folder) at a time. A command that runs stages holds an exclusive
// flock on <run>/orchestrate-<stage>.lock for each stage it runs, and
// `orchestrate impact` one on <folder>/orchestrate.lock; the tasks of a
// scheduler array (--task) hold their stage's lock shared, so they run side
// by side but never beside a whole-stage run. Commands on different stages
// (a scheduler's flow merge beside the calibration) do not wait for each
// other. The lock file names its holders (pid, host, start, command) for the
// message of the command that is turned away. The kernel drops the lock when
// its holder dies, so a killed command never leaves the folder locked.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>

namespace mill::jobs {

// Thrown when another command holds the run folder; the message names it.
struct RunFolderBusy : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class RunLock {
 public:
  enum class Mode { Shared, Exclusive };
  // Takes the lock without waiting (creating the folder); throws
  // RunFolderBusy naming the holder when another command has it.
  // `stage` empty: the whole folder (an impact folder).
  RunLock(const std::filesystem::path& run_dir, Mode mode, const std::string& command,
          const std::string& stage = "");
  ~RunLock();
  RunLock(const RunLock&) = delete;
  RunLock& operator=(const RunLock&) = delete;

  static std::filesystem::path file(const std::filesystem::path& run_dir,
                                    const std::string& stage = "");
  // Not empty when the file system has no locks: the command runs unlocked,
  // and this says so (to print as a warning).
  const std::string& warning() const { return warning_; }

 private:
  int fd_ = -1;
  std::string warning_;
};

}  // namespace mill::jobs
