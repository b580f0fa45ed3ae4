// plot_breakage.py on a small hand-made sweep: PNGs exist, critical velocity
// agrees with the C++ FindCriticalVelocity.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "postprocess/breakage_results.h"
#include "postprocess/distributions.h"
#include "postprocess/jk_fit.h"
#include "temp_dir.h"

namespace mill::post {
namespace {

namespace fs = std::filesystem;
const std::string kPython = "/usr/bin/python3";
const std::string kScript = MILL_PLOT_BREAKAGE_SCRIPT;

// True when the system Python can import the plotting stack.
bool PythonHasPlotting() {
  const std::string cmd = kPython + " -c 'import matplotlib, numpy' >/dev/null 2>&1";
  return std::system(cmd.c_str()) == 0;
}

TEST(PlotBreakage, WritesPngsAndCriticalVelocity) {
  if (!PythonHasPlotting()) GTEST_SKIP() << kPython << " lacks matplotlib/numpy";
  const mill::test::TempDir dir("mill_post_plot_breakage_" + std::to_string(getpid()));
  const std::string summary = (dir / "summary.csv").string();
  const std::string passing = (dir / "size_distributions.csv").string();
  std::ofstream pass(passing);
  pass << "velocity_m_s,angle_deg,sieve_mm,passing_percent,passing_percent_min,passing_percent_"
          "max\n";

  // Two repeats at four speeds; largest piece falls from 1 to 0.01.
  const double speeds[] = {20.0, 60.0, 100.0, 150.0};
  const double largest[2][4] = {{1.0, 0.6, 0.1, 0.01}, {0.95, 0.4, 0.03, 0.02}};
  std::vector<SweepPoint> points;
  for (int rep = 0; rep < 2; ++rep) {
    for (int k = 0; k < 4; ++k) {
      ImpactResult r;
      ImpactSummary& s = r.summary;
      s.velocity_m_s = speeds[k];
      s.angle_deg = 90.0;
      s.repeat = rep;
      s.n_elements = 100;
      s.n_single = 10 * (k + 1) + rep;
      s.n_multi = 5 - k;
      s.n_pieces = s.n_single + s.n_multi;
      s.largest_mass_fraction = largest[rep][k];
      s.specific_energy_J_kg = 0.5 * speeds[k] * speeds[k];
      s.comminution_efficiency = 0.01 * (k + 1) + 0.002 * rep;
      AppendSummaryCsv(summary, s);
      points.push_back({speeds[k], rep, largest[rep][k]});
    }
    for (double sieve : {2.0, 4.0, 8.0, 16.0, 40.0})
      pass << speeds[rep] << ",90," << sieve << "," << 100 * sieve / 40 << "," << 90 * sieve / 40
           << "," << 100 * sieve / 40 << "\n";
  }
  pass.close();
  const fs::path out = dir / "plots";
  const std::string cmd = kPython + " " + kScript + " --summary " + summary + " --passing " +
                          passing + " --out " + out.string() +
                          " --threshold 0.05 --velocities 20,100,150";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  for (const char* png : {"pieces_vs_velocity.png", "largest_vs_velocity.png", "passing_vs_size.png",
                          "comminution_efficiency_vs_velocity.png"}) {
    ASSERT_TRUE(fs::exists(out / png)) << png;
    EXPECT_GT(fs::file_size(out / png), 1000u) << png;
  }
  std::ifstream in(out / "critical_velocity.json");
  const auto j = nlohmann::json::parse(in);
  const auto c = FindCriticalVelocity(points, 0.05);
  const auto& a = j.at("angles").at("90");
  EXPECT_NEAR(a.at("critical_velocity_m_s").get<double>(), *c.of_mean_curve, 1e-9);
  EXPECT_NEAR(a.at("min_m_s").get<double>(), *c.min, 1e-9);
  EXPECT_NEAR(a.at("max_m_s").get<double>(), *c.max, 1e-9);
  EXPECT_NEAR(a.at("std_m_s").get<double>(), *c.stddev, 1e-9);
}

TEST(PlotJk, DrawsPointsFitAndOreCardAndNamesABadFile) {
  if (!PythonHasPlotting()) GTEST_SKIP() << kPython << " lacks matplotlib/numpy";
  const mill::test::TempDir dir("mill_post_plot_jk_" + std::to_string(getpid()));
  std::ofstream pts(dir / "jk_points.csv");
  pts << "angle_deg,velocity_m_s,repeat,ecs_kWh_t,t10_percent,t10_resolved\n";
  for (double v : {20.0, 60.0, 100.0, 150.0}) {
    const double e = SpecificEnergyKWhPerTonne(v);
    pts << "90," << v << ",0," << e << "," << JkT10(50, 1.1, e) << "," << (v > 20 ? 1 : 0) << "\n";
  }
  pts.close();
  std::ofstream(dir / "jk_fit.json")
      << R"([{"angle_deg": 90, "fitted": true, "A_percent": 50, "b_t_per_kWh": 1.1,)"
      << R"( "ore_card": {"A_percent": 55, "b_t_per_kWh": 0.9}}])";
  const std::string base = kPython + " " + MILL_PLOT_JK_SCRIPT + " --points " +
                           (dir / "jk_points.csv").string() + " --out " + (dir / "plots").string() +
                           " --fit ";
  ASSERT_EQ(std::system((base + (dir / "jk_fit.json").string()).c_str()), 0);
  EXPECT_GT(fs::file_size(dir / "plots" / "jk_t10_vs_ecs.png"), 1000u);
  std::ofstream(dir / "bad.json") << R"([{"angle_deg": 90, "fitted": true}])";
  const std::string bad = base + (dir / "bad.json").string() + " 2> " + (dir / "err.txt").string();
  EXPECT_NE(std::system(bad.c_str()), 0);
  std::ifstream err(dir / "err.txt");
  const std::string text((std::istreambuf_iterator<char>(err)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("A_percent"), std::string::npos) << text;
}

// A summary.csv without ledgers (efficiency NaN) draws no efficiency plot.
TEST(PlotBreakage, NoEfficiencyPlotWithoutLedgers) {
  if (!PythonHasPlotting()) GTEST_SKIP() << kPython << " lacks matplotlib/numpy";
  const mill::test::TempDir dir("mill_post_plot_no_ledger_" + std::to_string(getpid()));
  fs::create_directories(dir / "plots");
  std::ofstream(dir / "plots" / "comminution_efficiency_vs_velocity.png") << "stale";
  const std::string summary = (dir / "summary.csv").string();
  for (double v : {20.0, 60.0}) {
    ImpactSummary s;
    s.velocity_m_s = v;
    s.n_single = 3;
    s.largest_mass_fraction = 60.0 / v / 3.0;
    AppendSummaryCsv(summary, s);
  }
  const std::string cmd =
      kPython + " " + kScript + " --summary " + summary + " --out " + (dir / "plots").string();
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  EXPECT_TRUE(fs::exists(dir / "plots" / "largest_vs_velocity.png"));
  EXPECT_FALSE(fs::exists(dir / "plots" / "comminution_efficiency_vs_velocity.png"));
}

// plot_energy_ledger.py on the hand-written ledger: a PNG; a ledger without
// a column stops with the file, line and column.
TEST(PlotEnergyLedger, DrawsTheStackAndNamesAMissingColumn) {
  if (!PythonHasPlotting()) GTEST_SKIP() << kPython << " lacks matplotlib/numpy";
  const mill::test::TempDir dir("mill_post_plot_ledger_" + std::to_string(getpid()));
  const std::string base = kPython + " " + MILL_PLOT_ENERGY_LEDGER_SCRIPT + " --ledger ";
  const std::string good = base + MILL_POST_TEST_DATA + "/ledger_small.csv --out " +
                           (dir / "energy_ledger.png").string() + " --title '150 m/s at 90 deg'";
  ASSERT_EQ(std::system(good.c_str()), 0) << good;
  EXPECT_GT(fs::file_size(dir / "energy_ledger.png"), 1000u);
  EXPECT_FALSE(fs::exists(dir / "energy_ledger.png.tmp"));
  std::ofstream(dir / "bad.csv") << "# a comment\nstep,time_s,input_J\n0,0,1\n";
  const std::string bad = base + (dir / "bad.csv").string() + " --out " +
                          (dir / "bad.png").string() + " 2> " + (dir / "err.txt").string();
  EXPECT_NE(std::system(bad.c_str()), 0);
  std::ifstream err(dir / "err.txt");
  const std::string text((std::istreambuf_iterator<char>(err)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("bad.csv:2: missing column(s) work_other_J"), std::string::npos) << text;
}

TEST(PlotBreakage, MissingColumnFailsWithItsName) {
  if (!PythonHasPlotting()) GTEST_SKIP() << kPython << " lacks matplotlib/numpy";
  const mill::test::TempDir dir("mill_post_plot_bad_" + std::to_string(getpid()));
  std::ofstream(dir / "s.csv") << "velocity_m_s,angle_deg\n1,90\n";
  const std::string cmd = kPython + " " + kScript + " --summary " + (dir / "s.csv").string() +
                          " --out " + (dir / "o").string() + " 2> " + (dir / "err.txt").string();
  EXPECT_NE(std::system(cmd.c_str()), 0);
  std::ifstream err(dir / "err.txt");
  const std::string text((std::istreambuf_iterator<char>(err)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("repeat"), std::string::npos) << text;
}

}  // namespace
}  // namespace mill::post
