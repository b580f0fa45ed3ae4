// Child-process engine runner with signal forwarding and log checks.
#include "engine/runner.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <deque>
#include <fstream>
#include <mutex>
#include <thread>

extern char** environ;

namespace mill::engine {
namespace fs = std::filesystem;

namespace {

// Process groups of running children; read by the signal handler.
constexpr int kMaxChildren = 64;
std::array<std::atomic<pid_t>, kMaxChildren> g_children{};
std::atomic<int> g_signal{0};

void forward_signal(int sig) {
  g_signal.store(sig);
  for (auto& c : g_children) {
    pid_t p = c.load();
    if (p > 0) kill(-p, sig);
  }
}

int register_child(pid_t pgid) {
  for (int i = 0; i < kMaxChildren; ++i) {
    pid_t expected = 0;
    if (g_children[i].compare_exchange_strong(expected, pgid)) return i;
  }
  return -1;
}

bool is_root() { return geteuid() == 0; }

}  // namespace

Interrupted::Interrupted(int sig)
    : std::runtime_error(fmt::format("interrupted by signal {} ({})", sig, strsignal(sig))), signal(sig) {}

void install_signal_forwarding() {
  struct sigaction sa {};
  sa.sa_handler = forward_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

int pending_signal() { return g_signal.load(); }

void throw_if_interrupted() {
  if (const int sig = pending_signal()) throw Interrupted(sig);
}

std::string find_program(const std::string& name) {
  if (name.find('/') != std::string::npos) return access(name.c_str(), X_OK) == 0 ? name : "";
  const char* path = getenv("PATH");
  std::string p = path ? path : "/usr/bin:/bin";
  size_t start = 0;
  while (start <= p.size()) {
    size_t end = p.find(':', start);
    if (end == std::string::npos) end = p.size();
    std::string dir = p.substr(start, end - start);
    if (!dir.empty()) {
      std::string cand = dir + "/" + name;
      if (access(cand.c_str(), X_OK) == 0) return cand;
    }
    start = end + 1;
  }
  return "";
}

std::map<std::string, std::string> openfoam_env() {
  // Debian's OpenFOAM v1912 needs WM_PROJECT_DIR to find its etc/ dictionaries.
  std::map<std::string, std::string> e;
  const char* have = getenv("WM_PROJECT_DIR");
  e["WM_PROJECT_DIR"] = have ? have : "/usr/share/openfoam";
  e["FOAM_SIGFPE"] = "true";  // floating-point exceptions abort: a NaN is an error, not a result
  return e;
}

std::vector<std::string> Runner::full_argv(const Command& cmd) {
  std::vector<std::string> a;
  if (cmd.np > 1 || cmd.mpi) {
    a = {"mpirun", "-np", std::to_string(cmd.np)};
    if (is_root()) a.push_back("--allow-run-as-root");
    // A workstation may have fewer cores than ranks asked for.
    a.push_back("--oversubscribe");
    for (const auto& [k, v] : cmd.env) {
      (void)v;
      a.push_back("-x");
      a.push_back(k);
    }
  }
  a.insert(a.end(), cmd.argv.begin(), cmd.argv.end());
  return a;
}

std::string Runner::tail(const fs::path& file, int n) {
  std::ifstream in(file);
  std::deque<std::string> lines;
  std::string l;
  while (std::getline(in, l)) {
    lines.push_back(l);
    if (static_cast<int>(lines.size()) > n) lines.pop_front();
  }
  std::string out;
  for (const auto& x : lines) out += "    " + x + "\n";
  return out;
}

std::vector<std::string> Runner::scan_errors(const fs::path& log, Engine e) {
  std::vector<std::string> errs;
  if (e == Engine::Generic) return errs;
  std::ifstream in(log);
  std::string l;
  while (std::getline(in, l)) {
    bool hit = false;
    if (e == Engine::Liggghts) {
      hit = l.rfind("ERROR", 0) == 0;  // "ERROR: ..." / "ERROR on proc N: ..."
      // Warnings that invalidate a run: elements that moved more than half
      // the neighbour skin between list builds (contacts were missed) and
      // elements lost from the domain.
      long n = 0;
      if (std::sscanf(l.c_str(), "Dangerous builds = %ld", &n) == 1 && n > 0) {
        errs.push_back(l + " (elements moved more than half the neighbour skin between neighbour-list builds: "
                           "contacts were missed; the time step is too long for the speeds)");
        continue;
      }
      if (l.find("Lost atoms") != std::string::npos) hit = true;
    }
    if (e == Engine::OpenFoam) hit = l.find("FOAM FATAL") != std::string::npos;
    if (hit) errs.push_back(l);
  }
  return errs;
}

// The run slots of Runner::limit_runs: a ticket queue, so that runs start in
// the order they asked (no fit starves while others take every free core).
struct Runner::Slots {
  std::mutex mu;
  std::condition_variable cv;
  int limit = 0;               // <= 0: no limit
  int running = 0;             // runs holding a slot
  unsigned long issued = 0;    // tickets handed out
  unsigned long admitted = 0;  // tickets let through, in order

  // Waits for this caller's turn and a free slot; false when a signal ends
  // the wait (the run then throws Interrupted, as every waiting run does).
  bool acquire() {
    std::unique_lock<std::mutex> lk(mu);
    const unsigned long ticket = issued++;
    while (ticket != admitted || (limit > 0 && running >= limit)) {
      if (pending_signal()) return false;
      cv.wait_for(lk, std::chrono::milliseconds(200));
    }
    ++admitted;
    ++running;
    cv.notify_all();
    return true;
  }
  void release() {
    std::lock_guard<std::mutex> g(mu);
    --running;
    cv.notify_all();
  }
};

void Runner::limit_runs(int n) {
  if (!slots_) slots_ = std::make_shared<Slots>();
  std::lock_guard<std::mutex> g(slots_->mu);
  slots_->limit = n;
  slots_->cv.notify_all();
}

Result Runner::run(const Command& cmd, const Poll& poll) {
  // A run slot for the length of the run (none to hold without a limit).
  struct SlotHold {
    Slots* s;
    ~SlotHold() {
      if (s) s->release();
    }
  } const slot_hold{slots_ && slots_->acquire() ? slots_.get() : nullptr};
  if (pending_signal()) throw Interrupted(pending_signal());
  const auto argv_s = full_argv(cmd);
  if (argv_s.empty()) throw std::logic_error("Runner::run: empty command");
  const std::string prog = find_program(argv_s[0]);
  if (prog.empty())
    throw EngineError(fmt::format("{}: program '{}' not found on PATH (is the project installed? see README)", cmd.job,
                                  argv_s[0]),
                      Result{127, 0, 0, {}});
  fs::create_directories(cmd.log.parent_path());

  std::vector<char*> argv;
  for (const auto& s : argv_s) argv.push_back(const_cast<char*>(s.c_str()));
  argv.push_back(nullptr);
  // Own Open MPI session base per run: concurrent engine runs (jobs, tests)
  // otherwise race on creating /tmp/ompi.<host>.<uid> and orte_init fails.
  char ompi_tmpl[] = "/tmp/mill-ompi-XXXXXX";
  const char* ompi_dir = cmd.env.count("OMPI_MCA_orte_tmpdir_base") ? nullptr : mkdtemp(ompi_tmpl);
  struct RemoveDir {
    const char* d;
    ~RemoveDir() {
      std::error_code ec;
      if (d) fs::remove_all(d, ec);
    }
  } remove_ompi{ompi_dir};
  // Environment built before fork: the child only calls async-signal-safe functions.
  std::vector<std::string> env_s;
  for (char** e = environ; *e; ++e) {
    const std::string kv = *e;
    if (!cmd.env.count(kv.substr(0, kv.find('=')))) env_s.push_back(kv);
  }
  for (const auto& [k, v] : cmd.env) env_s.push_back(k + "=" + v);
  if (ompi_dir) {
    env_s.erase(std::remove_if(env_s.begin(), env_s.end(),
                               [](const std::string& kv) { return kv.rfind("OMPI_MCA_orte_tmpdir_base=", 0) == 0; }),
                env_s.end());
    env_s.push_back(std::string("OMPI_MCA_orte_tmpdir_base=") + ompi_dir);
  }
  std::vector<char*> envp;
  for (const auto& s : env_s) envp.push_back(const_cast<char*>(s.c_str()));
  envp.push_back(nullptr);

  const auto t0 = std::chrono::steady_clock::now();
  const pid_t parent = getpid();
  const long open_max = sysconf(_SC_OPEN_MAX);  // the child's fallback if close_range fails
  pid_t pid = fork();
  if (pid < 0) throw std::runtime_error(std::string("fork failed: ") + strerror(errno));
  if (pid == 0) {
    setpgid(0, 0);  // own process group: signals reach the whole engine tree
    // An orchestrate killed outright (SIGKILL) forwards nothing: the kernel
    // then sends SIGTERM to the engine, which mpirun passes to its ranks.
    // It fires when the forking thread ends; that thread waits for the child.
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(125);  // orchestrate died before the prctl
    int fd = open(cmd.log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0) _exit(126);
    dup2(fd, 1);
    dup2(fd, 2);
    close(fd);
    int devnull = open("/dev/null", O_RDONLY);
    if (devnull >= 0) dup2(devnull, 0);
    if (!cmd.cwd.empty() && chdir(cmd.cwd.c_str()) != 0) _exit(126);
    // The engine gets stdin, stdout and stderr only. Files another thread of
    // orchestrate has open at the fork (an HDF5 file being written: HDF5
    // opens without O_CLOEXEC and locks with flock) would otherwise stay open
    // in the engine for its whole run, and the lock with them: that thread's
    // next open of its own file then failed ("HDF5 could not open the file
    // for writing", an impact job lost now and then with --jobs 2).
    if (syscall(SYS_close_range, 3U, ~0U, 0U) != 0)
      for (long f = 3; f < open_max; ++f) close(static_cast<int>(f));
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    execve(prog.c_str(), argv.data(), envp.data());
    _exit(127);
  }
  setpgid(pid, pid);  // also from the parent, to close the race
  const int slot = register_child(pid);
  if (pending_signal()) kill(-pid, pending_signal());

  int status = 0;
  auto last_poll = std::chrono::steady_clock::now();
  for (;;) {
    pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    if (r < 0 && errno != EINTR) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (poll && std::chrono::steady_clock::now() - last_poll > std::chrono::seconds(1)) {
      last_poll = std::chrono::steady_clock::now();
      poll(cmd.log);
    }
  }
  if (slot >= 0) g_children[slot].store(0);

  Result res;
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (WIFEXITED(status)) {
    res.exit_code = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    res.exit_code = -1;
    res.signal = WTERMSIG(status);
  }
  res.error_lines = scan_errors(cmd.log, cmd.engine);
  if (pending_signal()) throw Interrupted(pending_signal());
  if (res.exit_code != 0 || !res.error_lines.empty()) {
    std::string why = res.signal ? fmt::format("killed by signal {} ({})", res.signal, strsignal(res.signal))
                                 : fmt::format("exit status {}", res.exit_code);
    if (res.exit_code == 0) why += ", but the log has engine errors";
    if (res.exit_code == 127 && res.error_lines.empty()) why += " (program could not be started)";
    std::string first = res.error_lines.empty() ? "" : "\n  engine error: " + res.error_lines.front();
    throw EngineError(fmt::format("{}: {} failed: {}{}\n  log: {}\n  last lines of the log:\n{}", cmd.job, argv_s[0],
                                  why, first, cmd.log.string(), tail(cmd.log, 15)),
                      res);
  }
  return res;
}

Result run_python(Runner& runner, const fs::path& script, const std::vector<std::string>& args,
                  const fs::path& log, const std::string& job) {
  Command c;
  c.argv = {"/usr/bin/python3", script.string()};
  c.argv.insert(c.argv.end(), args.begin(), args.end());
  c.cwd = log.parent_path();
  c.log = log;
  c.job = job;
  return runner.run(c);
}

}  // namespace mill::engine
