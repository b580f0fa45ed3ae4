// The adaptive time step (breakage.adaptive_step, fix step/adaptive) end to
// end: a 200-element lump shattered at 150 m/s through `orchestrate`, once
// with the adaptive step and once with the fixed one.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sstream>

#include "e2e_util.h"

namespace fs = std::filesystem;

namespace {

using namespace mill::e2e;

const std::string kData = MILL_TEST_DATA;

struct StepRow {
  double step, time, dt, dt_bonds, intact;
};

// The rows of fix step/adaptive's file (step,time_s,dt_s,dt_bonds_s,intact_bonds).
std::vector<StepRow> read_steps(const fs::path& file) {
  std::vector<StepRow> rows;
  std::istringstream in(slurp(file));
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line[0] == 's') continue;
    StepRow r{};
    char c;
    std::istringstream ls(line);
    ls >> r.step >> c >> r.time >> c >> r.dt >> c >> r.dt_bonds >> c >> r.intact;
    if (ls) rows.push_back(r);
  }
  return rows;
}

// The case, with breakage.adaptive_step set to `adaptive`, run into its own folder.
fs::path run_case(bool adaptive) {
  const fs::path dir = scratch(adaptive ? "adaptive" : "fixed");
  std::string text = slurp(kData + "/tiny_adaptive.yaml");
  if (!adaptive) text.replace(text.find("adaptive_step: true"), 19, "adaptive_step: false");
  spit(dir / "case.yaml", text);
  const int st = orchestrate("--case " + (dir / "case.yaml").string() +
                                 " --stage breakage --output " + (dir / "run").string(),
                             dir / "run.log");
  EXPECT_EQ(st, 0) << slurp(dir / "run.log");
  return dir / "run/breakage/jobs/v150_a90_r0";
}

// The adaptive run: the energy ledger closes within its bound (1 % of the
// energy put in, the run's residual_bound; a row beyond it stops the run)
// and the step grew after the lump shattered. The fixed run: no step file,
// and the same breakage within the spread of such a small lump.
TEST(AdaptiveStep, LedgerClosesAndStepGrowsAfterShattering) {
  const fs::path adaptive = run_case(true), fixed = run_case(false);
  const auto ra = nlohmann::json::parse(slurp(adaptive / "result.json"));
  const auto rf = nlohmann::json::parse(slurp(fixed / "result.json"));
  const double res_a = ra.at("energy").at("residual_fraction").get<double>();
  const double res_f = rf.at("energy").at("residual_fraction").get<double>();

  const auto rows = read_steps(adaptive / "run/steps.csv");
  ASSERT_GE(rows.size(), 3u) << "fix step/adaptive wrote no rows";
  // The step of the first chunk (before the first re-evaluation) and the bonds made.
  const double bonds0 = std::stod(slurp(adaptive / "run/bonds_initial.txt"));
  const std::string log = slurp(adaptive / "run/liggghts.log");
  const size_t at = log.find("impact: dt ");
  ASSERT_NE(at, std::string::npos) << "no 'impact: dt' line in the log";
  const double dt0 = std::stod(log.substr(at + 11));
  double dt_max = dt0, intact_at_growth = -1;
  for (const auto& r : rows) {
    if (r.dt > dt0 * 1.01 && intact_at_growth < 0) intact_at_growth = r.intact;
    dt_max = std::max(dt_max, r.dt);
    EXPECT_TRUE(r.dt_bonds == 0 || r.dt <= 0.5 * r.dt_bonds * (1 + 1e-9))
        << "step " << r.dt << " s above half the bonds' critical step " << r.dt_bonds
        << " s at t = " << r.time;
  }
  std::printf(
      "adaptive step: %zu re-evaluations, step %.3g s (first chunk, %g bonds made) -> %.3g s (at "
      "most), "
      "first growth with %g bonds left; residual/input %.2e adaptive, %.2e fixed (bound 1e-2); "
      "broken bonds %.1f%% "
      "adaptive, %.1f%% fixed; largest piece %.1f%% / %.1f%%\n",
      rows.size(), dt0, bonds0, dt_max, intact_at_growth, res_a, res_f,
      100 * ra.at("broken_bond_fraction").get<double>(),
      100 * rf.at("broken_bond_fraction").get<double>(),
      100 * ra.at("largest_mass_fraction").get<double>(),
      100 * rf.at("largest_mass_fraction").get<double>());
  EXPECT_LT(std::abs(res_a), 0.01);  // the ledger's bound (residual_bound of the deck)
  EXPECT_GT(dt_max, 1.5 * dt0) << "the step did not grow";
  EXPECT_GE(intact_at_growth, 0);
  EXPECT_LT(intact_at_growth, 0.5 * bonds0) << "the step grew before the lump had shattered";
  EXPECT_FALSE(fs::exists(fixed / "run/steps.csv"));
  // Both shattered the lump: at 150 m/s nearly every bond breaks.
  EXPECT_GT(ra.at("broken_bond_fraction").get<double>(), 0.9);
  EXPECT_NEAR(ra.at("broken_bond_fraction").get<double>(),
              rf.at("broken_bond_fraction").get<double>(), 0.05);
}

}  // namespace
