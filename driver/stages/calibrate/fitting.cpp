// The calibrate stage's fitting scheme: score, update, best iteration.
#include "stages/calibrate/fitting.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "postprocess/lab_tests.h"

namespace mill::calibrate {

// Errors of one iteration against the ore card and whether all are met.
void Fitting::score(Iteration& it) const {
  it.err_E = post::RelativeError(it.ucs.r.youngs_modulus, t_.E);
  it.err_ucs = post::RelativeError(it.ucs.r.ucs, t_.ucs);
  it.err_t = post::RelativeError(it.br.r.tensile_strength, t_.tensile);
  it.err_nu = std::abs(it.ucs.r.poisson_ratio - t_.nu);
  it.score =
      std::max({it.err_E / tol_, it.err_ucs / tol_, it.err_t / tol_, it.err_nu / kNuTolerance});
  it.converged = it.score <= 1.0;
}

// Next micro parameters: one damped log-space secant step per parameter,
// each driven by its own macro property (bond modulus -> E, stiffness ratio
// -> nu, bond tensile strength -> Brazilian strength), all from the same
// pair of tests, and one UCS/tensile lever (moment factor, friction angle,
// cohesion ratio) once E and the tensile strength are met.
BondParams Fitting::update(const std::vector<Iteration>& hist,
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
  BondParams p = now.p;
  // E scales with the bond modulus (all bond springs do), so the slope is near 1.
  const post::SecantRule e_rule{true, 1.0, 0.5, 1.5, std::log(4.0)};
  // nu rises with kn/ks; about +0.1 per e-fold at these ratios (first guess).
  const post::SecantRule nu_rule{false, 0.1, 0.02, 0.5, 0.7};
  // Strengths scale with bond strengths when the failure mode stays the same
  // (the closed-form start can be an order of magnitude off: wide cap).
  const post::SecantRule s_rule{true, 1.0, 0.3, 2.0, std::log(16.0)};
  p.modulus = post::SecantUpdate(
                  e_rule, pt(now.p.modulus, now.ucs.r.youngs_modulus),
                  prev ? prev_pt(prev->p.modulus, prev->ucs.r.youngs_modulus) : std::nullopt, t_.E)
                  .x_new;
  p.stiffness_ratio = std::clamp(
      post::SecantUpdate(
          nu_rule, pt(now.p.stiffness_ratio, now.ucs.r.poisson_ratio),
          prev ? prev_pt(prev->p.stiffness_ratio, prev->ucs.r.poisson_ratio) : std::nullopt, t_.nu)
          .x_new,
      0.5, 20.0);
  p.tensile =
      post::SecantUpdate(
          s_rule, pt(now.p.tensile, now.br.r.tensile_strength),
          prev ? prev_pt(prev->p.tensile, prev->br.r.tensile_strength) : std::nullopt, t_.tensile)
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
  const double have = now.ucs.r.ucs / now.br.r.tensile_strength;
  if (now.err_E <= tol_ && now.err_t <= tol_ && post::RelativeError(have, want) > tol_) {
    // The moment factor and friction-angle moves are coarse (each raised the
    // ratio by ~20 %): used only for a gap larger than that, else the cohesion.
    // A flat joint has neither coarse lever: its elements carry the moments
    // whole, and its friction angle is also its broken elements' friction;
    // its lever is the cohesion (bench/README.md, "Strength ratio:
    // coordination and cohesion with the flat joint").
    const bool far_below =
        have * kCoarseLeverGap < want && now.p.model == BondModel::parallel;
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
      // The ratio's slope in log space: about 1 for the parallel bond; 0.35-0.56
      // for the flat joint at coordination 10 (c/sigma_c 5 -> 10 -> 20 gave
      // 7.59 -> 9.68 -> 14.27; bench/README.md), so a wider step there.
      const bool fj = now.p.model == BondModel::flat_joint;
      const post::SecantRule c_rule{true, fj ? 0.5 : 1.0, fj ? 0.25 : 0.5, 2.0,
                                    std::log(fj ? 3.0 : 2.0)};
      const bool prev_moved =
          prev && std::abs(std::log(prev->p.cohesion / prev->p.tensile / ratio_now)) > 1e-6;
      ratio = post::SecantUpdate(c_rule, pt(ratio_now, have),
                                 prev_moved ? prev_pt(prev->p.cohesion / prev->p.tensile,
                                                      prev->ucs.r.ucs / prev->br.r.tensile_strength)
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

// The best iteration: most targets within tolerance, then the smallest
// worst error (in tolerance units): an unreachable target must not hide
// the iteration that meets the others.
size_t Fitting::best(const std::vector<Iteration>& hist) const {
  auto met = [&](const Iteration& it) {
    return (it.err_E <= tol_) + (it.err_ucs <= tol_) + (it.err_t <= tol_) +
           (it.err_nu <= kNuTolerance);
  };
  size_t best = 0;
  for (size_t i = 1; i < hist.size(); ++i)
    if (met(hist[i]) > met(hist[best]) ||
        (met(hist[i]) == met(hist[best]) && hist[i].score < hist[best].score))
      best = i;
  return best;
}

}  // namespace mill::calibrate
