// Size fractions, t10 and the critical velocity on hand-made data.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <set>

#include "postprocess/distributions.h"
#include "postprocess/fragments.h"

namespace mill::post {
namespace {

TEST(Distributions, DefaultEdgesGiveTwelveFractions) {
  const auto e = DefaultFractionEdges();
  EXPECT_EQ(e.size(), 13u);
  EXPECT_NO_THROW(ValidateFractionEdges(e));
}

TEST(Distributions, BadEdgesAreRejectedWithTheIndex) {
  try {
    ValidateFractionEdges({0.0, 0.2, 0.1});
    FAIL() << "expected PostError";
  } catch (const PostError& e) {
    EXPECT_NE(std::string(e.what()).find("size_fraction_edges[2]"), std::string::npos);
  }
}

TEST(Distributions, FractionsSumToOneAndBinsAreHalfOpen) {
  const std::vector<double> edges = {0.0, 0.1, 0.5, 1.0};
  // 0.1 sits on an edge (goes up), 1.0 is the top edge and 1.3 above it (top).
  const std::vector<double> d = {0.05, 0.1, 0.7, 1.0, 1.3};
  const std::vector<double> m = {1.0, 2.0, 3.0, 4.0, 10.0};
  const auto f = SizeFractionMass(d, m, edges);
  ASSERT_EQ(f.size(), 3u);
  EXPECT_DOUBLE_EQ(f[0], 1.0 / 20.0);
  EXPECT_DOUBLE_EQ(f[1], 2.0 / 20.0);
  EXPECT_DOUBLE_EQ(f[2], 17.0 / 20.0);
  EXPECT_NEAR(std::accumulate(f.begin(), f.end(), 0.0), 1.0, 1e-15);
}

TEST(Distributions, DefaultFractionsSumToOne) {
  const std::vector<double> d = {0.01, 0.06, 0.08, 0.12, 0.33, 0.45, 0.66, 0.8, 0.9, 0.99};
  const std::vector<double> m = {0.3, 1.1, 0.7, 2.0, 5.0, 0.1, 0.2, 3.3, 9.0, 0.01};
  const auto f = SizeFractionMass(d, m, DefaultFractionEdges());
  EXPECT_EQ(f.size(), 12u);
  EXPECT_NEAR(std::accumulate(f.begin(), f.end(), 0.0), 1.0, 1e-14);
}

TEST(Distributions, T10OnHandMadePieces) {
  // Finer than 0.1: 1 + 2 of 10 mass units; the piece at exactly 0.1 is not finer.
  EXPECT_DOUBLE_EQ(T10Percent({0.05, 0.09, 0.1, 0.5}, {1.0, 2.0, 3.0, 4.0}), 30.0);
  EXPECT_DOUBLE_EQ(T10Percent({0.5}, {1.0}), 0.0);
}

TEST(CriticalVelocity, InterpolatesTheFirstCrossing) {
  const auto v = FirstCrossingBelow({10, 20, 40, 80}, {1.0, 0.6, 0.2, 0.01}, 0.05);
  ASSERT_TRUE(v.has_value());
  EXPECT_NEAR(*v, 40.0 + 0.15 * 40.0 / 0.19, 1e-12);
}

TEST(CriticalVelocity, OrderOfPointsDoesNotMatter) {
  const auto v = FirstCrossingBelow({80, 10, 40, 20}, {0.01, 1.0, 0.2, 0.6}, 0.05);
  ASSERT_TRUE(v.has_value());
  EXPECT_NEAR(*v, 40.0 + 0.15 * 40.0 / 0.19, 1e-12);
}

TEST(CriticalVelocity, FirstFallIsUsedNotALaterOne) {
  // Falls below at 30, recovers at 40 (noise), falls again: the first counts.
  const auto v = FirstCrossingBelow({10, 30, 40, 50}, {0.5, 0.0, 0.5, 0.0}, 0.1);
  EXPECT_NEAR(*v, 10.0 + 0.4 * 20.0 / 0.5, 1e-12);
}

TEST(CriticalVelocity, NeverBelowAndAlreadyBelow) {
  EXPECT_FALSE(FirstCrossingBelow({10, 20}, {1.0, 0.9}, 0.05).has_value());
  EXPECT_DOUBLE_EQ(*FirstCrossingBelow({10, 20}, {0.01, 0.0}, 0.05), 10.0);
  EXPECT_FALSE(FirstCrossingBelow({}, {}, 0.05).has_value());
}

TEST(CriticalVelocity, SpreadOverRepeats) {
  const std::vector<SweepPoint> pts = {{10, 0, 1.0}, {20, 0, 0.5}, {30, 0, 0.0},
                                       {10, 1, 1.0}, {20, 1, 0.3}, {30, 1, 0.02}};
  const auto c = FindCriticalVelocity(pts, 0.1);
  ASSERT_EQ(c.per_repeat.size(), 2u);
  EXPECT_NEAR(*c.per_repeat[0], 28.0, 1e-12);
  EXPECT_NEAR(*c.per_repeat[1], 20.0 + 2.0 / 0.28, 1e-12);
  EXPECT_NEAR(*c.of_mean_curve, 20.0 + 3.0 / 0.39, 1e-12);
  EXPECT_EQ(c.n_crossed, 2);
  EXPECT_NEAR(*c.min, 20.0 + 2.0 / 0.28, 1e-12);
  EXPECT_NEAR(*c.max, 28.0, 1e-12);
  EXPECT_NEAR(*c.stddev, (28.0 - (20.0 + 2.0 / 0.28)) / std::sqrt(2.0), 1e-12);
}

// More repeats at the speeds around the crossing (breakage.crossing_velocities):
// repeats 0-1 at 10, 20 and 30 m/s, repeats 2-3 at 20 and 30 only. The mean
// curve averages all four at 20 and 30 (20: 0.45, 30: 0.0); the per-repeat
// spread reads repeats 0 and 1 only (a curve from 20 m/s up would put repeat
// 3, below 0.1 at 20 m/s already, at 20 m/s: a crossing it never showed).
TEST(CriticalVelocity, RepeatsAtSomeSpeedsOnlyCountInTheMeanCurveNotTheSpread) {
  const std::vector<SweepPoint> pts = {{10, 0, 1.0},  {20, 0, 0.5}, {30, 0, 0.0},  {10, 1, 1.0},
                                       {20, 1, 0.3},  {30, 1, 0.0}, {20, 2, 0.95}, {30, 2, 0.0},
                                       {20, 3, 0.05}, {30, 3, 0.0}};
  EXPECT_EQ(RepeatsAtEveryVelocity(pts), (std::set<int>{0, 1}));
  const auto c = FindCriticalVelocity(pts, 0.1);
  EXPECT_EQ(c.repeats, (std::vector<int>{0, 1}));
  ASSERT_EQ(c.per_repeat.size(), 2u);
  EXPECT_NEAR(*c.per_repeat[0], 28.0, 1e-12);
  EXPECT_NEAR(*c.per_repeat[1], 20.0 + 2.0 / 0.3, 1e-12);
  EXPECT_NEAR(*c.of_mean_curve, 20.0 + 3.5 / 0.45, 1e-12);  // (0.5+0.3+0.95+0.05)/4 = 0.45
  EXPECT_EQ(c.n_crossed, 2);
  EXPECT_NEAR(*c.min, 20.0 + 2.0 / 0.3, 1e-12);
  EXPECT_EQ(RepeatsAtEveryVelocity({}), std::set<int>{});
}

// The repeat-averaged curve (10: 1.0, 20: 0.4, 30: 0.01) read between and at
// its speeds, and nowhere outside them.
TEST(CriticalVelocity, MeanCurveAtASpeed) {
  const std::vector<SweepPoint> pts = {{10, 0, 1.0}, {20, 0, 0.5}, {30, 0, 0.0},
                                       {10, 1, 1.0}, {20, 1, 0.3}, {30, 1, 0.02}};
  EXPECT_DOUBLE_EQ(*MeanCurveAt(pts, 20.0), 0.4);
  EXPECT_DOUBLE_EQ(*MeanCurveAt(pts, 10.0), 1.0);
  EXPECT_DOUBLE_EQ(*MeanCurveAt(pts, 30.0), 0.01);
  EXPECT_NEAR(*MeanCurveAt(pts, 25.0), 0.205, 1e-15);
  EXPECT_FALSE(MeanCurveAt(pts, 9.9).has_value());
  EXPECT_FALSE(MeanCurveAt(pts, 30.1).has_value());
  EXPECT_FALSE(MeanCurveAt({}, 20.0).has_value());
}

}  // namespace
}  // namespace mill::post

namespace mill::post {
namespace {

TEST(PassingCurve, CumulativePercentIsTheRunningSum) {
  const auto p = CumulativePassingPercent({0.1, 0.3, 0.6});
  ASSERT_EQ(p.size(), 3u);
  EXPECT_DOUBLE_EQ(p[0], 10.0);
  EXPECT_DOUBLE_EQ(p[1], 40.0);
  EXPECT_DOUBLE_EQ(p[2], 100.0);
}

TEST(PassingCurve, P80ByHandBetweenTwoSieves) {
  // 70 % passes 4 mm, 100 % 8 mm: P80 = 4 x 2^(10/30) mm.
  const std::vector<double> sieves = {1, 2, 4, 8}, passing = {10, 40, 70, 100};
  EXPECT_NEAR(*SizeAtPercentPassing(sieves, passing, 80), 4 * std::pow(2.0, 1.0 / 3.0), 1e-12);
  EXPECT_NEAR(*SizeAtPercentPassing(sieves, passing, 40), 2.0, 1e-12);  // on a sieve
  EXPECT_FALSE(SizeAtPercentPassing(sieves, passing, 5));               // finer than 1 mm
  EXPECT_FALSE(SizeAtPercentPassing({1, 2}, {10, 60}, 80));             // never reached
  EXPECT_THROW(SizeAtPercentPassing({2, 1}, {10, 60}, 50), PostError);
}

// A distribution whose passing is exactly linear in log(size) between 0.5
// and 40 mm: P(d) = 100 ln(d / 0.5) / ln(80); P80 = 0.5 x 80^0.8 mm, whatever
// sieves it is read at.
TEST(PassingCurve, P50AndP80OfALogUniformDistribution) {
  const std::vector<double> sieves = {1.0, 2.5, 6.0, 13.0, 27.0, 40.0};
  std::vector<double> mass;
  double below = 0.0;
  for (double s : sieves) {
    const double p = std::log(s / 0.5) / std::log(80.0);
    mass.push_back(p - below);
    below = p;
  }
  const auto passing = CumulativePassingPercent(mass);
  EXPECT_NEAR(passing.back(), 100.0, 1e-12);
  EXPECT_NEAR(*SizeAtPercentPassing(sieves, passing, 80), 0.5 * std::pow(80.0, 0.8), 1e-9);
  EXPECT_NEAR(*SizeAtPercentPassing(sieves, passing, 50), 0.5 * std::pow(80.0, 0.5), 1e-9);
}

}  // namespace
}  // namespace mill::post

// Below the threshold at the slowest speed (repeats averaged): the critical
// speed FindCriticalVelocity gives is only an upper bound.
TEST(CriticalVelocity, BelowAtTheSlowestSpeedIsAnUpperBound) {
  using mill::post::BelowAtSlowest;
  using mill::post::SweepPoint;
  const std::vector<SweepPoint> above = {{20, 0, 0.9}, {10, 0, 0.5}, {10, 1, 0.6}, {40, 0, 0.01}};
  EXPECT_FALSE(BelowAtSlowest(above, 0.05));
  const std::vector<SweepPoint> below = {{20, 0, 0.001}, {10, 0, 0.02}, {10, 1, 0.07}};
  EXPECT_TRUE(BelowAtSlowest(below, 0.05));   // mean 0.045 at 10 m/s
  EXPECT_FALSE(BelowAtSlowest(below, 0.04));  // 0.045 is not below 0.04
  EXPECT_FALSE(BelowAtSlowest({}, 0.05));
}
