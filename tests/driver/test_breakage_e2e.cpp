// The breakage stage end to end with real LIGGGHTS runs: a tiny campaign's
// physics trends, resuming, a kill mid-campaign, and `orchestrate impact`.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "jobs/job_store.h"
#include "postprocess/breakage_results.h"

#include "e2e_util.h"

namespace fs = std::filesystem;

namespace {

using namespace mill::e2e;

const std::string kData = MILL_TEST_DATA;

// One campaign shared by the tests below (3 impacts of a 200-element lump).
class TinyCampaign : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new mill::test::TempDir(scratch("campaign"));
    status_ = orchestrate("--case " + kData + "/tiny_breakage.yaml --stage breakage --output " + dir_->string(),
                          *dir_ / "first.log");
  }
  static void TearDownTestSuite() { delete dir_; }  // removed if every test passed
  static mill::test::TempDir* dir_;
  static int status_;
};
mill::test::TempDir* TinyCampaign::dir_ = nullptr;
int TinyCampaign::status_ = -1;

TEST_F(TinyCampaign, RunsAndWritesEveryOutput) {
  ASSERT_EQ(status_, 0) << slurp(*dir_ / "first.log");
  for (const char* f : {"summary.csv", "fractions.csv", "breakage.h5", "critical_velocity.json",
                        "size_distributions.csv", "size_distributions.json", "jk_fit.json", "jk_points.csv",
                        "plots/largest_vs_velocity.png", "plots/pieces_vs_velocity.png", "plots/passing_vs_size.png",
                        "plots/jk_t10_vs_ecs.png", "jobs/v20_a90_r0/fragments.vtp", "jobs/v20_a90_r0/result.json",
                        "comminution_efficiency.json", "plots/comminution_efficiency_vs_velocity.png",
                        "plots/energy_ledger_fastest.png", "jobs/v20_a90_r0/energy_ledger.csv",
                        "jobs/v20_a90_r0/energy_ledger.png"})
    EXPECT_TRUE(fs::exists(*dir_ / "breakage" / f)) << f;
  EXPECT_FALSE(fs::exists(*dir_ / "breakage/plots/mass_distribution.png"));  // replaced by the passing curves
}

// Passing curves in mm: the intact lump at 1 m/s is all in the top size
// fraction, so its P80 lies in the top sieve interval (0.85-1 x the 20 mm
// lump); shattered at 150 m/s it is far finer.
TEST_F(TinyCampaign, SizeDistributionsInMillimetres) {
  ASSERT_EQ(status_, 0);
  const auto sd = nlohmann::json::parse(slurp(*dir_ / "breakage/size_distributions.json"));
  EXPECT_DOUBLE_EQ(sd.at("lump_diameter_mm").get<double>(), 20.0);
  const auto& conds = sd.at("conditions");
  ASSERT_EQ(conds.size(), 3u);
  const double slow = conds[0].at("p80_mm").get<double>();
  EXPECT_GT(slow, 17.0);
  EXPECT_LE(slow, 20.0);
  EXPECT_LT(conds[2].at("p80_mm").get<double>(), 0.5 * slow);
  EXPECT_NEAR(conds[0].at("passing_percent").back().get<double>(), 100.0, 1e-9);
  // A 200-element lump cannot resolve t10: no JK fit, and the reason says so.
  const auto jk = nlohmann::json::parse(slurp(*dir_ / "breakage/jk_fit.json"));
  ASSERT_EQ(jk.size(), 1u);
  EXPECT_FALSE(jk[0].at("fitted").get<bool>());
  EXPECT_EQ(jk[0].at("points_used").get<int>(), 0);
  EXPECT_NE(jk[0].at("reason").get<std::string>().find("not resolved"), std::string::npos);
}

TEST_F(TinyCampaign, SlowImpactBouncesIntactFastOneShatters) {
  ASSERT_EQ(status_, 0);
  const auto rows = mill::post::ReadSummaryCsv((*dir_ / "breakage" / "summary.csv").string());
  ASSERT_EQ(rows.size(), 3u);
  const auto& slow = rows[0];
  EXPECT_DOUBLE_EQ(slow.velocity_m_s, 1.0);
  EXPECT_EQ(slow.n_pieces, 1);
  EXPECT_EQ(slow.broken_bond_fraction, 0.0);
  EXPECT_DOUBLE_EQ(slow.largest_mass_fraction, 1.0);
  const auto& fast = rows[2];
  EXPECT_DOUBLE_EQ(fast.velocity_m_s, 150.0);
  EXPECT_LT(fast.largest_mass_fraction, 0.10);
  // Along the sweep: more pieces, smaller largest piece.
  for (size_t i = 1; i < rows.size(); ++i) {
    EXPECT_GT(rows[i].n_pieces, rows[i - 1].n_pieces);
    EXPECT_LT(rows[i].largest_mass_fraction, rows[i - 1].largest_mass_fraction);
  }
  for (const auto& r : rows) EXPECT_EQ(r.n_elements, 200);
}

// The energy ledger of each impact in its result.json: the intact bounce
// breaks nothing and makes no new surface; the shattering impact puts part of
// the energy into broken bonds; every balance closes to within 1%.
TEST_F(TinyCampaign, EnergyLedgerOfEveryImpact) {
  ASSERT_EQ(status_, 0);
  auto energy = [&](const char* job) {
    return nlohmann::json::parse(slurp(*dir_ / "breakage/jobs" / job / "result.json")).at("energy");
  };
  const auto slow = energy("v1_a90_r0"), fast = energy("v150_a90_r0");
  for (const auto& e : {slow, fast}) {
    for (const char* k : {"input_J", "ke_trans_J", "bond_released_J", "contact_damping_J", "contact_friction_J", "residual_fraction",
                          "max_element_speed_m_s", "max_element_speed_time_s", "wall_overlap_max",
                          "comminution_efficiency", "new_surface_m2", "energy_per_new_surface_J_m2"})
      EXPECT_TRUE(e.contains(k)) << k;
    EXPECT_LT(std::abs(e.at("residual_fraction").get<double>()), 0.01);
    EXPECT_GT(e.at("input_J").get<double>(), 0.0);
  }
  EXPECT_EQ(slow.at("comminution_efficiency").get<double>(), 0.0);
  EXPECT_EQ(slow.at("new_surface_m2").get<double>(), 0.0);
  EXPECT_TRUE(slow.at("energy_per_new_surface_J_m2").is_null());
  EXPECT_GT(fast.at("comminution_efficiency").get<double>(), 0.0);
  EXPECT_LT(fast.at("comminution_efficiency").get<double>(), 1.0);
  EXPECT_GT(fast.at("energy_per_new_surface_J_m2").get<double>(), 0.0);
  const auto rows = mill::post::ReadSummaryCsv((*dir_ / "breakage" / "summary.csv").string());
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_DOUBLE_EQ(rows[2].comminution_efficiency, fast.at("comminution_efficiency").get<double>());
  EXPECT_GE(rows[2].max_element_speed_m_s, 150.0 * 0.99);
}

TEST_F(TinyCampaign, SizeFractionsSumToOnePerImpact) {
  ASSERT_EQ(status_, 0);
  std::ifstream in(*dir_ / "breakage" / "fractions.csv");
  std::string line;
  std::getline(in, line);
  std::map<std::string, double> sum;
  while (std::getline(in, line)) {
    const auto last = line.rfind(',');
    const std::string key = line.substr(0, line.find(',', line.find(',', line.find(',') + 1) + 1));
    sum[key] += std::stod(line.substr(last + 1));
  }
  ASSERT_EQ(sum.size(), 3u);
  for (const auto& [k, s] : sum) EXPECT_NEAR(s, 1.0, 1e-9) << k;
}

TEST_F(TinyCampaign, RerunSkipsDoneJobs) {
  ASSERT_EQ(status_, 0);
  const auto t0 = fs::last_write_time(*dir_ / "breakage/jobs/v20_a90_r0/STATUS");
  const int st = orchestrate("--case " + kData + "/tiny_breakage.yaml --stage breakage --output " + dir_->string(),
                             *dir_ / "second.log");
  EXPECT_EQ(st, 0) << slurp(*dir_ / "second.log");
  EXPECT_NE(slurp(*dir_ / "second.log").find("3 already done"), std::string::npos) << slurp(*dir_ / "second.log");
  EXPECT_EQ(fs::last_write_time(*dir_ / "breakage/jobs/v20_a90_r0/STATUS"), t0);
}

// SIGTERM mid-campaign: finished jobs stay done, the running one is marked
// failed (never done), and a rerun completes without redoing finished jobs.
TEST(KillResume, KilledCampaignResumes) {
  const auto dir = scratch("kill");
  const std::vector<std::string> args = {"--case", kData + "/tiny_breakage.yaml", "--stage", "breakage", "--jobs", "1",
                                         "--output", dir.string()};
  const pid_t pid = spawn_orchestrate(args, dir / "killed.log");
  // Wait until the first job is done and the second is running, then kill.
  const fs::path stage = dir / "breakage", first = stage / "jobs/v1_a90_r0/STATUS";
  const bool ready = wait_for([&] {
    return job_state(stage, "v1_a90_r0") == mill::jobs::State::Done &&
           job_state(stage, "v20_a90_r0") == mill::jobs::State::Running;
  }, 120);
  if (!ready) kill(pid, SIGKILL);
  ASSERT_TRUE(ready) << slurp(dir / "killed.log");
  kill(pid, SIGTERM);
  EXPECT_EQ(finish(pid), 128 + SIGTERM) << slurp(dir / "killed.log");
  EXPECT_EQ(job_state(stage, "v20_a90_r0"), mill::jobs::State::Failed);
  EXPECT_FALSE(fs::exists(stage / "jobs/v20_a90_r0/summary.csv"));
  const auto t_first = fs::last_write_time(first);

  std::string line;
  for (const auto& a : args) line += "'" + a + "' ";
  EXPECT_EQ(orchestrate(line, dir / "resumed.log"), 0) << slurp(dir / "resumed.log");
  EXPECT_EQ(fs::last_write_time(first), t_first) << "the finished job was redone";
  EXPECT_EQ(mill::post::ReadSummaryCsv((stage / "summary.csv").string()).size(), 3u);
}

TEST(ImpactCommand, WritesOneRowInItsFolder) {
  const auto dir = scratch("impact");
  const int st = orchestrate("impact --velocity 2 --elements 120 --output " + dir.string(), dir / "impact.log");
  ASSERT_EQ(st, 0) << slurp(dir / "impact.log");
  const auto rows = mill::post::ReadSummaryCsv((dir / "summary.csv").string());
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].n_elements, 120);
  EXPECT_DOUBLE_EQ(rows[0].velocity_m_s, 2.0);
  EXPECT_TRUE(fs::exists(dir / "fractions.csv"));
  EXPECT_NE(slurp(dir / "impact.log").find("pieces"), std::string::npos);
}

// The impact deck on 2 ranks (its cuts kept on the lump by fix
// balance/weighted): the lump breaks as on one rank, to 2 % in pieces and
// 0.02 in the largest piece's mass fraction (only the order of sums
// differs, styles.Mpi.ImpactOneVersusTwoRanks's tolerance).
// The lump: the sandstone card's 40 mm lump of parallel bonds (the schema's
// bond model; the bundled cases' flat joints hold at 8 m/s), as the default
// case's was when this test was written.
TEST(ImpactCommand, TwoRanksBreakTheLumpAsOne) {
  const auto dir = scratch("impact_ranks");
  spit(dir / "case.yaml",
       "name: impact_ranks\nore: {card: sandstone}\nlump: {n_elements: 400, diameter: 0.04}\n"
       "breakage: {duration_after_contact: 3.0e-3}\n");
  std::vector<mill::post::ImpactSummary> rows[2];
  for (int np = 1; np <= 2; ++np) {
    const fs::path out = dir / ("np" + std::to_string(np));
    const int st =
        orchestrate("--case " + (dir / "case.yaml").string() + " --np " + std::to_string(np) +
                        " impact --velocity 8 --elements 400 --output " + out.string(),
                    dir / ("np" + std::to_string(np) + ".log"));
    ASSERT_EQ(st, 0) << slurp(dir / ("np" + std::to_string(np) + ".log"));
    rows[np - 1] = mill::post::ReadSummaryCsv((out / "summary.csv").string());
    ASSERT_EQ(rows[np - 1].size(), 1u);
  }
  EXPECT_NE(slurp(dir / "np2/run/liggghts.log").find("1 by 1 by 2 MPI processor grid"),
            std::string::npos);
  const auto &one = rows[0][0], &two = rows[1][0];
  EXPECT_GT(one.n_pieces, 20) << "the lump hardly broke: the test would be vacuous";
  EXPECT_NEAR(static_cast<double>(two.n_pieces) / one.n_pieces, 1.0, 0.02);
  EXPECT_NEAR(two.largest_mass_fraction, one.largest_mass_fraction, 0.02);
}

}  // namespace

namespace {

TEST_F(TinyCampaign, ReportEmbedsTheBreakageResults) {
  ASSERT_EQ(status_, 0);
  const int st = orchestrate("--case " + kData + "/tiny_breakage.yaml --stage report --output " + dir_->string(),
                             *dir_ / "report.log");
  ASSERT_EQ(st, 0) << slurp(*dir_ / "report.log");
  const std::string html = slurp(*dir_ / "report/index.html");
  EXPECT_NE(html.find("Stage 2: breakage of one lump"), std::string::npos);
  EXPECT_NE(html.find("data:image/png;base64,"), std::string::npos);
  EXPECT_NE(html.find("has not run"), std::string::npos);  // flow etc. did not run here
  const auto summary = nlohmann::json::parse(slurp(*dir_ / "report/summary.json"));
  EXPECT_EQ(summary.at("breakage_impacts").get<int>(), 3);
  // The headline says it in words: the critical speed at 90 degrees.
  EXPECT_NE(html.find("critical impact speed (largest piece &lt; 5%), 90 deg"), std::string::npos);
  EXPECT_NE(html.find("breakage/plots/passing_vs_size.png"), std::string::npos);
  keep_run(*dir_, *dir_);  // a finished run for e2e.compare
}

}  // namespace

namespace {

// Conditions from a (hand-made) transport result: two bins, weights 3:1,
// and the mill product is their weighted size distribution.
TEST(MillProduct, ConditionsFromTransportImpacts) {
  const auto dir = scratch("product");
  fs::create_directories(dir / "transport/rpm2000");
  std::ofstream(dir / "transport/rpm2000/impacts.csv")
      << "time_s,particle_id,surface,x_m,y_m,z_m,speed_m_s,normal_speed_m_s,tangential_speed_m_s,angle_deg\n"
      << "0.01,1,flywheel,0,0,0,5,5,0,90\n0.02,2,flywheel,0,0,0,6,6,0,90\n0.03,3,flywheel,0,0,0,7,7,0,90\n"
      << "0.04,4,flywheel,0,0,0,80,80,0,90\n0.05,5,housing,0,0,0,30,30,0,90\n";
  auto o = orchestrate("--case " + kData + "/tiny_product.yaml --stage breakage --list-tasks --output " + dir.string(),
                       dir / "tasks.log");
  ASSERT_EQ(o, 0) << slurp(dir / "tasks.log");
  EXPECT_NE(slurp(dir / "tasks.log").find("rpm2000_b0_v6_a90_r0"), std::string::npos) << slurp(dir / "tasks.log");
  EXPECT_NE(slurp(dir / "tasks.log").find("rpm2000_b1_v80_a90_r0"), std::string::npos) << slurp(dir / "tasks.log");
  ASSERT_EQ(orchestrate("--case " + kData + "/tiny_product.yaml --stage breakage --output " + dir.string(),
                        dir / "run.log"),
            0)
      << slurp(dir / "run.log");
  const auto product = nlohmann::json::parse(slurp(dir / "breakage/product.json"));
  ASSERT_EQ(product.size(), 1u);
  const auto& p = product[0];
  EXPECT_EQ(p.at("conditions").get<int>(), 2);
  double sum = 0;
  for (double f : p.at("fraction_mass").get<std::vector<double>>()) sum += f;
  EXPECT_NEAR(sum, 1.0, 1e-9);
  // Weighted by hand from the two impacts' own results (3 of 4 impacts in bin 0).
  const auto rows = mill::post::ReadSummaryCsv((dir / "breakage/summary.csv").string());
  ASSERT_EQ(rows.size(), 2u);
  const double expect = 0.75 * rows[0].single_mass_fraction + 0.25 * rows[1].single_mass_fraction;
  EXPECT_NEAR(p.at("fully_shredded_mass_fraction").get<double>(), expect, 1e-9);
}

}  // namespace
