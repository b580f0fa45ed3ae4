// The JKMRC breakage relation between t10 and the specific impact energy,
// fitted to a breakage sweep: t10 = A (1 - exp(-b Ecs)) (Napier-Munn, Morrell,
// Morrison & Kojovic 1996, "Mineral Comminution Circuits", JKMRC).
// A (%) is the t10 that more energy no longer raises, b (t/kWh) how fast t10
// approaches it, A x b the slope at zero energy (the ore's breakage index).
// Used by the breakage stage after a sweep; the drop-weight test's energy is
// replaced by the impact's V^2/2.
#pragma once

#include <optional>
#include <set>
#include <string>
#include <vector>

namespace mill::post {

// 1 kWh/t = 3.6e6 J per 1000 kg = 3600 J/kg.
inline constexpr double kJoulePerKgPerKWhPerTonne = 3600.0;

// Specific impact energy Ecs of an impact at `speed_m_s`, in kWh/t: V^2/2.
double SpecificEnergyKWhPerTonne(double speed_m_s);

// t10 (%) of the JK relation at Ecs (kWh/t).
double JkT10(double a_percent, double b_t_per_kwh, double ecs_kwh_t);

// One fit of A and b by least squares.
struct JkFit {
  bool ok = false;
  std::string reason;           // why there is no fit (when !ok)
  std::string note;             // a caveat on a fit that did succeed
  double a_percent = 0.0;       // A, %
  double b_t_per_kwh = 0.0;     // b, t/kWh
  double a_se_percent = 0.0;    // standard error of A from the fit (0 with 2 points)
  double b_se_t_per_kwh = 0.0;  // standard error of b
  double rms_residual_percent = 0.0;
  int n_points = 0;
  int iterations = 0;
  double ab() const { return a_percent * b_t_per_kwh; }
};

// b x Ecs beyond which t10 is within 5 % of A: ln 20.
inline constexpr double kSaturatedBEcs = 2.995732273553991;

// Fits A and b to (Ecs, t10) pairs by Levenberg-Marquardt on the sum of
// squared t10 residuals, from a start read off the data (A a little above the
// largest t10, b from the linearised relation). Needs at least 3 points at
// 2 or more distinct energies > 0 and some t10 > 0; else !ok with the reason.
// A fit whose every point is past saturation (b x the lowest Ecs > ln 20:
// b bounded from below only) is !ok too, the reason giving that bound.
// Throws PostError on mismatched lengths or non-finite values.
JkFit FitJk(const std::vector<double>& ecs_kwh_t, const std::vector<double>& t10_percent);

// One point of a sweep for the JK fit.
struct JkPoint {
  double ecs_kwh_t = 0.0;
  double t10_percent = 0.0;
  int repeat = 0;
};

// min, max, mean and sample standard deviation (n-1; absent below 2) of a value.
struct Spread {
  double min = 0.0, max = 0.0, mean = 0.0;
  std::optional<double> stddev;
};

// The fit to all points, and its spread over repeats: each repeat (one lump
// orientation over the whole sweep) is fitted on its own; the spread of A, b
// and A x b is over the repeats whose fit succeeded (absent when none did).
struct JkSweepFit {
  JkFit pooled;
  std::vector<int> repeats;       // repeat ids, ascending
  std::vector<JkFit> per_repeat;  // same order
  int n_repeats_fitted = 0;
  std::optional<Spread> a_percent, b_t_per_kwh, ab;
};

// `whole`, when given: the repeats fitted on their own (those at every speed
// of the sweep, RepeatsAtEveryVelocity); the others count in the pooled fit only.
JkSweepFit FitJkSweep(const std::vector<JkPoint>& points, const std::set<int>* whole = nullptr);

}  // namespace mill::post
