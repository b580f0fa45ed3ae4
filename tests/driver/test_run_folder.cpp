// A run folder has one writer at a time (the run-folder lock), a STATUS of a
// process that is gone reads as stale, an engine does not outlive a killed
// orchestrate, and planning stops on SIGINT and SIGTERM as running does.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "cli.h"
#include "engine/runner.h"
#include "jobs/job_store.h"
#include "jobs/run_lock.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using mill::jobs::RunFolderBusy;
using mill::jobs::RunLock;

namespace {

// An empty folder, removed when the test passes.
mill::test::TempDir fresh_dir(const std::string& name) {
  return mill::test::TempDir("mill_run_folder_" + name + "_" + std::to_string(getpid()));
}

struct Out {
  int status;
  std::string text;
};

Out orchestrate(const std::string& args) {
  const std::string cmd = "'" + std::string(ORCHESTRATE_EXE) + "' " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string text;
  std::array<char, 4096> buf{};
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) text.append(buf.data(), n);
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, text};
}

const std::string kData = MILL_TEST_DATA;

TEST(RunLock, SecondWriterIsTurnedAwayNamingTheHolder) {
  const auto d = fresh_dir("lock");
  auto first = std::make_unique<RunLock>(d, RunLock::Mode::Exclusive, "orchestrate --stage all");
  try {
    RunLock second(d, RunLock::Mode::Exclusive, "orchestrate --stage breakage");
    FAIL() << "a second exclusive lock was granted";
  } catch (const RunFolderBusy& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("in use by another orchestrate (pid " + std::to_string(getpid()) + " on "),
              std::string::npos)
        << m;
    EXPECT_NE(m.find(" since 20"), std::string::npos) << m;
    EXPECT_NE(m.find("(orchestrate --stage all)"), std::string::npos) << m;
  }
  EXPECT_THROW(RunLock(d, RunLock::Mode::Shared, "orchestrate --task 1"), RunFolderBusy);
  first.reset();  // released: the next writer gets it
  EXPECT_NO_THROW(RunLock(d, RunLock::Mode::Exclusive, "orchestrate --stage breakage"));
}

TEST(RunLock, ArrayTasksShareTheFolderButNotWithAWholeRun) {
  const auto d = fresh_dir("shared");
  RunLock a(d, RunLock::Mode::Shared, "orchestrate --task 0");
  EXPECT_NO_THROW(RunLock(d, RunLock::Mode::Shared, "orchestrate --task 1"));
  EXPECT_THROW(RunLock(d, RunLock::Mode::Exclusive, "orchestrate --stage breakage"), RunFolderBusy);
}

// Each stage has its own lock: a scheduler chain merges one stage while
// another runs; the same stage is still one writer at a time.
TEST(RunLock, StagesOfOneFolderLockApart) {
  const auto d = fresh_dir("stages");
  RunLock flow(d, RunLock::Mode::Exclusive, "orchestrate --stage flow --merge-only", "flow");
  EXPECT_NO_THROW(RunLock(d, RunLock::Mode::Exclusive, "orchestrate --stage calibrate",
                          "calibrate"));
  try {
    RunLock again(d, RunLock::Mode::Exclusive, "orchestrate --stage flow", "flow");
    FAIL() << "a second exclusive lock of stage flow was granted";
  } catch (const RunFolderBusy& e) {
    EXPECT_NE(std::string(e.what()).find("stage flow of the run folder is in use"),
              std::string::npos)
        << e.what();
  }
}

// A second orchestrate on a folder in use exits 1 and says who holds it.
TEST(RunLock, OrchestrateRefusesAFolderInUse) {
  const auto d = fresh_dir("busy_cmd");
  RunLock held(d, RunLock::Mode::Exclusive, "orchestrate --stage all", "breakage");
  const Out o = orchestrate(
      "--case " + kData + "/good_small.yaml --stage breakage --merge-only --output " + d.string());
  EXPECT_EQ(o.status, 1) << o.text;
  EXPECT_NE(o.text.find("in use by another orchestrate (pid " + std::to_string(getpid())),
            std::string::npos)
      << o.text;
  // Reading the plan needs no lock.
  EXPECT_EQ(orchestrate("--case " + kData +
                        "/good_small.yaml --stage breakage --dry-run --output " + d.string())
                .status,
            0);
}

// A process that exited: its pid is free (and reaped).
long gone_pid() {
  const pid_t p = fork();
  if (p == 0) _exit(0);
  waitpid(p, nullptr, 0);
  return p;
}

TEST(StaleStatus, RunningForAGoneProcessIsStale) {
  const auto d = fresh_dir("stale");
  const std::string args =
      "--case " + kData + "/good_small.yaml --stage breakage --output " + d.string();
  const std::string list = orchestrate(args + " --list-tasks").text;
  const std::string label = list.substr(2, list.find('\t', 2) - 2);
  const long pid = gone_pid();
  fs::create_directories(d / "breakage" / "jobs" / label);
  std::ofstream(d / "breakage" / "jobs" / label / "STATUS")
      << "running\nid=0\npid=" << pid << "\nhost=" << mill::jobs::JobStore::hostname()
      << "\nstart_ticks=1\n";
  const Out plan = orchestrate(args + " --dry-run");
  EXPECT_NE(plan.text.find("stale: was running as pid " + std::to_string(pid)), std::string::npos)
      << plan.text;
  const Out merge = orchestrate(args + " --merge-only");
  EXPECT_EQ(merge.status, 1) << merge.text;
  EXPECT_NE(merge.text.find("running as pid " + std::to_string(pid) + " on " +
                            mill::jobs::JobStore::hostname() + ", which is gone (stale"),
            std::string::npos)
      << merge.text;
}

bool process_gone(long pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string s;
  if (!std::getline(in, s)) return true;
  const size_t rp = s.rfind(')');
  return rp != std::string::npos && rp + 2 < s.size() && s[rp + 2] == 'Z';  // a zombie runs nothing
}

// orchestrate killed outright (SIGKILL forwards nothing): the engine child
// gets the parent-death signal and ends.
TEST(Runner, EngineDiesWithAKilledOrchestrate) {
  const auto d = fresh_dir("pdeath");
  const fs::path pid_file = d / "engine.pid";
  const pid_t orch = fork();
  if (orch == 0) {
    mill::engine::Command c;
    c.argv = {"/bin/sh", "-c",
              "echo $$ > " + pid_file.string() + ".tmp && mv " + pid_file.string() + ".tmp " +
                  pid_file.string() + " && exec sleep 60"};
    c.cwd = d;
    c.log = d / "log.txt";
    c.job = "test/pdeath";
    try {
      mill::engine::Runner().run(c);
    } catch (...) {
    }
    _exit(0);
  }
  for (int i = 0; i < 250 && !fs::exists(pid_file); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_TRUE(fs::exists(pid_file)) << "the engine never started";
  long engine = 0;
  std::ifstream(pid_file) >> engine;
  ASSERT_GT(engine, 0);
  kill(orch, SIGKILL);
  waitpid(orch, nullptr, 0);
  bool gone = false;
  for (int i = 0; i < 150 && !gone; ++i) {
    gone = process_gone(engine);
    if (!gone) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (!gone) kill(static_cast<pid_t>(engine), SIGKILL);
  EXPECT_TRUE(gone) << "the engine (pid " << engine
                    << ") kept running after orchestrate was killed";
}

// A signal that arrives while orchestrate plans ends it with 128+N before
// any job runs or any file is written. In a forked process: the signal state
// of the test binary stays clean.
int plan_with_pending_signal(int sig, const fs::path& out) {
  const pid_t p = fork();
  if (p == 0) {
    mill::engine::install_signal_forwarding();
    raise(sig);
    std::string a0 = "orchestrate", a1 = "--case", a2 = kData + "/good_small.yaml", a3 = "--stage",
                a4 = "all", a5 = "--dry-run", a6 = "--output", a7 = out.string();
    char* argv[] = {a0.data(), a1.data(), a2.data(), a3.data(), a4.data(),
                    a5.data(), a6.data(), a7.data(), nullptr};
    std::ostringstream o, e;
    _exit(mill::cli_main(8, argv, o, e));
  }
  int st = 0;
  waitpid(p, &st, 0);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

TEST(PlanningSignals, SigtermAndSigintStopThePlan) {
  const auto d = fresh_dir("plan_signal");
  EXPECT_EQ(plan_with_pending_signal(SIGTERM, d / "run"), 143);
  EXPECT_EQ(plan_with_pending_signal(SIGINT, d / "run"), 130);
  EXPECT_FALSE(fs::exists(d / "run"));
}

}  // namespace
