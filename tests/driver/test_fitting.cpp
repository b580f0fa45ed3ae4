// The calibrate stage's fitting scheme on hand-made iterations (no engine):
// the order of the UCS/tensile levers and the secant's memory across a lever
// move (docs/calibration.md, "Fitting scheme").
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "stages/calibrate/fitting.h"

using namespace mill;
using namespace mill::calibrate;

namespace {

const Targets kCard{18.69e9, 0.18, 50e6, 5e6};  // sandstone

// An iteration with parameters p that achieved E, nu, UCS and T.
Iteration made(const BondParams& p, double E, double nu, double ucs, double t) {
  Iteration it;
  it.p = p;
  it.ucs.r.youngs_modulus = E;
  it.ucs.r.poisson_ratio = nu;
  it.ucs.r.ucs = ucs;
  it.br.r.tensile_strength = t;
  return it;
}

BondParams start() {
  BondParams p;
  p.modulus = 68e9;
  p.stiffness_ratio = 4.0;
  p.tensile = 30e6;
  p.cohesion = 60e6;
  p.friction_angle_deg = 30.0;
  p.moment_factor = 1.0;
  return p;
}

}  // namespace

// E and T met, UCS/T 4 against 10: the first lever is the moment factor
// (to 0), nothing else of the strength levers moves.
TEST(Fitting, FirstLeverIsTheMomentFactor) {
  const Fitting fit(kCard, 0.1);
  std::vector<Iteration> hist{made(start(), 18.69e9, 0.18, 20e6, 5e6)};
  fit.score(hist.back());
  std::vector<std::string> notes;
  const BondParams p = fit.update(hist, notes);
  EXPECT_EQ(p.moment_factor, 0.0);
  EXPECT_EQ(p.friction_angle_deg, 30.0);
  EXPECT_DOUBLE_EQ(p.cohesion / p.tensile, 2.0);  // cohesion ratio unchanged
  ASSERT_FALSE(notes.empty());
  EXPECT_NE(notes.back().find("moment factor"), std::string::npos) << notes.back();
}

// With beta already 0, the next lever is the friction angle, to its cap.
TEST(Fitting, SecondLeverIsTheFrictionAngle) {
  const Fitting fit(kCard, 0.1);
  BondParams p0 = start();
  p0.moment_factor = 0.0;
  std::vector<Iteration> hist{made(p0, 18.69e9, 0.18, 24e6, 5e6)};
  fit.score(hist.back());
  std::vector<std::string> notes;
  const BondParams p = fit.update(hist, notes);
  EXPECT_EQ(p.moment_factor, 0.0);
  EXPECT_EQ(p.friction_angle_deg, kMaxFrictionAngle);
  EXPECT_DOUBLE_EQ(p.cohesion / p.tensile, 2.0);
}

// Both levers spent: the cohesion ratio rises (UCS/T below the card's).
TEST(Fitting, ThenTheCohesionRatio) {
  const Fitting fit(kCard, 0.1);
  BondParams p0 = start();
  p0.moment_factor = 0.0;
  p0.friction_angle_deg = kMaxFrictionAngle;
  std::vector<Iteration> hist{made(p0, 18.69e9, 0.18, 28e6, 5e6)};
  fit.score(hist.back());
  std::vector<std::string> notes;
  const BondParams p = fit.update(hist, notes);
  EXPECT_GT(p.cohesion / p.tensile, 2.0);
  EXPECT_LE(p.cohesion / p.tensile, 4.0 + 1e-12);  // at most x2 per step
}

// A ratio above the card's never moves the moment factor or the friction
// angle: only the cohesion, downwards.
TEST(Fitting, TooStrongInCompressionMovesOnlyTheCohesion) {
  const Fitting fit(kCard, 0.1);
  std::vector<Iteration> hist{made(start(), 18.69e9, 0.18, 80e6, 5e6)};
  fit.score(hist.back());
  std::vector<std::string> notes;
  const BondParams p = fit.update(hist, notes);
  EXPECT_EQ(p.moment_factor, 1.0);
  EXPECT_EQ(p.friction_angle_deg, 30.0);
  EXPECT_LT(p.cohesion / p.tensile, 2.0);
}

// No lever moves while E or T is off (most sensitive first).
TEST(Fitting, LeversWaitForEAndTensile) {
  const Fitting fit(kCard, 0.1);
  std::vector<Iteration> hist{made(start(), 12e9, 0.18, 20e6, 3e6)};
  fit.score(hist.back());
  std::vector<std::string> notes;
  const BondParams p = fit.update(hist, notes);
  EXPECT_EQ(p.moment_factor, 1.0);
  EXPECT_EQ(p.friction_angle_deg, 30.0);
  EXPECT_GT(p.modulus, 68e9);
  EXPECT_GT(p.tensile, 30e6);
}

// After a lever move the tensile secant does not use the iteration before
// it: the step is the first-slope step (slope 1: sigma_b x T_card / T).
// Through the old point it would have used the slope between two different
// materials. Tolerance: 1e-9 relative.
TEST(Fitting, NoSecantAcrossALeverMove) {
  const Fitting fit(kCard, 0.1);
  BondParams before = start();
  BondParams after = before;
  after.moment_factor = 0.0;
  after.tensile = 0.8 * before.tensile;  // moved too: a secant through both would be defined
  std::vector<Iteration> hist{made(before, 18.69e9, 0.18, 20e6, 5e6),
                              made(after, 18.69e9, 0.18, 55e6, 11e6)};
  for (auto& it : hist) fit.score(it);
  std::vector<std::string> notes;
  const BondParams p = fit.update(hist, notes);
  EXPECT_NEAR(p.tensile / (after.tensile * 5e6 / 11e6), 1.0, 1e-9);
}

// A small gap (UCS/T 12 % below the card's) is closed with the cohesion, not
// with a coarse lever that would change the material for ~20 %.
TEST(Fitting, SmallGapUsesTheCohesion) {
  const Fitting fit(kCard, 0.1);
  std::vector<Iteration> hist{made(start(), 18.69e9, 0.18, 44.6e6, 5e6)};  // UCS/T 8.9
  fit.score(hist.back());
  std::vector<std::string> notes;
  const BondParams p = fit.update(hist, notes);
  EXPECT_EQ(p.moment_factor, 1.0);
  EXPECT_EQ(p.friction_angle_deg, 30.0);
  EXPECT_GT(p.cohesion / p.tensile, 2.0);
}

// Flat joints: neither coarse lever moves (the elements carry the moments
// whole; the friction angle is also the broken elements' friction); the
// cohesion ratio takes one damped step of the flat joint's first slope 0.5:
// UCS/T 5 against 10 wants ln 2 / 0.5 = ln 4, capped at x 3.
TEST(Fitting, FlatJointMovesTheCohesionAlone) {
  const Fitting fit(kCard, 0.1);
  BondParams p0 = start();
  p0.model = BondModel::flat_joint;
  std::vector<Iteration> hist{made(p0, 18.69e9, 0.18, 25e6, 5e6)};
  fit.score(hist.back());
  std::vector<std::string> notes;
  const BondParams p = fit.update(hist, notes);
  EXPECT_EQ(p.model, BondModel::flat_joint);
  EXPECT_EQ(p.moment_factor, 1.0);
  EXPECT_EQ(p.friction_angle_deg, 30.0);
  EXPECT_NEAR(p.cohesion / p.tensile, 2.0 * 3.0, 1e-9);
  // A smaller gap: ratio 8 against 10 -> x (10/8)^(1/0.5), below the cap.
  std::vector<Iteration> near{made(p0, 18.69e9, 0.18, 40e6, 5e6)};
  fit.score(near.back());
  const BondParams q = fit.update(near, notes);
  EXPECT_NEAR(q.cohesion / q.tensile, 2.0 * 1.25 * 1.25, 1e-9);
}
