// Progress::eta_seconds: the time left of a stage whose jobs differ in cost.
#include <gtest/gtest.h>

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

}  // namespace
