// Job state: skip done, rerun changed/failed/stale, atomic writes survive kills.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <thread>

#include "jobs/job_store.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using namespace mill::jobs;

namespace {

// An empty folder, removed when the test passes.
mill::test::TempDir fresh_dir(const std::string& name) {
  return mill::test::TempDir("mill_test_" + name + "_" + std::to_string(getpid()));
}

const nlohmann::json kIn = {{"velocity", 150.0}, {"angle", 90.0}};

TEST(JobId, DependsOnInputsOnlyCanonically) {
  nlohmann::json a = {{"b", 1}, {"a", 2}}, b = {{"a", 2}, {"b", 1}};
  EXPECT_EQ(job_id(a), job_id(b));
  EXPECT_NE(job_id(a), job_id(nlohmann::json{{"a", 2}, {"b", 1.5}}));
  EXPECT_EQ(job_id(a).size(), 16u);
}

TEST(JobStore, SchedulerJobAndLogStayInStatus) {
  const auto dir = fresh_dir("sched");
  JobStore s(dir);
  s.mark_running("j", kIn, "1234_5", "/runs/x/hpc/logs/mill-x-breakage_1234_5.out");
  s.mark_failed("j", "liggghts-mill exited with status 1");
  const Status st = s.read_status("j");
  EXPECT_EQ(st.state, State::Failed);
  EXPECT_EQ(st.scheduler_job, "1234_5");
  EXPECT_EQ(st.log, "/runs/x/hpc/logs/mill-x-breakage_1234_5.out");
  // A local rerun (no scheduler) clears them.
  s.mark_running("j", kIn);
  EXPECT_TRUE(s.read_status("j").scheduler_job.empty());
  EXPECT_TRUE(s.read_status("j").log.empty());
}

TEST(JobStore, NewThenDoneIsSkipped) {
  const auto dir = fresh_dir("done");
  JobStore s(dir);
  EXPECT_EQ(s.decide("j", kIn, false).decision, Decision::Run);
  s.mark_running("j", kIn);
  s.mark_done("j");
  auto v = s.decide("j", kIn, false);
  EXPECT_EQ(v.decision, Decision::Skip);
  EXPECT_EQ(s.decide("j", kIn, true).decision, Decision::Run);  // --force
  std::ifstream st(s.job_dir("j") / "STATUS");
  std::string first;
  std::getline(st, first);
  EXPECT_EQ(first, "done");
  EXPECT_TRUE(fs::exists(s.job_dir("j") / "job.json"));
}

TEST(JobStore, ChangedInputReruns) {
  const auto dir = fresh_dir("changed");
  JobStore s(dir);
  s.mark_running("j", kIn);
  s.mark_done("j");
  nlohmann::json changed = kIn;
  changed["velocity"] = 100.0;
  auto v = s.decide("j", changed, false);
  EXPECT_EQ(v.decision, Decision::Run);
  EXPECT_EQ(v.why, "inputs changed");
}

TEST(JobStore, FailedReruns) {
  const auto dir = fresh_dir("failed");
  JobStore s(dir);
  s.mark_running("j", kIn);
  s.mark_failed("j", "liggghts exit status 1");
  auto v = s.decide("j", kIn, false);
  EXPECT_EQ(v.decision, Decision::Run);
  EXPECT_NE(v.why.find("liggghts exit status 1"), std::string::npos);
}

TEST(JobStore, RunningWithDeadPidReruns) {
  const auto dir = fresh_dir("stale");
  // A child marks the job running, then dies without finishing it.
  pid_t pid = fork();
  if (pid == 0) {
    JobStore(dir).mark_running("j", kIn);
    _exit(0);
  }
  int st = 0;
  waitpid(pid, &st, 0);
  JobStore s(dir);
  EXPECT_EQ(s.read_status("j").state, State::Running);
  EXPECT_EQ(s.read_status("j").pid, pid);
  auto v = s.decide("j", kIn, false);
  EXPECT_EQ(v.decision, Decision::Run);
  EXPECT_NE(v.why.find("stale"), std::string::npos);
}

TEST(JobStore, RunningWithLivePidIsBusy) {
  const auto dir = fresh_dir("busy");
  JobStore s(dir);
  s.mark_running("j", kIn);  // this very process: alive
  EXPECT_EQ(s.decide("j", kIn, false).decision, Decision::Busy);
}

TEST(JobStore, PidReuseIsDetectedByStartTime) {
  const long me = getpid();
  const auto ticks = JobStore::process_start_ticks(me);
  ASSERT_GT(ticks, 0u);
  EXPECT_TRUE(JobStore::process_alive(me, ticks));
  EXPECT_FALSE(JobStore::process_alive(me, ticks + 12345));
}

TEST(AtomicWrite, KilledWriterLeavesNoFinishedFile) {
  const auto dir = fresh_dir("kill");
  const fs::path out = dir / "summary.csv";
  pid_t pid = fork();
  if (pid == 0) {
    atomic_write_with(out, [](std::ostream& o) {
      for (int i = 0; i < 1000; ++i) {
        o << "row " << i << "\n" << std::flush;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
    });
    _exit(0);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  kill(pid, SIGKILL);
  int st = 0;
  waitpid(pid, &st, 0);
  ASSERT_TRUE(WIFSIGNALED(st)) << "the writer finished before it was killed; the test proves nothing";
  EXPECT_FALSE(fs::exists(out));
  bool tmp_seen = false;
  for (const auto& e : fs::directory_iterator(dir)) tmp_seen |= e.path().string().find(".tmp.") != std::string::npos;
  EXPECT_TRUE(tmp_seen);  // the partial data is under a temporary name only
}

TEST(AtomicWrite, CompleteWriteIsVisible) {
  const auto dir = fresh_dir("ok");
  const fs::path f = dir / "a.txt";
  atomic_write(f, "hello\n");
  std::ifstream in(f);
  std::string s;
  std::getline(in, s);
  EXPECT_EQ(s, "hello");
}

}  // namespace
