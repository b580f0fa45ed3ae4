// The fitting scheme of the calibrate stage (docs/calibration.md, "Fitting
// scheme"): the errors of an iteration against the ore card, the next bond
// parameters (a damped Gauss-Newton step on a local linear model), and the iteration kept
// as the result. A change here changes what a calibration gives: bump
// kDeckVersion in calibrate_stage.cpp.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "lump/material.h"
#include "stages/calibrate/lab_runs.h"
#include "stages/calibrate/local_model.h"

namespace mill::calibrate {

// Tolerance on Poisson's ratio (absolute).
inline constexpr double kNuTolerance = 0.05;
// Cap on cohesion / bond tensile strength (the last UCS/tensile lever).
inline constexpr double kMaxCohesionRatio = 50.0;
// Friction angle the UCS/tensile lever raises the bond's to [deg]: tan 60 =
// 1.73; above it tau_c = c - sigma_n tan(phi) leaves little shear strength
// under tension.
inline constexpr double kMaxFrictionAngle = 60.0;
// Bounds of kn/ks and of c / sigma_b from below.
inline constexpr double kMinStiffnessRatio = 0.5;
inline constexpr double kMaxStiffnessRatio = 20.0;
inline constexpr double kMinCohesionRatio = 0.1;
// Bound of the flat joint's tension softening lambda from above (the
// calibrated row's range; 1 is brittle, the bound from below).
inline constexpr double kMaxSoftening = 1000.0;
// The local model: iterations it uses at most, the ridge weight of the prior
// slopes (as a difference of 0.14 in log parameters), the step's damping
// (relative to the prior's diagonal), and the UCS's weight when the ratio is
// out of reach (the tensile strength first).
inline constexpr size_t kModelPoints = 5;
inline constexpr double kRidge = 0.02;
inline constexpr double kDamping = 0.01;
inline constexpr double kUcsWeightOutOfReach = 0.05;
// The coarse UCS/tensile levers (moment factor, friction angle) move only
// while the card's ratio is more than this factor above the one reached.
inline constexpr double kCoarseLeverGap = 1.2;

// What the fit reads from an iteration: E, nu and the UCS of its UCS tests
// and the tensile strength of its Brazilian tests (or, with
// calibrate.tensile_test direct, of its direct tension tests), each the mean over the
// fit's specimen packings (calibrate.fit_packings; with one, its own).
struct Measured {
  double E = 0, nu = 0, ucs = 0, tensile = 0;
};

// One iteration: the bond parameters tried, both tests on the first
// packing and on the fit's further ones (and the semi-circular bend test
// when the toughness is a target), their errors.
struct Iteration {
  BondParams p;
  UcsRun ucs;  // on the first packing (calibrate.seed's): its curves are the report's
  BrazilianRun br;
  std::optional<UcsRun> tension;  // the direct tension test (calibrate.tensile_test direct)
  std::vector<PackingRun> more;  // on the fit's further packings (calibrate.fit_packings - 1)
  std::optional<ScbRun> scb;
  // The responses the fit aims at the ore card: the means over all packings.
  Measured measured() const;
  // Wall seconds of the tests on the fit's further packings.
  double more_seconds() const;
  double err_E = 0, err_ucs = 0, err_t = 0, err_nu = 0;
  double err_kic = 0;  // relative error of K_IC (0 when not a target)
  bool converged = false;
  double score = 0;  // worst error in units of its tolerance
};

// The Brazilian strength of an iteration's discs, the mean over the fit's
// packings; NaN when a disc did not split (post::kBrazilianSplitFraction).
// With calibrate.tensile_test direct the discs run on the kept parameters
// only, a check.
double brazilian_mean(const Iteration& it);

// The flat joint's local model's start: prior slopes J0, the range each
// measured slope is kept in, the step cap per parameter (local_model.h).
// Rows: ln E, nu, ln UCS, ln T, ln K_IC (the last used when the toughness is
// a target).
inline constexpr size_t kFitResponses = 5;
using FitMat = MatN<kFitResponses>;
using FitVec = VecN<kFitResponses>;
struct LocalModelPrior {
  FitMat J0{}, lo{}, hi{};
  ParamVec max_step{};
};
// direct: the tensile row of the direct tension test (calibrate.tensile_test).
LocalModelPrior flat_joint_prior(bool direct = false);

// Fits to the targets within relative tolerance tol (nu: kNuTolerance).
class Fitting {
 public:
  Fitting(const Targets& t, double tol) : t_(t), tol_(tol) {}
  const Targets& targets() const { return t_; }
  double tolerance() const { return tol_; }

  // Errors of one iteration against the ore card and whether all are met.
  void score(Iteration& it) const;
  // Next micro parameters from the iterations so far (by the last one's
  // bond model: secant_update or joint_update).
  BondParams update(const std::vector<Iteration>& hist, std::vector<std::string>& notes) const;
  // The parallel bond's: one damped secant step per parameter on its own
  // target, then its coarse UCS/tensile levers.
  BondParams secant_update(const std::vector<Iteration>& hist,
                           std::vector<std::string>& notes) const;
  // The flat joint's: one damped Gauss-Newton step of all four on the local
  // linear model (local_model.h).
  BondParams joint_update(const std::vector<Iteration>& hist,
                          std::vector<std::string>& notes) const;
  // Index of the iteration kept as the result: the most targets met, then
  // the smallest worst error; with the toughness a target,
  // best_compromise().
  size_t best(const std::vector<Iteration>& hist) const;
  // The toughness fit's result: an iteration that meets every target (the
  // smallest worst error), else the smallest sum of squared errors in
  // tolerance units (the joint step's objective); usable iterations only.
  size_t best_compromise(const std::vector<Iteration>& hist) const;
  // True when the toughness K_IC is a target (and each iteration runs the
  // semi-circular bend test).
  bool fits_toughness() const { return t_.toughness > 0; }
  // True when an iteration's responses can be fitted: E, UCS and the
  // tensile strength (and K_IC when it ran) finite and > 0, nu finite (a
  // specimen that failed at once can give a negative modulus).
  static bool usable(const Iteration& it);

 private:
  Targets t_;
  double tol_;
};

}  // namespace mill::calibrate
