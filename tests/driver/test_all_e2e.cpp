// The whole workflow with real engines, as README command 1 runs it but on
// tiny settings: `orchestrate --stage all` from a folder with the default
// relative run folder (flow on the tiny OpenFOAM mesh, sample, transport,
// calibrate, breakage at the transport's impact conditions, report), killed
// with SIGTERM mid-breakage and rerun: the rerun finishes without redoing any
// job that had finished (checked by the jobs' STATUS modification times).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>

#include "e2e_util.h"

namespace fs = std::filesystem;

namespace {

using namespace mill::e2e;
using mill::jobs::State;

// Every job's STATUS under the run folder: path -> modification time.
std::map<fs::path, fs::file_time_type> status_times(const fs::path& run) {
  std::map<fs::path, fs::file_time_type> t;
  for (const auto& e : fs::recursive_directory_iterator(run))
    if (e.path().filename() == "STATUS") t[e.path()] = fs::last_write_time(e.path());
  return t;
}

// Labels of the breakage jobs in state s.
std::vector<std::string> breakage_jobs(const fs::path& run, State s) {
  std::vector<std::string> out;
  const fs::path stage = run / "breakage", jobs = stage / "jobs";
  if (!fs::is_directory(jobs)) return out;
  for (const auto& e : fs::directory_iterator(jobs))
    if (fs::exists(e.path() / "STATUS") && job_state(stage, e.path().filename().string()) == s)
      out.push_back(e.path().filename().string());
  return out;
}

TEST(WholeWorkflow, StageAllKilledMidBreakageResumesWithoutRedoingJobs) {
  auto dir = scratch("all");
  const fs::path run = dir / "runs" / "tiny_all";  // the default, relative run folder
  const std::vector<std::string> args = {"--case", std::string(MILL_TEST_DATA) + "/tiny_all.yaml", "--stage", "all"};

  // First run: killed once one breakage job is done and the next is running.
  const pid_t pid = spawn_orchestrate(args, dir / "killed.log", dir);
  bool exited = false;
  int early_status = 0;
  const bool ready = wait_for([&] {
    if (waitpid(pid, &early_status, WNOHANG) == pid) exited = true;  // e.g. an earlier stage failed
    return exited || (!breakage_jobs(run, State::Done).empty() && !breakage_jobs(run, State::Running).empty());
  }, 600);
  ASSERT_FALSE(exited) << "orchestrate ended before the kill (status " << early_status << "):\n"
                       << slurp(dir / "killed.log");
  if (!ready) kill(pid, SIGKILL);
  ASSERT_TRUE(ready) << "never saw a breakage job done and another running:\n" << slurp(dir / "killed.log");
  kill(pid, SIGTERM);
  ASSERT_EQ(finish(pid), 128 + SIGTERM) << slurp(dir / "killed.log");

  const auto done_before = breakage_jobs(run, State::Done);
  const auto killed = breakage_jobs(run, State::Failed);
  ASSERT_EQ(killed.size(), 1u) << "the running job must be marked failed:\n" << slurp(dir / "killed.log");
  EXPECT_TRUE(breakage_jobs(run, State::Running).empty());
  EXPECT_FALSE(fs::exists(run / "breakage/jobs" / killed[0] / "summary.csv"));
  EXPECT_FALSE(fs::exists(run / "report/index.html"));
  // Stage 1 and the calibration finished before the kill; their STATUS and
  // that of every finished breakage job must not be written again.
  std::map<fs::path, fs::file_time_type> finished;
  for (const auto& [f, t] : status_times(run))
    if (mill::jobs::JobStore(f.parent_path().parent_path().parent_path())
            .read_status(f.parent_path().filename().string())
            .state == State::Done)
      finished[f] = t;
  for (const char* stage : {"flow/jobs/rpm2000", "sample/jobs/rpm2000", "transport/jobs/rpm2000",
                            "calibrate/jobs/calibration"})
    EXPECT_EQ(finished.count(run / stage / "STATUS"), 1u) << stage << " was not done before the kill";

  // Rerun: finishes, redoes nothing that was done, completes the rest.
  ASSERT_EQ(orchestrate("--case " + args[1] + " --stage all", dir / "resumed.log", dir), 0) << slurp(dir / "resumed.log");
  const auto after = status_times(run);
  for (const auto& [f, t] : finished) {
    ASSERT_EQ(after.count(f), 1u) << f;
    EXPECT_EQ(after.at(f), t) << "redone after the kill: " << f;
  }
  // 2 bins x 2 repeats, and one in-mill lump of each of the two feed classes.
  EXPECT_EQ(breakage_jobs(run, State::Done).size(), 6u) << slurp(dir / "resumed.log");
  EXPECT_NE(slurp(dir / "resumed.log")
                .find("breakage: 6 jobs, " + std::to_string(done_before.size()) + " already done"),
            std::string::npos)
      << slurp(dir / "resumed.log");

  // What the stages produced, chained for real.
  EXPECT_TRUE(fs::exists(run / "sample/rpm2000/field.h5"));  // transport read the sampled CFD field
  const auto s = nlohmann::json::parse(slurp(run / "transport/rpm2000/summary.json"));
  EXPECT_EQ(s.at("n_particles").get<int>(), 6);
  EXPECT_GT(s.at("n_flywheel_impacts").get<int>(), 0);
  EXPECT_TRUE(fs::exists(run / "transport/rpm2000/plots/trajectories.png"));
  EXPECT_TRUE(fs::exists(run / "breakage/product.csv"));
  const std::string html = slurp(run / "report/index.html");
  EXPECT_NE(html.find("Stage 1b: ore lumps through the mill"), std::string::npos);
  EXPECT_NE(html.find("sample/rpm2000/"), std::string::npos);
  EXPECT_TRUE(fs::exists(run / "breakage/plots/product_vs_rpm.png"));
  // Conditions binned from transport have one speed and angle each: the
  // critical velocity is taken over all of them pooled, not per angle.
  const auto crit = nlohmann::json::parse(slurp(run / "breakage/critical_velocity.json"));
  ASSERT_EQ(crit.size(), 1u) << crit.dump();
  EXPECT_TRUE(crit[0].at("angle_deg").is_null());
  EXPECT_TRUE(fs::exists(run / "report/figures/mill_geometry.png"));
  EXPECT_TRUE(fs::exists(run / "report/figures/flow_convergence_rpm2000.png"));
  EXPECT_NE(html.find("mill geometry (STL)"), std::string::npos);
  EXPECT_NE(html.find("breakage/plots/product_vs_rpm.png"), std::string::npos);
  // Headline numbers, one entry per stage that ran.
  const auto h = nlohmann::json::parse(slurp(run / "report/summary.json")).at("headline");
  EXPECT_EQ(h.at("flow").at("rpm2000").at("iterations").get<int>(), 30);
  EXPECT_EQ(h.at("transport").at("rpm2000").at("lumps").get<int>(), 6);
  EXPECT_TRUE(h.at("calibration").contains("achieved"));
  const auto& prod = h.at("product").at("rpm2000");
  EXPECT_EQ(prod.at("conditions").get<int>(), 2);
  const double shredded = prod.at("fully_shredded_mass_fraction").get<double>();
  EXPECT_GE(shredded, 0.0);
  EXPECT_LE(shredded, 1.0);

  // The mill product in mm: P80 in product.json, drawn against rpm, in the headline in words.
  const auto product = nlohmann::json::parse(slurp(run / "breakage/product.json"));
  ASSERT_EQ(product.size(), 1u);
  const auto& p0 = product[0];
  ASSERT_TRUE(p0.at("p80_mm").is_number()) << p0.dump();
  const double p80 = p0.at("p80_mm").get<double>();
  EXPECT_GT(p80, 0.0);
  EXPECT_LE(p80, 20.0);  // no piece is coarser than the 20 mm lump
  EXPECT_DOUBLE_EQ(prod.at("p80_mm").get<double>(), p80);
  const size_t head = html.find("<h2>Headline</h2>"), head_end = html.find("<h2>", head + 1);
  ASSERT_NE(head, std::string::npos);
  const std::string headline = html.substr(head, head_end - head);
  EXPECT_NE(headline.find(fmt::format("{:.3g} mm", p80)), std::string::npos) << headline;
  EXPECT_NE(headline.find("gas mass flow through the mill, 2000 rpm"), std::string::npos) << headline;
  EXPECT_NE(headline.find("calibrated UCS"), std::string::npos) << headline;
  // No dotted keys (calibration.achieved.ucs) in the headline: only words and numbers.
  for (size_t i = 1; i + 1 < headline.size(); ++i)
    if (headline[i] == '.' && std::isalpha(static_cast<unsigned char>(headline[i - 1])) &&
        std::isalpha(static_cast<unsigned char>(headline[i + 1])))
      ADD_FAILURE() << "dotted key in the headline: " << headline.substr(i > 30 ? i - 30 : 0, 60);
  // The raw per-rpm keys of the flow report are folded away.
  const size_t raw = html.find("flow/flow_summary.json</h3>");
  ASSERT_NE(raw, std::string::npos);
  const size_t open = html.rfind("<details>", raw), close = html.rfind("</details>", raw);
  ASSERT_NE(open, std::string::npos);
  EXPECT_TRUE(close == std::string::npos || close < open) << "flow_summary.json is not inside a <details> block";

  // The feed through the whole chain: each of its two classes through the
  // real transport (its own lumps in the sampled flow), struck in the
  // turning mill from its own first strikes, its column of the breakage
  // matrix measured, the closed circuit solved and its decision in the
  // report's headline.
  const auto fc = nlohmann::json::parse(slurp(run / "transport/feed_classes.json")).at("classes");
  const std::vector<double> class_mm = {std::sqrt(22.4 * 31.5), std::sqrt(16 * 22.4)};
  for (size_t k = 0; k < 2; ++k) {
    ASSERT_TRUE(fc[k].at("transport").get<bool>()) << fc[k].dump(2);
    EXPECT_NEAR(fc[k].at("lump_diameter_mm").get<double>(), class_mm[k], 1e-9);
    const auto cs = nlohmann::json::parse(
        slurp(run / fmt::format("transport/class_{}/rpm2000/summary.json", k)));
    EXPECT_EQ(cs.at("n_particles").get<int>(), 6);
    EXPECT_GT(cs.at("n_flywheel_impacts").get<int>(), 0) << "class " << k;
    EXPECT_EQ(fc[k].at("rotor_speeds")[0].at("n_flywheel_impacts"), cs.at("n_flywheel_impacts"));
    // One in-mill run of the class, from one of its own lumps' strikes.
    int runs = 0;
    for (const auto& e : fs::directory_iterator(run / "breakage/jobs"))
      if (e.path().filename().string().rfind(fmt::format("rpm2000_c{}_mill_p", k), 0) == 0) {
        ++runs;
        const auto m = nlohmann::json::parse(slurp(e.path() / "in_mill.json"));
        EXPECT_EQ(m.at("feed_class").get<size_t>(), k);
      }
    EXPECT_EQ(runs, 1) << "class " << k;
  }
  // lump.diameter (20 mm) is in class 1, which ran its own lumps: none of
  // lump.diameter's own in-mill runs.
  for (const auto& e : fs::directory_iterator(run / "breakage/jobs"))
    EXPECT_EQ(e.path().filename().string().rfind("rpm2000_mill_p", 0), std::string::npos)
        << e.path();
  const auto bm = nlohmann::json::parse(slurp(run / "breakage/breakage_matrix.json"));
  const auto& cols = bm.at("rotor_speeds")[0].at("columns");
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(cols[k].at("origin"), "measured") << cols[k].dump();
    EXPECT_EQ(cols[k].at("runs"), "the class's own (its representative size)");
  }
  const auto circuit = nlohmann::json::parse(slurp(run / "breakage/circuit.json"));
  const auto& c0 = circuit.at("rotor_speeds")[0];
  ASSERT_TRUE(c0.at("steady").get<bool>()) << c0.dump(2);
  EXPECT_LE(c0.at("mass_balance_residual").get<double>(), 1e-9);
  const std::string sentence = circuit.at("decision").at("sentence").get<std::string>();
  EXPECT_NE(headline.find("lowest rotor speed for a product P80 &lt;= 6 mm"), std::string::npos)
      << headline;
  EXPECT_NE(headline.find(sentence), std::string::npos) << sentence;
  EXPECT_EQ(h.at("circuit_decision").at("sentence"), sentence);
  keep_run(run, dir);  // a finished run for e2e.compare and report.browser
}

}  // namespace
