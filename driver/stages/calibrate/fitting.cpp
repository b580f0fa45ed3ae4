// The calibrate stage's fitting scheme: score, update, best iteration.
#include "stages/calibrate/fitting.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "postprocess/lab_tests.h"
#include "stages/calibrate/local_model.h"

namespace mill::calibrate {

namespace {

// The mean of one response over the packings; NaN when a packing's is not
// finite (or, for a modulus or strength, not > 0): a failed test leaves the
// mean unusable (Fitting::usable), as it leaves a single test.
double mean_of(const std::vector<double>& v, bool positive) {
  double sum = 0;
  for (double x : v) {
    if (!std::isfinite(x) || (positive && x <= 0)) return std::numeric_limits<double>::quiet_NaN();
    sum += x;
  }
  return sum / static_cast<double>(v.size());
}

// A Brazilian test's tensile strength, NaN when the disc did not split (its
// largest load is a crushed disc's, post::kBrazilianSplitFraction): no
// model can use it, so the fit steps back (Fitting::update).
double tensile_of(const BrazilianRun& b) {
  return b.r.no_split ? std::numeric_limits<double>::quiet_NaN() : b.r.tensile_strength;
}

// The tensile strength the fit reads from one packing: the direct tension
// test's peak when it ran (calibrate.tensile_test direct), else the
// Brazilian disc's.
double tensile_of(const BrazilianRun& b, const std::optional<UcsRun>& tension) {
  return tension ? tension->r.ucs : tensile_of(b);
}

}  // namespace

// The arithmetic means over the packings: a lab's reading of several
// specimens. With one packing its own values, whatever they are, but for
// the tensile strength of a disc that did not split.
Measured Iteration::measured() const {
  if (more.empty())
    return {ucs.r.youngs_modulus, ucs.r.poisson_ratio, ucs.r.ucs, tensile_of(br, tension)};
  std::vector<double> E{ucs.r.youngs_modulus}, nu{ucs.r.poisson_ratio}, u{ucs.r.ucs},
      t{tensile_of(br, tension)};
  for (const PackingRun& r : more) {
    E.push_back(r.ucs.r.youngs_modulus);
    nu.push_back(r.ucs.r.poisson_ratio);
    u.push_back(r.ucs.r.ucs);
    t.push_back(tensile_of(r.br, r.tension));
  }
  return {mean_of(E, true), mean_of(nu, false), mean_of(u, true), mean_of(t, true)};
}

double brazilian_mean(const Iteration& it) {
  double sum = tensile_of(it.br);
  for (const PackingRun& r : it.more) sum += tensile_of(r.br);
  return sum / static_cast<double>(it.more.size() + 1);
}

double Iteration::more_seconds() const {
  double s = 0;
  for (const PackingRun& r : more)
    s += r.ucs.seconds + r.br.seconds + (r.tension ? r.tension->seconds : 0.0);
  return s;
}

// Errors of one iteration against the ore card and whether all are met.
void Fitting::score(Iteration& it) const {
  const Measured m = it.measured();
  it.err_E = post::RelativeError(m.E, t_.E);
  it.err_ucs = post::RelativeError(m.ucs, t_.ucs);
  it.err_t = post::RelativeError(m.tensile, t_.tensile);
  it.err_nu = std::abs(m.nu - t_.nu);
  // K_IC: a target only with the toughness fit; an iteration without its
  // bend test then misses it.
  it.err_kic = !fits_toughness() ? 0.0
               : it.scb          ? post::RelativeError(it.scb->toughness, t_.toughness)
                                 : 1e300;
  it.score = std::max({it.err_E / tol_, it.err_ucs / tol_, it.err_t / tol_,
                       it.err_nu / kNuTolerance, it.err_kic / tol_});
  // A NaN response (a disc that did not split) is no measurement: never
  // within tolerance, whatever the others say (std::max skips a NaN).
  if (!usable(it)) it.score = std::numeric_limits<double>::infinity();
  it.converged = it.score <= 1.0;
}

namespace {

// The continuous parameters in log space (local_model.h).
ParamVec params_of(const BondParams& p) {
  return {std::log(p.modulus), std::log(p.stiffness_ratio), std::log(p.tensile),
          std::log(p.cohesion / p.tensile), std::log(p.softening)};
}

// The responses of an iteration (local_model.h): the four macro targets
// and ln K_IC (0 without a bend test: then not a target, weight 0).
FitVec responses_of(const Iteration& it) {
  const Measured m = it.measured();
  return {std::log(m.E), m.nu, std::log(m.ucs), std::log(m.tensile),
          it.scb ? std::log(it.scb->toughness) : 0.0};
}

// True when two iterations were made with the same coarse levers (moment
// factor, friction angle): the same response curves.
bool same_levers(const BondParams& a, const BondParams& b) {
  return a.moment_factor == b.moment_factor && a.friction_angle_deg == b.friction_angle_deg;
}

}  // namespace

LocalModelPrior flat_joint_prior(bool direct) {
  LocalModelPrior m;
  // Rows: ln E, nu, ln UCS, ln T; columns: ln E_b, ln kn/ks, ln sigma_b,
  // ln c/sigma_b. Measured: the lever sensitivities of the sandstone's
  // flat-joint calibration (default specimens, bond gap 1.0; the table in
  // docs/calibration.md, "Fitting scheme"; the fit it gives: bench/README.md,
  // "The joint step of the fit (flat joint)"), each stepped x 1.2 alone
  // from the result, converted from (ln sigma_b, ln c) to (ln sigma_b,
  // ln c/sigma_b): the sigma_b column is the sum of both (sigma_b and c
  // together x k), the ratio column the cohesion's. Scale invariance of a
  // linear-elastic brittle packing says the strengths' sigma_b column is 1
  // (sigma_b and c together x k give both strengths x k): measured 1.00 and
  // 1.04. nu moves with kn/ks (0.9 per e-fold at kn/ks 1.8: far more than
  // the parallel bond's 0.1) and, through the damage before half the peak,
  // with the strengths.
  // The toughness row (ln K_IC, from the semi-circular bend test), measured
  // on the same specimens from the joint-step fit's result (bench/README.md,
  // "The toughness as a target of the fit"): K_IC follows sigma_b (slope
  // 0.97 over sigma_b x 5 with c fixed; c/sigma_b 5.6 -> 2 at the same
  // sigma_b changed it by 0.0 %; E_b x 1.2 by 0.0 %) and falls with kn/ks
  // (-0.5: x 1.2 gave -9 %): the notch opens in tension, and a sigma_b
  // column of 1 is scale invariance again.
  m.J0 = {{{0.96, -0.67, 0.0, -0.15},
           {0.08, 0.9, -0.09, 0.26},
           {0.24, -0.09, 1.0, 1.0},
           {-0.02, -0.09, 1.0, 0.67},
           {0.0, -0.5, 1.0, 0.0}}};
  // The direct tension test (calibrate.tensile_test direct) opens the
  // interfaces of one cross-section in tension: its strength follows
  // sigma_b alone. Measured on the flat joint's mean fit (three packings'
  // first ball, bond gap 1.4; bench/README.md, "The direct tension test"):
  // sigma_b 0.34 -> 3.5 MPa gave 0.36 -> 3.49 MPa, and c x 2 at sigma_b 3.5
  // MPa left it at 3.49 MPa (the UCS x 1.76).
  if (direct) m.J0[3] = {-0.02, -0.09, 1.0, 0.0};
  // The fifth column, ln lambda (the tension softening, free only when K_IC
  // is a target): measured on the direct fit's first packing (bench/README.md,
  // "Tension softening with the direct test": lambda 1 -> 4 -> 10 -> 30 at
  // fixed bonds): the toughness rises 0.46-0.60 per e-fold, the direct
  // strength 0.42-0.48 up to lambda 10 and 0.21 above it (the cylinder's
  // strength saturates where every element of a section softens before it
  // breaks: the ratio K_IC/T the lever moves), the UCS 0.15-0.19, E and nu
  // within their noise; the Brazilian disc's strength 0.33 (lambda 1 -> 4
  // and -> 20, "Tension softening as a lever for K_IC/T").
  for (size_t i = 0; i < kFitResponses; ++i) m.J0[i][4] = 0.0;
  m.J0[2][4] = 0.17;
  m.J0[3][4] = direct ? 0.35 : 0.33;
  m.J0[4][4] = 0.55;
  // What the measured slopes may become: each diagonal slope keeps the sign
  // physics gives it, each coupling a bounded size.
  m.lo = {{{0.5, -1.5, -0.5, -0.5, -0.2},
           {-0.2, 0.05, -0.6, -0.6, -0.2},
           {-0.5, -1.0, 0.3, -0.2, 0.0},
           {-0.5, -1.0, 0.3, -0.2, 0.0},
           {-0.5, -1.0, 0.3, -0.5, 0.2}}};
  m.hi = {{{1.5, 0.5, 0.5, 0.5, 0.2},
           {0.2, 1.5, 0.6, 0.6, 0.2},
           {0.5, 1.0, 2.0, 2.0, 0.5},
           {0.5, 1.0, 2.0, 2.0, 0.8},
           {0.5, 1.0, 2.0, 0.5, 1.0}}};
  // Trust region per iteration: x/÷ 4, e^0.7, 16 and 3 (the secants' caps);
  // the softening x/÷ 8 (from brittle, the card's toughness can ask for
  // lambda near 100: three steps).
  m.max_step = {std::log(4.0), 0.7, std::log(16.0), std::log(3.0), std::log(8.0)};
  return m;
}

// The flat joint's next parameters: one damped Gauss-Newton step of its
// continuous parameters (the softening only when K_IC is a target with the
// direct test) on the local linear model of the iterations so far
// (local_model.h). A flat joint has no coarse lever (its elements
// carry the moments whole; its friction angle is also its broken elements'
// friction).
BondParams Fitting::joint_update(const std::vector<Iteration>& hist,
                                 std::vector<std::string>& notes) const {
  const Iteration& now = hist.back();
  BondParams p = now.p;
  const double want = t_.ucs / t_.tensile;
  const Measured m = now.measured();
  const double have = m.ucs / m.tensile;
  // The local model from the last kModelPoints iterations (far points bend
  // a linear model).
  std::vector<ModelPointN<kFitResponses>> pts;
  for (size_t k = hist.size(); k-- > 0 && pts.size() < kModelPoints;) {
    if (!same_levers(hist[k].p, now.p) || !same_model(hist[k].p, now.p)) break;  // a start from elsewhere
    pts.insert(pts.begin(), {params_of(hist[k].p), responses_of(hist[k])});
  }
  const LocalModelPrior prior = flat_joint_prior(t_.direct);
  const FitMat J = estimate_jacobian(pts, prior.J0, kRidge, prior.lo, prior.hi);
  const ParamVec u = params_of(now.p);
  const FitVec y = responses_of(now);
  // The toughness row counts only when K_IC is a target (and measured).
  const bool kic = fits_toughness() && now.scb.has_value();
  const FitVec e{std::log(t_.E) - y[0], t_.nu - y[1], std::log(t_.ucs) - y[2],
                 std::log(t_.tensile) - y[3], kic ? std::log(t_.toughness) - y[4] : 0.0};
  const double w = 1.0 / std::log1p(tol_);
  StepRuleN<kFitResponses> rule;
  rule.weight = {w, 1.0 / kNuTolerance, w, w, kic ? w : 0.0};
  rule.mu = kDamping;
  // Damping scale per parameter: its prior slope on the target it moves
  // most, in tolerance units (the ratio's: the UCS's slope over the
  // tensile's), so that the damping shortens each Newton step alike.
  // The softening's: its slope on K_IC over T (the ratio it moves).
  rule.scale = {w * prior.J0[0][0], prior.J0[1][1] / kNuTolerance, w * prior.J0[3][2],
                w * (prior.J0[2][3] - prior.J0[3][3]), w * (prior.J0[4][4] - prior.J0[3][4])};
  rule.max_step = prior.max_step;
  rule.lower = {-1e300, std::log(kMinStiffnessRatio), -1e300, std::log(kMinCohesionRatio), 0.0};
  rule.upper = {1e300, std::log(kMaxStiffnessRatio), 1e300, std::log(kMaxCohesionRatio),
                std::log(kMaxSoftening)};
  // The tension softening moves only when K_IC is a target and the tensile
  // strength is the direct test's: with the four targets it is no lever (it
  // would trade the toughness no one asked for against nothing), and on the
  // Brazilian disc it moves T as it moves K_IC (slopes 0.33 and 0.37 per
  // e-fold, bench/README.md, "Tension softening as a lever for K_IC/T"),
  // not their ratio: sigma_b's work again. It stays where the calibration
  // started it (1, brittle).
  rule.free[4] = kic && t_.direct ? 1.0 : 0.0;
  ParamVec du = damped_step(J, e, u, rule);
  // Both strengths still off after the predicted step: the ratio is out of
  // the levers' reach in one step (the step cap, the cohesion cap or a
  // ratio that no longer rises). The cohesion ratio keeps its step; the
  // other parameters are re-solved with the tensile strength first (it sets
  // where an impact fractures); the UCS takes what is left.
  const FitVec dy = predict(J, du);
  const double tol_log = std::log1p(tol_);
  if (std::abs(e[2] - dy[2]) > tol_log && std::abs(e[3] - dy[3]) > tol_log) {
    rule.weight[2] = kUcsWeightOutOfReach * w;
    rule.free[3] = 0.0;
    rule.held[3] = du[3];
    du = damped_step(J, e, u, rule);
    notes.push_back(fmt::format(
        "iteration {}: UCS/tensile {:.2f} (card {:.1f}) out of the levers' reach in one step: "
        "cohesion ratio x {:.3g}, the tensile strength first",
        hist.size(), have, want, std::exp(du[3])));
  }
  p.modulus = std::exp(u[0] + du[0]);
  p.stiffness_ratio = std::exp(u[1] + du[1]);
  p.tensile = std::exp(u[2] + du[2]);
  const double ratio = std::exp(u[3] + du[3]);
  if (ratio >= kMaxCohesionRatio * (1.0 - 1e-12))
    notes.push_back(
        fmt::format("cohesion capped at {:g} x the bond tensile strength", kMaxCohesionRatio));
  p.cohesion = ratio * p.tensile;
  if (du[4] != 0.0) {  // held: exactly as it was
    p.softening = std::exp(u[4] + du[4]);
    notes.push_back(fmt::format("iteration {}: tension softening {:.3g} -> {:.3g}", hist.size(),
                                now.p.softening, p.softening));
  }
  p.origin = "calibrate iteration " + std::to_string(hist.size() + 1);
  return p;
}

// The parallel bond's next parameters: one damped log-space secant step per parameter,
// each driven by its own macro property (bond modulus -> E, stiffness ratio
// -> nu, bond tensile strength -> Brazilian strength), all from the same
// pair of tests, and one UCS/tensile lever (moment factor, friction angle,
// cohesion ratio) once E and the tensile strength are met.
BondParams Fitting::secant_update(const std::vector<Iteration>& hist,
                                  std::vector<std::string>& notes) const {
  const Iteration& now = hist.back();
  const Iteration* prev = hist.size() > 1 ? &hist[hist.size() - 2] : nullptr;
  // A lever move (moment factor, friction angle) changes every response
  // curve: no secant through an iteration made before it.
  if (prev && (prev->p.moment_factor != now.p.moment_factor ||
               prev->p.friction_angle_deg != now.p.friction_angle_deg))
    prev = nullptr;
  auto pt = [](double x, double y) { return post::SecantPoint{x, y}; };
  auto prev_pt = [&](double x, double y) -> std::optional<post::SecantPoint> { return pt(x, y); };
  const Measured m = now.measured();
  const Measured mp = prev ? prev->measured() : Measured{};  // read only when prev
  BondParams p = now.p;
  // E scales with the bond modulus (all bond springs do), so the slope is near 1.
  const post::SecantRule e_rule{true, 1.0, 0.5, 1.5, std::log(4.0)};
  // nu rises with kn/ks; about +0.1 per e-fold at these ratios (first guess).
  const post::SecantRule nu_rule{false, 0.1, 0.02, 0.5, 0.7};
  // Strengths scale with bond strengths when the failure mode stays the same
  // (the closed-form start can be an order of magnitude off: wide cap).
  const post::SecantRule s_rule{true, 1.0, 0.3, 2.0, std::log(16.0)};
  p.modulus = post::SecantUpdate(e_rule, pt(now.p.modulus, m.E),
                                 prev ? prev_pt(prev->p.modulus, mp.E) : std::nullopt, t_.E)
                  .x_new;
  p.stiffness_ratio = std::clamp(
      post::SecantUpdate(nu_rule, pt(now.p.stiffness_ratio, m.nu),
                         prev ? prev_pt(prev->p.stiffness_ratio, mp.nu) : std::nullopt, t_.nu)
          .x_new,
      0.5, 20.0);
  p.tensile =
      post::SecantUpdate(s_rule, pt(now.p.tensile, m.tensile),
                         prev ? prev_pt(prev->p.tensile, mp.tensile) : std::nullopt, t_.tensile)
          .x_new;
  // The UCS/tensile ratio: once E and the tensile strength are within
  // tolerance (most sensitive first), one lever per iteration, in the order
  // the levers were measured to raise the ratio (bench/README.md, "Rock
  // strength levers"): the moment factor 1 -> 0 (bending no longer counts
  // towards failure; Potyondy 2015), then the friction angle to
  // kMaxFrictionAngle (the Mohr-Coulomb strength rises with compression and
  // falls with tension), then damped secant steps on the cohesion ratio
  // c / sigma_b (the tensile lever moves both strengths). A ratio above the
  // card's, or within kCoarseLeverGap below it, moves only the cohesion.
  const double ratio_now = now.p.cohesion / now.p.tensile;
  double ratio = ratio_now;
  const double want = t_.ucs / t_.tensile;
  const double have = m.ucs / m.tensile;
  if (now.err_E <= tol_ && now.err_t <= tol_ && post::RelativeError(have, want) > tol_) {
    // The moment factor and friction-angle moves are coarse (each raised the
    // ratio by ~20 %): used only for a gap larger than that, else the cohesion.
    const bool far_below = have * kCoarseLeverGap < want;
    if (far_below && p.moment_factor > 0.0) {
      p.moment_factor = 0.0;
      notes.push_back(
          fmt::format("iteration {}: UCS/tensile {:.2f} (card {:.1f}): moment factor {:g} -> 0",
                      hist.size(), have, want, now.p.moment_factor));
    } else if (far_below && p.friction_angle_deg < kMaxFrictionAngle) {
      p.friction_angle_deg = kMaxFrictionAngle;
      notes.push_back(fmt::format(
          "iteration {}: UCS/tensile {:.2f} (card {:.1f}): bond friction angle {:g} -> {:g} deg",
          hist.size(), have, want, now.p.friction_angle_deg, kMaxFrictionAngle));
    } else {
      // The ratio's slope in log space: about 1 for the parallel bond.
      const post::SecantRule c_rule{true, 1.0, 0.5, 2.0, std::log(2.0)};
      const bool prev_moved =
          prev && std::abs(std::log(prev->p.cohesion / prev->p.tensile / ratio_now)) > 1e-6;
      ratio = post::SecantUpdate(
                  c_rule, pt(ratio_now, have),
                  prev_moved ? prev_pt(prev->p.cohesion / prev->p.tensile, mp.ucs / mp.tensile)
                             : std::nullopt,
                  want)
                  .x_new;
    }
  }
  if (ratio > kMaxCohesionRatio) {
    ratio = kMaxCohesionRatio;
    notes.push_back(
        fmt::format("cohesion capped at {:g} x the bond tensile strength", kMaxCohesionRatio));
  }
  p.cohesion = ratio * p.tensile;
  p.origin = "calibrate iteration " + std::to_string(hist.size() + 1);
  return p;
}

// Next micro parameters: the parallel bond's secant steps, the flat joint's
// joint step (docs/calibration.md, "Fitting scheme": measured, the joint
// step wandered on the parallel bond, whose failure mode switches with its
// levers).
BondParams Fitting::update(const std::vector<Iteration>& hist,
                           std::vector<std::string>& notes) const {
  std::vector<Iteration> good;
  for (const auto& it : hist)
    if (usable(it)) good.push_back(it);
  const Iteration& last = hist.back();
  const Measured lm = last.measured();
  if (!usable(last)) {
    // A response no model can use: step back half way (in log space) from
    // this iteration's parameters towards the last usable iteration's, with
    // that iteration's coarse levers; a line search of the step that failed.
    if (good.empty())
      throw std::runtime_error(fmt::format(
          "iteration {}: the specimens gave no usable response (E {:.3g} GPa, nu {:.3g}, UCS "
          "{:.3g} MPa, tensile {:.3g} MPa) and no earlier iteration did: the fit has nothing to "
          "step back to; start from other bond parameters (calibrate.starts, or the ore card's "
          "calibrated: section)",
          hist.size(), lm.E / 1e9, lm.nu, lm.ucs / 1e6, lm.tensile / 1e6));
    const BondParams& g = good.back().p;
    BondParams p = g;
    // Halfway from the failed parameters towards the last usable ones: a
    // second failure in a row halves the step again.
    const BondParams& b = last.p;
    p.modulus = std::sqrt(g.modulus * b.modulus);
    p.stiffness_ratio = std::sqrt(g.stiffness_ratio * b.stiffness_ratio);
    p.tensile = std::sqrt(g.tensile * b.tensile);
    p.cohesion = std::sqrt(g.cohesion * b.cohesion);
    p.softening = std::sqrt(g.softening * b.softening);
    p.origin = "calibrate iteration " + std::to_string(hist.size() + 1);
    notes.push_back(fmt::format(
        "iteration {}: no usable response (E {:.3g} GPa, UCS {:.3g} MPa, tensile {:.3g} MPa): "
        "stepped back half way towards the parameters of the last usable iteration",
        hist.size(), lm.E / 1e9, lm.ucs / 1e6, lm.tensile / 1e6));
    return p;
  }
  // The steps see the usable iterations only (their notes count those).
  BondParams p = last.p.model == BondModel::flat_joint ? joint_update(good, notes)
                                                       : secant_update(good, notes);
  p.origin = "calibrate iteration " + std::to_string(hist.size() + 1);
  return p;
}

bool Fitting::usable(const Iteration& it) {
  const Measured m = it.measured();
  const double E = m.E, nu = m.nu, ucs = m.ucs, t = m.tensile;
  const double k = it.scb ? it.scb->toughness : 1.0;
  return std::isfinite(E) && std::isfinite(nu) && std::isfinite(ucs) && std::isfinite(t) &&
         std::isfinite(k) && E > 0 && ucs > 0 && t > 0 && k > 0;
}

// The best iteration: most targets within tolerance, then the smallest
// worst error (in tolerance units): an unreachable target must not hide
// the iteration that meets the others.
size_t Fitting::best(const std::vector<Iteration>& hist) const {
  if (fits_toughness()) return best_compromise(hist);
  auto met = [&](const Iteration& it) {
    return (it.err_E <= tol_) + (it.err_ucs <= tol_) + (it.err_t <= tol_) +
           (it.err_nu <= kNuTolerance) + (fits_toughness() && it.err_kic <= tol_);
  };
  // Unusable iterations (a NaN response) are never kept while another is.
  size_t best = 0;
  while (best + 1 < hist.size() && !usable(hist[best])) ++best;
  for (size_t i = best + 1; i < hist.size(); ++i)
    if (usable(hist[i]) && (met(hist[i]) > met(hist[best]) ||
                            (met(hist[i]) == met(hist[best]) && hist[i].score < hist[best].score)))
      best = i;
  return best;
}

// With the toughness a target the five targets can pull against each other
// (docs/calibration.md, "The toughness as a target"), and counting the
// targets met keeps an iteration that meets three and misses the tensile
// strength by 104 % (measured, 3344-element specimens) over one that misses
// three by 20-40 %. Kept instead: an iteration that meets every target (the
// smallest worst error), else the smallest sum of the squared errors in
// tolerance units, the objective the joint step minimises
// (ln(achieved / target) / ln(1 + tolerance) for E, UCS, T and K_IC, the
// difference / 0.05 for nu). Unusable iterations are never kept.
size_t Fitting::best_compromise(const std::vector<Iteration>& hist) const {
  const double w = 1.0 / std::log1p(tol_);
  auto objective = [&](const Iteration& it) {
    auto sq = [&](double achieved, double target) {
      const double e = w * std::log(achieved / target);
      return e * e;
    };
    const Measured m = it.measured();
    const double nu = (m.nu - t_.nu) / kNuTolerance;
    return sq(m.E, t_.E) + sq(m.ucs, t_.ucs) + sq(m.tensile, t_.tensile) +
           (it.scb ? sq(it.scb->toughness, t_.toughness) : 1e300) + nu * nu;
  };
  size_t best = 0;
  bool have = false, met = false;
  double best_value = 0.0;
  for (size_t i = 0; i < hist.size(); ++i) {
    if (!usable(hist[i])) continue;
    const bool conv = hist[i].converged;
    const double value = conv ? hist[i].score : objective(hist[i]);
    if (!have || (conv && !met) || (conv == met && value < best_value)) {
      best = i;
      best_value = value;
      have = true;
      met = conv;
    }
  }
  return best;
}

}  // namespace mill::calibrate
