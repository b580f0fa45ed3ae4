// breakage.strength_velocities on a finished tiny run: the workflow run of
// e2e.stage_all (CTest fixture: $MILL_E2E_RUNS/tiny_all) copied, its case
// given strength impacts and its breakage stage rerun. Only the strength
// impacts run (the other jobs keep their ids); the critical impact speed
// then crosses between them, below every impact stage 1 gave; the mill's
// product is the same to the byte (it reads stage 1's bins only). A sweep
// case with strength impacts is a named error.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "e2e_util.h"

namespace fs = std::filesystem;

namespace {

using namespace mill::e2e;

fs::path fixture_run() {
  const char* r = std::getenv("MILL_E2E_RUNS");
  return r ? fs::path(r) / "tiny_all" : fs::path();
}

TEST(StrengthImpacts, LocateTheCriticalSpeedAndLeaveTheProduct) {
  const fs::path src = fixture_run();
  ASSERT_TRUE(fs::exists(src / "breakage/product.json"))
      << "run e2e.stage_all first (CTest fixture): " << src;
  const auto dir = scratch("strength");
  const fs::path run = dir / "run";
  fs::copy(fs::canonical(src), run, fs::copy_options::recursive);  // the fixture is a link
  std::string text = slurp(fs::path(MILL_TEST_DATA) / "tiny_all.yaml");
  const std::string anchor = "  velocity_bins: 2\n";
  ASSERT_NE(text.find(anchor), std::string::npos);
  text.replace(text.find(anchor), anchor.size(), anchor + "  strength_velocities: [5, 30]\n");
  spit(dir / "case.yaml", text);
  const std::string product_before = slurp(run / "breakage/product.json");
  double slowest_mill = 1e9;
  for (const auto& e : fs::directory_iterator(run / "breakage/jobs")) {
    const std::string label = e.path().filename().string();
    if (label.rfind("rpm2000_b", 0) != 0) continue;
    const auto job = nlohmann::json::parse(slurp(e.path() / "job.json"));
    slowest_mill = std::min(slowest_mill, job.at("inputs").at("velocity").get<double>());
  }
  ASSERT_LT(slowest_mill, 1e9) << "no stage-1 impact in the fixture";

  ASSERT_EQ(orchestrate("--case '" + (dir / "case.yaml").string() +
                            "' --stage breakage --output '" + run.string() + "'",
                        dir / "strength.log"),
            0)
      << slurp(dir / "strength.log");
  const std::string log = slurp(dir / "strength.log");
  // 2 speeds x breakage.repeats (2) new; the 4 binned impacts and 2 in-mill lumps kept.
  EXPECT_NE(log.find("finished: 4 run, 6 skipped"), std::string::npos) << log;
  for (const char* label :
       {"strength_v5_a90_r0", "strength_v5_a90_r1", "strength_v30_a90_r0", "strength_v30_a90_r1"}) {
    const auto job = nlohmann::json::parse(slurp(run / "breakage/jobs" / label / "job.json"));
    EXPECT_TRUE(job.at("inputs").at("strength").get<bool>()) << label;
    EXPECT_TRUE(fs::exists(run / "breakage/jobs" / label / "summary.csv")) << label;
  }
  // The lump holds at 5 m/s and shatters at 30 (150 elements, closed to the
  // card by the fixture's calibration): the crossing lies between them.
  const auto crit = nlohmann::json::parse(slurp(run / "breakage/critical_velocity.json"));
  ASSERT_EQ(crit.size(), 1u) << crit.dump();
  ASSERT_TRUE(crit[0].at("critical_velocity_m_s").is_number()) << crit.dump();
  const double v = crit[0].at("critical_velocity_m_s").get<double>();
  EXPECT_FALSE(crit[0].at("upper_bound").get<bool>()) << crit.dump();
  EXPECT_GT(v, 5.0);
  EXPECT_LE(v, 30.0);
  EXPECT_LT(v, slowest_mill) << "located below stage 1's slowest impact";
  // The summary has the strength impacts' rows; the product is stage 1's alone.
  const std::string summary = slurp(run / "breakage/summary.csv");
  EXPECT_NE(summary.find("\n5,90,0,"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\n30,90,1,"), std::string::npos) << summary;
  EXPECT_EQ(slurp(run / "breakage/product.json"), product_before);
}

TEST(StrengthImpacts, OnASweepCaseIsANamedError) {
  const auto dir = scratch("strength_sweep");
  std::string text = slurp(fs::path(MILL_TEST_DATA) / "tiny_all.yaml");
  const std::string from = "  conditions: transport\n";
  ASSERT_NE(text.find(from), std::string::npos);
  text.replace(text.find(from), from.size(),
               "  conditions: sweep\n  strength_velocities: [5, 30]\n");
  spit(dir / "case.yaml", text);
  EXPECT_NE(orchestrate("--case '" + (dir / "case.yaml").string() + "' --stage breakage --dry-run",
                        dir / "bad.log"),
            0);
  const std::string log = slurp(dir / "bad.log");
  EXPECT_NE(log.find("breakage.strength_velocities"), std::string::npos) << log;
  EXPECT_NE(log.find("breakage.conditions: transport"), std::string::npos) << log;
}

}  // namespace
