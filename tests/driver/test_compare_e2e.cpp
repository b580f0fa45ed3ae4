// `orchestrate compare` on two finished tiny runs that earlier end-to-end
// tests leave behind (CTest fixtures: $MILL_E2E_RUNS/tiny_all from
// e2e.stage_all, $MILL_E2E_RUNS/tiny_breakage from e2e.breakage), and its
// argument checks: a folder that is not a finished run is a named error.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "e2e_util.h"

namespace fs = std::filesystem;

namespace {

using namespace mill::e2e;

fs::path runs() {
  const char* r = std::getenv("MILL_E2E_RUNS");
  return r ? fs::path(r) : fs::path();
}

TEST(Compare, TwoFinishedRunsSideBySide) {
  const fs::path all = runs() / "tiny_all", sweep = runs() / "tiny_breakage";
  ASSERT_TRUE(fs::exists(all / "report/summary.json")) << "run e2e.stage_all first (CTest fixture): " << all;
  ASSERT_TRUE(fs::exists(sweep / "report/summary.json")) << "run e2e.breakage first (CTest fixture): " << sweep;
  const auto dir = scratch("compare");
  const fs::path out = dir / "cmp";
  ASSERT_EQ(orchestrate("compare '" + all.string() + "' '" + sweep.string() + "' --output '" + out.string() + "'",
                        dir / "compare.log"),
            0)
      << slurp(dir / "compare.log");
  const std::string html = slurp(out / "index.html");
  // One column per run, named by its case.
  EXPECT_NE(html.find("<th>tiny_all</th>"), std::string::npos);
  EXPECT_NE(html.find("<th>tiny_breakage</th>"), std::string::npos);
  // Headline rows of both: the product of the workflow run, the sweep's critical speed.
  const auto product = nlohmann::json::parse(slurp(all / "breakage/product.json"));
  const std::string p80 = fmt::format("{:.3g} mm", product.at(0).at("p80_mm").get<double>());
  EXPECT_NE(html.find("<td>product P80, 2000 rpm</td><td>" + p80), std::string::npos) << p80;
  const auto crit = nlohmann::json::parse(slurp(sweep / "breakage/critical_velocity.json"));
  const std::string v = fmt::format("{:.0f} m/s", crit.at(0).at("critical_velocity_m_s").get<double>());
  EXPECT_NE(html.find("<td>critical impact speed (largest piece &lt; 5%), 90 deg</td><td>-</td><td>" + v),
            std::string::npos)
      << v;
  // The product curves, overlaid in one embedded figure; links to both reports.
  // The workflow run's decision on its feed's target P80, beside the sweep
  // that has no feed.
  const auto circuit = nlohmann::json::parse(slurp(all / "breakage/circuit.json"));
  const std::string decision = circuit.at("decision").at("sentence").get<std::string>();
  EXPECT_NE(html.find("<td>lowest rotor speed for a product P80 &lt;= 6 mm</td><td>" + decision +
                      "</td><td>-</td>"),
            std::string::npos)
      << decision;
  EXPECT_GT(fs::file_size(out / "figures/compare_passing.png"), 5000u);
  EXPECT_NE(html.find("data:image/png;base64,"), std::string::npos);
  // Every link (the two reports) resolves from the page's folder.
  int reports = 0;
  for (size_t at = html.find("href=\""); at != std::string::npos; at = html.find("href=\"", at + 1)) {
    const std::string ref = html.substr(at + 6, html.find('"', at + 6) - at - 6);
    EXPECT_TRUE(fs::exists(out / ref)) << ref;
    reports += ref.size() > 17 && ref.compare(ref.size() - 17, 17, "report/index.html") == 0;
  }
  EXPECT_EQ(reports, 2);
}

TEST(Compare, AFolderThatIsNotAFinishedRunIsANamedError) {
  const fs::path all = runs() / "tiny_all";
  const auto dir = scratch("compare_bad");
  fs::create_directories(dir / "half_done/breakage");  // a run whose report never ran
  EXPECT_EQ(orchestrate("compare '" + all.string() + "' '" + (dir / "half_done").string() + "' --output '" +
                            (dir / "o").string() + "'",
                        dir / "half.log"),
            2);
  EXPECT_NE(slurp(dir / "half.log").find((dir / "half_done").string() + ": not a finished run"), std::string::npos)
      << slurp(dir / "half.log");
  EXPECT_NE(slurp(dir / "half.log").find("--stage all"), std::string::npos) << slurp(dir / "half.log");
  EXPECT_FALSE(fs::exists(dir / "o/index.html"));

  EXPECT_EQ(orchestrate("compare '" + all.string() + "' '" + (dir / "nowhere").string() + "'", dir / "none.log"), 2);
  EXPECT_NE(slurp(dir / "none.log").find("nowhere: no such run folder"), std::string::npos) << slurp(dir / "none.log");

  EXPECT_EQ(orchestrate("compare '" + all.string() + "'", dir / "one.log"), 2);
  EXPECT_NE(slurp(dir / "one.log").find("at least two run folders"), std::string::npos) << slurp(dir / "one.log");

  EXPECT_EQ(orchestrate("compare '" + all.string() + "' '" + all.string() + "'", dir / "twice.log"), 2);
  EXPECT_NE(slurp(dir / "twice.log").find("given twice"), std::string::npos) << slurp(dir / "twice.log");
}

}  // namespace
