// The JK t10-Ecs fit on synthetic sweeps with known A and b.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "postprocess/fragments.h"
#include "postprocess/jk_fit.h"

namespace mill::post {
namespace {

TEST(JkFit, EnergyOfAnImpactIsHalfTheSpeedSquaredInKWhPerTonne) {
  // 60 m/s: 1800 J/kg = 0.5 kWh/t.
  EXPECT_DOUBLE_EQ(SpecificEnergyKWhPerTonne(60.0), 0.5);
}

TEST(JkFit, RecoversAAndBFromExactData) {
  std::vector<double> e, t;
  for (double x : {0.05, 0.1, 0.2, 0.4, 0.8, 1.6, 3.2}) {
    e.push_back(x);
    t.push_back(JkT10(48.0, 1.7, x));
  }
  const JkFit f = FitJk(e, t);
  ASSERT_TRUE(f.ok) << f.reason;
  EXPECT_NEAR(f.a_percent, 48.0, 1e-6);
  EXPECT_NEAR(f.b_t_per_kwh, 1.7, 1e-6);
  EXPECT_NEAR(f.ab(), 48.0 * 1.7, 1e-4);
  EXPECT_LT(f.rms_residual_percent, 1e-6);
}

// Three repeats of a sweep from 10 to 150 m/s with +-1.5 % (of t10) scatter
// that differs per repeat, as lump orientations give.
TEST(JkFit, RecoversAAndBWithinTwoPercentFromScatteredRepeats) {
  const double a_true = 55.0, b_true = 0.9;
  std::vector<JkPoint> pts;
  const double wiggle[3][5] = {{0.015, -0.01, 0.005, -0.015, 0.01},
                               {-0.012, 0.015, -0.008, 0.01, -0.005},
                               {0.005, 0.0, 0.012, -0.01, -0.015}};
  const double speeds[] = {20, 40, 60, 100, 150};
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 5; ++k) {
      const double e = SpecificEnergyKWhPerTonne(speeds[k]);
      pts.push_back({e, JkT10(a_true, b_true, e) * (1 + wiggle[r][k]), r});
    }
  const JkSweepFit s = FitJkSweep(pts);
  ASSERT_TRUE(s.pooled.ok) << s.pooled.reason;
  EXPECT_NEAR(s.pooled.a_percent, a_true, 0.02 * a_true);
  EXPECT_NEAR(s.pooled.b_t_per_kwh, b_true, 0.02 * b_true);
  EXPECT_GT(s.pooled.a_se_percent, 0.0);
  ASSERT_EQ(s.n_repeats_fitted, 3);
  ASSERT_TRUE(s.a_percent && s.b_t_per_kwh && s.ab);
  EXPECT_LE(s.a_percent->min, s.pooled.a_percent * 1.05);
  EXPECT_GE(s.a_percent->max, s.pooled.a_percent * 0.95);
  EXPECT_LT(s.a_percent->min, s.a_percent->max);  // the repeats differ
  ASSERT_TRUE(s.ab->stddev);
  EXPECT_GT(*s.ab->stddev, 0.0);
}

TEST(JkFit, TooFewPointsOrNoBreakageIsNotAFit) {
  EXPECT_FALSE(FitJk({0.1, 0.2}, {5, 9}).ok);
  const JkFit same = FitJk({0.3, 0.3, 0.3}, {5, 6, 7});
  EXPECT_FALSE(same.ok);
  EXPECT_NE(same.reason.find("distinct"), std::string::npos) << same.reason;
  const JkFit none = FitJk({0.1, 0.2, 0.4}, {0, 0, 0});
  EXPECT_FALSE(none.ok);
  EXPECT_NE(none.reason.find("t10 is 0"), std::string::npos) << none.reason;
  EXPECT_THROW(FitJk({0.1, 0.2}, {1.0}), PostError);
}

// A sweep whose every impact is past saturation: t10 = A (1 - exp(-b Ecs))
// with b x the lowest Ecs = 8 (t10 there 99.97 % of A) plus +-1 % scatter,
// as the default case's transport impacts (53-149 m/s) gave a lump whose
// critical speed is about 30 m/s: the sum of squares is flat in b beyond
// the data, so b (and A x b: 4.06e5 there) is not the ore's. Not a fit;
// the reason gives the closed-form bound b > ln 20 / Ecs_min. The same
// relation sampled down to b Ecs = 0.4 still fits (b within 2 %).
TEST(JkFit, ASweepPastSaturationEverywhereIsNotAFit) {
  const double a_true = 96.0, b_true = 20.0, e_min = 0.4;
  std::vector<double> e, t;
  const double wiggle[] = {0.01, -0.01, 0.005, -0.005, 0.0, 0.01};
  for (int k = 0; k < 6; ++k) {
    e.push_back(e_min * (1 + 0.5 * k));
    t.push_back(JkT10(a_true, b_true, e.back()) * (1 + wiggle[k]));
  }
  const JkFit f = FitJk(e, t);
  EXPECT_FALSE(f.ok) << "A " << f.a_percent << " b " << f.b_t_per_kwh;
  EXPECT_NE(f.reason.find("past saturation"), std::string::npos) << f.reason;
  // ln 20 / 0.4 = 7.49 t/kWh.
  EXPECT_NE(f.reason.find("b > ln 20 / Ecs = 7.49 t/kWh"), std::string::npos) << f.reason;

  std::vector<double> e2, t2;
  for (double x : {0.02, 0.05, 0.1, 0.2, 0.4, 0.8}) {
    e2.push_back(x);
    t2.push_back(JkT10(a_true, b_true, x));
  }
  const JkFit g = FitJk(e2, t2);
  ASSERT_TRUE(g.ok) << g.reason;
  EXPECT_NEAR(g.b_t_per_kwh, b_true, 0.02 * b_true);
}

TEST(JkFit, ARepeatWithTooFewPointsIsLeftOutOfTheSpread) {
  std::vector<JkPoint> pts;
  for (double e : {0.1, 0.3, 0.9, 2.0}) pts.push_back({e, JkT10(40, 1.2, e), 0});
  pts.push_back({0.5, JkT10(40, 1.2, 0.5), 1});  // repeat 1: one point only
  const JkSweepFit s = FitJkSweep(pts);
  ASSERT_TRUE(s.pooled.ok);
  EXPECT_EQ(s.n_repeats_fitted, 1);
  ASSERT_EQ(s.per_repeat.size(), 2u);
  EXPECT_FALSE(s.per_repeat[1].ok);
  EXPECT_FALSE(s.a_percent->stddev);  // one repeat: no standard deviation
}

// Repeats 1-2 at two of the four energies only (more repeats at the speeds
// of the crossing): pooled with the others, not fitted on their own when the
// repeats at every speed are given; without them they would be.
TEST(JkFit, RepeatsAtSomeSpeedsOnlyArePooledNotFittedOnTheirOwn) {
  std::vector<JkPoint> pts;
  for (double e : {0.1, 0.3, 0.9, 2.0}) pts.push_back({e, JkT10(40, 1.2, e), 0});
  for (int r : {1, 2})
    for (double e : {0.3, 0.9}) pts.push_back({e, JkT10(40, 1.2, e) * (r == 1 ? 1.02 : 0.98), r});
  const std::set<int> whole = {0};
  const JkSweepFit s = FitJkSweep(pts, &whole);
  ASSERT_TRUE(s.pooled.ok) << s.pooled.reason;
  EXPECT_NEAR(s.pooled.a_percent, 40.0, 0.05 * 40.0);  // every point pooled
  EXPECT_EQ(s.repeats, (std::vector<int>{0}));
  EXPECT_EQ(s.n_repeats_fitted, 1);
  EXPECT_NEAR(s.a_percent->mean, 40.0, 1e-3 * 40.0);  // repeat 0: exact data
  EXPECT_EQ(FitJkSweep(pts).repeats, (std::vector<int>{0, 1, 2}));
}

}  // namespace
}  // namespace mill::post
