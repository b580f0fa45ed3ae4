// Virtual laboratory tests of the bonded ore: reading the load curves the
// UCS, Brazilian, triaxial and semi-circular bend decks write, turning them
// into stress and strain, the elastic constants, strengths, failure envelope
// and fracture toughness, and the update step of the calibration.
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
  std::vector<double> intact_bonds;    // bonds (flat joints: interfaces) holding
  std::vector<double> broken_bonds;    // cumulative count (flat joints: elements)
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
  std::vector<double> broken_bonds;    // as in LoadCurve (may be empty: then not used)
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
  // The first sample after the specimen failed (kUcsFailureFraction), the
  // curve's size when it did not.
  size_t failure_index = 0;
  LinearFit fit;                                // stress vs strain over the fit window
  double fit_stress_lo = 0, fit_stress_hi = 0;  // Pa, the window
};

// The specimen has failed at the first sample whose stress has fallen below
// this fraction of the highest stress before it, with bonds broken since
// that highest stress: the UCS is that peak. After such a drop the debris
// compacted between the platens can carry more than the intact specimen did
// (measured: parallel bonds at a 60 deg bond friction angle rose to 1.05-1.4
// x their first peak after a drop of 30-40 %; bench/README.md, "The UCS
// before the debris"), which is not the rock's strength. A dip without
// broken bonds (the platens' start-up) is not a failure.
inline constexpr double kUcsFailureFraction = 0.7;

// The fit window is the loading branch (before the peak) with stress between
// lo_frac and hi_frac of the peak (ISRM-style average modulus of the linear
// part; the low end skips seating, the high end the onset of cracking).
// The peak is the highest stress before failure (kUcsFailureFraction; with
// no broken-bond counts, of the whole curve). Throws when the curve has no
// positive peak or fewer than 3 points in the window.
UcsResult AnalyseUcs(const StressStrain& s, double lo_frac = 0.2, double hi_frac = 0.5);

// Brazilian tensile strength of a disc of diameter D and thickness t under
// line load F (ISRM 1978): sigma_t = 2 F / (pi D t).
double BrazilianTensileStrength(double force_N, double diameter_m, double thickness_m);

// The first sample after failure: the first whose value has fallen below
// `fraction` x the highest value before it with bonds broken since that
// highest value; values.size() when there is none (or no broken-bond counts).
size_t FailureIndex(const std::vector<double>& values, const std::vector<double>& broken_bonds,
                    double fraction);

// The disc has split at the first sample whose load has fallen below this
// fraction of the highest load before it, with bonds broken since (the rule
// of kUcsFailureFraction): the tensile strength is that peak (ISRM 1978:
// the load at failure). After the split the jaws load the halves, whose
// debris can carry more than the intact disc (measured: 1.00-1.47 x the
// split load in the bundled cases' fits, mostly at a 60 deg bond friction
// angle, up to 6 x on flat joints there; bench/README.md, "The Brazilian
// strength at the split"). A disc with no such drop that has lost at least
// kBrazilianCrushedLoss of its bonds was crushed: its largest load is that
// of a disc compacting under the jaws, not a tensile strength (`no_split`);
// one that lost fewer is still whole when the run ends (its cap): the
// largest load is a lower bound of its strength, used as before.
inline constexpr double kBrazilianSplitFraction = 0.7;
// Measured: discs that reached their cap unsplit still held 95-98 % of their
// bonds when whole (a strong start), 5-30 % (flat joints at 60 deg) and 77 %
// (a parallel bond after a dip to 0.79 x) when crushed.
inline constexpr double kBrazilianCrushedLoss = 0.1;

struct BrazilianResult {
  double peak_force = 0;        // N
  double tensile_strength = 0;  // Pa
  double displacement_at_peak = 0;
  size_t peak_index = 0;
  // The first sample after the split (kBrazilianSplitFraction), the curve's
  // size when the disc did not split; no_split: it did not (then
  // tensile_strength is the largest load's, no tensile strength).
  size_t split_index = 0;
  bool no_split = false;
  double bonds_lost = 0;  // share of the disc's bonds broken by the run's end
};
BrazilianResult AnalyseBrazilian(const LoadCurve& c, double diameter_m, double thickness_m);

// One triaxial run as written by liggghts_inputs/triaxial.in.tmpl: the load
// curve of the axial stage (total axial forces, sigma_1 x end area) and the
// inward radial force applied to the lateral shell at each sample.
struct TriaxialCurve {
  LoadCurve load;
  std::vector<double> confining_force;  // N, summed over the shell
};

// Read a triaxial curve file (`# ...` comments, then: step time displacement
// f_top f_bottom lateral_strain bonds broken confining_force). Throws with the
// file name and line on a bad line.
TriaxialCurve ReadTriaxialCurve(const std::string& file);

// What a triaxial test gives: the peak of the deviatoric stress
// sigma_1 - sigma_3 and the principal stresses there (compression > 0).
struct TriaxialResult {
  double sigma3 = 0;    // Pa, confinement at the peak: confining force / lateral area
  double sigma1 = 0;    // Pa, axial stress at the peak: mean platen force / end area
  double deviator = 0;  // Pa, sigma1 - sigma3
  double strain_at_peak = 0;
  size_t peak_index = 0;
  double broken_before_loading = 0;  // bonds the confinement broke (first sample)
};

// The peak is that of sigma_1 - sigma_3 (the deck's stopping rule watches the
// same quantity). Throws when a length or an area is not > 0, or when the
// deviatoric stress never becomes positive.
TriaxialResult AnalyseTriaxial(const TriaxialCurve& c, double gauge_length_m, double end_area_m2,
                               double lateral_area_m2);

// A peak strength: the principal stresses at failure (compression > 0), Pa.
struct StrengthPoint {
  double sigma3 = 0, sigma1 = 0;
};

// The Mohr-Coulomb envelope in principal stresses,
//   sigma_1 = ucs + q sigma_3,  q = (1 + sin phi) / (1 - sin phi),
//   c = ucs (1 - sin phi) / (2 cos phi)
// (the Coulomb criterion written with the principal stresses: Jaeger, Cook &
// Zimmerman 2007, ch. 4).
struct MohrCoulomb {
  double ucs = 0;                 // Pa, sigma_1 at sigma_3 = 0
  double q = 0;                   // d sigma_1 / d sigma_3
  double friction_angle_deg = 0;  // phi
  double cohesion = 0;            // Pa
  double Sigma1(double sigma3) const { return ucs + q * sigma3; }
};

// Least-squares line sigma_1 = ucs + q sigma_3 through the points (exact
// through two), and phi and c from it. Throws with fewer than two distinct
// confinements, or when q <= 1 (no positive friction angle) or ucs <= 0.
MohrCoulomb FitMohrCoulomb(const std::vector<StrengthPoint>& points);

// The Hoek-Brown criterion of intact rock,
//   sigma_1 = sigma_3 + sigma_ci sqrt(m_i sigma_3 / sigma_ci + 1)
// (Hoek & Brown 1997, eq. 2). With y = (sigma_1 - sigma_3)^2 and
// x = sigma_3 it is the line y = m_i sigma_ci x + sigma_ci^2, fitted by least
// squares (the regression of Hoek & Brown 1997, appendix; exact through two
// points).
struct HoekBrown {
  double sigma_ci = 0;  // Pa, uniaxial compressive strength of the intact rock
  double m_i = 0;
  double Sigma1(double sigma3) const;
};

// Throws with fewer than two distinct confinements, or when the fit gives
// sigma_ci^2 <= 0 or m_i <= 0.
HoekBrown FitHoekBrown(const std::vector<StrengthPoint>& points);

// The dimensionless stress intensity factor of the semi-circular bend
// specimen, Y' = -1.297 + 9.516 s/R - (0.47 + 16.457 s/R) beta
// + (1.071 + 34.401 s/R) beta^2, beta = a/R (Kuruppu et al. 2014, eq. 2: a
// fit to finite-element results for the suggested geometry, s/R from 0.5 to
// 0.8 and a/R from 0.4 to 0.6). Throws unless 0 < a/R < 1 and 0 < s/R < 1.
double ScbGeometryFactor(double notch_ratio, double span_ratio);

// Mode-I fracture toughness from the peak load P of a semi-circular bend
// test: K_IC = Y' P sqrt(pi a) / (2 R B) (Kuruppu et al. 2014, eq. 1), in
// Pa m^0.5. R radius, B thickness, a notch length, s half the support span.
double ScbToughness(double force_N, double radius_m, double thickness_m, double notch_m,
                    double half_span_m);

struct ScbResult {
  double peak_force = 0;       // N
  double geometry_factor = 0;  // Y'
  double toughness = 0;        // Pa m^0.5
  double displacement_at_peak = 0;
  size_t peak_index = 0;
};
// The peak of the mean of the load-point and support forces, and K_IC there.
ScbResult AnalyseScb(const LoadCurve& c, double radius_m, double thickness_m, double notch_m,
                     double half_span_m);

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
