// The virtual direct tension test (liggghts_inputs/tension.in.tmpl: the UCS
// cylinder pulled apart by its end layers) on a fixed flat-joint material,
// with real LIGGGHTS runs through the calibrate stage's own code
// (calibrate::pack_specimen, calibrate::LabBench::tension and ::ucs).
// Checked against laws, each with its tolerance:
// - equilibrium: the quasi-static specimen pulls its two grips with equal
//   and opposite forces (Newton's third law through the specimen);
// - scale invariance: bond strengths (tensile strength and cohesion) x 2 at
//   the same stiffness double the direct tensile strength (a brittle packing
//   of linear bonds breaks at twice the stretch, every force twice as large);
// - elastic symmetry: linear bonds give the same modulus in tension as in
//   compression;
// - it pulls: the same cylinder in compression holds several times more
//   (a deck that ignored `pull` would measure the UCS again).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>

#include "config/case_config.h"
#include "e2e_util.h"
#include "lab_context.h"
#include "lump/material.h"
#include "postprocess/lab_tests.h"
#include "stages/calibrate/lab_runs.h"
#include "stages/calibrate/specimen.h"
#include "stages/stage.h"

namespace fs = std::filesystem;

namespace {

using namespace mill;
using namespace mill::e2e;

constexpr long kElements = 300;
constexpr double kStrainRate = 0.5;  // 1/s

// The fixed material: flat joints with the bonds of the sandstone's flat-joint
// fit on the mean of three packings (bench/README.md, "Fitting the mean of
// three packings": E_b 15.75 GPa, kn/ks 1.49, c 17.0 MPa) with sigma_b 3.5
// MPa, about the card's direct tensile strength.
BondParams fixed_bonds(const config::CaseConfig& cfg, double scale) {
  BondParams b = estimate_bond_params(cfg.ore, cfg.doc);
  b.modulus = 15.75e9;
  b.stiffness_ratio = 1.49;
  b.tensile = 3.5e6 * scale;
  b.cohesion = 17.0e6 * scale;
  b.friction_angle_deg = 30.0;
  b.origin = "fixed (test_tension_e2e)";
  return b;
}

TEST(DirectTension, GripsInEquilibriumStrengthScalesWithTheBondsAndBelowTheUcs) {
  const auto dir = scratch("tension");
  spit(dir / "case.yaml",
       fmt::format(
           "name: tension\nore: {{card: sandstone}}\n"
           "lump: {{n_elements: 150, diameter: 0.02, bond_model: flat_joint, bond_gap: 1.0, "
           "max_bonds: 32}}\n"
           "calibrate: {{n_elements: {}, strain_rate: {}, seed: 2003, tensile_test: direct}}\n"
           "resources: {{np: 1, jobs: 1}}\n",
           kElements, kStrainRate));
  test::LabContext lab_ctx(dir, MILL_PROJECT_DIR);
  const config::CaseConfig& cfg = lab_ctx.cfg;
  StageContext& ctx = lab_ctx.ctx;
  // The sandstone card's direct tensile strength: 0.7 x 5 MPa (sedimentary).
  ASSERT_NEAR(tensile_target(cfg), 3.5e6, 1.0);

  const calibrate::Specimen sp = calibrate::pack_specimen(ctx, "tension", dir, kElements);
  calibrate::Targets targets{cfg.ore.real("youngs_modulus"), cfg.ore.real("poisson_ratio"),
                             cfg.ore.real("ucs"), tensile_target(cfg)};
  targets.direct = true;
  calibrate::LabBench lab(ctx, "tension", dir, sp, targets);
  const calibrate::UcsRun one =
      lab.tension(fixed_bonds(cfg, 1.0), kStrainRate, {"tension_x1", "tension, bonds x 1", 0.0});
  const calibrate::UcsRun two =
      lab.tension(fixed_bonds(cfg, 2.0), kStrainRate, {"tension_x2", "tension, bonds x 2", 0.3});
  const calibrate::UcsRun ucs =
      lab.ucs(fixed_bonds(cfg, 1.0), kStrainRate, {"ucs_x1", "UCS, bonds x 1", 0.6});
  const std::string table = fmt::format(
      "direct tensile {:.3f} MPa (bonds x 1), {:.3f} MPa (x 2): ratio {:.4f}; UCS {:.3f} MPa; "
      "E in tension {:.2f} GPa, in compression {:.2f} GPa; {:.0f} + {:.0f} + {:.0f} s",
      one.r.ucs / 1e6, two.r.ucs / 1e6, two.r.ucs / one.r.ucs, ucs.r.ucs / 1e6,
      one.r.youngs_modulus / 1e9, ucs.r.youngs_modulus / 1e9, one.seconds, two.seconds,
      ucs.seconds);
  std::cout << table << "\n";

  for (const calibrate::UcsRun* r : {&one, &two}) {
    // It broke: the load fell below kUcsFailureFraction of its peak before the cap.
    ASSERT_TRUE(r->peaked) << r->tag << ": " << table;
    ASSERT_GT(r->r.ucs, 0.0) << r->tag << ": " << table;
    // Equilibrium: at the peak each grip carries the same force within 5 %
    // (the grips move at constant speed; the specimen's inertia at a strain
    // rate of 0.5/s is negligible, and the curve's samples are quasi-static).
    const size_t k = r->r.peak_index;
    const double top = r->curve.force_top[k], bot = r->curve.force_bottom[k];
    EXPECT_GT(top, 0.0) << r->tag << ": a grip pushed instead of pulling; " << table;
    EXPECT_NEAR(top / bot, 1.0, 0.05)
        << r->tag << ": grips " << top << " and " << bot << " N; " << table;
  }
  // Scale invariance: x 2 the bond strengths, x 2 the strength, within 5 %
  // (measured 1.979; the Hertz contacts of touching unbonded elements are
  // not linear, and they carry little in tension).
  EXPECT_NEAR(two.r.ucs / one.r.ucs, 2.0, 0.1) << table;
  // Elastic symmetry: the bonds are linear springs, as stiff in tension as
  // in compression, so the secant moduli at half the peak agree within 5 %
  // (measured 0.2 %; the Hertz contacts of touching unbonded elements act
  // in compression only, and little before the peak).
  EXPECT_NEAR(one.r.youngs_modulus / ucs.r.youngs_modulus, 1.0, 0.05) << table;
  // It pulls: a rock's UCS is several times its tensile strength; the
  // same cylinder in compression holds more than three times the load.
  ASSERT_TRUE(ucs.peaked) << table;
  EXPECT_GT(ucs.r.ucs, 3.0 * one.r.ucs) << table;
}

}  // namespace
