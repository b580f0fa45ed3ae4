// The virtual triaxial test on a fixed material (fixed bond parameters, no
// calibration) with real LIGGGHTS runs, through the calibrate stage's own
// code: the specimen packed and carved as the stage does
// (calibrate::pack_specimen), each confinement run by calibrate::LabBench's
// triaxial test (liggghts_inputs/triaxial.in.tmpl, analysed by
// post::AnalyseTriaxial), the envelope fitted by post::FitMohrCoulomb.
// Issue 28: "A triaxial test on a fixed material gives a peak stress on the
// Mohr-Coulomb line that its own two confinements define, within 5 %."
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <stdlib.h>

#include <array>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "config/case_config.h"
#include "e2e_util.h"
#include "engine/runner.h"
#include "lab_context.h"
#include "lump/material.h"
#include "postprocess/energy_ledger.h"
#include "postprocess/lab_tests.h"
#include "progress.h"
#include "stages/calibrate/checks.h"
#include "stages/calibrate/lab_runs.h"
#include "stages/calibrate/specimen.h"
#include "stages/stage.h"

namespace fs = std::filesystem;

namespace {

using namespace mill;
using namespace mill::e2e;

// The specimen: 300 elements of the size of a 150-element, 20 mm lump (as in
// the tests' tiny calibration, tests/data/tiny_calibrate.yaml), carved from a
// ball packed with seed 2003 (1350 elements), loaded at the calibrate stage's
// default strain rate. Packing and the three runs took 46 s on one core.
constexpr long kElements = 300;
constexpr double kStrainRate = 0.5;  // 1/s

// The fixed material: the sandstone card's contacts and the bond parameters
// of the default case's signed-criterion fit (bench/README.md, "Rock
// strength levers": E_b 67.99 GPa, kn/ks 4.02, sigma_b 30.69 MPa, c 61.39 MPa,
// phi 30 deg), no calibration.
BondParams fixed_bonds(const config::CaseConfig& cfg) {
  BondParams b = estimate_bond_params(cfg.ore, cfg.doc);
  b.modulus = 67.99e9;
  b.stiffness_ratio = 4.02;
  b.tensile = 30.694e6;
  b.cohesion = 61.389e6;
  b.friction_angle_deg = 30.0;
  b.moment_factor = 1.0;
  b.origin = "fixed (test_triaxial_e2e)";
  return b;
}

// The confining pressures, Pa: none (the UCS test), then 0.1 and 0.2 x the
// material's UCS (about 25 MPa), the calibrate stage's default
// calibrate.confining_pressures. Up to about UCS/4 the bonded packing
// follows Mohr-Coulomb (docs/calibration.md, "Virtual triaxial test": on the
// default 400-element specimen the line through any two peaks at sigma_3
// 0-5 MPa predicted the others within 3.8 %; the peak at 10 MPa, about
// UCS/2, lay 22 % below the line), which is why the calibrate stage confines
// at 0.1 and 0.2 x UCS.
const std::vector<double> kPressures = {0.0, 2.5e6, 5.0e6};

TEST(TriaxialEnvelope, MiddlePeakLiesOnTheMohrCoulombLineOfTheOuterConfinements) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto dir = scratch("triaxial");
  spit(dir / "case.yaml", fmt::format("name: triaxial_envelope\nore: {{card: sandstone}}\n"
                                      "lump: {{n_elements: 150, diameter: 0.02, bond_gap: 0.2}}\n"
                                      "calibrate: {{n_elements: {}, strain_rate: {}, seed: 2003}}\n"
                                      "resources: {{np: 1, jobs: 1}}\n",
                                      kElements, kStrainRate));
  test::LabContext lab_ctx(dir, MILL_PROJECT_DIR);
  const config::CaseConfig& cfg = lab_ctx.cfg;
  StageContext& ctx = lab_ctx.ctx;

  const calibrate::Specimen sp = calibrate::pack_specimen(ctx, "triaxial", dir, kElements);
  // The targets only size each run (its strain cap and sampling interval);
  // the UCS here is about the material's (25 MPa), not the card's 50.
  const calibrate::Targets targets{cfg.ore.real("youngs_modulus"), cfg.ore.real("poisson_ratio"),
                                   25e6, cfg.ore.real("tensile_strength")};
  calibrate::LabBench lab(ctx, "triaxial", dir, sp, targets);
  const BondParams bonds = fixed_bonds(cfg);

  std::vector<calibrate::TriaxialRun> runs;
  std::string table;
  for (size_t k = 0; k < kPressures.size(); ++k) {
    const std::string tag = fmt::format("triaxial_{}", k + 1);
    runs.push_back(lab.triaxial(bonds, kStrainRate, kPressures[k],
                                {tag, fmt::format("triaxial at {:.3g} MPa", kPressures[k] / 1e6),
                                 static_cast<double>(k) / kPressures.size()}));
    const post::TriaxialResult& r = runs.back().r;
    table += fmt::format(
        "  {}: p {:.3f} MPa, sigma_3 {:.3f} MPa, sigma_1 {:.3f} MPa at strain {:.5f}, "
        "{} bonds broken by the confinement, {:.1f} s\n",
        tag, kPressures[k] / 1e6, r.sigma3 / 1e6, r.sigma1 / 1e6, r.strain_at_peak,
        r.broken_before_loading, runs.back().seconds);
  }
  const post::TriaxialResult &lo = runs[0].r, &mid = runs[1].r, &hi = runs[2].r;

  // Each run peaked (it did not reach its strain cap still loading), under
  // the confinement asked: sigma_3 at the peak is the confining force the
  // deck applied over the lateral area, so a deck that dropped or mis-scaled
  // the confinement fails here. The follower forces keep it within a few
  // per cent as the specimen bulges; 10 % as the calibrate e2e test allows.
  for (size_t k = 0; k < runs.size(); ++k) {
    EXPECT_TRUE(runs[k].peaked) << runs[k].tag << "\n" << table;
    if (kPressures[k] > 0)
      EXPECT_NEAR(runs[k].r.sigma3 / kPressures[k], 1.0, 0.1) << runs[k].tag << "\n" << table;
    else
      EXPECT_EQ(runs[k].r.sigma3, 0.0) << table;
    // The confinement alone broke no bond: the peaks are those of the intact
    // material, whose envelope the line is.
    EXPECT_EQ(runs[k].r.broken_before_loading, 0.0) << runs[k].tag << "\n" << table;
  }

  // The peak must rise with the confinement by more than the confinement
  // itself: q = d sigma_1 / d sigma_3 > 1 is a positive friction angle. A
  // deck whose confinement only added sigma_3 to the axial stress without
  // strengthening the specimen (the same deviator at every confinement:
  // q = 1) would put the middle peak on its line too; this rules it out. The
  // bonded packing gave q 2.87 (phi 28.9 deg) on the default specimen and
  // 2.46 (phi 24.9 deg) here; q >= 1.5 (phi >= 11.5 deg) leaves room for
  // the packing's scatter and admits no confinement without effect.
  const double q = (hi.sigma1 - lo.sigma1) / (hi.sigma3 - lo.sigma3);
  ASSERT_GE(q, 1.5) << table;
  // The Mohr-Coulomb line sigma_1 = UCS_mc + q sigma_3 through the outer two
  // confinements (FitMohrCoulomb is exact through two points).
  const post::MohrCoulomb mc =
      post::FitMohrCoulomb({{lo.sigma3, lo.sigma1}, {hi.sigma3, hi.sigma1}});
  // The middle confinement is an interpolation: its peak lies on the line
  // within 5 % (issue 28). Basis: on the default 400-element specimen the
  // line through any two peaks up to UCS/4 predicted the others within
  // 3.8 %; this specimen gave +0.57 % (+0.97 % at 2 1/s). The line's own
  // peaks carry the scatter of a few hundred elements, so a tighter bound
  // would test the packing's noise rather than the envelope; the 22 % by
  // which the envelope bends at UCS/2 is far outside it.
  const double predicted = mc.Sigma1(mid.sigma3);
  const double deviation = mid.sigma1 / predicted - 1.0;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::string summary = fmt::format(
      "{}line: UCS_mc {:.3f} MPa, q {:.3f} (phi {:.1f} deg, c {:.3f} MPa); middle peak "
      "{:.3f} MPa against {:.3f} MPa on the line: {:+.2f} %; specimen {} elements "
      "(cylinder radius {:.2f} mm), {:.0f} s in all",
      table, mc.ucs / 1e6, mc.q, mc.friction_angle_deg, mc.cohesion / 1e6, mid.sigma1 / 1e6,
      predicted / 1e6, 100 * deviation, kElements, sp.cyl_r * 1e3, seconds);
  EXPECT_LE(std::abs(deviation), 0.05) << summary;
  std::cout << summary << "\n";
}

// A shell element that has come loose is no longer pressed. Measured: a
// corner element of a 400-element flat-joint cylinder at 10.5 MPa lost its
// bonds, the constant push carried it across the open end face and the
// energy ledger stopped the run at 411 m/s. Here the specimen is a simple
// cubic lattice of 1 mm elements (centres 2 mm apart, 13 columns x 9 layers,
// bonded face to face) with one shell element at mid-height standing alone:
// its three neighbours removed, a 2 mm gap between it and the next element
// in. A deck that pushed it (the pressure shared over the whole shell: about
// 96 N at 5 MPa on an element of 10.8 mg) would send it across the gap at
// tens of m/s during the hydrostatic ramp (closed form: 67 m/s); pressed
// only while held, nothing moves faster than the quasi-static loading.
TEST(TriaxialConfinement, LooseShellElementIsNotPushed) {
  const auto dir = scratch("triaxial_loose");
  spit(dir / "case.yaml",
       "name: triaxial_loose\nore: {card: sandstone}\n"
       "lump: {n_elements: 150, diameter: 0.02, bond_gap: 0.2}\n"
       "calibrate: {strain_rate: 0.5}\nresources: {np: 1, jobs: 1}\n");
  test::LabContext lab_ctx(dir, MILL_PROJECT_DIR);
  const config::CaseConfig& cfg = lab_ctx.cfg;
  StageContext& ctx = lab_ctx.ctx;

  constexpr double r = 1e-3, rho = 2580.0;
  std::vector<std::array<int, 3>> cells;  // lattice indices, centres at 2 r x index
  for (int i = -2; i <= 2; ++i)
    for (int j = -2; j <= 2; ++j)
      for (int k = -4; k <= 4; ++k) {
        if (4 * (i * i + j * j) > 19) continue;  // centres within 4.45 mm of the axis
        const bool gone = (i == 1 && j == 0 && k == 0) || (i == 2 && j == 0 && std::abs(k) == 1);
        if (!gone) cells.push_back({i, j, k});
      }
  ASSERT_EQ(cells.size(), 13u * 9u - 3u);
  std::string atoms;
  for (std::size_t n = 0; n < cells.size(); ++n)
    atoms += fmt::format("{} 1 {} {} {} {} {}\n", n + 1, 2 * r, rho, 2 * r * cells[n][0],
                         2 * r * cells[n][1], 2 * r * cells[n][2]);
  spit(dir / "ball.data", fmt::format("lattice\n\n{} atoms\n2 atom types\n\n-0.02 0.02 xlo xhi\n"
                                      "-0.02 0.02 ylo yhi\n-0.02 0.02 zlo zhi\n\nAtoms\n\n{}",
                                      cells.size(), atoms));
  calibrate::Specimen sp;
  sp.ball = dir / "ball.data";
  sp.ball_elements = static_cast<long>(cells.size());
  sp.mean_radius = r;
  sp.cyl_r = 4.45e-3;  // the lattice's 13 columns; the shell: the four at 4 mm
  // The lattice's columns carry the axial load face to face and do not fail
  // before the strain cap; a UCS of 1 MPa here only shortens the axial stage
  // (its cap is 4 x (UCS + 5 p) / E).
  const calibrate::Targets targets{cfg.ore.real("youngs_modulus"), cfg.ore.real("poisson_ratio"),
                                   1e6, cfg.ore.real("tensile_strength")};
  calibrate::LabBench lab(ctx, "triaxial_loose", dir, sp, targets);
  constexpr double p = 5e6;
  const calibrate::TriaxialRun t =
      lab.triaxial(fixed_bonds(cfg), kStrainRate, p, {"triaxial_loose", "triaxial at 5 MPa", 0.0});

  // The hydrostatic stage: the ramp p / (E strain rate) and half of it held.
  const double hydrostatic_end = 1.5 * p / (cfg.ore.real("youngs_modulus") * kStrainRate);
  const post::EnergyLedger ledger =
      post::ReadEnergyLedger((dir / "runs" / "triaxial_loose" / "ledger.csv").string());
  const auto& time = ledger.column("time_s");
  const auto& speed = ledger.column("max_speed_m_s");
  double fastest = 0.0;
  std::size_t rows = 0;
  for (std::size_t k = 0; k < ledger.rows(); ++k)
    if (time[k] <= hydrostatic_end) {
      fastest = std::max(fastest, speed[k]);
      ++rows;
    }
  ASSERT_GE(rows, 3u) << "ledger rows in the hydrostatic stage (until " << hydrostatic_end << " s)";
  // Quasi-static: the lattice's own motion under the ramp is mm/s; a pushed
  // loose element reaches tens of m/s. 1 m/s between them.
  EXPECT_LT(fastest, 1.0) << "fastest element in the hydrostatic stage, m/s";
  // The held shell elements carry the whole pressure, less the subtracted
  // mean: sum_i f (1 - u_i . m) = p A_lat (1 - |m|^2), m the mean of their
  // unit radial vectors. Held: the four columns at 4 mm (9 elements each)
  // but the two removed and the loose one, so the +x column has 6:
  // m_x = (6 - 9) / 33. With the loose element counted (m_x = (7 - 9) / 34)
  // the share would be about 0.997 instead of 0.9917 (measured 0.9968).
  const post::TriaxialCurve curve =
      post::ReadTriaxialCurve((dir / "runs" / "triaxial_loose" / "triaxial_curve.txt").string());
  ASSERT_FALSE(curve.confining_force.empty());
  const double a_lat = calibrate::info_at(t.info, "lateral_area", t.info_file);
  const double m_x = (6.0 - 9.0) / 33.0;
  EXPECT_NEAR(curve.confining_force.front() / (p * a_lat), 1.0 - m_x * m_x, 1e-3)
      << "confining force at the start of the axial loading, N: " << curve.confining_force.front();
  std::cout << fmt::format(
      "loose shell element: fastest element {:.4f} m/s until {:.3g} s; "
      "confining force {:.2f} N of p x lateral area {:.2f} N\n",
      fastest, hydrostatic_end, curve.confining_force.front(), p * a_lat);
}

// A triaxial check whose engine run fails (here a deck the engine rejects
// at once; measured: a flat joint at bond gap 1.4 under 11.6 MPa of
// confinement, where the energy ledger stopped an element at 411 m/s) is a
// failed check, named with its reason in the notes and left out of the
// envelope, not an exception that throws the calibration's fit away.
TEST(TriaxialCheck, FailedRunIsANamedCheckNotALostCalibration) {
  const auto dir = scratch("triaxial_failed");
  const fs::path project = dir / "project";
  fs::create_directories(project / "liggghts_inputs" / "materials");
  fs::copy_file(fs::path(MILL_PROJECT_DIR) / "liggghts_inputs" / "materials" / "sandstone.yaml",
                project / "liggghts_inputs" / "materials" / "sandstone.yaml");
  spit(project / "liggghts_inputs" / "triaxial.in.tmpl", "no_such_command 1\n");
  spit(dir / "case.yaml",
       "name: triaxial_failed\nore: {card: sandstone}\n"
       "resources: {np: 1, jobs: 1}\n");
  test::LabContext lab_ctx(dir, project);
  const config::CaseConfig& cfg = lab_ctx.cfg;
  StageContext& ctx = lab_ctx.ctx;
  calibrate::Specimen sp;
  sp.ball = dir / "ball.data";  // never read: the deck fails first
  sp.mean_radius = 1e-3;
  sp.cyl_r = 8e-3;
  const calibrate::Targets targets{cfg.ore.real("youngs_modulus"), cfg.ore.real("poisson_ratio"),
                                   cfg.ore.real("ucs"), cfg.ore.real("tensile_strength")};
  calibrate::LabBench lab(ctx, "triaxial_failed", dir, sp, targets);
  calibrate::UcsRun ucs;
  ucs.r.ucs = 50e6;
  const calibrate::Checks c = calibrate::run_checks(
      lab, fixed_bonds(cfg), ucs, kStrainRate, {5e6, 10e6}, calibrate::CheckTargets{}, 0.0, 0.1, 1);
  EXPECT_TRUE(c.triaxial.empty());
  ASSERT_EQ(c.failed.size(), 2u);
  EXPECT_NE(c.failed[0].find("triaxial_1 (runs/triaxial_1, confinement 5 MPa) failed"),
            std::string::npos)
      << c.failed[0];
  EXPECT_NE(c.failed[1].find("ERROR"), std::string::npos) << c.failed[1];
  EXPECT_EQ(c.failed[1].find('\n'), std::string::npos) << "one line: " << c.failed[1];
  // The notes say so, and no envelope is made from one point.
  ASSERT_GE(c.notes.size(), 2u);
  EXPECT_EQ(c.notes[0], c.failed[0]);
  EXPECT_FALSE(c.mc.has_value());
  EXPECT_FALSE(c.envelope_error.empty());
}

}  // namespace
