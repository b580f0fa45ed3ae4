// The calibrate stage's fitting scheme on hand-made iterations (no engine):
// the parallel bond's order of the UCS/tensile levers and the secant's
// memory across a lever move; the flat joint's joint step on synthetic
// materials (docs/calibration.md, "Fitting scheme").
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "calibrate_test_iterations.h"
#include "stages/calibrate/fitting.h"

using namespace mill;
using namespace mill::calibrate;

namespace {

const Targets kCard{18.69e9, 0.18, 50e6, 5e6};  // sandstone

// An iteration with parameters p that achieved E, nu, UCS and T.
Iteration made(const BondParams& p, double E, double nu, double ucs, double t) {
  return mill::test::iteration(p, E, nu, ucs, t);
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
// cohesion ratio moves by the prior's slopes (flat_joint_prior(): UCS/T
// rises by J0[UCS][ratio] - J0[T][ratio] = 0.33 per e-fold of
// c / sigma_c): UCS/T 5 against 10 wants ln 2 / 0.33 = 2.1 > ln 3, so x 3
// (the cap), and sigma_c comes down to keep T.
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
  EXPECT_LT(p.tensile, p0.tensile);
  // A smaller gap: ratio 8 against 10: below the cap, the Newton step of
  // the ratio within 15 % (the damping and the prior's couplings through nu
  // and E, which the other parameters take up, shorten it).
  const FitMat& J0 = flat_joint_prior().J0;
  const double newton = std::log(1.25) / (J0[2][3] - J0[3][3]);
  std::vector<Iteration> near{made(p0, 18.69e9, 0.18, 40e6, 5e6)};
  fit.score(near.back());
  const BondParams q = fit.update(near, notes);
  const double step = std::log(q.cohesion / q.tensile / 2.0);
  EXPECT_GT(step, 0.85 * newton);
  EXPECT_LE(step, 1.15 * newton);
}

namespace {

// A synthetic material: responses from the parameters through a coupled
// map in log space (E follows kn/ks too, the strengths follow the ratio
// with their own slopes) and a ratio that saturates at ratio_max (the flat
// joint's at nu's kn/ks, bench/README.md). Stands in for the engine.
struct Material {
  double ratio_max = 30.0;  // UCS/T the cohesion tends to
  // K_IC per bond tensile strength [m^0.5] (0: no bend test): the notch
  // opens in tension, so K_IC follows sigma_b, with a weak coupling to the
  // cohesion ratio and the stiffness ratio.
  double kic_per_sigma = 0.0;
  bool direct = false;  // a direct tension test too (its strength: T)
  // The tension softening lambda: T, UCS and K_IC x lambda^0.3, ^0.2 and
  // ^0.6 (the measured slopes 0.21-0.48, 0.15-0.19, 0.46-0.60; bench/README.md,
  // "Tension softening with the direct test"; the prior's 0.33-0.35, 0.17, 0.55).
  Iteration test(const BondParams& p) const {
    const double le = std::log(p.modulus), lk = std::log(p.stiffness_ratio),
                 ls = std::log(p.tensile), lr = std::log(p.cohesion / p.tensile),
                 ll = std::log(p.softening);
    const double E = std::exp(0.93 * le - 0.25 * lk + 0.0);
    const double nu = 0.06 + 0.13 * lk + 0.02 * lr;
    const double T = std::exp(ls + 0.45 * lr - 0.15 + 0.3 * ll);
    // UCS/T rises with the ratio c / sigma as 4 rho^0.6 and saturates at
    // ratio_max (a smooth minimum of the two).
    const double free_ratio = 4.0 * std::pow(p.cohesion / p.tensile, 0.6);
    const double R =
        std::pow(std::pow(free_ratio, -4.0) + std::pow(ratio_max, -4.0), -0.25);
    Iteration it;
    it.p = p;
    it.ucs.r.youngs_modulus = E * 0.35;
    it.ucs.r.poisson_ratio = nu;
    it.ucs.r.ucs = R * T * std::exp(-0.1 * ll);
    it.br.r.tensile_strength = T;
    if (direct) {  // the direct tension test reads T (the disc: a check)
      it.tension.emplace();
      it.tension->r.ucs = T;
    }
    if (kic_per_sigma > 0) {
      it.scb.emplace();
      it.scb->toughness = kic_per_sigma * p.tensile * std::exp(0.05 * lr - 0.05 * lk + 0.6 * ll);
    }
    return it;
  }
};

// Runs the fit as the stage does (score, stop when converged, update).
std::vector<Iteration> run_fit(const Fitting& fit, const Material& m, BondParams p, int max_it) {
  std::vector<Iteration> hist;
  std::vector<std::string> notes;
  for (int k = 0; k < max_it; ++k) {
    hist.push_back(m.test(p));
    fit.score(hist.back());
    if (hist.back().converged) break;
    p = fit.update(hist, notes);
  }
  return hist;
}

}  // namespace

// A coupled material (every response moved by two or three parameters,
// slopes 7-50 % off the prior's) is fitted within tolerance in at most 8
// iterations from a start 3-7 x off its targets.
TEST(Fitting, JointStepConvergesOnACoupledMaterial) {
  const Fitting fit(kCard, 0.1);
  BondParams p = start();
  p.model = BondModel::flat_joint;
  const auto hist = run_fit(fit, Material{}, p, 8);
  EXPECT_TRUE(hist.back().converged)
      << hist.size() << " iterations, score " << hist.back().score;
}

// A ratio that saturates at 9 (card 10; 8.9 at c / sigma 9): reachable only
// by meeting both strengths within tolerance on either side. The fit
// balances them (UCS about 5 % low, T about 5 % high) and converges; a
// secant on the ratio alone would push the cohesion to its cap and leave T
// and UCS as they fall.
TEST(Fitting, BalancesStrengthsWhenTheRatioSaturatesWithinTolerance) {
  const Fitting fit(kCard, 0.1);
  BondParams p = start();
  p.model = BondModel::flat_joint;
  const auto hist = run_fit(fit, Material{9.0}, p, 12);
  const Iteration& best = hist[fit.best(hist)];
  EXPECT_TRUE(best.converged) << "score " << best.score << " after " << hist.size();
  EXPECT_LE(best.err_ucs, 0.1);
  EXPECT_LE(best.err_t, 0.1);
}

// A ratio out of reach (saturates at 5.5 against 10): the tensile strength
// is met first (it sets where an impact fractures), with E and nu; the UCS
// is the one target missed, and the notes say the ratio was out of reach.
TEST(Fitting, TensileFirstWhenTheRatioIsOutOfReach) {
  const Fitting fit(kCard, 0.1);
  BondParams p = start();
  p.model = BondModel::flat_joint;
  std::vector<Iteration> hist;
  std::vector<std::string> notes;
  const Material m{5.5};
  for (int k = 0; k < 12; ++k) {
    hist.push_back(m.test(p));
    fit.score(hist.back());
    p = fit.update(hist, notes);
  }
  const Iteration& best = hist[fit.best(hist)];
  EXPECT_LE(best.err_E, 0.1);
  EXPECT_LE(best.err_nu, kNuTolerance);
  EXPECT_LE(best.err_t, 0.1);
  EXPECT_GT(best.err_ucs, 0.3);
  bool said = false;
  for (const auto& n : notes) said = said || n.find("out of the levers' reach") != std::string::npos;
  EXPECT_TRUE(said);
}

// A specimen that failed at once (a negative modulus, as measured on a
// parallel-bond fit from another start): the next parameters lie half way,
// in log space, between the failed ones and the last usable iteration's.
TEST(Fitting, UnusableResponseStepsBackHalfWay) {
  const Fitting fit(kCard, 0.1);
  BondParams bad = start();
  bad.modulus = 4 * start().modulus;
  bad.stiffness_ratio = start().stiffness_ratio / 4;
  bad.tensile = start().tensile / 9;
  bad.cohesion = start().cohesion / 9;
  bad.moment_factor = 0.0;
  std::vector<Iteration> hist{made(start(), 15e9, 0.17, 18e6, 4.6e6),
                              made(bad, -0.59e9, 17.9, 2.7e6, 0.45e6)};
  for (auto& it : hist) fit.score(it);
  EXPECT_TRUE(Fitting::usable(hist[0]));
  EXPECT_FALSE(Fitting::usable(hist[1]));
  std::vector<std::string> notes;
  const BondParams p = fit.update(hist, notes);
  EXPECT_NEAR(p.modulus, 2 * start().modulus, 1e-6 * p.modulus);
  EXPECT_NEAR(p.stiffness_ratio, start().stiffness_ratio / 2, 1e-12);
  EXPECT_NEAR(p.tensile, start().tensile / 3, 1e-6);
  EXPECT_NEAR(p.cohesion, start().cohesion / 3, 1e-6);
  EXPECT_EQ(p.moment_factor, start().moment_factor);  // the usable iteration's lever
  EXPECT_EQ(p.origin, "calibrate iteration 3");
  ASSERT_FALSE(notes.empty());
  EXPECT_NE(notes.back().find("iteration 2: no usable response"), std::string::npos)
      << notes.back();
  // The failed iteration is never the result.
  EXPECT_EQ(fit.best(hist), 0u);
}

// Nothing usable yet (the first iteration failed): a named error, not a
// secant through a negative modulus.
TEST(Fitting, UnusableFirstIterationIsANamedError) {
  const Fitting fit(kCard, 0.1);
  std::vector<Iteration> hist{made(start(), -1e9, 0.2, 5e6, 1e6)};
  fit.score(hist.back());
  std::vector<std::string> notes;
  try {
    fit.update(hist, notes);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("iteration 1: the specimens gave no usable response"),
              std::string::npos)
        << e.what();
  }
}

// A Brazilian disc that did not split (post::kBrazilianSplitFraction) gives
// no tensile strength: the iteration is unusable (its T NaN, on one packing
// or in the mean of several), never within tolerance even when the load it
// reached matches the card, never the result, and the next step goes back
// half way towards the last usable parameters.
TEST(Fitting, DiscThatDidNotSplitIsNoMeasurement) {
  const Fitting fit(kCard, 0.1);
  BondParams p0 = start();
  p0.model = BondModel::flat_joint;
  BondParams p1 = p0;
  p1.tensile = 0.25 * p0.tensile;
  p1.cohesion = 0.25 * p0.cohesion;
  std::vector<Iteration> hist{made(p0, 18.69e9, 0.18, 30e6, 6e6),
                              made(p1, 18.69e9, 0.18, 50e6, 5e6)};  // the card's numbers
  hist[1].br.r.no_split = true;
  for (auto& it : hist) fit.score(it);
  EXPECT_TRUE(std::isnan(hist[1].measured().tensile));
  EXPECT_FALSE(Fitting::usable(hist[1]));
  EXPECT_FALSE(hist[1].converged);
  EXPECT_EQ(fit.best(hist), 0u);
  std::vector<std::string> notes;
  const BondParams p = fit.update(hist, notes);
  EXPECT_NEAR(p.tensile / (0.5 * p0.tensile), 1.0, 1e-12);
  EXPECT_NE(notes.back().find("iteration 2: no usable response"), std::string::npos)
      << notes.back();
  // On one of three packings: the mean is no measurement either.
  Iteration three = made(p0, 18.69e9, 0.18, 50e6, 5e6);
  three.more = {mill::test::packing_run(2, 18.69e9, 0.18, 50e6, 5e6),
                mill::test::packing_run(3, 18.69e9, 0.18, 50e6, 5e6)};
  fit.score(three);
  EXPECT_TRUE(three.converged);
  three.more[1].br.r.no_split = true;
  fit.score(three);
  EXPECT_TRUE(std::isnan(three.measured().tensile));
  EXPECT_FALSE(three.converged);
}

// A NaN anywhere is unusable too.
TEST(Fitting, NonFiniteResponseIsUnusable) {
  EXPECT_FALSE(Fitting::usable(made(start(), 18e9, NAN, 50e6, 5e6)));
  EXPECT_FALSE(Fitting::usable(made(start(), 18e9, 0.2, 50e6, 0.0)));
  EXPECT_TRUE(Fitting::usable(made(start(), 18e9, 0.7, 50e6, 5e6)));  // nu > 0.5: damage, fittable
}

namespace {

// The parameters the toughness tests' cards are made from: E_b 40 GPa,
// kn/ks 2, sigma_b 4 MPa, c/sigma_b 12.
BondParams truth_params() {
  BondParams p = start();
  p.model = BondModel::flat_joint;
  p.modulus = 40e9;
  p.stiffness_ratio = 2.0;
  p.tensile = 4e6;
  p.cohesion = 12 * 4e6;
  return p;
}

// The sandstone card with its K_IC (0.73 MPa m^0.5) a target.
Targets sandstone_with_toughness() {
  Targets t = kCard;
  t.toughness = 0.73e6;
  return t;
}

// The fit's start with flat joints.
BondParams flat_start() {
  BondParams p = start();
  p.model = BondModel::flat_joint;
  return p;
}

// The card material m gives at those parameters, K_IC included.
Targets card_of(const Material& m) {
  const Iteration card = m.test(truth_params());
  Targets t{card.ucs.r.youngs_modulus, card.ucs.r.poisson_ratio, card.ucs.r.ucs,
            card.br.r.tensile_strength};
  t.toughness = card.scb->toughness;
  return t;
}

}  // namespace

// The toughness as a fifth target (flat joints; docs/calibration.md, "The
// toughness as a target"). A card made by the synthetic material itself at
// known parameters (E_b 40 GPa, kn/ks 2, sigma_b 4 MPa, c/sigma_b 12), so
// that all five targets can be met together: from the start 3-7 x off, the
// fit meets E, nu, UCS, T and K_IC within tolerance in at most 10
// iterations, and reaches the card's sigma_b (within 10 %).
TEST(Fitting, ToughnessTargetPinsTheBondTensileStrength) {
  const Material m{30.0, 0.1};
  const Targets t = card_of(m);
  const Fitting fit(t, 0.1);
  EXPECT_TRUE(fit.fits_toughness());
  BondParams p = start();
  p.model = BondModel::flat_joint;
  const auto hist = run_fit(fit, m, p, 10);
  const Iteration& best = hist[fit.best(hist)];
  EXPECT_TRUE(best.converged) << hist.size() << " iterations, score " << best.score
                              << ", K_IC error " << best.err_kic;
  EXPECT_LE(best.err_kic, 0.1);
  EXPECT_NEAR(best.p.tensile / truth_params().tensile, 1.0, 0.1);
  // The Brazilian test's fit: the softening is no lever (it moves the
  // disc's T as it moves K_IC), held at 1.
  for (const Iteration& it : hist) EXPECT_EQ(it.p.softening, 1.0);
}

// A card whose K_IC/T no brittle joint reaches: made by the synthetic
// material at the parameters above with tension softening lambda 40 (K_IC/T
// x 40^0.3 = 3.0 the brittle material's at those bonds, as the sandstone
// asks of the flat joint: bench/README.md, "Tension softening with the
// direct test"), T read from the direct tension test. From the brittle
// start the fit frees the softening (K_IC a target) and meets all five
// targets within tolerance in at most 12 iterations, with lambda within
// x/÷ 1.5 of the card's. Without K_IC a target the softening never moves.
TEST(Fitting, ToughnessBeyondTheBrittleRatioIsMetBySoftening) {
  const Material m{30.0, 0.1, true};
  BondParams truth = truth_params();
  truth.softening = 40.0;
  const Iteration card_it = m.test(truth);
  Targets t{card_it.ucs.r.youngs_modulus, card_it.ucs.r.poisson_ratio, card_it.ucs.r.ucs,
            card_it.br.r.tensile_strength};
  t.toughness = card_it.scb->toughness;
  t.direct = true;  // T is the direct tension test's (here the material's T)
  t.brazilian = t.tensile;
  const Fitting fit(t, 0.1);
  BondParams p = start();
  p.model = BondModel::flat_joint;
  ASSERT_EQ(p.softening, 1.0);
  const auto hist = run_fit(fit, m, p, 12);
  const Iteration& best = hist[fit.best(hist)];
  EXPECT_TRUE(best.converged) << hist.size() << " iterations, score " << best.score
                              << ", K_IC error " << best.err_kic << ", lambda " << best.p.softening;
  EXPECT_NEAR(std::log(best.p.softening / 40.0), 0.0, std::log(1.5)) << best.p.softening;
  Targets four = t;
  four.toughness = 0;
  for (const Iteration& it : run_fit(Fitting(four, 0.1), m, p, 6)) EXPECT_EQ(it.p.softening, 1.0);
}

// K_IC out of reach at the sigma_b the tensile strength needs (the card's
// K_IC 4 x what the material gives there): the fit never passes quietly:
// not converged, and the K_IC error is what it says it misses.
TEST(Fitting, ToughnessOutOfReachIsNeverAQuietPass) {
  const Material m{30.0, 0.1};
  Targets t = card_of(m);
  t.toughness *= 4.0;
  const Fitting fit(t, 0.1);
  BondParams p = start();
  p.model = BondModel::flat_joint;
  const auto hist = run_fit(fit, m, p, 12);
  for (const auto& it : hist) EXPECT_FALSE(it.converged);
  const Iteration& best = hist[fit.best(hist)];
  EXPECT_GT(best.score, 1.0);
  // Some target is off by more than its tolerance: K_IC, or the strengths
  // that the compromise gave up for it.
  EXPECT_TRUE(best.err_kic > 0.1 || best.err_t > 0.1 || best.err_ucs > 0.1);
}

// An iteration of a toughness fit without its bend test misses K_IC; a fit
// that does not aim at K_IC ignores a bend test that ran (its step is the
// same with and without it).
TEST(Fitting, ToughnessCountsOnlyWhenItIsATarget) {
  const Fitting with(sandstone_with_toughness(), 0.1), without(kCard, 0.1);
  const BondParams p = flat_start();
  Iteration it = made(p, 18.69e9, 0.18, 50e6, 5e6);
  with.score(it);
  EXPECT_FALSE(it.converged) << "no bend test: K_IC is not met";
  without.score(it);
  EXPECT_TRUE(it.converged);
  Iteration a = made(p, 15e9, 0.25, 30e6, 4e6), b = a;
  b.scb.emplace();
  b.scb->toughness = 0.1e6;
  without.score(a);
  without.score(b);
  std::vector<std::string> notes;
  const BondParams pa = without.update({a}, notes), pb = without.update({b}, notes);
  EXPECT_EQ(pa.modulus, pb.modulus);
  EXPECT_EQ(pa.stiffness_ratio, pb.stiffness_ratio);
  EXPECT_EQ(pa.tensile, pb.tensile);
  EXPECT_EQ(pa.cohesion, pb.cohesion);
  // With K_IC a target and measured 7 x low, the step raises sigma_b.
  with.score(b);
  const BondParams pk = with.update({b}, notes);
  EXPECT_GT(pk.tensile, pb.tensile);
}

// The toughness fit keeps the best compromise, not the most targets met
// (measured: the 3344-element specimens' iterations 2 and 3,
// bench/README.md, "The toughness as a target of the fit"): iteration 2
// meets E, nu and the UCS and misses T by 104 % and K_IC by 37 %; iteration
// 3 meets E and nu and misses the UCS by 29 %, T by 38 %, K_IC by 31 %. The
// squared errors in tolerance units sum to 81 and 39: iteration 3 is kept.
// The four-target fit keeps iteration 2 (three met against two). An
// iteration that meets every target wins over both; an unusable one never.
TEST(Fitting, ToughnessFitKeepsTheBestCompromise) {
  const Fitting with(sandstone_with_toughness(), 0.1), without(kCard, 0.1);
  const BondParams p = flat_start();
  auto it_of = [&](double E, double nu, double ucs, double T, double kic) {
    Iteration it = made(p, E, nu, ucs, T);
    it.scb.emplace();
    it.scb->toughness = kic;
    return it;
  };
  std::vector<Iteration> hist{it_of(20.34e9, 0.1386, 50.64e6, 10.20e6, 0.460e6),
                              it_of(18.52e9, 0.1537, 35.59e6, 6.90e6, 0.506e6)};
  for (auto& it : hist) with.score(it);
  EXPECT_EQ(with.best(hist), 1u);
  std::vector<Iteration> four = hist;
  for (auto& it : four) without.score(it);
  EXPECT_EQ(without.best(four), 0u);
  // Every target met: kept whatever the others' sums.
  hist.push_back(it_of(18.9e9, 0.17, 47e6, 5.3e6, 0.70e6));
  with.score(hist.back());
  ASSERT_TRUE(hist.back().converged);
  EXPECT_EQ(with.best(hist), 2u);
  // An unusable iteration (negative modulus) is never kept.
  std::vector<Iteration> bad{it_of(-1e9, 0.18, 50e6, 5e6, 0.73e6), hist[1]};
  for (auto& it : bad) with.score(it);
  EXPECT_EQ(with.best(bad), 1u);
}

// calibrate.tensile_test direct: the fit reads the direct tension test's
// strength (the pulled cylinder's peak, UcsRun::r.ucs), not the Brazilian
// disc's, which then is a check: a model whose disc reads twice the card
// converges on its direct strength, a disc that did not split leaves the
// iteration usable, and the mean over packings is the direct tests' mean.
TEST(Fitting, DirectTensionIsTheFittedTensileStrength) {
  Targets card{18.69e9, 0.18, 50e6, 3.5e6};  // the sandstone's direct: 0.7 x 5 MPa
  card.direct = true;
  card.brazilian = 5e6;
  const Fitting fit(card, 0.1);
  BondParams p0 = start();
  p0.model = BondModel::flat_joint;
  Iteration it = made(p0, 18.69e9, 0.18, 50e6, 11e6);  // the disc: 11 MPa
  it.tension.emplace();
  it.tension->r.ucs = 3.6e6;
  it.br.r.no_split = true;
  fit.score(it);
  EXPECT_DOUBLE_EQ(it.measured().tensile, 3.6e6);
  EXPECT_TRUE(Fitting::usable(it));
  EXPECT_TRUE(it.converged) << it.score;
  // Three packings: the mean of the direct tests, 3.2, 3.5 and 4.4 MPa.
  it.more = {mill::test::packing_run(2, 18.69e9, 0.18, 50e6, 1e6),
             mill::test::packing_run(3, 18.69e9, 0.18, 50e6, 1e6)};
  it.tension->r.ucs = 3.2e6;
  it.more[0].tension.emplace();
  it.more[0].tension->r.ucs = 3.5e6;
  it.more[1].tension.emplace();
  it.more[1].tension->r.ucs = 4.4e6;
  fit.score(it);
  EXPECT_NEAR(it.measured().tensile, 3.7e6, 1e-6);
  EXPECT_NEAR(it.err_t, 0.2 / 3.5, 1e-12);
  EXPECT_TRUE(it.converged);
  // The prior's tensile row: the direct test follows sigma_b alone.
  EXPECT_EQ(flat_joint_prior(true).J0[3][3], 0.0);
  EXPECT_EQ(flat_joint_prior(true).J0[3][2], 1.0);
  EXPECT_GT(flat_joint_prior(false).J0[3][3], 0.5);
}

// A synthetic flat-joint material whose direct tensile strength follows the
// bond tensile strength alone and whose UCS follows the cohesion (the
// measured pattern, bench/README.md, "The direct tension test"), fitted to
// the sandstone's UCS / direct tensile strength of 14.3 from the
// closed-form start: within tolerance in at most 8 iterations.
TEST(Fitting, JointStepConvergesOnADirectTensionMaterial) {
  Targets card{18.69e9, 0.18, 50e6, 3.5e6};
  card.direct = true;
  card.brazilian = 5e6;
  const Fitting fit(card, 0.1);
  auto test = [](const BondParams& p) {
    const double le = std::log(p.modulus), lk = std::log(p.stiffness_ratio),
                 ls = std::log(p.tensile), lc = std::log(p.cohesion);
    Iteration it;
    it.p = p;
    it.ucs.r.youngs_modulus = 0.35 * std::exp(0.93 * le - 0.25 * lk);
    it.ucs.r.poisson_ratio = 0.06 + 0.13 * lk;
    it.ucs.r.ucs = std::exp(0.8 * lc + 0.2 * ls + 0.4);
    it.br.r.tensile_strength = 3.0 * p.tensile;  // the disc: a check, not fitted
    it.tension.emplace();
    it.tension->r.ucs = 1.02 * p.tensile;
    return it;
  };
  BondParams p = start();
  p.model = BondModel::flat_joint;
  p.modulus = 2.0 * 18.69e9;
  p.tensile = 0.8 * 5e6;
  p.cohesion = 10.0 * p.tensile;
  std::vector<Iteration> hist;
  std::vector<std::string> notes;
  for (int k = 0; k < 8; ++k) {
    hist.push_back(test(p));
    fit.score(hist.back());
    if (hist.back().converged) break;
    p = fit.update(hist, notes);
  }
  const Measured m = hist.back().measured();
  EXPECT_TRUE(hist.back().converged) << hist.size() << " iterations, score " << hist.back().score
                                     << ", UCS/T " << m.ucs / m.tensile;
}
