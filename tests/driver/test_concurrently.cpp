// run_concurrently (stages/stage_util.h): independent tasks of one job on up
// to `lanes` threads; every task runs once, the first failing task's
// exception comes back as it was, lanes > 1 really overlaps tasks.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include "engine/runner.h"
#include "stages/stage_util.h"

namespace {

using mill::run_concurrently;

std::vector<std::function<void()>> counting_tasks(std::vector<int>& hits) {
  std::vector<std::function<void()>> t;
  for (std::size_t i = 0; i < hits.size(); ++i) t.push_back([&hits, i] { ++hits[i]; });
  return t;
}

TEST(RunConcurrently, EveryTaskRunsOnceWhateverTheLanes) {
  for (int lanes : {0, 1, 2, 3, 16}) {
    std::vector<int> hits(7, 0);
    run_concurrently(counting_tasks(hits), lanes);
    for (std::size_t i = 0; i < hits.size(); ++i) EXPECT_EQ(hits[i], 1) << "lanes " << lanes;
  }
  run_concurrently({}, 2);  // nothing to do
}

TEST(RunConcurrently, OneLaneRunsInOrderOnThisThread) {
  std::vector<int> order;
  const auto me = std::this_thread::get_id();
  bool same_thread = true;
  std::vector<std::function<void()>> t;
  for (int i = 0; i < 4; ++i)
    t.push_back([&, i] {
      order.push_back(i);
      same_thread = same_thread && std::this_thread::get_id() == me;
    });
  run_concurrently(t, 1);
  EXPECT_EQ(order, (std::vector<int>{0, 1, 2, 3}));
  EXPECT_TRUE(same_thread);
}

// Two tasks that each wait for the other: they finish only if they overlap
// (each gives up after 10 s, so a sequential run fails instead of hanging).
TEST(RunConcurrently, TwoLanesOverlapTwoTasks) {
  std::mutex mu;
  std::condition_variable cv;
  int arrived = 0;
  std::atomic<int> met{0};
  auto meet = [&] {
    std::unique_lock<std::mutex> lock(mu);
    ++arrived;
    cv.notify_all();
    if (cv.wait_for(lock, std::chrono::seconds(10), [&] { return arrived >= 2; })) ++met;
  };
  run_concurrently({meet, meet}, 2);
  EXPECT_EQ(met.load(), 2);
}

// The exception of the first task (by index) that threw comes back with its
// type (Interrupted must stay Interrupted: it stops the whole run), and no
// task starts once a failure is recorded.
TEST(RunConcurrently, FirstFailureIsRethrownAsItWas) {
  std::atomic<int> started{0};
  std::vector<std::function<void()>> t = {
      [&] { ++started; },
      [&] {
        ++started;
        throw mill::engine::Interrupted(15);
      },
  };
  for (int i = 0; i < 6; ++i) t.push_back([&] { ++started; });
  EXPECT_THROW(run_concurrently(t, 1), mill::engine::Interrupted);
  EXPECT_EQ(started.load(), 2);  // one lane: nothing after the failure
  // Two lanes: the first task fails at once, the others take 20 ms each;
  // the lane that took one of them finds the failure recorded after it and
  // stops, so at most the failing task and one other ever start.
  std::vector<std::function<void()>> slow = {[&] {
    ++started;
    throw mill::engine::Interrupted(15);
  }};
  for (int i = 0; i < 7; ++i)
    slow.push_back([&] {
      ++started;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    });
  started = 0;
  try {
    run_concurrently(slow, 2);
    FAIL() << "no exception";
  } catch (const mill::engine::Interrupted& e) {
    EXPECT_EQ(e.signal, 15);
  }
  EXPECT_LE(started.load(), 2);
  // Both fail: the first by index comes back (the second fails later, so
  // the first has surely run).
  std::vector<std::function<void()>> two = {[] { throw std::runtime_error("first"); },
                                            [] {
                                              std::this_thread::sleep_for(
                                                  std::chrono::milliseconds(100));
                                              throw std::logic_error("second");
                                            }};
  for (int lanes : {1, 2}) {
    try {
      run_concurrently(two, lanes);
      FAIL() << "no exception";
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "first");
    }
  }
}

}  // namespace
