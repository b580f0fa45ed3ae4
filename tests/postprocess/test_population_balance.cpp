// The closed-circuit population balance on hand-made breakage matrices:
// mass conservation, closed forms of small circuits, the pass-by-pass
// iteration, P80 of the product and the errors a bad matrix or cut gives.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <random>

#include "postprocess/fragments.h"
#include "postprocess/population_balance.h"

namespace mill::post {
namespace {

double Sum(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); }

// The text of the PostError that `f` throws ("" and a failure when none).
template <class F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const PostError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a PostError";
  return "";
}

// A random lower-triangular, column-stochastic matrix of n classes.
BreakageMatrix RandomBreakage(std::size_t n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  BreakageMatrix b(n, std::vector<double>(n, 0.0));
  for (std::size_t j = 0; j < n; ++j) {
    double sum = 0.0;
    for (std::size_t i = j; i < n; ++i) sum += (b[i][j] = u(rng));
    for (std::size_t i = j; i < n; ++i) b[i][j] /= sum;
  }
  return b;
}

// Mass is conserved to 1e-12 relative over random circuits: random breakage,
// a sharp cut at a random sieve or a random classification, random feed.
TEST(PopulationBalance, MassIsConservedForRandomCircuits) {
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const SizeClasses classes = GeometricSieveSeries(63.0, std::sqrt(2.0), 10);
  for (int trial = 0; trial < 200; ++trial) {
    const BreakageMatrix b = RandomBreakage(classes.size(), rng);
    std::vector<double> c(classes.size()), f(classes.size());
    if (trial % 2 == 0) {
      c = SharpCutClassification(classes, classes.upper_mm[1 + trial % 8]);
    } else {
      for (double& x : c) x = u(rng);
    }
    for (double& x : f) x = u(rng);
    const CircuitState s = SolveCircuit(classes, b, c, f);
    EXPECT_LE(std::abs(Sum(s.product) - Sum(f)) / Sum(f), 1e-12) << "trial " << trial;
    EXPECT_LE(s.mass_balance_residual, 1e-12) << "trial " << trial;
    EXPECT_DOUBLE_EQ(s.feed_total, Sum(f));
    // The steady-state equation m = f + C B m itself, to 1e-12 of the mill input.
    for (std::size_t i = 0; i < classes.size(); ++i) {
      EXPECT_NEAR(s.mill_input[i], f[i] + s.returned[i], 1e-12 * Sum(s.mill_input))
          << "trial " << trial;
      EXPECT_GE(s.product[i], 0.0);
    }
    EXPECT_NEAR(s.circulating_load, Sum(s.returned) / Sum(f), 1e-15 * (1 + s.circulating_load));
  }
}

// Two classes, 1 coarse (above the cut) and 2 fine, B = [[b, 0], [1-b, 1]],
// sharp cut c = (1, 0), feed (f1, f2). By hand:
//   m1 = f1 + b m1          => m1 = f1 / (1 - b);   m2 = f2
//   out = (b m1, (1-b) m1 + m2) = (b f1 / (1 - b), f1 + f2)
//   product = (0, f1 + f2);  returned = b f1 / (1 - b)
//   circulating load = b f1 / ((1 - b) (f1 + f2)).
TEST(PopulationBalance, TwoClassSharpCutMatchesTheClosedForm) {
  const double b = 0.3, f1 = 2.0, f2 = 0.5;
  const SizeClasses classes = MakeSizeClasses({40.0, 20.0});
  const std::vector<double> c = SharpCutClassification(classes, 20.0);
  ASSERT_EQ(c, (std::vector<double>{1.0, 0.0}));
  const CircuitState s = SolveCircuit(classes, {{b, 0.0}, {1.0 - b, 1.0}}, c, {f1, f2});
  EXPECT_NEAR(s.mill_input[0], f1 / (1 - b), 1e-12);
  EXPECT_NEAR(s.mill_input[1], f2, 1e-12);
  EXPECT_NEAR(s.mill_output[0], b * f1 / (1 - b), 1e-12);
  EXPECT_NEAR(s.mill_output[1], f1 + f2, 1e-12);
  EXPECT_NEAR(s.product[0], 0.0, 1e-12);
  EXPECT_NEAR(s.product[1], f1 + f2, 1e-12);
  EXPECT_NEAR(s.returned[0], b * f1 / (1 - b), 1e-12);
  EXPECT_NEAR(s.circulating_load, b * f1 / ((1 - b) * (f1 + f2)), 1e-12);
  EXPECT_LE(s.mass_balance_residual, 1e-15);
}

// The same two classes with a partial return c of the coarse class (a cut
// inside it): m1 = f1 / (1 - c b), product = ((1 - c) b m1, (1 - b) m1 + f2),
// which sums to f1 + f2; circulating load = c b f1 / ((1 - c b) (f1 + f2)).
TEST(PopulationBalance, TwoClassPartialReturnMatchesTheClosedForm) {
  const double b = 0.6, cc = 0.7, f1 = 1.5, f2 = 0.25;
  const SizeClasses classes = MakeSizeClasses({40.0, 20.0});
  const CircuitState s = SolveCircuit(classes, {{b, 0.0}, {1.0 - b, 1.0}}, {cc, 0.0}, {f1, f2});
  const double m1 = f1 / (1 - cc * b);
  EXPECT_NEAR(s.mill_input[0], m1, 1e-12);
  EXPECT_NEAR(s.product[0], (1 - cc) * b * m1, 1e-12);
  EXPECT_NEAR(s.product[1], (1 - b) * m1 + f2, 1e-12);
  EXPECT_NEAR(s.circulating_load, cc * b * f1 / ((1 - cc * b) * (f1 + f2)), 1e-12);
  EXPECT_NEAR(s.product_total, f1 + f2, 1e-12);
}

// A cut above the top sieve returns nothing: one pass, product = B f.
TEST(PopulationBalance, NothingAboveTheCutGivesNoCirculatingLoad) {
  std::mt19937 rng(7);
  const SizeClasses classes = GeometricSieveSeries(40.0, 2.0, 5);
  const BreakageMatrix b = RandomBreakage(classes.size(), rng);
  const std::vector<double> c = SharpCutClassification(classes, 100.0);
  EXPECT_EQ(c, std::vector<double>(classes.size(), 0.0));
  const std::vector<double> f = {0.4, 0.3, 0.2, 0.1, 0.0};
  const CircuitState s = SolveCircuit(classes, b, c, f);
  EXPECT_EQ(s.circulating_load, 0.0);
  EXPECT_EQ(Sum(s.returned), 0.0);
  for (std::size_t i = 0; i < classes.size(); ++i) {
    double bf = 0.0;
    for (std::size_t j = 0; j <= i; ++j) bf += b[i][j] * f[j];
    EXPECT_NEAR(s.product[i], bf, 1e-15);
    EXPECT_EQ(s.mill_input[i], f[i]);
  }
  const PassHistory h = IterateCircuit(classes, b, c, f);
  EXPECT_EQ(h.passes, 1);
}

// Sieves 40, 20, 10, 5 mm, cut at 10 mm, feed 1 in the 20-40 mm class and
//   B = [[0.5, 0,   0,   0],
//        [0.3, 0.4, 0,   0],
//        [0.1, 0.4, 0.7, 0],
//        [0.1, 0.2, 0.3, 1]].
// By hand: m0 = 1 / (1 - 0.5) = 2, m1 = 0.3 * 2 / (1 - 0.4) = 1, m2 = m3 = 0;
// out = (1, 1, 0.1*2 + 0.4*1, 0.1*2 + 0.2*1) = (1, 1, 0.6, 0.4); returned 2
// (circulating load 2), product (0, 0, 0.6, 0.4). Passing at 5, 10, 20, 40 mm:
// 40, 100, 100, 100 %. P80 log-linear between 5 mm (40 %) and 10 mm (100 %):
// 5 * 2^((80 - 40) / 60) = 5 * 2^(2/3) mm; P50 = 5 * 2^(1/6) mm.
TEST(PopulationBalance, P80OfTheSteadyProductForAKnownMatrix) {
  const SizeClasses classes = MakeSizeClasses({40.0, 20.0, 10.0, 5.0});
  const BreakageMatrix b = {
      {0.5, 0.0, 0.0, 0.0}, {0.3, 0.4, 0.0, 0.0}, {0.1, 0.4, 0.7, 0.0}, {0.1, 0.2, 0.3, 1.0}};
  const CircuitState s =
      SolveCircuit(classes, b, SharpCutClassification(classes, 10.0), {1.0, 0.0, 0.0, 0.0});
  EXPECT_NEAR(s.circulating_load, 2.0, 1e-12);
  const std::vector<double> expected = {0.0, 0.0, 0.6, 0.4};
  for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR(s.product[i], expected[i], 1e-12);
  const auto p80 = SizeAtPercentPassing(classes, s.product, 80);
  const auto p50 = SizeAtPercentPassing(classes, s.product, 50);
  ASSERT_TRUE(p80 && p50);
  EXPECT_NEAR(*p80, 5.0 * std::pow(2.0, 2.0 / 3.0), 1e-12);
  EXPECT_NEAR(*p50, 5.0 * std::pow(2.0, 1.0 / 6.0), 1e-12);
  // Below the finest sieve the P-value is not resolved (the breakage stage's convention).
  EXPECT_FALSE(SizeAtPercentPassing(classes, s.product, 30).has_value());
}

// Pass by pass, the circuit settles on the direct solution; for two classes
// the batch left after k passes is b^k f1 (of f1 + f2) exactly.
TEST(PopulationBalance, PassIterationConvergesToTheDirectSolution) {
  std::mt19937 rng(3);
  const SizeClasses classes = GeometricSieveSeries(50.0, std::sqrt(2.0), 8);
  const BreakageMatrix b = RandomBreakage(classes.size(), rng);
  const std::vector<double> c = SharpCutClassification(classes, 12.0);
  const std::vector<double> f = {0.3, 0.4, 0.2, 0.1, 0, 0, 0, 0};
  const CircuitState direct = SolveCircuit(classes, b, c, f);
  const PassHistory h = IterateCircuit(classes, b, c, f, 1e-14);
  EXPECT_GT(h.passes, 1);
  ASSERT_EQ(h.remaining.size(), static_cast<std::size_t>(h.passes));
  EXPECT_LE(h.remaining.back(), 1e-14);
  for (std::size_t k = 1; k < h.remaining.size(); ++k)
    EXPECT_LT(h.remaining[k], h.remaining[k - 1]);
  for (std::size_t i = 0; i < classes.size(); ++i) {
    EXPECT_NEAR(h.state.mill_input[i], direct.mill_input[i], 1e-12 * Sum(direct.mill_input));
    EXPECT_NEAR(h.state.product[i], direct.product[i], 1e-12);
  }
  EXPECT_NEAR(h.state.circulating_load, direct.circulating_load, 1e-12);

  const double bb = 0.5, f1 = 1.0, f2 = 1.0;
  const SizeClasses two = MakeSizeClasses({40.0, 20.0});
  const PassHistory h2 =
      IterateCircuit(two, {{bb, 0.0}, {1 - bb, 1.0}}, {1.0, 0.0}, {f1, f2}, 1e-6);
  // 0.5^k / 2 <= 1e-6 first at k = 19 (0.5^19 / 2 = 9.5e-7; 0.5^18 / 2 = 1.9e-6).
  EXPECT_EQ(h2.passes, 19);
  for (std::size_t k = 0; k < h2.remaining.size(); ++k)
    EXPECT_NEAR(h2.remaining[k], std::pow(bb, static_cast<double>(k + 1)) * f1 / (f1 + f2), 1e-15);
}

// A class above the cut that never breaks (b_jj = 1) is reported by name,
// by the direct solution and by the iteration alike, without looping.
TEST(PopulationBalance, AClassAboveTheCutThatNeverBreaksIsNamed) {
  const SizeClasses classes = MakeSizeClasses({40.0, 20.0, 10.0});
  const BreakageMatrix b = {{0.5, 0.0, 0.0}, {0.25, 1.0, 0.0}, {0.25, 0.0, 1.0}};
  const std::vector<double> c = SharpCutClassification(classes, 10.0);
  const std::vector<double> f = {1.0, 0.0, 0.0};
  for (const std::string& msg : {ErrorOf([&] { SolveCircuit(classes, b, c, f); }),
                                 ErrorOf([&] { IterateCircuit(classes, b, c, f); })}) {
    EXPECT_NE(msg.find("10-20 mm class"), std::string::npos) << msg;
    EXPECT_NE(msg.find("does not break"), std::string::npos) << msg;
    EXPECT_NE(msg.find("never leaves"), std::string::npos) << msg;
  }
  // The same class, reached by nothing, holds nothing: no error.
  const BreakageMatrix b2 = {{0.5, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.5, 0.0, 1.0}};
  const CircuitState s = SolveCircuit(classes, b2, c, f);
  EXPECT_EQ(s.mill_input[1], 0.0);
  EXPECT_NEAR(s.product[2], 1.0, 1e-15);
}

// A circuit too slow for the passes allowed names its slowest class.
TEST(PopulationBalance, TooFewPassesNameTheSlowestClass) {
  const SizeClasses classes = MakeSizeClasses({40.0, 20.0});
  const std::string msg = ErrorOf([&] {
    IterateCircuit(classes, {{0.999, 0.0}, {0.001, 1.0}}, {1.0, 0.0}, {1.0, 0.0}, 1e-12, 100);
  });
  EXPECT_NE(msg.find("after 100 passes"), std::string::npos) << msg;
  EXPECT_NE(msg.find("20-40 mm class"), std::string::npos) << msg;
}

// The straddling class returns the part above the cut, even in log(size).
TEST(PopulationBalance, SharpCutInterpolatesTheStraddlingClassInLogSize) {
  const SizeClasses classes = MakeSizeClasses({40.0, 20.0, 10.0});
  const auto c = SharpCutClassification(classes, 10.0 * std::sqrt(2.0));
  EXPECT_EQ(c[0], 1.0);
  EXPECT_NEAR(c[1], 0.5, 1e-15);  // ln(20 / 14.14) / ln(20 / 10)
  EXPECT_EQ(c[2], 0.0);
  EXPECT_EQ(SharpCutClassification(classes, 20.0), (std::vector<double>{1.0, 0.0, 0.0}));
  EXPECT_EQ(SharpCutClassification(classes, 10.0), (std::vector<double>{1.0, 1.0, 0.0}));
  const std::string msg = ErrorOf([&] { SharpCutClassification(classes, 5.0); });
  EXPECT_NE(msg.find("inside the finest size class"), std::string::npos) << msg;
}

TEST(PopulationBalance, BadBreakageMatricesAreRejectedNamingTheEntry) {
  const SizeClasses classes = MakeSizeClasses({40.0, 20.0});
  std::string msg = ErrorOf([&] { ValidateBreakageMatrix(classes, {{0.5, 0.2}, {0.5, 0.8}}); });
  EXPECT_NE(msg.find("b[0][1]"), std::string::npos) << msg;
  EXPECT_NE(msg.find("coarser"), std::string::npos) << msg;
  msg = ErrorOf([&] { ValidateBreakageMatrix(classes, {{0.5, 0.0}, {0.4, 1.0}}); });
  EXPECT_NE(msg.find("column 0 (the 20-40 mm class) sums to 0.9"), std::string::npos) << msg;
  msg = ErrorOf([&] { ValidateBreakageMatrix(classes, {{1.0, 0.0}}); });
  EXPECT_NE(msg.find("1 rows for 2 size classes"), std::string::npos) << msg;
  msg = ErrorOf([&] { SolveCircuit(classes, {{0.5, 0.0}, {0.5, 1.0}}, {1.0, 0.0}, {0.0, 0.0}); });
  EXPECT_NE(msg.find("feed"), std::string::npos) << msg;
  msg = ErrorOf([&] { MakeSizeClasses({20.0, 40.0}); });
  EXPECT_NE(msg.find("strictly descending"), std::string::npos) << msg;
}

// Rosin-Rammler on sieves 10, 20, 40 mm with d63 = 20 mm, n = 1: retained
// exp(-d/20), so the classes hold 1 - e^-0.5, e^-0.5 - e^-1 and (with the
// tail above 40 mm) e^-1.
TEST(PopulationBalance, RosinRammlerFractionsSumToOne) {
  const auto r = RosinRammlerFractions({10.0, 20.0, 40.0}, 20.0, 1.0);
  ASSERT_EQ(r.size(), 3u);
  EXPECT_NEAR(r[0], 1 - std::exp(-0.5), 1e-15);
  EXPECT_NEAR(r[1], std::exp(-0.5) - std::exp(-1.0), 1e-15);
  EXPECT_NEAR(r[2], std::exp(-1.0), 1e-15);
  EXPECT_NEAR(Sum(RosinRammlerFractions({1, 2, 4, 8, 16, 32}, 9.0, 1.3)), 1.0, 1e-15);
  EXPECT_NEAR(RosinRammlerRetained(20.0, 20.0, 2.5), std::exp(-1.0), 1e-15);  // d63: 63.2 % passing
}

TEST(PopulationBalance, SieveSeriesAndRepresentativeSizes) {
  const SizeClasses s = GeometricSieveSeries(40.0, 2.0, 3);
  EXPECT_EQ(s.upper_mm, (std::vector<double>{40.0, 20.0, 10.0}));
  EXPECT_EQ(SizeClassesFromSieves({10.0, 20.0, 40.0}).upper_mm, s.upper_mm);
  EXPECT_NEAR(RepresentativeSize(s, 0), std::sqrt(800.0), 1e-12);
  EXPECT_NEAR(RepresentativeSize(s, 2), std::sqrt(50.0), 1e-12);  // lower edge 10 / 2 by the series
  EXPECT_EQ(s.name(0), "20-40 mm");
  EXPECT_EQ(s.name(2), "below-10 mm");
}

// The decision: the lowest rotor speed whose product P80 meets a target.
TEST(LowestSpeedMeetingP80, InterpolatesLinearlyInRpmWhereP80CrossesTheTarget) {
  // P80 12, 9, 6, 5 mm at 1000..2500 rpm (given out of order); a 7 mm target
  // is crossed between 1500 (9 mm) and 2000 rpm (6 mm): 1500 + 2/3 x 500.
  const auto d = LowestSpeedMeetingP80({{2000, 6}, {1000, 12}, {2500, 5}, {1500, 9}}, 7.0);
  EXPECT_EQ(d.kind, TargetDecision::Kind::crossed);
  EXPECT_NEAR(d.rpm, 1500 + 500 * 2.0 / 3.0, 1e-9);
  EXPECT_EQ(d.below_rpm, 1500);
  EXPECT_EQ(d.above_rpm, 2000);
  EXPECT_TRUE(d.interpolated);
  EXPECT_TRUE(d.met_above);
  EXPECT_EQ(DecisionSentence(d), "met from 1833 rpm (interpolated between 1500 and 2000 rpm)");
  // A target met exactly at a simulated speed: that speed.
  EXPECT_NEAR(LowestSpeedMeetingP80({{1000, 12}, {1500, 9}}, 9.0).rpm, 1500, 1e-9);
}

TEST(LowestSpeedMeetingP80, MetEverywhereOrNowhereSaysSo) {
  const auto all = LowestSpeedMeetingP80({{1000, 4}, {1500, 3}}, 7.0);
  EXPECT_EQ(all.kind, TargetDecision::Kind::met_at_lowest);
  EXPECT_EQ(all.rpm, 1000);
  EXPECT_EQ(DecisionSentence(all), "met at every simulated speed: lowest simulated 1000 rpm");
  const auto none = LowestSpeedMeetingP80({{1000, 12}, {1500, 9}}, 7.0);
  EXPECT_EQ(none.kind, TargetDecision::Kind::not_met);
  EXPECT_EQ(DecisionSentence(none), "not met at any simulated speed");
  // One speed only.
  EXPECT_EQ(LowestSpeedMeetingP80({{2000, 6}}, 7.0).kind, TargetDecision::Kind::met_at_lowest);
}

TEST(LowestSpeedMeetingP80, NoSteadyStateBelowAndAP80ThatRisesAgain) {
  const double inf = HUGE_VAL;
  // No steady state at 1000 rpm: nothing to interpolate from.
  const auto d = LowestSpeedMeetingP80({{1000, inf}, {1500, 6}}, 7.0);
  EXPECT_EQ(d.kind, TargetDecision::Kind::crossed);
  EXPECT_FALSE(d.interpolated);
  EXPECT_EQ(d.rpm, 1500);
  EXPECT_EQ(DecisionSentence(d),
            "met from 1500 rpm (no steady state at 1000 rpm to interpolate from)");
  // Met at 1500 but not again at 2500 rpm: said.
  const auto up = LowestSpeedMeetingP80({{1000, 8}, {1500, 6}, {2000, 6.5}, {2500, 7.5}}, 7.0);
  EXPECT_FALSE(up.met_above);
  EXPECT_EQ(up.first_unmet_above, 2500);
  EXPECT_NE(DecisionSentence(up).find("but not at 2500 rpm"), std::string::npos);
}

TEST(LowestSpeedMeetingP80, BadInputIsAnError) {
  EXPECT_THROW(LowestSpeedMeetingP80({}, 7.0), PostError);
  EXPECT_THROW(LowestSpeedMeetingP80({{1000, 8}}, 0.0), PostError);
  const std::string e = ErrorOf([] { LowestSpeedMeetingP80({{1000, 8}, {1000, 6}}, 7.0); });
  EXPECT_NE(e.find("1000 rpm given twice"), std::string::npos) << e;
}

}  // namespace
}  // namespace mill::post
