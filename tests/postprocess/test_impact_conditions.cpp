// Binning of impacts into breakage conditions and the weighted mill product,
// on hand-made data with answers worked out by hand.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "postprocess/fragments.h"
#include "postprocess/impact_conditions.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using namespace mill::post;

namespace {

// A hand-made impacts.csv: six flywheel impacts, two housing impacts.
//   flywheel normal speeds 10, 12, 30, 31, 50, 2(slow: ignored below 5 m/s)
mill::test::TempPath HandMadeImpacts() {
  mill::test::TempPath p("mill_impacts_" + std::to_string(getpid()) + ".csv");
  std::ofstream o(p.path());
  o << "time_s,particle_id,surface,x_m,y_m,z_m,speed_m_s,normal_speed_m_s,tangential_speed_m_s,angle_deg\n"
    << "0.01,1,flywheel,0,0,0,20,10,17.32,30\n"
    << "0.02,2,flywheel,0,0,0,24,12,20.78,30\n"
    << "0.03,3,flywheel,0,0,0,30,30,0,90\n"
    << "0.04,4,flywheel,0,0,0,31,31,0,90\n"
    << "0.05,5,flywheel,0,0,0,100,50,86.6,30\n"
    << "0.06,6,flywheel,0,0,0,4,2,3.46,30\n"
    << "0.07,1,housing,0,0,0,40,40,0,90\n"
    << "0.08,2,housing,0,0,0,41,41,0,90\n";
  return p;
}

TEST(BinImpacts, EqualWidthBinsOfNormalSpeedWithShares) {
  const auto file = HandMadeImpacts();
  const auto impacts = ReadImpactsCsv(file.string());
  ASSERT_EQ(impacts.size(), 8u);
  // Flywheel only, slower than 5 m/s ignored: normal speeds 10..50 in 4 bins of 10 m/s:
  // [10,20): 10, 12   [20,30): -   [30,40): 30, 31   [40,50]: 50
  const auto c = BinImpacts(impacts, {"flywheel"}, 4, 5.0);
  ASSERT_EQ(c.size(), 3u);  // the empty bin is dropped
  EXPECT_EQ(c[0].count, 2);
  EXPECT_NEAR(c[0].weight, 0.4, 1e-12);
  EXPECT_NEAR(c[0].velocity_m_s, 22.0, 1e-12);
  EXPECT_NEAR(c[0].angle_deg, 30.0, 1e-12);
  EXPECT_NEAR(c[0].normal_speed_m_s, 11.0, 1e-12);
  EXPECT_NEAR(c[0].normal_low_m_s, 10.0, 1e-12);
  EXPECT_NEAR(c[0].normal_high_m_s, 20.0, 1e-12);
  EXPECT_EQ(c[1].bin, 2);
  EXPECT_NEAR(c[1].weight, 0.4, 1e-12);
  EXPECT_NEAR(c[1].velocity_m_s, 30.5, 1e-12);
  EXPECT_EQ(c[2].count, 1);  // the top edge belongs to the last bin
  EXPECT_NEAR(c[2].weight, 0.2, 1e-12);
  double w = 0;
  for (const auto& x : c) w += x.weight;
  EXPECT_NEAR(w, 1.0, 1e-12);
}

TEST(BinImpacts, WallImpactsWhenAsked) {
  const auto file = HandMadeImpacts();
  const auto impacts = ReadImpactsCsv(file.string());
  const auto c = BinImpacts(impacts, {"flywheel", "housing"}, 1, 5.0);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c[0].count, 7);
  EXPECT_NEAR(c[0].normal_speed_m_s, (10 + 12 + 30 + 31 + 50 + 40 + 41) / 7.0, 1e-12);
}

TEST(BinImpacts, NoQualifyingImpactIsAnError) {
  const auto file = HandMadeImpacts();
  const auto impacts = ReadImpactsCsv(file.string());
  EXPECT_THROW(BinImpacts(impacts, {"flywheel"}, 3, 1000.0), PostError);
  EXPECT_THROW(BinImpacts(impacts, {"flywheel"}, 0), PostError);
}

TEST(CombineProduct, WeightedSumOfDistributions) {
  // Two conditions, weights 3:1 (normalised to 0.75, 0.25), three fractions.
  ConditionBreakage a{3.0, {0.2, 0.3, 0.5}, 0.1, 0.6, 10.0};
  ConditionBreakage b{1.0, {0.6, 0.4, 0.0}, 0.5, 0.1, 50.0};
  const auto p = CombineProduct({a, b});
  ASSERT_EQ(p.fraction_mass.size(), 3u);
  EXPECT_NEAR(p.fraction_mass[0], 0.75 * 0.2 + 0.25 * 0.6, 1e-12);
  EXPECT_NEAR(p.fraction_mass[1], 0.75 * 0.3 + 0.25 * 0.4, 1e-12);
  EXPECT_NEAR(p.fraction_mass[2], 0.75 * 0.5, 1e-12);
  EXPECT_NEAR(p.fraction_mass[0] + p.fraction_mass[1] + p.fraction_mass[2], 1.0, 1e-12);  // mass conserved
  EXPECT_NEAR(p.single_mass_fraction, 0.2, 1e-12);
  EXPECT_NEAR(p.largest_mass_fraction, 0.475, 1e-12);
  EXPECT_NEAR(p.t10_percent, 20.0, 1e-12);
}

TEST(CombineProduct, MismatchedFractionsAreAnError) {
  EXPECT_THROW(CombineProduct({{1.0, {1.0}, 0, 0, 0}, {1.0, {0.5, 0.5}, 0, 0, 0}}), PostError);
  EXPECT_THROW(CombineProduct({}), PostError);
}

}  // namespace
