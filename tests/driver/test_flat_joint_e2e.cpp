// The flat joint through the breakage stage (issue 28): a tiny campaign with
// lump.bond_model: flat_joint runs fix bond/flatjoint in the impact deck
// (liggghts_inputs/lump_bonds.in: bond/${bond_style} with the model's
// ${bond_model_keys}), records the model in every job's result, conserves
// energy in the ledger, and breaks more at the faster impact.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <regex>
#include <string>

#include "e2e_util.h"

namespace fs = std::filesystem;
using namespace mill::e2e;

namespace {
const std::string kData = MILL_TEST_DATA;

nlohmann::json result_of(const fs::path& run, const std::string& job) {
  return nlohmann::json::parse(slurp(run / "breakage" / "jobs" / job / "result.json"));
}
}  // namespace

TEST(FlatJointBreakage, ImpactsRunWithFlatJointsAndConserveEnergy) {
  const fs::path dir = scratch("flat_joint");
  const fs::path run = dir / "run";
  ASSERT_EQ(orchestrate("--case " + kData + "/tiny_flat_joint.yaml --stage breakage --output " +
                            run.string(),
                        dir / "orchestrate.log"),
            0)
      << slurp(dir / "orchestrate.log");
  double broken[2] = {0, 0};
  int k = 0;
  for (const char* job : {"v5_a90_r0", "v80_a90_r0"}) {
    const auto r = result_of(run, job);
    const auto& b = r["bond_parameters"];
    EXPECT_EQ(b.value("bond_model", ""), "flat_joint") << job;
    EXPECT_EQ(b.value("joint_rings", 0), 1) << job;
    EXPECT_EQ(b.value("joint_sectors", 0), 3) << job;
    EXPECT_FALSE(b.contains("moment_factor")) << job << ": a parallel bond's row";
    // The deck made flat joints at the coordination of the interaction range.
    const std::string log = slurp(run / "breakage" / "jobs" / job / "run" / "liggghts.log");
    std::smatch m;
    ASSERT_TRUE(std::regex_search(
        log, m, std::regex("fix bond/flatjoint: created [0-9]+ bonds among [0-9]+ atoms, mean "
                           "coordination ([0-9.]+)")))
        << job << ": no flat joints in the engine log";
    EXPECT_GT(std::stod(m[1]), 8.0) << job << ": coordination of bond gap 1.0";
    // Energy conservation (fix energy/ledger): the residual stays below 1 % of
    // the energy given at every row of the run.
    EXPECT_LT(r["energy"].value("residual_fraction_max", 1.0), 0.01) << job;
    broken[k++] = r.value("broken_bond_fraction", -1.0);
  }
  EXPECT_GE(broken[0], 0.0);
  EXPECT_GT(broken[1], broken[0]) << "80 m/s must break more interfaces than 5 m/s";
  fs::remove_all(dir);
}
