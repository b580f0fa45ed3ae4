// Parameter sets from different starts through the calibrate and breakage
// stages: calibrate.starts 2 fits twice (the second from the estimate
// scaled by its Halton factors), publishes the second set where the
// breakage stage reads it, and the breakage stage repeats its sweep with
// that set and reports each set's critical speed and the band.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "e2e_util.h"
#include "stages/calibrate/starts.h"

namespace fs = std::filesystem;
using namespace mill::e2e;

namespace {
const std::string kData = MILL_TEST_DATA;

nlohmann::json json_of(const fs::path& f) { return nlohmann::json::parse(slurp(f)); }
}  // namespace

TEST(CalibrationSets, TwoStartsGiveTwoSetsAndTheBreakageBandOverThem) {
  const auto dir = scratch("calibration_sets");
  const fs::path run = dir / "run";
  ASSERT_EQ(orchestrate("--case " + kData + "/tiny_sets.yaml --stage calibrate-breakage --output " +
                            run.string(),
                        dir / "orchestrate.log"),
            0)
      << slurp(dir / "orchestrate.log");

  // The calibrate stage: two fits, the second from its own start.
  const auto sets = json_of(run / "calibrate" / "sets.json");
  ASSERT_EQ(sets["starts"].get<int>(), 2);
  const auto& s2 = sets["sets"][1];
  EXPECT_EQ(s2["start"].get<int>(), 2);
  const auto f2 = mill::calibrate::start_factors(2);
  EXPECT_NEAR(s2["start_factors"]["bond_modulus"].get<double>(), f2[0], 1e-12);
  const auto start2 = json_of(run / "calibrate" / "jobs" / "calibration_start2" / "report.json");
  const auto start1 = json_of(run / "calibrate" / "jobs" / "calibration" / "report.json");
  // Iteration 1 of each fit ran its own start: the bond moduli differ by the factor.
  const double eb1 = start1["iterations"][0]["bond"]["bond_modulus"].get<double>();
  const double eb2 = start2["iterations"][0]["bond"]["bond_modulus"].get<double>();
  EXPECT_NEAR(eb2 / eb1, f2[0], 1e-6);
  // Only the primary set carries the checks.
  EXPECT_FALSE(start1["checks"]["triaxial"].empty()) << start1["checks"].dump();
  EXPECT_TRUE(start2["checks"]["triaxial"].empty() || start2["checks"]["triaxial"].is_null())
      << start2["checks"].dump();
  ASSERT_TRUE(fs::exists(run / "calibrate" / "sets" / "start2" / "calibrated.yaml"));
  EXPECT_NE(slurp(run / "calibrate" / "report.md").find("Parameter sets from different starts"),
            std::string::npos);

  // The breakage stage: the sweep twice, each set's lumps with its own bonds.
  const auto r1 = json_of(run / "breakage" / "jobs" / "v40_a90_r0" / "result.json");
  const auto r2 = json_of(run / "breakage" / "jobs" / "set2_v40_a90_r0" / "result.json");
  const double b1 = r1["bond_parameters"]["modulus"].get<double>();
  const double b2 = r2["bond_parameters"]["modulus"].get<double>();
  EXPECT_NEAR(b1, start1["calibrated"]["bond_modulus"].get<double>(), 1e-6 * b1);
  EXPECT_NEAR(b2, start2["calibrated"]["bond_modulus"].get<double>(), 1e-6 * b2);
  EXPECT_NE(b1, b2);
  // The merged tables hold the primary set only.
  const std::string summary = slurp(run / "breakage" / "summary.csv");
  EXPECT_EQ(std::count(summary.begin(), summary.end(), '\n'), 4) << summary;  // header + 3
  // Each set's critical speed; set 1's is critical_velocity.json's.
  const auto crit = json_of(run / "breakage" / "critical_velocity.json");
  const auto band = json_of(run / "breakage" / "calibration_sets.json");
  ASSERT_EQ(band["sets"].get<int>(), 2);
  const auto& e = band["entries"][0];
  ASSERT_EQ(e["sets"].size(), 2u);
  EXPECT_EQ(e["sets"][0]["critical_velocity_m_s"], crit[0]["critical_velocity_m_s"]);
  for (const auto& s : e["sets"]) EXPECT_EQ(s["impacts"].get<int>(), 3);
  // The band spans the sets that crossed.
  if (e["min_m_s"].is_number())
    for (const auto& s : e["sets"])
      if (s["critical_velocity_m_s"].is_number()) {
        EXPECT_LE(e["min_m_s"].get<double>(), s["critical_velocity_m_s"].get<double>());
        EXPECT_GE(e["max_m_s"].get<double>(), s["critical_velocity_m_s"].get<double>());
      }
  // A rerun plans nothing new: every job is done.
  ASSERT_EQ(orchestrate("--case " + kData + "/tiny_sets.yaml --stage calibrate-breakage --output " +
                            run.string() + " --dry-run",
                        dir / "dry.log"),
            0);
  EXPECT_EQ(slurp(dir / "dry.log").find("[todo]"), std::string::npos) << slurp(dir / "dry.log");
}
