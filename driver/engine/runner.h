// Starting engine programs (LIGGGHTS, OpenFOAM utilities and solvers) as
// child processes: through mpirun when np > 1, log beside the job, signals
// forwarded, success judged by exit status and the engine's own error lines.
#pragma once

#include <chrono>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace mill::engine {

// Which engine's error lines to look for in the log.
enum class Engine { Generic, Liggghts, OpenFoam };

struct Command {
  std::vector<std::string> argv;           // program and arguments (no mpirun)
  std::filesystem::path cwd;               // working directory (must exist)
  std::filesystem::path log;               // stdout+stderr go here (truncated)
  std::map<std::string, std::string> env;  // extra environment
  int np = 1;                              // > 1: run through mpirun -np N
  bool mpi = false;                        // true: use mpirun even for np == 1
  Engine engine = Engine::Generic;
  std::string job;  // label for messages: "breakage/v150_a90_r0"
};

struct Result {
  int exit_code = 0;                     // exit status, or -1 when killed by a signal
  int signal = 0;                        // terminating signal, 0 if none
  double seconds = 0;                    // wall time
  std::vector<std::string> error_lines;  // the engine's own error lines
};

// A failed engine run: the message names the job, the log and its last lines.
struct EngineError : std::runtime_error {
  EngineError(const std::string& msg, Result r) : std::runtime_error(msg), result(std::move(r)) {}
  Result result;
};

// Raised when orchestrate itself got SIGINT/SIGTERM while a child ran.
struct Interrupted : std::runtime_error {
  explicit Interrupted(int sig);
  int signal;
};

class Runner {
 public:
  // Called about once a second while the child runs, with the log path.
  using Poll = std::function<void(const std::filesystem::path& log)>;

  // Run and wait. Throws EngineError on failure, Interrupted on a signal.
  // With a limit set (limit_runs), first waits for a free run slot; the
  // wait is not part of Result::seconds.
  Result run(const Command& cmd, const Poll& poll = nullptr);

  // At most n runs of this runner (and its copies) at once, from any
  // number of threads; they start in the order they asked. n <= 0: no
  // limit (the default). The calibrate stage runs all its fits at once
  // and lets this hand out the cores (resources.jobs) run by run.
  void limit_runs(int n);

  // The full argv actually executed (mpirun prefix included), for logs.
  static std::vector<std::string> full_argv(const Command& cmd);

  // Last n lines of a file (for failure messages).
  static std::string tail(const std::filesystem::path& file, int n);

  // Error lines the given engine writes in its log.
  static std::vector<std::string> scan_errors(const std::filesystem::path& log, Engine e);

 private:
  struct Slots;  // the run slots of limit_runs, shared by copies
  std::shared_ptr<Slots> slots_;
};

// Runs a plotting script of postprocess/ with Debian's python3 (it has
// matplotlib): `python3 script args...` in the folder of `log`, its output
// into `log`; `job` names it in messages. Throws as Runner::run does.
Result run_python(Runner& runner, const std::filesystem::path& script,
                  const std::vector<std::string>& args, const std::filesystem::path& log,
                  const std::string& job);

// Install SIGINT/SIGTERM handlers that forward the signal to running
// children (their process groups) and make Runner::run throw Interrupted.
void install_signal_forwarding();
// The signal received so far, 0 if none.
int pending_signal();
// Throws Interrupted when SIGINT or SIGTERM has arrived: long loops that
// start no child (planning) call it so that they stop as a run does.
void throw_if_interrupted();

// Environment for OpenFOAM binaries (WM_PROJECT_DIR etc.).
std::map<std::string, std::string> openfoam_env();

// Path of a program: $PATH lookup, "" if not found.
std::string find_program(const std::string& name);

}  // namespace mill::engine
