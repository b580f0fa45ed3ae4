// The levers' sensitivities on hand-made lab results (no engine): the levers
// of each bond model and their steps, the arithmetic against its closed form,
// the verdict (moves a target, not free), the noise from the rate check, and
// the reports (docs/calibration.md, "Lever sensitivities").
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "stages/calibrate/energy_report.h"
#include "stages/calibrate/sensitivity.h"

using namespace mill;
using namespace mill::calibrate;

namespace {

BondParams result_params() {
  BondParams p;
  p.modulus = 57.8e9;
  p.stiffness_ratio = 2.27;
  p.tensile = 9.0e6;
  p.cohesion = 31.1e6;
  p.friction_angle_deg = 60.0;
  p.moment_factor = 0.0;
  p.radius_multiplier = 1.0;
  return p;
}

// The result's iteration: E 19 GPa, nu 0.15, UCS 27 MPa, tensile 5 MPa.
Iteration base_iteration() {
  Iteration it;
  it.p = result_params();
  it.ucs.tag = "it10_ucs";
  it.br.tag = "it10_brazilian";
  it.ucs.r.youngs_modulus = 19e9;
  it.ucs.r.poisson_ratio = 0.15;
  it.ucs.r.ucs = 27e6;
  it.br.r.tensile_strength = 5e6;
  return it;
}

// The lever named `calibrated` of p's levers.
Lever lever(const BondParams& p, const std::string& calibrated) {
  for (const Lever& l : sensitivity_levers(p))
    if (calibrated == l.row->calibrated) return l;
  ADD_FAILURE() << "no lever " << calibrated;
  return {};
}

// A lever's runs that reached E, nu, UCS and tensile.
LeverRun run_of(const Lever& l, double E, double nu, double ucs, double t) {
  LeverRun r;
  r.lever = l;
  r.ucs.tag = std::string("sens_") + l.row->calibrated + "_ucs";
  r.br.tag = std::string("sens_") + l.row->calibrated + "_brazilian";
  r.ucs.r.youngs_modulus = E;
  r.ucs.r.poisson_ratio = nu;
  r.ucs.r.ucs = ucs;
  r.br.r.tensile_strength = t;
  r.ucs.seconds = 2.0;
  r.br.seconds = 1.0;
  return r;
}

}  // namespace

// The parallel bond's levers are the fitted rows of the table, in its order
// (the radius multiplier is the case's, not fitted); the flat joint has no
// moment factor. Scales x1.2, the friction angle +5 deg (-5 near 90), the
// moment factor -0.25 clamped into [0, 1], +0.25 from 0.
TEST(CalibrateSensitivity, LeversAndStepsFollowTheTable) {
  BondParams p = result_params();
  const std::vector<Lever> par = sensitivity_levers(p);
  std::vector<std::string> names;
  for (const Lever& l : par) names.push_back(l.row->calibrated);
  EXPECT_EQ(names, (std::vector<std::string>{"bond_modulus", "stiffness_ratio",
                                             "bond_tensile_strength", "bond_cohesion",
                                             "bond_friction_angle", "bond_moment_factor"}));
  EXPECT_TRUE(par[0].multiplicative);
  EXPECT_DOUBLE_EQ(par[0].to, 1.2 * 57.8e9);
  EXPECT_DOUBLE_EQ(par[3].to, 1.2 * 31.1e6);
  EXPECT_FALSE(par[4].multiplicative);
  EXPECT_DOUBLE_EQ(par[4].to, 65.0);
  EXPECT_FALSE(par[5].multiplicative);
  EXPECT_DOUBLE_EQ(par[5].to, 0.25);  // from 0: up
  p.moment_factor = 1.0;
  EXPECT_DOUBLE_EQ(lever(p, "bond_moment_factor").to, 0.75);
  p.moment_factor = 0.1;
  EXPECT_DOUBLE_EQ(lever(p, "bond_moment_factor").to, 0.0);  // clamped
  p.friction_angle_deg = 87.0;
  EXPECT_DOUBLE_EQ(lever(p, "bond_friction_angle").to, 82.0);

  // Each perturbed set differs from p in its lever only.
  p = result_params();
  const BondParams q = perturbed(p, par[2]);
  EXPECT_DOUBLE_EQ(q.tensile, 1.2 * p.tensile);
  EXPECT_DOUBLE_EQ(q.cohesion, p.cohesion);
  EXPECT_DOUBLE_EQ(q.modulus, p.modulus);

  p.model = BondModel::flat_joint;
  const std::vector<Lever> fj = sensitivity_levers(p);
  ASSERT_EQ(fj.size(), 6u);  // and its tension softening, x 1.2 from 1 (brittle)
  for (const Lever& l : fj) EXPECT_FALSE(l.row->parallel_only) << l.row->calibrated;
  EXPECT_TRUE(lever(p, "joint_softening").multiplicative);
  EXPECT_DOUBLE_EQ(lever(p, "joint_softening").to, 1.2);
  EXPECT_DOUBLE_EQ(perturbed(p, lever(p, "joint_softening")).softening, 1.2);
  p.model = BondModel::parallel;  // no softening lever: the parallel bond has none
  for (const Lever& l : sensitivity_levers(p)) EXPECT_FALSE(l.row->joint_only) << l.row->calibrated;
}

// The closed form: (dT/T)/(dx/x) for E, UCS, tensile and d nu / d ln x for
// nu under a x1.2 step; dT/T and d nu per unit of an added lever.
TEST(CalibrateSensitivity, ArithmeticMatchesTheClosedForm) {
  const Iteration base = base_iteration();
  // Bond modulus x1.2: E +19 % -> elasticity 0.95; nu 0.15 -> 0.152;
  // UCS +2 %, tensile -1 %.
  const LeverRun m = run_of(lever(base.p, "bond_modulus"), 19e9 * 1.19, 0.152, 27e6 * 1.02,
                            5e6 * 0.99);
  const LeverSensitivity s = lever_sensitivity(base, m);
  EXPECT_NEAR(s.E.change, 0.19, 1e-12);
  EXPECT_NEAR(s.E.value, 0.19 / 0.2, 1e-12);
  EXPECT_NEAR(s.nu.change, 0.002, 1e-12);
  EXPECT_NEAR(s.nu.value, 0.002 / std::log(1.2), 1e-12);
  EXPECT_NEAR(s.ucs.value, 0.02 / 0.2, 1e-12);
  EXPECT_NEAR(s.tensile.value, -0.01 / 0.2, 1e-12);

  // Friction angle 60 -> 65 deg: UCS +10 % -> 0.02 per deg; nu -0.01 -> -0.002 per deg.
  const LeverRun f = run_of(lever(base.p, "bond_friction_angle"), 19e9, 0.14, 27e6 * 1.1, 5e6);
  const LeverSensitivity sf = lever_sensitivity(base, f);
  EXPECT_NEAR(sf.ucs.value, 0.1 / 5.0, 1e-12);
  EXPECT_NEAR(sf.nu.value, -0.01 / 5.0, 1e-12);
  EXPECT_NEAR(sf.E.value, 0.0, 1e-12);
  EXPECT_EQ(sensitivity_unit(f.lever, false), "dT/T per deg");
  EXPECT_EQ(sensitivity_unit(f.lever, true), "d nu per deg");
  EXPECT_EQ(sensitivity_unit(m.lever, false), "elasticity (dT/T)/(dx/x)");

  // Moment factor 0 -> 0.25: UCS -5 % -> -0.2 per unit of beta.
  const LeverRun b = run_of(lever(base.p, "bond_moment_factor"), 19e9, 0.15, 27e6 * 0.95, 5e6);
  EXPECT_NEAR(lever_sensitivity(base, b).ucs.value, -0.05 / 0.25, 1e-12);
}

// A lever moves a target by more than the tolerance per step, or by more
// than the noise, or by neither: then it is not free.
TEST(CalibrateSensitivity, VerdictSortsStrongWeakAndNotFree) {
  const Iteration base = base_iteration();
  const Noise noise;  // floors: 1 %, nu 0.005
  const LeverVerdict strong = lever_verdict(
      lever_sensitivity(base, run_of(lever(base.p, "bond_tensile_strength"), 19e9, 0.15,
                                     27e6 * 1.15, 5e6 * 1.18)),
      0.1, noise);
  EXPECT_EQ(strong.strong, (std::vector<std::string>{"UCS", "tensile"}));
  EXPECT_TRUE(strong.free());
  const LeverVerdict weak = lever_verdict(
      lever_sensitivity(base, run_of(lever(base.p, "stiffness_ratio"), 19e9 * 0.97, 0.17, 27e6,
                                     5e6)),
      0.1, noise);
  EXPECT_TRUE(weak.strong.empty());
  EXPECT_EQ(weak.above_noise, (std::vector<std::string>{"E", "nu"}));
  const LeverVerdict none = lever_verdict(
      lever_sensitivity(base, run_of(lever(base.p, "bond_friction_angle"), 19e9, 0.152,
                                     27e6 * 1.005, 5e6 * 0.995)),
      0.1, noise);
  EXPECT_TRUE(none.above_noise.empty());
  EXPECT_FALSE(none.free());
}

// Without a rate check the noise is the floors; with one, its changes raise
// them (the UCS's also for the tensile strength).
TEST(CalibrateSensitivity, NoiseIsTheRateCheckAboveTheFloors) {
  const Iteration base = base_iteration();
  const Noise floors = sensitivity_noise(base.ucs, nullptr);
  EXPECT_DOUBLE_EQ(floors.E, kNoiseFloorRelative);
  EXPECT_DOUBLE_EQ(floors.nu, kNoiseFloorNu);
  UcsRun half = base.ucs;
  half.r.ucs = 27e6 * 0.962;
  half.r.youngs_modulus = 19e9 * 1.001;
  half.r.poisson_ratio = 0.16;
  const Noise n = sensitivity_noise(base.ucs, &half);
  EXPECT_NEAR(n.ucs, 0.038, 1e-12);
  EXPECT_NEAR(n.tensile, 0.038, 1e-12);
  EXPECT_DOUBLE_EQ(n.E, kNoiseFloorRelative);
  EXPECT_NEAR(n.nu, 0.01, 1e-12);
}

// report.json's object per lever (step, per target value and change, the
// verdict, the runs) and report.md's table and sentences; the energy report
// lists the lever runs after the rate check and before the checks.
TEST(CalibrateSensitivity, ReportsCarryTheTableAndTheVerdicts) {
  const Iteration base = base_iteration();
  const std::vector<LeverRun> runs = {
      run_of(lever(base.p, "bond_modulus"), 19e9 * 1.19, 0.152, 27e6 * 1.02, 5e6 * 0.99),
      run_of(lever(base.p, "bond_friction_angle"), 19e9, 0.151, 27e6 * 1.004, 5e6)};
  const Noise noise;
  const nlohmann::json j = sensitivity_json(base, runs, 0.1, noise);
  const auto& m = j.at("levers").at("bond_modulus");
  EXPECT_EQ(m.at("step").at("kind"), "multiply");
  EXPECT_DOUBLE_EQ(m.at("step").at("size").get<double>(), 1.2);
  EXPECT_NEAR(m.at("targets").at("youngs_modulus").at("value").get<double>(), 0.95, 1e-12);
  EXPECT_NEAR(m.at("targets").at("poisson_ratio").at("value").get<double>(),
              0.002 / std::log(1.2), 1e-12);
  EXPECT_EQ(m.at("moves_beyond_tolerance"), nlohmann::json::array({"E"}));
  EXPECT_TRUE(m.at("free").get<bool>());
  EXPECT_EQ(m.at("runs"), nlohmann::json::array({"sens_bond_modulus_ucs",
                                                 "sens_bond_modulus_brazilian"}));
  const auto& f = j.at("levers").at("bond_friction_angle");
  EXPECT_EQ(f.at("step").at("kind"), "add");
  EXPECT_DOUBLE_EQ(f.at("step").at("size").get<double>(), 5.0);
  EXPECT_EQ(f.at("targets").at("ucs").at("unit"), "dT/T per deg");
  EXPECT_FALSE(f.at("free").get<bool>());
  EXPECT_EQ(j.at("not_free"), nlohmann::json::array({"bond_friction_angle"}));
  EXPECT_DOUBLE_EQ(j.at("wall_seconds").get<double>(), 6.0);

  const std::string md = sensitivity_markdown(base, runs, 0.1, noise);
  EXPECT_NE(md.find("## Lever sensitivities"), std::string::npos) << md;
  EXPECT_NE(md.find("| bond_modulus | x1.2 (57.8 GPa -> 69.36 GPa) | +0.95 (+19.0%) |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| bond_friction_angle | +5 deg (60 deg -> 65 deg) |"), std::string::npos)
      << md;
  EXPECT_NE(md.find("per step: bond_modulus (E)."), std::string::npos) << md;
  EXPECT_NE(md.find("bond_friction_angle (default: 30 deg). It is not free"), std::string::npos)
      << md;

  Outcome o;
  o.hist = {base};
  o.half = UcsRun{};
  o.half->tag = "rate_check_ucs";
  o.sensitivity = runs;
  o.checks.triaxial.emplace_back();
  o.checks.triaxial.back().tag = "triaxial_1";
  const auto all = lab_runs(o);
  ASSERT_EQ(all.size(), 8u);
  EXPECT_EQ(all[2]->tag, "rate_check_ucs");
  EXPECT_EQ(all[3]->tag, "sens_bond_modulus_ucs");
  EXPECT_EQ(all[4]->tag, "sens_bond_modulus_brazilian");
  EXPECT_EQ(all[6]->tag, "sens_bond_friction_angle_brazilian");
  EXPECT_EQ(all[7]->tag, "triaxial_1");
  EXPECT_NE(energy_markdown(o).find("| sens_bond_friction_angle_ucs |"), std::string::npos);
}
