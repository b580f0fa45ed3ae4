// The closed circuit's energy per tonne on hand-made systems: the
// class-weighted ore power against the closed-form steady mill input, the
// nearest-class rule for a class without lumps, and the kWh/t read at a
// decided rotor speed.
#include <gtest/gtest.h>

#include <cmath>

#include "postprocess/breakage_matrix.h"
#include "postprocess/circuit_energy.h"
#include "postprocess/fragments.h"
#include "postprocess/population_balance.h"

namespace mill::post {
namespace {

// Two classes, a coarse one (10-20 mm) and the finest (below 10 mm); one
// pass keeps b00 of the coarse class and sends b10 = 1 - b00 to the fine;
// the classification returns c0 of the coarse class and c1 of the fine one.
// Closed form of (I - C B) m = f:
//   m0 = f0 / (1 - c0 b00),
//   m1 = (f1 + c1 b10 m0) / (1 - c1 b11),  b11 = 1,
// and P_ore = (m0 w0 + m1 w1) [t/h] x 1000 / 3600 [kg/s per t/h].
TEST(CircuitEnergy, OrePowerIsTheSteadyMillInputPerClassTimesItsWork) {
  const SizeClasses classes = MakeSizeClasses({20, 10});
  const double b00 = 0.6, b10 = 0.4, c0 = 0.9, c1 = 0.3, f0 = 5, f1 = 2;
  const double w0 = 120, w1 = 45, gas_W = 30000;
  const CircuitState s = SolveCircuit(classes, {{b00, 0}, {b10, 1}}, {c0, c1}, {f0, f1});
  const double m0 = f0 / (1 - c0 * b00);
  const double m1 = (f1 + c1 * b10 * m0) / (1 - c1);
  const std::vector<ClassWork> work = {{w0, true, 0}, {w1, true, 1}};
  const CircuitEnergy e = MillEnergyPerTonne(s.mill_input, work, gas_W, f0 + f1);
  const double ore_W = (m0 * w0 + m1 * w1) * 1000.0 / 3600.0;
  EXPECT_NEAR(e.ore_W, ore_W, 1e-12 * ore_W);
  EXPECT_NEAR(e.ore_power_W[0], m0 * w0 / 3.6, 1e-12 * m0 * w0 / 3.6);
  EXPECT_NEAR(e.ore_power_W[1], m1 * w1 / 3.6, 1e-12 * m1 * w1 / 3.6);
  // kWh/t of fresh feed: (P_gas + P_ore) [kW] / (f0 + f1) [t/h].
  const double kwh_t = (gas_W + ore_W) / 1000 / (f0 + f1);
  EXPECT_NEAR(e.total_kWh_t, kwh_t, 1e-12 * kwh_t);
  EXPECT_NEAR(e.ore_kWh_t, ore_W / 1000 / (f0 + f1), 1e-12 * kwh_t);
  // Every pass through the rotor counted: (m0 + m1) t per (f0 + f1) t fed.
  EXPECT_NEAR(e.passes_per_tonne, (m0 + m1) / (f0 + f1), 1e-12);
  EXPECT_NEAR(e.passes_per_tonne, 1 + s.circulating_load, 1e-12);
  // Without the gas: the ore's alone.
  const CircuitEnergy ore = MillEnergyPerTonne(s.mill_input, work, std::nullopt, f0 + f1);
  EXPECT_FALSE(ore.gas_W.has_value());
  EXPECT_NEAR(ore.total_kWh_t, ore_W / 1000 / (f0 + f1), 1e-12 * kwh_t);
}

TEST(CircuitEnergy, BeaterWorkPerKgIsSummedWorkOverSummedMass) {
  // 15 J over 0.05 kg: 300 J/kg, not the mean of the ratios (1000 and 125).
  EXPECT_NEAR(BeaterWorkPerKg({{10, 0.01}, {5, 0.04}}), 300.0, 1e-12 * 300);
  EXPECT_THROW(BeaterWorkPerKg({}), PostError);
  EXPECT_THROW(BeaterWorkPerKg({{1, 0}}), PostError);
  EXPECT_THROW(MillEnergyPerTonne({1, 2}, {{1, true, 0}}, std::nullopt, 3), PostError);
  EXPECT_THROW(MillEnergyPerTonne({1}, {{1, true, 0}}, std::nullopt, 0), PostError);
}

// A class without lumps takes the w of the measured class nearest in
// log(representative size), the coarser of two equally near; the finest
// class likewise.
TEST(CircuitEnergy, AClassWithoutLumpsTakesTheNearestMeasuredClasssWork) {
  // Sieves 32, 16, 8, 4, 2 mm: classes 0..4, one octave apart.
  const SizeClasses classes = GeometricSieveSeries(32, 2, 5);
  const auto w = BeaterWorkPerClass(classes, {{0, 200.0}, {3, 50.0}});
  ASSERT_EQ(w.size(), 5u);
  EXPECT_TRUE(w[0].measured);
  EXPECT_EQ(w[0].J_per_kg, 200.0);
  EXPECT_TRUE(w[3].measured);
  EXPECT_EQ(w[3].J_per_kg, 50.0);
  // Class 1 is one octave from class 0 and two from class 3.
  EXPECT_FALSE(w[1].measured);
  EXPECT_EQ(w[1].from, 0u);
  EXPECT_EQ(w[1].J_per_kg, 200.0);
  // Class 2 is two octaves from class 0 and one from class 3.
  EXPECT_FALSE(w[2].measured);
  EXPECT_EQ(w[2].from, 3u);
  EXPECT_EQ(w[2].J_per_kg, 50.0);
  // The finest class (below 2 mm, representative sqrt(2 x 1) mm) is one
  // octave from class 3.
  EXPECT_FALSE(w[4].measured);
  EXPECT_EQ(w[4].from, 3u);
  // Equally near (class 1 between classes 0 and 2): the coarser.
  const auto tie = BeaterWorkPerClass(classes, {{0, 200.0}, {2, 80.0}});
  EXPECT_EQ(tie[1].from, 0u);
  EXPECT_EQ(tie[1].J_per_kg, 200.0);
  EXPECT_EQ(NearestMeasuredClass(classes, 1, {2, 0}), 0u);
  EXPECT_THROW(BeaterWorkPerClass(classes, {}), PostError);
}

// kWh/t at a crossed decision: interpolated in rpm with the weights of the
// decided rpm.
TEST(CircuitEnergy, KWhPerTonneAtTheDecidedSpeed) {
  // P80 12, 9, 6 mm at 1000, 1500, 2000 rpm; a 7 mm target is met from
  // 1500 + 2/3 x 500 rpm. kWh/t 2, 3, 4.5: at the decision 3 + 2/3 x 1.5 = 4.
  const auto d = LowestSpeedMeetingP80({{1000, 12}, {1500, 9}, {2000, 6}}, 7.0);
  ASSERT_EQ(d.kind, TargetDecision::Kind::crossed);
  const std::map<double, double> kwh = {{1000, 2.0}, {1500, 3.0}, {2000, 4.5}};
  ASSERT_TRUE(ValueAtDecision(d, kwh).has_value());
  EXPECT_NEAR(*ValueAtDecision(d, kwh), 4.0, 1e-12);
  // Met at the lowest speed: that speed's own; not met: none.
  EXPECT_EQ(*ValueAtDecision(LowestSpeedMeetingP80({{1000, 6}, {1500, 5}}, 7.0), kwh), 2.0);
  EXPECT_FALSE(ValueAtDecision(LowestSpeedMeetingP80({{1000, 12}}, 7.0), kwh).has_value());
  // A speed it needs without a value (no steady state there): none.
  EXPECT_FALSE(ValueAtDecision(d, {{1500, 3.0}}).has_value());
  // Not interpolated (no steady state below): the faster speed's own.
  const auto faster = LowestSpeedMeetingP80({{1000, HUGE_VAL}, {1500, 6}}, 7.0);
  EXPECT_EQ(*ValueAtDecision(faster, kwh), 3.0);

  // With the gas only when every speed has it; else the ore's alone.
  CircuitEnergy lo, hi;
  lo.total_kWh_t = 3.0;
  lo.ore_kWh_t = 1.0;
  hi.total_kWh_t = 4.5;
  hi.ore_kWh_t = 2.5;
  const std::map<double, CircuitEnergy> by_rpm = {{1500, lo}, {2000, hi}};
  const DecisionEnergy with_gas = EnergyAtDecision(d, by_rpm, true);
  EXPECT_NEAR(*with_gas.kWh_t, 4.0, 1e-12);
  EXPECT_FALSE(with_gas.ore_only);
  const DecisionEnergy ore = EnergyAtDecision(d, by_rpm, false);
  EXPECT_NEAR(*ore.kWh_t, 1.0 + 2.0 / 3.0 * 1.5, 1e-12);
  EXPECT_TRUE(ore.ore_only);
  EXPECT_EQ(DecisionSentence(d, 4.0, false),
            "met from 1833 rpm (interpolated between 1500 and 2000 rpm), at 4 kWh/t");
  EXPECT_EQ(DecisionSentence(d, 2.0, true),
            "met from 1833 rpm (interpolated between 1500 and 2000 rpm), at 2 kWh/t (ore only: "
            "not every speed has a gas flow run)");
}

}  // namespace
}  // namespace mill::post
