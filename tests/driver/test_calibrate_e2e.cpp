// The calibrate stage end to end with real LIGGGHTS runs: the two virtual lab
// tests on a tiny specimen with their energy ledgers, the fitting loop
// recovering bond parameters that are known to reach a synthetic target, and
// the ore card's own calibration.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "config/case_config.h"
#include "e2e_util.h"
#include "lump/material.h"
#include "lump/packing.h"

namespace fs = std::filesystem;

namespace {

using namespace mill::e2e;

const std::string kData = MILL_TEST_DATA;

nlohmann::json read_json(const fs::path& f) { return nlohmann::json::parse(slurp(f)); }

// One tiny calibration (one iteration: both tests once, the half-rate UCS,
// the levers' sensitivities and the checks) shared by the tests below.
class TinyCalibration : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new mill::test::TempDir(scratch("tiny"));
    status_ = orchestrate(
        "--case " + kData + "/tiny_calibrate.yaml --stage calibrate --output " + dir_->string(),
        *dir_ / "first.log");
  }
  static void TearDownTestSuite() { delete dir_; }  // removed if every test passed
  static mill::test::TempDir* dir_;
  static int status_;
};
mill::test::TempDir* TinyCalibration::dir_ = nullptr;
int TinyCalibration::status_ = -1;

TEST_F(TinyCalibration, BothTestsGiveFinitePositivePropertiesAndEveryOutput) {
  ASSERT_EQ(status_, 0) << slurp(*dir_ / "first.log");
  const auto r = read_json(*dir_ / "calibrate" / "report.json");
  for (const char* k : {"youngs_modulus", "poisson_ratio", "ucs", "tensile_strength"}) {
    const double v = r["achieved"][k].get<double>();
    EXPECT_TRUE(std::isfinite(v) && v > 0) << k << " = " << v;
  }
  // Plausible orders of magnitude for a sandstone-like bonded packing.
  EXPECT_GT(r["achieved"]["youngs_modulus"].get<double>(), 1e9);
  EXPECT_LT(r["achieved"]["poisson_ratio"].get<double>(), 0.5);
  EXPECT_GT(r["achieved"]["ucs"].get<double>(), r["achieved"]["tensile_strength"].get<double>());
  EXPECT_EQ(r["specimen"]["ucs_cylinder"]["elements"].get<double>(), 200);
  EXPECT_EQ(r["specimen"]["brazilian_disc"]["elements"].get<double>(), 200);
  EXPECT_TRUE(r["rate_check"]["ucs"].get<double>() > 0);

  // Every output, in the format the breakage stage reads.
  for (const char* f :
       {"calibrated.yaml", "report.md", "report.json", "curves.csv", "plots/ucs_stress_strain.png",
        "plots/brazilian_load_displacement.png", "plots/convergence.png"})
    EXPECT_TRUE(fs::exists(*dir_ / "calibrate" / f)) << f;
  const YAML::Node y = YAML::LoadFile((*dir_ / "calibrate" / "calibrated.yaml").string());
  for (const char* k : {"bond_modulus", "stiffness_ratio", "bond_tensile_strength", "bond_cohesion",
                        "bond_friction_angle", "input_hash"})
    EXPECT_TRUE(y["calibrated"][k]) << k;
  const auto cfg = mill::config::load_case(kData + "/tiny_calibrate.yaml", MILL_PROJECT_DIR);
  EXPECT_EQ(y["calibrated"]["input_hash"].as<std::string>(), mill::calibration_hash(cfg));
  // The lump scale it was fitted for: the element radius the specimen ball
  // was packed for (the packed ball's own mean scatters around it by 1-2 %).
  const double radius =
      mill::target_mean_radius(cfg.doc.integer("lump.n_elements"), cfg.doc.real("lump.diameter"),
                               cfg.doc.real("lump.radius_spread"));
  EXPECT_NEAR(y["calibrated"]["fitted_for"]["element_radius_m"].as<double>(), radius,
              1e-5 * radius);
  EXPECT_NEAR(y["specimen"]["mean_element_radius_m"].as<double>(), radius, 0.05 * radius);
  EXPECT_DOUBLE_EQ(y["calibrated"]["fitted_for"]["bond_gap"].as<double>(),
                   cfg.doc.real("lump.bond_gap"));
  EXPECT_EQ(mill::uncalibrated_reason(cfg, *dir_), "");
  const mill::BondParams b = mill::bond_params_for(cfg, *dir_);
  EXPECT_NE(b.origin.find("calibrated"), std::string::npos) << b.origin;
  EXPECT_DOUBLE_EQ(b.modulus, y["calibrated"]["bond_modulus"].as<double>());
  EXPECT_NE(slurp(*dir_ / "calibrate" / "report.md").find("| E (GPa) |"), std::string::npos);

  // Every lab run's energy ledger: the platens put energy in and the balance
  // closes; report.md tabulates them.
  const std::vector<std::pair<std::string, nlohmann::json>> runs = {
      {"it1_ucs", r["iterations"][0]["energy"]["ucs"]},
      {"it1_brazilian", r["iterations"][0]["energy"]["brazilian"]},
      {"rate_check_ucs", r["rate_check"]["energy"]},
      {"packing1_ucs", r["packing_check"]["runs"][0]["energy"]["ucs"]},
      {"packing2_brazilian", r["packing_check"]["runs"][1]["energy"]["brazilian"]},
      {"sens_bond_modulus_ucs", r["sensitivity"]["levers"]["bond_modulus"]["energy"]["ucs"]},
      {"sens_bond_moment_factor_brazilian",
       r["sensitivity"]["levers"]["bond_moment_factor"]["energy"]["brazilian"]},
      {"triaxial_1", r["checks"]["triaxial"][0]["energy"]},
      {"triaxial_2", r["checks"]["triaxial"][1]["energy"]}};
  for (const auto& [run, e] : runs) {
    ASSERT_TRUE(e.is_object()) << run << ": " << r.dump(2);
    for (const char* k :
         {"input_J", "work_other_J", "bond_released_J", "residual_J", "residual_fraction",
          "residual_fraction_max", "max_element_speed_m_s", "comminution_efficiency"})
      EXPECT_TRUE(e.contains(k) && e[k].is_number()) << run << ": " << k << " in " << e.dump();
    EXPECT_LT(std::abs(e["residual_fraction_max"].get<double>()), 0.01) << run << ": " << e.dump();
    EXPECT_GT(e["input_J"].get<double>() + e["work_other_J"].get<double>(), 0.0)
        << run << ": " << e.dump();
    EXPECT_GE(e["bond_released_J"].get<double>(), 0.0) << run << ": " << e.dump();
  }
  const auto& worst = r["energy"];
  // 2 (iteration) + 1 (rate check) + 4 (2 further packings: a UCS and a
  // Brazilian each) + 12 (6 levers) + 2 (triaxial checks) + 6 (the bend
  // test's half discs, calibrate.scb_orientations).
  EXPECT_EQ(worst["lab_runs"].get<int>(), 27) << worst.dump();
  // The packing check: the fit's seed and two more, each property's spread.
  const auto& pc = r["packing_check"];
  ASSERT_TRUE(pc.is_object()) << r.dump(2);
  // Three distinct packings (neighbouring calibrate.seed values can share a
  // prime: the check takes the next streams whose first seed is new).
  ASSERT_EQ(pc["seeds"].size(), 3u);
  EXPECT_NE(pc["seeds"][0], pc["seeds"][1]);
  EXPECT_NE(pc["seeds"][1], pc["seeds"][2]);
  EXPECT_NE(pc["seeds"][0], pc["seeds"][2]);
  const auto& tv = pc["tensile_strength"]["values"];
  EXPECT_NE(tv[1].get<double>(), tv[2].get<double>()) << pc.dump();  // not one packing twice
  for (const char* k : {"youngs_modulus", "poisson_ratio", "ucs", "tensile_strength"}) {
    ASSERT_EQ(pc[k]["values"].size(), 3u) << k;
    EXPECT_GE(pc[k]["spread"].get<double>(), 0.0) << k;
    EXPECT_EQ(pc[k]["within"].get<bool>(),
              pc[k]["spread"].get<double>() <= pc[k]["limit"].get<double>())
        << k;
  }
  EXPECT_TRUE(fs::exists(*dir_ / "calibrate" / "jobs" / "calibration" /
                         ("specimen_seed" + std::to_string(pc["seeds"][2].get<long>())) /
                         "ball.data"));
  EXPECT_NE(slurp(*dir_ / "calibrate" / "report.md").find("## Packing check"), std::string::npos);
  EXPECT_LT(worst["worst_residual_fraction_max"].get<double>(), 0.01) << worst.dump();
  const std::string worst_run = worst["worst_run"].get<std::string>();
  EXPECT_TRUE(std::any_of(runs.begin(), runs.end(), [&](const auto& run) {
    return run.first == worst_run;
  })) << worst_run;
  const std::string md = slurp(*dir_ / "calibrate" / "report.md");
  EXPECT_NE(md.find("## Energy ledger"), std::string::npos) << md;
  for (const char* row :
       {"| it1_ucs * |", "| it1_brazilian * |", "| rate_check_ucs |", "| sens_bond_modulus_ucs |",
        "| sens_bond_cohesion_brazilian |", "| triaxial_1 |", "| triaxial_2 |"})
    EXPECT_NE(md.find(row), std::string::npos) << row << " in\n" << md;
  EXPECT_NE(md.find("Largest residual of any lab run: "), std::string::npos) << md;

  // The checks after the fit: a triaxial peak at each confining pressure of
  // the case (0.1 and 0.2 x the UCS reached), the envelope through them and
  // the UCS, the SCB test (the sandstone card gives K_IC); each against the
  // card, and said to be no lever. The 200-element specimen loaded at 2 1/s
  // is too coarse for a trustworthy envelope (its confinement breaks bonds):
  // either the fit or the reason it has none must be reported.
  const auto& ck = r["checks"];
  ASSERT_TRUE(ck.is_object()) << r.dump(2);
  EXPECT_NE(ck["note"].get<std::string>().find("not a lever yet"), std::string::npos);
  ASSERT_EQ(ck["triaxial"].size(), 2u) << ck.dump(2);
  for (size_t k = 0; k < 2; ++k) {
    const auto& t = ck["triaxial"][k];
    const double p = static_cast<double>(k + 1) * 0.1 * r["achieved"]["ucs"].get<double>();
    EXPECT_NEAR(t["confining_pressure_Pa"].get<double>() / p, 1.0, 1e-12) << t.dump();
    EXPECT_NEAR(t["sigma3_Pa"].get<double>() / p, 1.0, 0.1) << t.dump();
    EXPECT_GT(t["sigma1_Pa"].get<double>(), t["sigma3_Pa"].get<double>()) << t.dump();
    EXPECT_NEAR(t["deviator_Pa"].get<double>(),
                t["sigma1_Pa"].get<double>() - t["sigma3_Pa"].get<double>(), 1e-6)
        << t.dump();
  }
  const auto& env = ck["envelope"];
  ASSERT_EQ(env["points"].size(), 3u) << env.dump(2);
  EXPECT_DOUBLE_EQ(env["points"][0]["sigma1_Pa"].get<double>(), r["achieved"]["ucs"].get<double>());
  const auto& vs = ck["against_card"];
  if (env["mohr_coulomb"].is_object()) {
    const double phi = env["mohr_coulomb"]["friction_angle_deg"].get<double>();
    EXPECT_TRUE(phi > 0 && phi < 90) << env.dump(2);
    EXPECT_GT(env["mohr_coulomb"]["cohesion_Pa"].get<double>(), 0.0) << env.dump(2);
    EXPECT_DOUBLE_EQ(vs["friction_angle"]["achieved"].get<double>(), phi) << vs.dump(2);
    EXPECT_NEAR(vs["friction_angle"]["relative_error"].get<double>(), std::abs(phi / 47.0 - 1),
                1e-12);
  } else {
    EXPECT_NE(env["error"].get<std::string>().find("Mohr-Coulomb fit"), std::string::npos)
        << env.dump(2);
    EXPECT_TRUE(vs["friction_angle"]["achieved"].is_null()) << vs.dump(2);
    EXPECT_NE(md.find("Not fitted: Mohr-Coulomb fit"), std::string::npos) << md;
  }
  EXPECT_DOUBLE_EQ(vs["friction_angle"]["target"].get<double>(), 47.0) << vs.dump(2);
  EXPECT_DOUBLE_EQ(vs["hoek_brown_mi"]["target"].get<double>(), 17.0) << vs.dump(2);
  EXPECT_DOUBLE_EQ(vs["fracture_toughness"]["target"].get<double>(), 0.73e6) << vs.dump(2);
  // The bend test: six half discs of 1.2 x the disc's radius (about 110
  // elements each on these 200-element specimens: every one has a load
  // point and supports, the arc doubled where its +-5 deg was empty), K_IC
  // their mean, each disc with its ledger.
  ASSERT_TRUE(ck["scb"].is_object()) << ck.dump(2);
  EXPECT_EQ(ck["scb"]["half_discs"].get<int>(), 6);
  ASSERT_EQ(ck["scb"]["discs"].size(), 6u);
  double mean = 0;
  for (const auto& d : ck["scb"]["discs"]) {
    const double k = d["fracture_toughness_Pa_m0.5"].get<double>();
    EXPECT_TRUE(std::isfinite(k) && k > 0) << d.dump();
    mean += k / 6;
    EXPECT_LT(std::abs(d["energy"].value("residual_fraction_max", 1.0)), 0.01) << d.dump();
  }
  EXPECT_NEAR(ck["scb"]["fracture_toughness_Pa_m0.5"].get<double>(), mean, 1e-9 * mean);
  EXPECT_NEAR(vs["fracture_toughness"]["achieved"].get<double>(), mean, 1e-9 * mean);
  EXPECT_NE(md.find("## Checks after the fit (not a lever yet)"), std::string::npos) << md;
  EXPECT_NE(md.find("| friction angle (deg) | 47.0 |"), std::string::npos) << md;

  // The levers' sensitivities (issue 28): the parallel bond's six fitted
  // levers, each stepped alone from the result, a finite sensitivity of each
  // target, and the signs physics fixes: a stiffer bond makes a stiffer
  // specimen (E about proportional to E_b), a stronger bond a stronger disc.
  const auto& sens = r["sensitivity"];
  ASSERT_TRUE(sens.is_object()) << r.dump(2);
  const auto& lv = sens["levers"];
  ASSERT_EQ(lv.size(), 6u) << sens.dump(2);
  for (const char* name : {"bond_modulus", "stiffness_ratio", "bond_tensile_strength",
                           "bond_cohesion", "bond_friction_angle", "bond_moment_factor"}) {
    ASSERT_TRUE(lv.contains(name)) << name << " in " << sens.dump(2);
    const auto& l = lv[name];
    EXPECT_NE(l["step"]["to"].get<double>(), l["step"]["from"].get<double>()) << l.dump();
    for (const char* k : {"youngs_modulus", "poisson_ratio", "ucs", "tensile_strength"})
      EXPECT_TRUE(std::isfinite(l["targets"][k]["value"].get<double>())) << name << " " << k;
    EXPECT_TRUE(l["free"].is_boolean()) << l.dump();
  }
  EXPECT_DOUBLE_EQ(lv["bond_modulus"]["step"]["size"].get<double>(), 1.2);
  EXPECT_DOUBLE_EQ(lv["bond_friction_angle"]["step"]["size"].get<double>(), 5.0);
  EXPECT_GT(lv["bond_modulus"]["targets"]["youngs_modulus"]["value"].get<double>(), 0.5)
      << sens.dump(2);
  EXPECT_GT(lv["bond_tensile_strength"]["targets"]["tensile_strength"]["value"].get<double>(), 0.0)
      << sens.dump(2);
  EXPECT_TRUE(lv["bond_modulus"]["free"].get<bool>()) << sens.dump(2);
  EXPECT_NE(md.find("## Lever sensitivities"), std::string::npos) << md;
  EXPECT_NE(md.find("| bond_modulus | x1.2 ("), std::string::npos) << md;
  EXPECT_NE(md.find("per step: "), std::string::npos) << md;

  // A rerun skips the done job.
  const int st = orchestrate(
      "--case " + kData + "/tiny_calibrate.yaml --stage calibrate --output " + dir_->string(),
      *dir_ / "second.log");
  EXPECT_EQ(st, 0) << slurp(*dir_ / "second.log");
  EXPECT_NE(slurp(*dir_ / "second.log").find("1 already done"), std::string::npos)
      << slurp(*dir_ / "second.log");
}

// report.json without wall times, the run folder named "<run>".
nlohmann::json without_times(const nlohmann::json& j, const std::string& run) {
  if (j.is_object()) {
    nlohmann::json o = nlohmann::json::object();
    for (auto it = j.begin(); it != j.end(); ++it)
      if (it.key().find("seconds") == std::string::npos) o[it.key()] = without_times(*it, run);
    return o;
  }
  if (j.is_array()) {
    nlohmann::json a = nlohmann::json::array();
    for (const auto& v : j) a.push_back(without_times(v, run));
    return a;
  }
  if (j.is_string()) {
    std::string s = j.get<std::string>();
    for (auto at = s.find(run); at != std::string::npos; at = s.find(run)) s.replace(at, run.size(), "<run>");
    return s;
  }
  return j;
}

// With --jobs 2 the one calibration job runs its independent lab tests two
// at a time (the UCS beside the Brazilian test, the levers' runs, the
// triaxial tests, the half discs): the same calibration to the last digit,
// and the tests did overlap.
TEST_F(TinyCalibration, TwoLanesGiveTheSameCalibrationWithTestsSideBySide) {
  ASSERT_EQ(status_, 0) << slurp(*dir_ / "first.log");
  const auto two = scratch("tiny_lanes");
  ASSERT_EQ(orchestrate("--case " + kData + "/tiny_calibrate.yaml --stage calibrate --jobs 2 --output " +
                            two.string(),
                        two / "log"),
            0)
      << slurp(two / "log");
  const auto a = without_times(read_json(*dir_ / "calibrate" / "report.json"), dir_->string());
  const auto b = without_times(read_json(two / "calibrate" / "report.json"), two.string());
  EXPECT_EQ(a, b) << "jobs 1:\n" << a.dump(1).substr(0, 3000) << "\njobs 2:\n" << b.dump(1).substr(0, 3000);
  EXPECT_EQ(slurp(*dir_ / "calibrate" / "calibrated.yaml"), slurp(two / "calibrate" / "calibrated.yaml"));
  // Overlap: each test of iteration 1 started (its info line) before the
  // other ended (its log's last write).
  const fs::path runs = two / "calibrate" / "jobs" / "calibration" / "runs";
  const auto started = [&](const char* r, const char* f) { return fs::last_write_time(runs / r / f); };
  EXPECT_LT(started("it1_ucs", "ucs_info.txt"), started("it1_brazilian", "liggghts.log"));
  EXPECT_LT(started("it1_brazilian", "brazilian_info.txt"), started("it1_ucs", "liggghts.log"));
}

// The tiny calibration fitted on two packings with a packing check of one,
// one triaxial confinement and one half disc (`extra`: more calibrate keys,
// ", key: value"), run in `dir` (its log: dir/log); the exit status.
int run_two_packings(const fs::path& dir, const std::string& name, const std::string& extra) {
  spit(dir / "case.yaml",
       "name: " + name +
           "\nore: {card: sandstone}\nlump: {n_elements: 150, diameter: 0.02, bond_gap: 0.2}\n"
           "calibrate: {n_elements: 200, max_iterations: 1, strain_rate: 2.0, seed: 2003, "
           "fit_packings: 2, packing_check: 1, rate_check: false, sensitivity: false, "
           "confining_pressures: [0.1], scb_orientations: 1" +
           extra + "}\nresources: {np: 1, jobs: 2}\n");
  return orchestrate(
      "--case " + (dir / "case.yaml").string() + " --stage calibrate --output " + dir.string(),
      dir / "log");
}

// calibrate.fit_packings 2: every iteration tests two packings and the fit
// reads their means (the achieved properties are the arithmetic means of
// the two packings' to the last digit); the packing check's table starts
// with both; the one-packing fit of the fixture keeps its job id (the key
// is not among its inputs).
TEST_F(TinyCalibration, FitOnTwoPackingsAimsTheirMeansAtTheCard) {
  ASSERT_EQ(status_, 0) << slurp(*dir_ / "first.log");
  const auto dir = scratch("tiny_fit_packings");
  ASSERT_EQ(run_two_packings(dir, "tiny_fit_packings", ""), 0) << slurp(dir / "log");
  const fs::path job = dir / "calibrate" / "jobs" / "calibration";
  const auto r = read_json(job / "report.json");
  const auto& packings = r["iterations"][0]["packings"];
  ASSERT_EQ(packings.size(), 2u) << r["iterations"][0].dump(1);
  EXPECT_NE(packings[0]["seed"], packings[1]["seed"]);
  EXPECT_TRUE(fs::exists(job / "runs" / "it1_p2_ucs" / "ledger.csv"));
  EXPECT_TRUE(fs::exists(job / "runs" / "it1_p2_brazilian" / "ledger.csv"));
  for (const char* k : {"youngs_modulus", "poisson_ratio", "ucs", "tensile_strength"}) {
    const double a = packings[0][k].get<double>(), b = packings[1][k].get<double>();
    EXPECT_NE(a, b) << k << ": two packings, one value";
    const double mean = 0.5 * (a + b);
    EXPECT_NEAR(r["iterations"][0]["achieved"][k].get<double>(), mean, 1e-12 * std::abs(mean)) << k;
    EXPECT_NEAR(r["achieved"][k].get<double>(), mean, 1e-12 * std::abs(mean)) << k;
  }
  // The errors are the means' against the card.
  const double t_mean = r["achieved"]["tensile_strength"].get<double>(),
               t_card = r["targets"]["tensile_strength"].get<double>();
  EXPECT_NEAR(r["iterations"][0]["errors"]["tensile_strength"].get<double>(),
              std::abs(t_mean - t_card) / t_card, 1e-9);
  // The packing check: the fit's two packings, then the further one.
  const auto& pc = r["packing_check"];
  EXPECT_EQ(pc["fit_packings"].get<int>(), 2);
  ASSERT_EQ(pc["seeds"].size(), 3u) << pc.dump(1);
  EXPECT_EQ(pc["seeds"][0], packings[0]["seed"]);
  EXPECT_EQ(pc["seeds"][1], packings[1]["seed"]);
  EXPECT_NE(pc["seeds"][2], pc["seeds"][0]);
  EXPECT_NE(pc["seeds"][2], pc["seeds"][1]);
  EXPECT_EQ(pc["tensile_strength"]["values"][1], packings[1]["tensile_strength"]);
  // Every run's ledger: 4 (the iteration) + 2 (the check) + 1 triaxial + 1 half disc.
  EXPECT_EQ(r["energy"]["lab_runs"].get<int>(), 8) << r["energy"].dump();
  const std::string md = slurp(job / "report.md");
  EXPECT_NE(md.find("the means over the fit's 2 specimen packings"), std::string::npos) << md;
  EXPECT_NE(
      md.find(fmt::format("seed {} (fit) | seed {} (fit) | seed {} |", pc["seeds"][0].get<long>(),
                          pc["seeds"][1].get<long>(), pc["seeds"][2].get<long>())),
      std::string::npos)
      << md;
  EXPECT_EQ(read_json(job / "job.json")["inputs"]["calibrate.fit_packings"].get<int>(), 2);
  EXPECT_FALSE(
      read_json(*dir_ / "calibrate" / "jobs" / "calibration" / "job.json")["inputs"].contains(
          "calibrate.fit_packings"));
}

// calibrate.tensile_test direct: each iteration runs the UCS and the direct
// tension test (the pulled cylinder) on every fit packing and the fit reads
// the latter's mean, aimed at the card's Brazilian strength x 0.7 (the
// sandstone is sedimentary); the Brazilian discs run once, on the kept
// parameters, and are reported as a check; the packing check pulls its
// cylinder too; every run's ledger is counted, the tension plot drawn; the
// job's inputs carry the target, the Brazilian fixture's do not.
TEST_F(TinyCalibration, DirectTensionFitReadsThePulledCylindersAndChecksTheDiscs) {
  ASSERT_EQ(status_, 0) << slurp(*dir_ / "first.log");
  const auto dir = scratch("tiny_direct");
  ASSERT_EQ(run_two_packings(dir, "tiny_direct", ", tensile_test: direct"), 0)
      << slurp(dir / "log");
  const fs::path job = dir / "calibrate" / "jobs" / "calibration";
  const auto r = read_json(job / "report.json");
  EXPECT_EQ(r["targets"]["tensile_test"], "direct");
  EXPECT_NEAR(r["targets"]["tensile_strength"].get<double>(), 3.5e6, 1e-3);
  EXPECT_NEAR(r["targets"]["brazilian_tensile_strength"].get<double>(), 5e6, 1e-3);
  const auto& it = r["iterations"][0];
  const auto& packings = it["packings"];
  ASSERT_EQ(packings.size(), 2u) << it.dump(1);
  const double a = packings[0]["direct_tensile_strength"].get<double>(),
               b = packings[1]["direct_tensile_strength"].get<double>();
  EXPECT_GT(a, 0.0);
  EXPECT_NE(a, b);
  EXPECT_NEAR(it["achieved"]["tensile_strength"].get<double>(), 0.5 * (a + b), 1e-12 * (a + b));
  EXPECT_NEAR(it["errors"]["tensile_strength"].get<double>(),
              std::abs(0.5 * (a + b) - 3.5e6) / 3.5e6, 1e-9);
  // The discs: on the kept parameters (here iteration 1) only, as a check.
  for (const char* run : {"it1_tension", "it1_p2_tension", "check_brazilian", "check_p2_brazilian",
                          "packing1_tension"})
    EXPECT_TRUE(fs::exists(job / "runs" / run / "ledger.csv")) << run;
  for (const char* run : {"it1_brazilian", "it1_p2_brazilian", "packing1_brazilian"})
    EXPECT_FALSE(fs::exists(job / "runs" / run)) << run;
  EXPECT_TRUE(it["achieved"].contains("brazilian_tensile_strength")) << it["achieved"].dump();
  EXPECT_EQ(packings[1]["brazilian_run"], "check_p2_brazilian");
  // The packing check's spread reads the direct test: its third value is
  // the check packing's pulled cylinder.
  const auto& pc = r["packing_check"];
  ASSERT_EQ(pc["runs"].size(), 1u) << pc.dump(1);
  EXPECT_EQ(pc["tensile_strength"]["values"][0], packings[0]["direct_tensile_strength"]);
  EXPECT_EQ(pc["tensile_strength"]["values"][2], pc["runs"][0]["direct_tensile_strength"]);
  // Every run's ledger: 2 UCS + 2 pulled cylinders + 2 check discs, the
  // packing check's 2, 1 triaxial, 1 half disc.
  EXPECT_EQ(r["energy"]["lab_runs"].get<int>(), 10) << r["energy"].dump();
  EXPECT_TRUE(fs::exists(job / "plots" / "tension_stress_strain.png"));
  const std::string md = slurp(job / "report.md");
  EXPECT_NE(md.find("| direct tensile (MPa) | 3.50 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| Brazilian tensile (MPa; the card's, not fitted) | 5.00 |"),
            std::string::npos)
      << md;
  const auto inputs = read_json(job / "job.json")["inputs"];
  EXPECT_EQ(inputs["calibrate.tensile_test"], "direct");
  EXPECT_NEAR(inputs["direct_tensile_strength"].get<double>(), 3.5e6, 1e-3);
  const auto fixture =
      read_json(*dir_ / "calibrate" / "jobs" / "calibration" / "job.json")["inputs"];
  EXPECT_FALSE(fixture.contains("calibrate.tensile_test"));
  EXPECT_FALSE(fixture.contains("direct_tensile_strength"));
}

// A card whose calibrated.* section does not match its properties (stale
// input_hash): the fit starts from that section. Used here to start from
// chosen parameters.
std::string card(const std::string& name, double E, double nu, double ucs, double tensile,
                 double Eb, double ratio, double sigma_b, double c) {
  return fmt::format(
      "name: {}\ndensity: 2580\nfriction: 0.5\nrestitution: 0.5\nyoungs_modulus: "
      "{:.9g}\npoisson_ratio: {:.9g}\n"
      "ucs: {:.9g}\ntensile_strength: {:.9g}\ncalibrated:\n  bond_modulus: {:.9g}\n  "
      "stiffness_ratio: {:.9g}\n"
      "  bond_tensile_strength: {:.9g}\n  bond_cohesion: {:.9g}\n  bond_friction_angle: 30\n  "
      "input_hash: stale\n",
      name, E, nu, ucs, tensile, Eb, ratio, sigma_b, c);
}

std::string tiny_case(const fs::path& card_file, int iterations) {
  return fmt::format(
      "name: synthetic\nore: {{card: {}}}\nlump: {{n_elements: 150, diameter: 0.02, bond_gap: "
      "0.2}}\n"
      "calibrate: {{n_elements: 200, max_iterations: {}, strain_rate: 2.0, seed: 2003, "
      "rate_check: false, sensitivity: false}}\nresources: {{np: 1, jobs: 1}}\n",
      card_file.string(), iterations);
}

// A synthetic target the loop is known to reach: the macro properties that
// known micro parameters P* give (one measuring run, started from P*). The
// fit of a card with exactly those properties then starts from P* with the
// bond modulus 1.5 x too high and the bond strengths (tensile and cohesion,
// same ratio) halved, and must come back to them. (The card's E is also the contact modulus of the
// elements, so P* is chosen to give E close to the card's E in the measuring run.)
TEST(SyntheticTarget, FitRecoversPerturbedBondModulusAndStrengths) {
  const double Eb = 16.6e9, ratio = 2.5, sigma_b = 10e6, c = 20e6;
  const auto dir = scratch("synthetic");
  // Measure with P*: twice, the second time with the card's E (the contact
  // modulus) set to the E measured the first time.
  double E_card = 6.4e9;
  nlohmann::json m;
  for (int pass = 1; pass <= 2; ++pass) {
    const fs::path d = dir / ("truth" + std::to_string(pass));
    fs::create_directories(d);
    spit(d / "truth.yaml", card("truth", E_card, 0.14, 5e6, 0.5e6, Eb, ratio, sigma_b, c));
    spit(d / "case.yaml", tiny_case(d / "truth.yaml", 1));
    ASSERT_EQ(orchestrate("--case " + (d / "case.yaml").string() + " --stage calibrate --output " +
                              d.string(),
                          d / "run.log"),
              0)
        << slurp(d / "run.log");
    m = read_json(d / "calibrate" / "report.json");
    ASSERT_DOUBLE_EQ(m["iterations"][0]["bond"]["bond_modulus"].get<double>(), Eb);
    E_card = m["achieved"]["youngs_modulus"].get<double>();
  }
  const auto& a = m["achieved"];

  fs::create_directories(dir / "fit");
  spit(dir / "fit" / "target.yaml",
       card("target", a["youngs_modulus"].get<double>(), a["poisson_ratio"].get<double>(),
            a["ucs"].get<double>(), a["tensile_strength"].get<double>(), 1.5 * Eb, ratio,
            0.5 * sigma_b, 0.5 * c));
  spit(dir / "fit" / "case.yaml", tiny_case(dir / "fit" / "target.yaml", 4));
  ASSERT_EQ(orchestrate("--case " + (dir / "fit" / "case.yaml").string() +
                            " --stage calibrate --output " + (dir / "fit").string(),
                        dir / "fit.log"),
            0)
      << slurp(dir / "fit.log");
  const std::string md = slurp(dir / "fit" / "calibrate" / "report.md");
  const auto r = read_json(dir / "fit" / "calibrate" / "report.json");
  EXPECT_DOUBLE_EQ(r["iterations"][0]["bond"]["bond_modulus"].get<double>(), 1.5 * Eb) << md;
  EXPECT_TRUE(r["within_tolerance"]["youngs_modulus"].get<bool>()) << md;
  EXPECT_TRUE(r["within_tolerance"]["tensile_strength"].get<bool>()) << md;
  EXPECT_TRUE(r["within_tolerance"]["poisson_ratio"].get<bool>()) << md;
  EXPECT_NEAR(r["calibrated"]["bond_modulus"].get<double>() / Eb, 1.0, 0.15) << md;
  EXPECT_NEAR(r["calibrated"]["bond_tensile_strength"].get<double>() / sigma_b, 1.0, 0.15) << md;
}

// A card whose calibrated.* section was fitted to its own properties: the
// stage copies it and runs no lab test.
TEST(CardCalibration, MatchingCardSectionIsCopiedWithoutFitting) {
  const auto dir = scratch("card");
  const std::string props =
      "name: carded\ndensity: 2580\nyoungs_modulus: 18.69e9\npoisson_ratio: 0.18\nucs: 50.0e6\n"
      "tensile_strength: 5.0e6\n";
  spit(dir / "carded.yaml", props);
  spit(dir / "case.yaml", "name: carded\nore: {card: " + (dir / "carded.yaml").string() +
                              "}\ncalibrate: {n_elements: 100}\nresources: {np: 1, jobs: 1}\n");
  const auto cfg = mill::config::load_case(dir / "case.yaml", MILL_PROJECT_DIR);
  const std::string hash = mill::calibration_hash(cfg);
  spit(dir / "carded.yaml", props +
                                "calibrated:\n  bond_modulus: 5.5e10\n  stiffness_ratio: 3.9\n"
                                "  bond_tensile_strength: 1.6e8\n  bond_cohesion: 6.0e7\n"
                                "  bond_friction_angle: 30\n  input_hash: " +
                                hash + "\n");
  const int st = orchestrate(
      "--case " + (dir / "case.yaml").string() + " --stage calibrate --output " + dir.string(),
      dir / "run.log");
  ASSERT_EQ(st, 0) << slurp(dir / "run.log");
  EXPECT_NE(slurp(dir / "run.log").find("no fitting"), std::string::npos) << slurp(dir / "run.log");
  EXPECT_FALSE(fs::exists(dir / "calibrate" / "jobs" / "calibration" / "specimen"));
  const YAML::Node y = YAML::LoadFile((dir / "calibrate" / "calibrated.yaml").string());
  EXPECT_DOUBLE_EQ(y["calibrated"]["bond_modulus"].as<double>(), 5.5e10);
  EXPECT_EQ(y["calibrated"]["input_hash"].as<std::string>(), hash);
  EXPECT_EQ(read_json(dir / "calibrate" / "report.json")["source"], "ore card");

  // A changed card (other UCS, stale hash) is fitted again: the plan says so.
  spit(dir / "carded.yaml",
       "name: carded\ndensity: 2580\nyoungs_modulus: 18.69e9\npoisson_ratio: 0.18\nucs: 60.0e6\n"
       "tensile_strength: 5.0e6\ncalibrated:\n  bond_modulus: 5.5e10\n  stiffness_ratio: 3.9\n"
       "  bond_tensile_strength: 1.6e8\n  bond_cohesion: 6.0e7\n  bond_friction_angle: 30\n"
       "  input_hash: " +
           hash + "\n");
  const int st2 = orchestrate("--case " + (dir / "case.yaml").string() +
                                  " --stage calibrate --dry-run --output " + dir.string(),
                              dir / "dry.log");
  EXPECT_EQ(st2, 0) << slurp(dir / "dry.log");
  EXPECT_NE(slurp(dir / "dry.log").find("UCS + Brazilian tests"), std::string::npos)
      << slurp(dir / "dry.log");
  EXPECT_NE(slurp(dir / "dry.log").find("todo"), std::string::npos) << slurp(dir / "dry.log");
}

}  // namespace
