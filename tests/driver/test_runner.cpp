// The engine runner: failures surface log and status; signals reach children.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "engine/runner.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using namespace mill::engine;

namespace {

// An empty folder, removed when the test passes.
mill::test::TempDir fresh_dir(const std::string& name) {
  return mill::test::TempDir("mill_runner_" + name + "_" + std::to_string(getpid()));
}

Command sh(const fs::path& dir, const std::string& script, Engine e = Engine::Generic) {
  Command c;
  c.argv = {"/bin/sh", "-c", script};
  c.cwd = dir;
  c.log = dir / "log.txt";
  c.engine = e;
  c.job = "test/job";
  return c;
}

TEST(Runner, SuccessReturnsZeroAndWritesLog) {
  const auto d = fresh_dir("ok");
  Runner r;
  auto res = r.run(sh(d, "echo hello from child"));
  EXPECT_EQ(res.exit_code, 0);
  std::ifstream in(d / "log.txt");
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "hello from child");
}

// An engine gets stdin, stdout and stderr only: a file this process has open
// (without O_CLOEXEC, as HDF5 opens its files, locked with flock) is not
// open in the engine, so the engine cannot hold that file's lock.
TEST(Runner, EngineInheritsNoOpenFileOfOrchestrate) {
  const auto d = fresh_dir("fds");
  const int fd = ::open((d.path() / "held.h5").c_str(), O_RDWR | O_CREAT, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(flock(fd, LOCK_EX), 0);
  Runner r;
  // And under no other number: what each of the shell's descriptors names.
  auto res = r.run(sh(d, "if [ -e /proc/$$/fd/" + std::to_string(fd) +
                             " ]; then echo inherited; else echo closed; fi; "
                             "for f in /proc/$$/fd/*; do readlink $f; done; true"));
  EXPECT_EQ(res.exit_code, 0);
  std::ifstream in(d.path() / "log.txt");
  std::string line, targets;
  std::getline(in, line);
  for (std::string t; std::getline(in, t);) targets += t + "\n";
  EXPECT_EQ(line, "closed") << targets;
  EXPECT_EQ(targets.find("held.h5"), std::string::npos) << targets;
  EXPECT_NE(targets.find("log.txt"), std::string::npos) << targets;  // stdout: the listing works
  ::close(fd);
}

TEST(Runner, FailingChildSurfacesLogPathAndExitStatus) {
  const auto d = fresh_dir("fail");
  Runner r;
  try {
    r.run(sh(d, "echo line one; echo the last words; exit 3"));
    FAIL() << "no error";
  } catch (const EngineError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("exit status 3"), std::string::npos) << m;
    EXPECT_NE(m.find((d / "log.txt").string()), std::string::npos) << m;
    EXPECT_NE(m.find("the last words"), std::string::npos) << m;
    EXPECT_NE(m.find("test/job"), std::string::npos) << m;
    EXPECT_EQ(e.result.exit_code, 3);
  }
}

TEST(Runner, EngineErrorLineFailsEvenWithExitZero) {
  const auto d = fresh_dir("errline");
  Runner r;
  EXPECT_THROW(r.run(sh(d, "echo 'ERROR: Illegal fix style'; exit 0", Engine::Liggghts)), EngineError);
  EXPECT_THROW(r.run(sh(d, "echo '--> FOAM FATAL ERROR: cannot find file'; exit 0", Engine::OpenFoam)), EngineError);
  EXPECT_NO_THROW(r.run(sh(d, "echo 'no error here'; exit 0", Engine::Liggghts)));
}

// LIGGGHTS warnings that invalidate a run fail it, with exit status 0 too:
// dangerous neighbour builds (missed contacts) and lost atoms.
TEST(Runner, DangerousBuildsAndLostAtomsFailTheRun) {
  const auto d = fresh_dir("danger");
  Runner r;
  EXPECT_NO_THROW(r.run(sh(d, "echo 'Dangerous builds = 0'", Engine::Liggghts)));
  for (const char* line : {"Dangerous builds = 12", "WARNING: Lost atoms: original 50 current 49"}) {
    try {
      r.run(sh(d, std::string("echo 'Neighbor list builds = 40'; echo '") + line + "'", Engine::Liggghts));
      ADD_FAILURE() << "accepted a run whose log says: " << line;
    } catch (const EngineError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(line), std::string::npos) << m;
      EXPECT_NE(m.find("exit status 0, but the log has engine errors"), std::string::npos) << m;
      EXPECT_NE(m.find("log.txt"), std::string::npos) << m;
    }
  }
  // Other engines' logs may print the same words without meaning.
  EXPECT_NO_THROW(r.run(sh(d, "echo 'Dangerous builds = 12'", Engine::Generic)));
}

TEST(Runner, MissingProgramIsAClearError) {
  const auto d = fresh_dir("missing");
  Command c = sh(d, "");
  c.argv = {"no-such-engine-xyz"};
  try {
    Runner().run(c);
    FAIL();
  } catch (const EngineError& e) {
    EXPECT_NE(std::string(e.what()).find("no-such-engine-xyz"), std::string::npos);
  }
}

TEST(Runner, MpirunPrefixWhenMoreThanOneRank) {
  Command c;
  c.argv = {"liggghts-mill", "-in", "x.in"};
  c.np = 2;
  auto a = Runner::full_argv(c);
  ASSERT_GE(a.size(), 3u);
  EXPECT_EQ(a[0], "mpirun");
  EXPECT_EQ(a[2], "2");
  const bool root_flag = std::find(a.begin(), a.end(), "--allow-run-as-root") != a.end();
  EXPECT_EQ(root_flag, geteuid() == 0);
  c.np = 1;
  EXPECT_EQ(Runner::full_argv(c)[0], "liggghts-mill");
}

TEST(Runner, EnvironmentReachesChild) {
  const auto d = fresh_dir("env");
  Command c = sh(d, "echo \"$MILL_TEST_VAR\"");
  c.env["MILL_TEST_VAR"] = "forty-two";
  Runner().run(c);
  std::ifstream in(d / "log.txt");
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "forty-two");
}

// limit_runs: runs from many threads (through copies of one runner) never
// exceed the limit at once, and reach it; a limit of 0 lets them all run.
// Each run appends "+" to a shared file when it starts and "-" when it ends
// (O_APPEND lines); the most "+" lines open at once is the concurrency.
int most_at_once(const fs::path& d, Runner& r, int runs) {
  const fs::path f = d / "events.txt";
  std::vector<std::thread> threads;
  for (int k = 0; k < runs; ++k)
    threads.emplace_back([&, k] {
      Runner copy = r;
      Command c = sh(d, "echo + >> " + f.string() + "; sleep 0.6; echo - >> " + f.string());
      c.log = d / ("log" + std::to_string(k) + ".txt");
      copy.run(c);
    });
  for (auto& t : threads) t.join();
  std::ifstream in(f);
  std::string line;
  int open = 0, most = 0, ends = 0;
  while (std::getline(in, line)) {
    open += line == "+" ? 1 : -1;
    ends += line == "-" ? 1 : 0;
    most = std::max(most, open);
  }
  EXPECT_EQ(ends, runs);
  fs::remove(f);
  return most;
}

TEST(Runner, LimitRunsCapsTheRunsAtOnceAcrossThreadsAndCopies) {
  const auto d = fresh_dir("limit");
  Runner r;
  r.limit_runs(2);
  EXPECT_EQ(most_at_once(d, r, 6), 2);
  r.limit_runs(1);
  EXPECT_EQ(most_at_once(d, r, 3), 1);
  r.limit_runs(0);
  EXPECT_GE(most_at_once(d, r, 3), 2) << "without a limit the runs should overlap";
}

// SIGTERM to orchestrate is forwarded to the engine, which sees it (trap),
// and run() reports the interruption. Done in a forked process so that the
// signal state of the test binary stays clean.
TEST(Runner, SigtermReachesTheChild) {
  const auto d = fresh_dir("sigterm");
  const fs::path marker = d / "got_term";
  pid_t pid = fork();
  if (pid == 0) {
    install_signal_forwarding();
    try {
      Runner().run(sh(d, "trap 'echo TERM > " + marker.string() + "; exit 0' TERM; echo ready; "
                         "while true; do sleep 0.05; done"));
    } catch (const Interrupted& e) {
      _exit(e.signal == SIGTERM ? 42 : 43);
    } catch (...) {
      _exit(44);
    }
    _exit(45);
  }
  // Wait until the child's shell is up, then terminate orchestrate's stand-in.
  for (int i = 0; i < 100 && !fs::exists(d / "log.txt"); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  kill(pid, SIGTERM);
  int st = 0;
  waitpid(pid, &st, 0);
  ASSERT_TRUE(WIFEXITED(st));
  EXPECT_EQ(WEXITSTATUS(st), 42);
  EXPECT_TRUE(fs::exists(marker)) << "the engine never saw SIGTERM";
}

}  // namespace
