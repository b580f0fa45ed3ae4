// The adaptive time step (breakage.adaptive_step, fix step/adaptive) end to
// end: a 200-element lump shattered at 150 m/s through `orchestrate`, once
// with the adaptive step and once with the fixed one.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

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

// The case, with breakage.adaptive_step set to `adaptive`, run into the folder `dir`.
fs::path run_case(const fs::path& dir, bool adaptive) {
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
// energy put in, the run's residual_bound; a row beyond it stops the run),
// the step grew after the lump shattered, and the VTK dumps stayed at their
// interval in simulated time. The fixed run: no step file,
// and the same breakage within the spread of such a small lump.
TEST(AdaptiveStep, LedgerClosesAndStepGrowsAfterShattering) {
  const auto adaptive_dir = scratch("adaptive"), fixed_dir = scratch("fixed");
  const fs::path adaptive = run_case(adaptive_dir, true), fixed = run_case(fixed_dir, false);
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

  // The VTK dumps (breakage.dump_interval 1e-4 s) stay at the interval in
  // simulated time while the step grows: snapshot k (run/post/lump_<step>.vtk)
  // at -2e-6 I <= t - k I < the step that ended there (the deck counts a time
  // within 1e-6 I of a multiple as on it; the step file's 10 digits),
  // one per interval up to the end of the run. A snapshot's time is rebuilt
  // from the step file: row r holds the step from r.step on.
  const double interval = 1e-4;
  auto time_of = [&](double step) {
    double t = step * dt0;
    for (const auto& r : rows)
      if (r.step <= step) t = r.time + (step - r.step) * r.dt;
    return t;
  };
  auto dt_before = [&](double step) {  // length of the step that ended at `step`
    double dt = dt0;
    for (const auto& r : rows)
      if (r.step < step) dt = r.dt;
    return dt;
  };
  std::vector<double> dump_steps;
  for (const auto& e : fs::directory_iterator(adaptive / "run/post")) {
    const std::string name = e.path().filename().string();
    // lump_<step>.vtk (not custom/vtk's lump_boundingBox_<step>.vtk)
    if (name.rfind("lump_", 0) == 0 && e.path().extension() == ".vtk" &&
        std::isdigit(static_cast<unsigned char>(name[5])))
      dump_steps.push_back(std::stod(name.substr(5)));
  }
  std::sort(dump_steps.begin(), dump_steps.end());
  const size_t stop_at = log.find("impact: stopped at t = ");
  ASSERT_NE(stop_at, std::string::npos) << "no 'impact: stopped at' line in the log";
  const double t_stop = std::stod(log.substr(stop_at + 23));
  ASSERT_GE(dump_steps.size(), 5u) << "too few VTK dumps in " << (adaptive / "run/post");
  EXPECT_EQ(static_cast<double>(dump_steps.size()), std::floor(t_stop / interval * (1 + 1e-9)) + 1)
      << "one dump per " << interval << " s up to t = " << t_stop << " s";
  double worst = 0;
  for (size_t k = 0; k < dump_steps.size(); ++k) {
    const double late = time_of(dump_steps[k]) - k * interval, dt = dt_before(dump_steps[k]);
    worst = std::max(worst, late / dt);
    EXPECT_GE(late, -2e-6 * interval) << "dump " << k << " at step " << dump_steps[k];
    EXPECT_LT(late, dt + 1e-9 * interval) << "dump " << k << " at step " << dump_steps[k] << ": "
                                          << late << " s after " << k << " x " << interval << " s";
  }
  std::printf("VTK dumps: %zu, every %g s up to t = %g s, at most %.3f steps late\n",
              dump_steps.size(), interval, t_stop, worst);
  // Both shattered the lump: at 150 m/s nearly every bond breaks.
  EXPECT_GT(ra.at("broken_bond_fraction").get<double>(), 0.9);
  EXPECT_NEAR(ra.at("broken_bond_fraction").get<double>(),
              rf.at("broken_bond_fraction").get<double>(), 0.05);
}

}  // namespace
