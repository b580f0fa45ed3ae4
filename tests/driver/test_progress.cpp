// Progress::eta_seconds: the time left of a stage whose jobs differ in cost;
// engine::deck_progress: how far a running deck is, from its log.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <sstream>
#include <thread>

#include "engine/liggghts.h"
#include "progress.h"

namespace {

using mill::Progress;

// Two in-mill lumps running after 16 short single impacts: each at 15 % after
// 30 s needs 170 s more; the mean finished job (2 s) must not set the ETA.
TEST(ProgressEta, LongRunningJobsSetTheEtaNotTheShortFinishedOnes) {
  const double eta = Progress::eta_seconds({{30.0, 0.15}, {30.0, 0.15}}, 0, 16, 32.0, 2);
  EXPECT_NEAR(eta, 170.0, 1e-9);
}

// The longest running job bounds the stage from below even when the summed
// work over the slots is less.
TEST(ProgressEta, LongestRunningJobIsALowerBound) {
  const double eta = Progress::eta_seconds({{10.0, 0.5}, {90.0, 0.1}}, 0, 3, 30.0, 2);
  EXPECT_NEAR(eta, 810.0, 1e-9);  // 90 s x 0.9 / 0.1; the sum over 2 slots is (10 + 810) / 2 = 410
}

// Queued jobs and a running job with no fraction yet count as the mean finished job.
TEST(ProgressEta, QueuedJobsCountAsTheMeanFinishedJob) {
  EXPECT_NEAR(Progress::eta_seconds({}, 6, 4, 40.0, 2), 30.0, 1e-9);
  EXPECT_NEAR(Progress::eta_seconds({{5.0, -1}}, 2, 4, 40.0, 1), 30.0, 1e-9);
}

// Nothing finished and no fraction reported: no estimate.
TEST(ProgressEta, NoInformationGivesNoEstimate) {
  EXPECT_LT(Progress::eta_seconds({{5.0, -1}}, 3, 0, 0.0, 1), 0.0);
  EXPECT_LT(Progress::eta_seconds({}, 0, 0, 0.0, 1), 0.0);
}

// With nothing finished, the projected running jobs give the mean for the queued ones.
TEST(ProgressEta, ProjectedRunningJobsStandInForTheMean) {
  // one job at 25 % after 10 s: 30 s left, 40 s in all; 2 queued at 40 s each, 1 slot
  EXPECT_NEAR(Progress::eta_seconds({{10.0, 0.25}}, 2, 0, 0.0, 1), 110.0, 1e-9);
}

// A job that reports steps without job_begin (a caller that forgot it) is
// timed from its first step: counted from zero seconds it would show "ETA 0s"
// for the whole run (the impact subcommand did, Nov 29). 50 % at its first
// step, 60 % a second later: 0.67-1 s left, printed "1s".
TEST(ProgressEta, AJobSteppedWithoutBeginIsTimedFromItsFirstStep) {
  std::ostringstream out;
  Progress p(out, /*tty=*/false, /*heartbeat_seconds=*/0.0);
  p.stage_begin("impact", 1, 0);
  p.job_step("impact_v4_a90_r0", "step 500/1000", 0.5);
  std::this_thread::sleep_for(std::chrono::milliseconds(1050));
  p.job_step("impact_v4_a90_r0", "step 600/1000", 0.6);
  const std::string text = out.str();
  const std::string last = text.substr(text.rfind("[impact]"));
  EXPECT_NE(last.find("ETA 1s"), std::string::npos) << text;
}

// A deck log as the impact deck writes it: a thermo line with another
// first column before the "nsteps" line (ignored), the nsteps/t_end line,
// then thermo lines "step time ..." every `every` steps, at the step change
// (a chunk's end, repeated at the next chunk's start) and at `last`. The step is dt0 up to step
// `change`, then dt1 (fix step/adaptive between chunks).
std::string deck_log(long nsteps, double t_end, double dt0, long change, double dt1, long last,
                     long every) {
  std::ostringstream log;
  log.precision(10);
  log << "    Step    Temp\n       0   12345.6 0 0\n";
  log << "impact: dt " << dt0 << " s, nsteps " << nsteps << ", t_end " << t_end
      << " s, bonds 10498\n";
  auto time = [&](long s) { return s <= change ? s * dt0 : change * dt0 + (s - change) * dt1; };
  auto line = [&](long s) { log << "  " << s << " " << time(s) << " 3344 1.5\n"; };
  for (long s = 0; s <= last; s += every) {
    line(s);
    if (s < change && s + every > change) line(change), line(change);  // chunk end and start
  }
  if (last % every != 0) line(last);
  return log.str();
}

// With a changing step the steps still to go are re-estimated from the step
// of the moment: 6 ms at 1e-7 s is 60 000 steps; after 2500 steps at 1e-7 s
// (0.25 ms) and 1250 at 2e-7 s (0.5 ms) the rest is 5.5 ms / 2e-7 s = 27 500
// steps, 31 250 in all. A job whose steps cost the same each (c seconds) has
// spent 3750 c and needs 27 500 c more: the ETA from this fraction is exact,
// where step / nsteps (0.0625) would project 56 250 c, twice too long.
TEST(DeckProgress, AdaptiveStepReestimatesTheStepsToGo) {
  std::istringstream log(deck_log(60000, 6e-3, 1e-7, 2500, 2e-7, 3750, 500));
  const auto p = mill::engine::deck_progress(log);
  EXPECT_EQ(p.step, 3750);
  EXPECT_NEAR(p.time, 5e-4, 1e-15);
  EXPECT_NEAR(p.t_end, 6e-3, 1e-15);
  EXPECT_EQ(p.total, 3750 + 27500);
  EXPECT_NEAR(p.fraction, 3750.0 / 31250.0, 1e-12);
  const double c = 0.01;  // seconds per step
  const double eta = Progress::eta_seconds({{3750 * c, p.fraction}}, 0, 0, 0.0, 1);
  EXPECT_NEAR(eta, 27500 * c, 1e-9 * 27500 * c);
}

// Fixed step: the re-estimate is the deck's own nsteps (ceil(t_end / dt)).
TEST(DeckProgress, FixedStepGivesTheDecksStepCount) {
  std::istringstream log(
      deck_log(59098, 59098 * 1.1e-7 - 1e-12, 1.1e-7, 1 << 30, 1.1e-7, 12000, 500));
  const auto p = mill::engine::deck_progress(log);
  EXPECT_EQ(p.step, 12000);
  EXPECT_EQ(p.total, 59098);
  EXPECT_NEAR(p.fraction, 12000.0 / 59098.0, 1e-12);
}

// A deck that prints no t_end (it stops by steps): step / nsteps, as before;
// nothing before the first thermo line after "nsteps".
TEST(DeckProgress, WithoutEndTimeStepOverNsteps) {
  std::istringstream log("transport: nsteps 40000\n   1000 1e-4 5 6\n   3000 3e-4 5 6\n");
  const auto p = mill::engine::deck_progress(log);
  EXPECT_EQ(p.total, 40000);
  EXPECT_NEAR(p.fraction, 3000.0 / 40000.0, 1e-12);
  std::istringstream early(
      "    Step    Temp\n       0   12345.6 0 0\nimpact: dt 1e-07 s, nsteps 100, "
      "t_end 1e-05 s, bonds 3\n");
  EXPECT_LT(mill::engine::deck_progress(early).fraction, 0.0);
}

}  // namespace
