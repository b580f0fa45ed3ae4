// Parameter sets from different starts: where the starts begin (Halton
// points), the table of the sets, and the band of critical speeds over them.
#include <gtest/gtest.h>

#include <cmath>

#include "stages/breakage/calibration_sets.h"
#include "stages/calibrate/starts.h"

namespace mill {
namespace {

using calibrate::start_factors;
using calibrate::start_params;

// Start 1 is the estimate itself; start 2 is the Halton point of index 2 in
// bases 2, 3, 5, 7: (1/4, 2/3, 2/5, 2/7), mapped to 2^(2h - 1).
TEST(CalibrationStarts, FactorsAreHaltonPointsInLogSpace) {
  for (double f : start_factors(1)) EXPECT_EQ(f, 1.0);
  const auto f2 = start_factors(2);
  EXPECT_NEAR(f2[0], std::pow(2.0, -0.5), 1e-12);
  EXPECT_NEAR(f2[1], std::pow(2.0, 1.0 / 3.0), 1e-12);
  EXPECT_NEAR(f2[2], std::pow(2.0, -0.2), 1e-12);
  EXPECT_NEAR(f2[3], std::pow(2.0, -3.0 / 7.0), 1e-12);
  // Index 3: (3/4, 1/9, 3/5, 3/7).
  const auto f3 = start_factors(3);
  EXPECT_NEAR(f3[0], std::pow(2.0, 0.5), 1e-12);
  EXPECT_NEAR(f3[1], std::pow(2.0, 2.0 / 9.0 - 1.0), 1e-12);
  EXPECT_NEAR(f3[2], std::pow(2.0, 0.2), 1e-12);
  EXPECT_NEAR(f3[3], std::pow(2.0, -1.0 / 7.0), 1e-12);
  // Every start of a case stays within x/÷ kStartSpread and differs from the others.
  for (int k = 2; k <= calibrate::kMaxStarts; ++k) {
    for (double f : start_factors(k)) {
      EXPECT_GT(f, 1.0 / calibrate::kStartSpread);
      EXPECT_LT(f, calibrate::kStartSpread);
    }
    for (int m = 2; m < k; ++m) EXPECT_NE(start_factors(k), start_factors(m)) << k << " " << m;
  }
}

TEST(CalibrationStarts, ParamsScaleTheEstimateWithinTheFitsBounds) {
  BondParams e;
  e.modulus = 20e9;
  e.stiffness_ratio = 2.5;
  e.tensile = 10e6;
  e.cohesion = 20e6;
  e.friction_angle_deg = 30;
  const BondParams p1 = start_params(e, 1);
  EXPECT_EQ(p1.modulus, e.modulus);
  EXPECT_EQ(p1.cohesion, e.cohesion);
  const BondParams p2 = start_params(e, 2);
  const auto f = start_factors(2);
  EXPECT_NEAR(p2.modulus, 20e9 * f[0], 1e-3);
  EXPECT_NEAR(p2.stiffness_ratio, 2.5 * f[1], 1e-12);
  EXPECT_NEAR(p2.tensile, 10e6 * f[2], 1e-6);
  EXPECT_NEAR(p2.cohesion / p2.tensile, 2.0 * f[3], 1e-12);
  EXPECT_EQ(p2.friction_angle_deg, 30);  // the coarse levers are not moved
  // A stiffness ratio near the fit's lower bound stays inside it.
  e.stiffness_ratio = 0.55;
  for (int k = 2; k <= calibrate::kMaxStarts; ++k)
    EXPECT_GE(start_params(e, k).stiffness_ratio, 0.5) << k;
}

// Rows of a sweep at one angle whose largest piece falls linearly from 1 at
// 0 m/s to 0 at `zero` m/s: crossing 0.25 at 0.75 zero.
std::vector<post::ImpactSummary> linear_sweep(double zero) {
  std::vector<post::ImpactSummary> rows;
  for (double v : {10.0, 20.0, 30.0, 40.0, 50.0, 60.0})
    for (int r = 0; r < 2; ++r) {
      post::ImpactSummary s;
      s.velocity_m_s = v;
      s.angle_deg = 90;
      s.repeat = r;
      s.largest_mass_fraction = std::max(0.0, 1.0 - v / zero);
      rows.push_back(s);
    }
  return rows;
}

TEST(CalibrationSetsBand, CriticalSpeedPerSetAndTheBand) {
  // Sets crossing at 30, 33 and 24 m/s (zero at 40, 44, 32).
  std::vector<breakage::SetRows> sets = {
      {1, linear_sweep(40.0)}, {2, linear_sweep(44.0)}, {3, linear_sweep(32.0)}};
  const nlohmann::json primary = nlohmann::json::array(
      {{{"angle_deg", 90.0}, {"critical_velocity_m_s", 30.0}}});
  const nlohmann::json calib = {
      {"sets",
       {{{"start", 1}, {"meets_card", true}},
        {{"start", 2}, {"meets_card", true}},
        {{"start", 3}, {"meets_card", false}}}}};
  const nlohmann::json j = breakage::calibration_sets_json(primary, sets, calib, 0.25, false);
  ASSERT_EQ(j["entries"].size(), 1u);
  const auto& e = j["entries"][0];
  EXPECT_NEAR(e["sets"][0]["critical_velocity_m_s"].get<double>(), 30.0, 1e-9);
  EXPECT_NEAR(e["sets"][1]["critical_velocity_m_s"].get<double>(), 33.0, 1e-9);
  EXPECT_NEAR(e["sets"][2]["critical_velocity_m_s"].get<double>(), 24.0, 1e-9);
  EXPECT_NEAR(e["min_m_s"].get<double>(), 24.0, 1e-9);
  EXPECT_NEAR(e["max_m_s"].get<double>(), 33.0, 1e-9);
  EXPECT_EQ(e["sets_crossing"].get<int>(), 3);
  // Over the sets that meet the card: 30-33.
  EXPECT_EQ(e["sets_meeting_card"].get<int>(), 2);
  EXPECT_NEAR(e["min_meeting_card_m_s"].get<double>(), 30.0, 1e-9);
  EXPECT_NEAR(e["max_meeting_card_m_s"].get<double>(), 33.0, 1e-9);
  // 24 is 20 % below 30: outside +-15 %.
  EXPECT_FALSE(e["within_15_percent"].get<bool>());
  // Without set 3 the band 30-33 is within +-15 % (33 = 1.10 x 30).
  sets.pop_back();
  const auto j2 = breakage::calibration_sets_json(primary, sets, calib, 0.25, false);
  EXPECT_TRUE(j2["entries"][0]["within_15_percent"].get<bool>());
}

// A set already shattered at the slowest speed only bounds its critical
// speed: the band is flagged and not judged within +-15 %.
TEST(CalibrationSetsBand, ShatteredAtTheSlowestSpeedIsAnUpperBound) {
  std::vector<breakage::SetRows> sets = {{1, linear_sweep(40.0)}, {2, linear_sweep(11.0)}};
  const nlohmann::json primary = nlohmann::json::array(
      {{{"angle_deg", 90.0}, {"critical_velocity_m_s", 30.0}}});
  const auto j = breakage::calibration_sets_json(primary, sets, nullptr, 0.25, false);
  const auto& e = j["entries"][0];
  EXPECT_FALSE(e["sets"][0]["upper_bound"].get<bool>());
  EXPECT_TRUE(e["sets"][1]["upper_bound"].get<bool>());  // 1 - 10/11 < 0.25 at 10 m/s
  EXPECT_NEAR(e["sets"][1]["critical_velocity_m_s"].get<double>(), 10.0, 1e-12);
  EXPECT_TRUE(e["upper_bound"].get<bool>());
  EXPECT_TRUE(e["within_15_percent"].is_null());
}

TEST(CalibrationSetsBand, ASetThatNeverShattersLeavesTheBandOpen) {
  std::vector<breakage::SetRows> sets = {{1, linear_sweep(40.0)}, {2, linear_sweep(400.0)}};
  const nlohmann::json primary = nlohmann::json::array(
      {{{"angle_deg", nullptr}, {"critical_velocity_m_s", 30.0}}});
  const auto j = breakage::calibration_sets_json(primary, sets, nullptr, 0.25, true);
  const auto& e = j["entries"][0];
  EXPECT_TRUE(e["sets"][1]["critical_velocity_m_s"].is_null());
  EXPECT_EQ(e["sets_crossing"].get<int>(), 1);
  EXPECT_TRUE(e["within_15_percent"].is_null());  // not known: one set never crossed
  EXPECT_EQ(e["sets_meeting_card"].get<int>(), 0);  // no calibrate/sets.json: none known to meet
}

TEST(CalibrationSetsTable, CountsTheSetsThatMeetTheCard) {
  std::vector<calibrate::StartResult> starts = {
      {1, "/r/calibrate/jobs/calibration",
       {{"converged", false},
        {"achieved", {{"youngs_modulus", 19e9}, {"ucs", 21e6}, {"tensile_strength", 5e6}}},
        {"not_reached", {"UCS 21.0 of 50.0 MPa"}}}},
      {2, "/r/calibrate/jobs/calibration_start2",
       {{"converged", true},
        {"achieved", {{"youngs_modulus", 18e9}, {"ucs", 49e6}, {"tensile_strength", 5e6}}}}}};
  const auto j = calibrate::sets_json(starts);
  EXPECT_EQ(j["starts"].get<size_t>(), 2u);
  EXPECT_EQ(j["meeting_card"].get<int>(), 1);
  EXPECT_FALSE(j["sets"][0]["meets_card"].get<bool>());
  EXPECT_TRUE(j["sets"][1]["meets_card"].get<bool>());
  EXPECT_EQ(j["sets"][1]["job"].get<std::string>(), "calibration_start2");
  const std::string md = calibrate::sets_markdown(j);
  EXPECT_NE(md.find("2 start(s), 1 meeting every target"), std::string::npos) << md;
  EXPECT_NE(md.find("no: UCS 21.0 of 50.0 MPa"), std::string::npos) << md;
  EXPECT_NE(md.find("| 9.80 |"), std::string::npos) << md;  // UCS/T of start 2
  EXPECT_EQ(md.find("K_IC"), std::string::npos) << md;     // no toughness fit: no column
  // Sets of the toughness fit carry K_IC: a column, "-" where a set has none.
  starts[1].report["achieved"]["fracture_toughness"] = 0.684e6;
  const std::string mk = calibrate::sets_markdown(calibrate::sets_json(starts));
  EXPECT_NE(mk.find("| UCS/T | K_IC (MPa m^0.5) | meets the card |"), std::string::npos) << mk;
  EXPECT_NE(mk.find("| 9.80 | 0.684 | yes |"), std::string::npos) << mk;
  EXPECT_NE(mk.find("| 4.20 | - | no: "), std::string::npos) << mk;
}

}  // namespace
}  // namespace mill
