// plot_breakage.py on a small hand-made sweep: PNGs exist, critical velocity
// agrees with the C++ FindCriticalVelocity.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "postprocess/breakage_results.h"
#include "postprocess/distributions.h"

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
  const fs::path dir = fs::temp_directory_path() / "mill_post_plot_breakage";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string summary = (dir / "summary.csv").string();
  const std::string fractions = (dir / "fractions.csv").string();

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
      AppendSummaryCsv(summary, s);
      r.fraction_edges = DefaultFractionEdges();
      r.fraction_mass.assign(12, 0.0);
      r.fraction_mass[11 - 3 * k] = largest[rep][k];
      r.fraction_mass[0] = 1.0 - largest[rep][k];
      AppendFractionsCsv(fractions, r);
      points.push_back({speeds[k], rep, largest[rep][k]});
    }
  }
  const fs::path out = dir / "plots";
  const std::string cmd = kPython + " " + kScript + " --summary " + summary + " --fractions " +
                          fractions + " --out " + out.string() +
                          " --threshold 0.05 --velocities 20,100,150";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  for (const char* png :
       {"pieces_vs_velocity.png", "largest_vs_velocity.png", "mass_distribution.png"}) {
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

TEST(PlotBreakage, MissingColumnFailsWithItsName) {
  if (!PythonHasPlotting()) GTEST_SKIP() << kPython << " lacks matplotlib/numpy";
  const fs::path dir = fs::temp_directory_path() / "mill_post_plot_bad";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "s.csv") << "velocity_m_s,angle_deg\n1,90\n";
  std::ofstream(dir / "f.csv") << "velocity_m_s\n1\n";
  const std::string cmd = kPython + " " + kScript + " --summary " + (dir / "s.csv").string() +
                          " --fractions " + (dir / "f.csv").string() + " --out " +
                          (dir / "o").string() + " 2> " + (dir / "err.txt").string();
  EXPECT_NE(std::system(cmd.c_str()), 0);
  std::ifstream err(dir / "err.txt");
  const std::string text((std::istreambuf_iterator<char>(err)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("repeat"), std::string::npos) << text;
}

}  // namespace
}  // namespace mill::post
