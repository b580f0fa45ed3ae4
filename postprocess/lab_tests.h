// Virtual laboratory tests of the bonded ore: reading the load curves the
// UCS and Brazilian decks write, turning them into stress and strain, the
// elastic constants and strengths, and the update step of the calibration.
// Pure functions (no engine, no driver).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace mill::post {

// One lab-test run as written by liggghts_inputs/{ucs,brazilian}.in.tmpl:
// platen closure and the reaction force of each platen (compression > 0).
struct LoadCurve {
  std::vector<double> time;            // s
  std::vector<double> displacement;    // platen closure, m
  std::vector<double> force_top;       // N
  std::vector<double> force_bottom;    // N
  std::vector<double> lateral_strain;  // radial strain of the mid-height elements (expansion > 0)
  std::vector<double> broken_bonds;    // cumulative count
  size_t size() const { return displacement.size(); }
  // Mean of the two platen forces at sample i (cancels most inertia).
  double force(size_t i) const { return 0.5 * (force_top[i] + force_bottom[i]); }
};

// Read a curve file (`# ...` comments, then: step time displacement f_top
// f_bottom lateral_strain bonds broken). Throws with the file name on a bad line.
LoadCurve ReadLoadCurve(const std::string& file);

// Axial stress and strain of a compression test (compression > 0).
struct StressStrain {
  std::vector<double> strain;          // displacement / gauge length
  std::vector<double> stress;          // Pa, mean platen force / area
  std::vector<double> lateral_strain;  // as in LoadCurve
};

// Stress = mean platen force / area, strain = closure / gauge length.
StressStrain ToStressStrain(const LoadCurve& c, double gauge_length_m, double area_m2);

// Least-squares line y = slope x + intercept over points [first, last].
struct LinearFit {
  double slope = 0, intercept = 0, r2 = 0;
  size_t first = 0, last = 0;
};
LinearFit FitLine(const std::vector<double>& x, const std::vector<double>& y, size_t first,
                  size_t last);

// What a UCS test gives: Young's modulus from the linear part of the loading
// branch, Poisson's ratio from the lateral strain over the same part, the
// uniaxial compressive strength at the peak.
struct UcsResult {
  double youngs_modulus = 0;  // Pa
  double poisson_ratio = 0;
  double ucs = 0;  // Pa, peak stress
  double strain_at_peak = 0;
  size_t peak_index = 0;
  LinearFit fit;                                // stress vs strain over the fit window
  double fit_stress_lo = 0, fit_stress_hi = 0;  // Pa, the window
};

// The fit window is the loading branch (before the peak) with stress between
// lo_frac and hi_frac of the peak (ISRM-style average modulus of the linear
// part; the low end skips seating, the high end the onset of cracking).
// Throws when the curve has no positive peak or fewer than 3 points in the window.
UcsResult AnalyseUcs(const StressStrain& s, double lo_frac = 0.2, double hi_frac = 0.5);

// Brazilian tensile strength of a disc of diameter D and thickness t under
// line load F (ISRM 1978): sigma_t = 2 F / (pi D t).
double BrazilianTensileStrength(double force_N, double diameter_m, double thickness_m);

struct BrazilianResult {
  double peak_force = 0;        // N
  double tensile_strength = 0;  // Pa
  double displacement_at_peak = 0;
  size_t peak_index = 0;
};
BrazilianResult AnalyseBrazilian(const LoadCurve& c, double diameter_m, double thickness_m);

// One calibration update of a micro parameter x towards a macro target.
// The response y(x) is modelled locally as a power law (log_response) or as
// linear in ln x (for a response such as Poisson's ratio that may be near 0):
//   log:    ln x' = ln x + (ln y* - ln y) / s,   s = d ln y / d ln x
//   linear: ln x' = ln x + (y* - y) / s,         s = d y / d ln x
// s is the secant slope through the previous point when there is one and x
// moved (clamped to [slope_min, slope_max] so that noise cannot reverse or
// blow up the step), else slope_default. The step in ln x is capped at
// +-max_log_step. A damped secant in log space; the pairing of one micro
// parameter per macro property, deformability before strength, follows the
// calibration practice of Potyondy & Cundall (2004).
struct SecantRule {
  bool log_response = true;
  double slope_default = 1.0;
  double slope_min = 0.2, slope_max = 3.0;
  double max_log_step = 1.0;  // factor e per iteration at most
};
struct SecantPoint {
  double x = 0, y = 0;
};
struct SecantStep {
  double x_new = 0;
  double slope = 0;  // the slope used
  bool used_secant = false;
};
SecantStep SecantUpdate(const SecantRule& rule, const SecantPoint& now,
                        const std::optional<SecantPoint>& prev, double target);

// Relative error |value - target| / |target|.
double RelativeError(double value, double target);

}  // namespace mill::post
