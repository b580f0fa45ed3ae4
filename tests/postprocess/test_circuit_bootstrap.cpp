// The bootstrap band over the in-mill lumps on hand-made lumps: the same
// seed gives the same band, identical lumps collapse it to the point value,
// one lump per class gives no band, and two different lumps span the
// outcomes of their resamples.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "postprocess/circuit_bootstrap.h"
#include "postprocess/fragments.h"

namespace mill::post {
namespace {

// Sieves 32, 16, 8, 4 mm: classes 0 (16-32 mm), 1 (8-16), 2 (4-8) and the
// finest (below 4); a sharp cut at 8 mm returns classes 0 and 1; feed 6 t/h
// of class 0 and 4 t/h of class 1; a P80 target of 6.4 mm.
CircuitSetup MillSetup() {
  CircuitSetup s;
  s.classes = GeometricSieveSeries(32, 2, 4);
  s.c = SharpCutClassification(s.classes, 8);
  s.feed_t_h = {6, 4, 0, 0};
  s.target_p80_mm = 6.4;
  return s;
}

// A lump of 1 kg whose pieces of 20, 10, 6 and 3 mm hold the given masses
// (a piece of no mass left out).
LumpRun Lump(double m20, double m10, double m6, double m3, double work_J) {
  LumpRun l;
  const double size[] = {20, 10, 6, 3}, mass[] = {m20, m10, m6, m3};
  for (int k = 0; k < 4; ++k)
    if (mass[k] > 0) {
      l.pieces.size_mm.push_back(size[k]);
      l.pieces.mass_kg.push_back(mass[k]);
    }
  l.work = {work_J, m20 + m10 + m6 + m3};
  return l;
}

// Two speeds: at 1000 rpm the lumps break less than at 2000 rpm.
std::vector<SpeedLumps> Speeds(bool identical) {
  const LumpRun a0 = Lump(0.5, 0.2, 0.2, 0.1, 40), b0 = Lump(0.3, 0.2, 0.3, 0.2, 60);
  const LumpRun a1 = Lump(0.0, 0.6, 0.3, 0.1, 30), b1 = Lump(0.0, 0.4, 0.4, 0.2, 45);
  const LumpRun c0 = Lump(0.1, 0.2, 0.4, 0.3, 90), d0 = Lump(0.05, 0.15, 0.4, 0.4, 110);
  const LumpRun c1 = Lump(0.0, 0.3, 0.4, 0.3, 60), d1 = Lump(0.0, 0.2, 0.4, 0.4, 75);
  std::vector<SpeedLumps> s(2);
  s[0].rpm = 1000;
  s[0].by_class[0] = identical ? std::vector<LumpRun>{a0, a0, a0} : std::vector<LumpRun>{a0, b0};
  s[0].by_class[1] = identical ? std::vector<LumpRun>{a1, a1} : std::vector<LumpRun>{a1, b1};
  s[0].gas_W = 20000;
  s[1].rpm = 2000;
  s[1].by_class[0] = identical ? std::vector<LumpRun>{c0, c0} : std::vector<LumpRun>{c0, d0};
  s[1].by_class[1] = identical ? std::vector<LumpRun>{c1, c1, c1} : std::vector<LumpRun>{c1, d1};
  s[1].gas_W = 35000;
  return s;
}

TEST(CircuitBootstrap, TheSameSeedGivesTheSameBand) {
  const auto a = BootstrapCircuit(MillSetup(), Speeds(false), {400, 7, 10, 90});
  const auto b = BootstrapCircuit(MillSetup(), Speeds(false), {400, 7, 10, 90});
  ASSERT_TRUE(a.defined);
  ASSERT_EQ(a.speeds.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(a.speeds[k].p80_mm.low, b.speeds[k].p80_mm.low);
    EXPECT_EQ(a.speeds[k].p80_mm.high, b.speeds[k].p80_mm.high);
    ASSERT_TRUE(a.speeds[k].kWh_t && b.speeds[k].kWh_t);
    EXPECT_EQ(a.speeds[k].kWh_t->high, b.speeds[k].kWh_t->high);
  }
  EXPECT_EQ(a.rpm.low, b.rpm.low);
  EXPECT_EQ(a.rpm.high, b.rpm.high);
  EXPECT_EQ(a.met_draws, b.met_draws);
  EXPECT_EQ(BandSentence(a), BandSentence(b));
  EXPECT_NE(BandSentence(a).find("10-90 % of 400 lump resamples: "), std::string::npos)
      << BandSentence(a);
}

TEST(CircuitBootstrap, IdenticalLumpsCollapseTheBandToThePointValue) {
  const CircuitSetup setup = MillSetup();
  const auto speeds = Speeds(true);
  std::vector<SpeedOutcome> point;
  std::map<double, CircuitEnergy> energy;
  for (const auto& s : speeds) {
    point.push_back(EvaluateSpeed(setup, s));
    ASSERT_TRUE(point.back().steady) << point.back().problem;
    energy[s.rpm] = point.back().energy;
  }
  const TargetDecision d = DecideFromOutcomes(setup, speeds, point);
  // The 6.4 mm target is crossed between the two speeds: the kWh/t is interpolated.
  ASSERT_EQ(d.kind, TargetDecision::Kind::crossed) << point[0].p80_mm << " " << point[1].p80_mm;
  const auto kwh = EnergyAtDecision(d, energy, true).kWh_t;
  ASSERT_TRUE(kwh.has_value());
  const auto band = BootstrapCircuit(setup, speeds);
  ASSERT_TRUE(band.defined);
  EXPECT_EQ(band.draws, 400);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_NEAR(band.speeds[k].p80_mm.low, point[k].p80_mm, 1e-12 * point[k].p80_mm);
    EXPECT_NEAR(band.speeds[k].p80_mm.high, point[k].p80_mm, 1e-12 * point[k].p80_mm);
    EXPECT_NEAR(band.speeds[k].kWh_t->low, point[k].energy.total_kWh_t, 1e-12);
    EXPECT_NEAR(band.speeds[k].kWh_t->high, point[k].energy.total_kWh_t, 1e-12);
  }
  EXPECT_NEAR(band.rpm.low, d.rpm, 1e-9);
  EXPECT_NEAR(band.rpm.high, d.rpm, 1e-9);
  EXPECT_EQ(band.met_draws, 400);
  ASSERT_TRUE(band.kWh_t.has_value());
  EXPECT_NEAR(band.kWh_t->low, *kwh, 1e-12 * *kwh);
  EXPECT_NEAR(band.kWh_t->high, *kwh, 1e-12 * *kwh);
}

TEST(CircuitBootstrap, OneLumpPerClassGivesNoBand) {
  auto speeds = Speeds(false);
  for (auto& s : speeds)
    for (auto& [j, lumps] : s.by_class) lumps.resize(1);
  const auto band = BootstrapCircuit(MillSetup(), speeds);
  EXPECT_FALSE(band.defined);
  EXPECT_EQ(band.reason, "1 lump per class: no band");
  EXPECT_EQ(BandSentence(band), "1 lump per class: no band");
  EXPECT_TRUE(band.speeds.empty());
}

// One speed whose class 0 has two different lumps A and B (class 1 one
// lump): a draw takes AA, AB or BB (1/4, 1/2, 1/4), so with 400 draws the
// 10th and 90th percentiles of P80 are those of AA and BB, not AB's (the
// original lumps').
TEST(CircuitBootstrap, TwoDifferentLumpsSpanTheirResamples) {
  CircuitSetup setup = MillSetup();
  setup.target_p80_mm.reset();
  const LumpRun a = Lump(0.5, 0.2, 0.2, 0.1, 40), b = Lump(0.1, 0.2, 0.4, 0.3, 90);
  const LumpRun one = Lump(0.0, 0.5, 0.3, 0.2, 30);
  const auto p80 = [&](std::vector<LumpRun> lumps) {
    SpeedLumps s;
    s.rpm = 1500;
    s.by_class[0] = std::move(lumps);
    s.by_class[1] = {one};
    return EvaluateSpeed(setup, s);
  };
  const SpeedOutcome aa = p80({a, a}), ab = p80({a, b}), bb = p80({b, b});
  const double lo = std::min({aa.p80_mm, ab.p80_mm, bb.p80_mm});
  const double hi = std::max({aa.p80_mm, ab.p80_mm, bb.p80_mm});
  ASSERT_LT(lo, ab.p80_mm);
  ASSERT_GT(hi, ab.p80_mm);
  SpeedLumps s;
  s.rpm = 1500;
  s.by_class[0] = {a, b};
  s.by_class[1] = {one};
  const auto band = BootstrapCircuit(setup, {s});
  ASSERT_TRUE(band.defined);
  EXPECT_FALSE(band.has_target);
  EXPECT_NEAR(band.speeds[0].p80_mm.low, lo, 1e-12 * lo);
  EXPECT_NEAR(band.speeds[0].p80_mm.high, hi, 1e-12 * hi);
  // The work resampled with the same lumps: kWh/t spans AA's and BB's too
  // (the gas absent: the ore's alone), not AB's.
  const double e_lo =
      std::min({aa.energy.total_kWh_t, ab.energy.total_kWh_t, bb.energy.total_kWh_t});
  const double e_hi =
      std::max({aa.energy.total_kWh_t, ab.energy.total_kWh_t, bb.energy.total_kWh_t});
  ASSERT_LT(e_lo, ab.energy.total_kWh_t);
  EXPECT_NEAR(band.speeds[0].kWh_t->low, e_lo, 1e-12);
  EXPECT_NEAR(band.speeds[0].kWh_t->high, e_hi, 1e-12);
}

TEST(CircuitBootstrap, PercentileIsLinearBetweenOrderStatistics) {
  // h = (4 - 1) p / 100: 0.3 and 2.7 for p = 10 and 90.
  EXPECT_NEAR(Percentile({4, 1, 3, 2}, 10), 1.3, 1e-12);
  EXPECT_NEAR(Percentile({4, 1, 3, 2}, 90), 3.7, 1e-12);
  EXPECT_EQ(Percentile({5}, 90), 5.0);
  EXPECT_TRUE(std::isinf(Percentile({1, HUGE_VAL}, 90)));
  EXPECT_EQ(Percentile({1, 1, HUGE_VAL}, 10), 1.0);
  EXPECT_THROW(Percentile({}, 50), PostError);
}

}  // namespace
}  // namespace mill::post
