// Virtual lab tests: load curves, elastic constants, strengths, failure envelope,
// fracture toughness, calibration step.
#include "postprocess/lab_tests.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace mill::post {

namespace {
// The numeric rows of a deck's curve file (comment lines start with '#'),
// each with at least `columns` numbers; `names` lists them for the error.
std::vector<std::vector<double>> ReadCurveRows(const std::string& file, size_t columns,
                                               const char* names) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file + ": cannot open the load curve");
  std::vector<std::vector<double>> rows;
  std::string line;
  int lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ss(line);
    std::vector<double> row(columns);
    for (double& v : row)
      if (!(ss >> v))
        throw std::runtime_error(fmt::format("{}:{}: expected {} numbers ({}), got '{}'", file,
                                             lineno, columns, names, line));
    rows.push_back(std::move(row));
  }
  return rows;
}

// The load-curve columns of one row: step time displacement f_top f_bottom
// lateral_strain bonds broken.
void AppendLoadRow(const std::vector<double>& r, LoadCurve& c) {
  c.time.push_back(r[1]);
  c.displacement.push_back(r[2]);
  c.force_top.push_back(r[3]);
  c.force_bottom.push_back(r[4]);
  c.lateral_strain.push_back(r[5]);
  c.intact_bonds.push_back(r[6]);
  c.broken_bonds.push_back(r[7]);
}
}  // namespace

// Read the deck's curve file; comment lines start with '#'.
LoadCurve ReadLoadCurve(const std::string& file) {
  LoadCurve c;
  for (const auto& r : ReadCurveRows(
           file, 8, "step time displacement force_top force_bottom lateral_strain bonds broken"))
    AppendLoadRow(r, c);
  return c;
}

// Read the triaxial deck's curve file: the load curve plus the confining force.
TriaxialCurve ReadTriaxialCurve(const std::string& file) {
  TriaxialCurve c;
  for (const auto& r : ReadCurveRows(file, 9,
                                     "step time displacement force_top force_bottom "
                                     "lateral_strain bonds broken confining_force")) {
    AppendLoadRow(r, c.load);
    c.confining_force.push_back(r[8]);
  }
  return c;
}

// Stress from the mean platen force, strain from the closure.
StressStrain ToStressStrain(const LoadCurve& c, double gauge_length_m, double area_m2) {
  if (!(gauge_length_m > 0) || !(area_m2 > 0))
    throw std::invalid_argument(
        fmt::format("ToStressStrain: gauge length and area must be > 0, got {} m, {} m^2",
                    gauge_length_m, area_m2));
  StressStrain s;
  for (size_t i = 0; i < c.size(); ++i) {
    s.strain.push_back(c.displacement[i] / gauge_length_m);
    s.stress.push_back(c.force(i) / area_m2);
    s.lateral_strain.push_back(c.lateral_strain[i]);
  }
  s.broken_bonds = c.broken_bonds;
  return s;
}

// Ordinary least squares over an index range.
LinearFit FitLine(const std::vector<double>& x, const std::vector<double>& y, size_t first,
                  size_t last) {
  if (last >= x.size() || last >= y.size() || last < first + 1)
    throw std::invalid_argument("FitLine: need at least 2 points in range");
  const double n = static_cast<double>(last - first + 1);
  double sx = 0, sy = 0;
  for (size_t i = first; i <= last; ++i) sx += x[i], sy += y[i];
  const double mx = sx / n, my = sy / n;
  double sxx = 0, sxy = 0, syy = 0;
  for (size_t i = first; i <= last; ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
    syy += (y[i] - my) * (y[i] - my);
  }
  LinearFit f;
  f.first = first;
  f.last = last;
  f.slope = sxx > 0 ? sxy / sxx : 0.0;
  f.intercept = my - f.slope * mx;
  f.r2 = (sxx > 0 && syy > 0) ? sxy * sxy / (sxx * syy) : 1.0;
  return f;
}

namespace {
// Index of the largest value among the first `end` (first one on ties).
size_t argmax(const std::vector<double>& v, size_t end = SIZE_MAX) {
  const auto last = v.begin() + static_cast<long>(std::min(end, v.size()));
  return static_cast<size_t>(std::max_element(v.begin(), last) - v.begin());
}
}  // namespace

size_t FailureIndex(const std::vector<double>& values, const std::vector<double>& broken_bonds,
                    double fraction) {
  if (broken_bonds.size() != values.size()) return values.size();
  size_t top = 0;
  for (size_t i = 1; i < values.size(); ++i) {
    if (values[i] > values[top])
      top = i;
    else if (values[i] < fraction * values[top] && broken_bonds[i] > broken_bonds[top])
      return i;
  }
  return values.size();
}

// E and nu from the linear part of the loading branch, UCS from the peak.
UcsResult AnalyseUcs(const StressStrain& s, double lo_frac, double hi_frac) {
  if (s.stress.empty()) throw std::runtime_error("UCS test: empty stress-strain curve");
  UcsResult r;
  // Failure: the stress below kUcsFailureFraction of its running maximum,
  // bonds broken since that maximum.
  r.failure_index = FailureIndex(s.stress, s.broken_bonds, kUcsFailureFraction);
  r.peak_index = argmax(s.stress, r.failure_index);
  r.ucs = s.stress[r.peak_index];
  r.strain_at_peak = s.strain[r.peak_index];
  if (!(r.ucs > 0))
    throw std::runtime_error("UCS test: the specimen never carried a compressive load");
  r.fit_stress_lo = lo_frac * r.ucs;
  r.fit_stress_hi = hi_frac * r.ucs;
  // The window: from the first loading point above lo to the last one below hi.
  size_t first = r.peak_index + 1, last = 0;
  for (size_t i = 0; i <= r.peak_index; ++i)
    if (s.stress[i] >= r.fit_stress_lo) {
      first = i;
      break;
    }
  for (size_t i = first; i <= r.peak_index && i < s.stress.size(); ++i)
    if (s.stress[i] <= r.fit_stress_hi) last = i;
  if (first > r.peak_index || last < first + 2)
    throw std::runtime_error(
        fmt::format("UCS test: fewer than 3 samples between {:.3g} and {:.3g} Pa before the "
                    "peak: sample the curve more often",
                    r.fit_stress_lo, r.fit_stress_hi));
  r.fit = FitLine(s.strain, s.stress, first, last);
  r.youngs_modulus = r.fit.slope;
  // nu = d(lateral strain) / d(axial strain) over the same window.
  r.poisson_ratio = FitLine(s.strain, s.lateral_strain, first, last).slope;
  return r;
}

// ISRM (1978) Brazilian formula.
double BrazilianTensileStrength(double force_N, double diameter_m, double thickness_m) {
  if (!(diameter_m > 0) || !(thickness_m > 0))
    throw std::invalid_argument(
        fmt::format("Brazilian test: diameter and thickness must be > 0, got {} m, {} m",
                    diameter_m, thickness_m));
  return 2.0 * force_N / (M_PI * diameter_m * thickness_m);
}

// Peak load of the disc and its tensile strength.
BrazilianResult AnalyseBrazilian(const LoadCurve& c, double diameter_m, double thickness_m) {
  if (c.size() == 0) throw std::runtime_error("Brazilian test: empty load curve");
  BrazilianResult r;
  std::vector<double> f(c.size());
  for (size_t i = 0; i < c.size(); ++i) f[i] = c.force(i);
  r.split_index = FailureIndex(f, c.broken_bonds, kBrazilianSplitFraction);
  // No split, and the disc has lost kBrazilianCrushedLoss of its bonds or
  // more: crushed. With fewer lost it is still whole at the run's end: the
  // largest load is a lower bound, as before (the stage notes the cap).
  const bool counts = c.intact_bonds.size() == f.size() && !f.empty() && c.intact_bonds[0] > 0;
  r.bonds_lost = counts ? 1.0 - c.intact_bonds.back() / c.intact_bonds.front() : 0.0;
  r.no_split = r.split_index == f.size() && r.bonds_lost >= kBrazilianCrushedLoss;
  r.peak_index = argmax(f, r.split_index);
  r.peak_force = f[r.peak_index];
  if (!(r.peak_force > 0))
    throw std::runtime_error("Brazilian test: the disc never carried a load");
  r.displacement_at_peak = c.displacement[r.peak_index];
  r.tensile_strength = BrazilianTensileStrength(r.peak_force, diameter_m, thickness_m);
  return r;
}

// Peak of the deviatoric stress of a triaxial test.
TriaxialResult AnalyseTriaxial(const TriaxialCurve& c, double gauge_length_m, double end_area_m2,
                               double lateral_area_m2) {
  if (!(gauge_length_m > 0) || !(end_area_m2 > 0) || !(lateral_area_m2 > 0))
    throw std::invalid_argument(fmt::format(
        "triaxial test: gauge length, end area and lateral area must be > 0, got {} m, {} m^2, "
        "{} m^2",
        gauge_length_m, end_area_m2, lateral_area_m2));
  if (c.load.size() == 0 || c.confining_force.size() != c.load.size())
    throw std::runtime_error("triaxial test: empty load curve, or a confining force missing");
  TriaxialResult r;
  std::vector<double> dev(c.load.size());
  for (size_t i = 0; i < dev.size(); ++i)
    dev[i] = c.load.force(i) / end_area_m2 - c.confining_force[i] / lateral_area_m2;
  r.peak_index = argmax(dev);
  r.deviator = dev[r.peak_index];
  if (!(r.deviator > 0))
    throw std::runtime_error("triaxial test: the axial stress never exceeded the confinement");
  r.sigma3 = c.confining_force[r.peak_index] / lateral_area_m2;
  r.sigma1 = r.sigma3 + r.deviator;
  r.strain_at_peak = c.load.displacement[r.peak_index] / gauge_length_m;
  r.broken_before_loading = c.load.broken_bonds.front();
  return r;
}

namespace {
// The least-squares line y = slope x + intercept through (x_k, y_k); throws
// unless there are two distinct x.
LinearFit FitStrengthLine(const std::vector<double>& x, const std::vector<double>& y,
                          const char* what) {
  const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
  if (x.size() < 2 || !(*hi > *lo))
    throw std::invalid_argument(fmt::format(
        "{}: need peaks at two different confinements, got {} point(s)", what, x.size()));
  return FitLine(x, y, 0, x.size() - 1);
}
}  // namespace

// Mohr-Coulomb line through the peaks, and its friction angle and cohesion.
MohrCoulomb FitMohrCoulomb(const std::vector<StrengthPoint>& points) {
  std::vector<double> x, y;
  for (const auto& p : points) x.push_back(p.sigma3), y.push_back(p.sigma1);
  const LinearFit f = FitStrengthLine(x, y, "Mohr-Coulomb fit");
  MohrCoulomb mc;
  mc.ucs = f.intercept;
  mc.q = f.slope;
  if (!(mc.q > 1) || !(mc.ucs > 0))
    throw std::runtime_error(
        fmt::format("Mohr-Coulomb fit: sigma_1 = {:.4g} Pa + {:.4g} sigma_3 has no positive "
                    "friction angle and cohesion (need a slope > 1 and an intercept > 0)",
                    mc.ucs, mc.q));
  // q = (1 + sin phi) / (1 - sin phi)  <=>  sin phi = (q - 1) / (q + 1).
  const double sin_phi = (mc.q - 1) / (mc.q + 1);
  const double phi = std::asin(sin_phi);
  mc.friction_angle_deg = phi * 180.0 / M_PI;
  mc.cohesion = mc.ucs * (1 - sin_phi) / (2 * std::cos(phi));
  return mc;
}

// Hoek & Brown (1997), eq. 2, intact rock (s = 1, a = 1/2).
double HoekBrown::Sigma1(double sigma3) const {
  return sigma3 + sigma_ci * std::sqrt(m_i * sigma3 / sigma_ci + 1);
}

// sigma_ci and m_i from the regression of (sigma_1 - sigma_3)^2 on sigma_3.
HoekBrown FitHoekBrown(const std::vector<StrengthPoint>& points) {
  std::vector<double> x, y;
  for (const auto& p : points) x.push_back(p.sigma3), y.push_back(std::pow(p.sigma1 - p.sigma3, 2));
  const LinearFit f = FitStrengthLine(x, y, "Hoek-Brown fit");
  if (!(f.intercept > 0) || !(f.slope > 0))
    throw std::runtime_error(fmt::format(
        "Hoek-Brown fit: (sigma_1 - sigma_3)^2 = {:.4g} Pa^2 + {:.4g} Pa sigma_3 gives no "
        "positive sigma_ci and m_i",
        f.intercept, f.slope));
  HoekBrown hb;
  hb.sigma_ci = std::sqrt(f.intercept);
  hb.m_i = f.slope / hb.sigma_ci;
  return hb;
}

// Kuruppu et al. (2014), eq. 2.
double ScbGeometryFactor(double notch_ratio, double span_ratio) {
  if (!(notch_ratio > 0 && notch_ratio < 1) || !(span_ratio > 0 && span_ratio < 1))
    throw std::invalid_argument(
        fmt::format("SCB test: need 0 < a/R < 1 and 0 < s/R < 1, got a/R = {}, s/R = {}",
                    notch_ratio, span_ratio));
  const double b = notch_ratio, sr = span_ratio;
  return -1.297 + 9.516 * sr - (0.47 + 16.457 * sr) * b + (1.071 + 34.401 * sr) * b * b;
}

// Kuruppu et al. (2014), eq. 1.
double ScbToughness(double force_N, double radius_m, double thickness_m, double notch_m,
                    double half_span_m) {
  if (!(radius_m > 0) || !(thickness_m > 0))
    throw std::invalid_argument(fmt::format(
        "SCB test: radius and thickness must be > 0, got {} m, {} m", radius_m, thickness_m));
  const double y = ScbGeometryFactor(notch_m / radius_m, half_span_m / radius_m);
  return y * force_N * std::sqrt(M_PI * notch_m) / (2 * radius_m * thickness_m);
}

// Peak load of the half disc and its toughness.
ScbResult AnalyseScb(const LoadCurve& c, double radius_m, double thickness_m, double notch_m,
                     double half_span_m) {
  if (c.size() == 0) throw std::runtime_error("SCB test: empty load curve");
  ScbResult r;
  std::vector<double> f(c.size());
  for (size_t i = 0; i < c.size(); ++i) f[i] = c.force(i);
  r.peak_index = argmax(f);
  r.peak_force = f[r.peak_index];
  if (!(r.peak_force > 0)) throw std::runtime_error("SCB test: the specimen never carried a load");
  r.displacement_at_peak = c.displacement[r.peak_index];
  r.geometry_factor = ScbGeometryFactor(notch_m / radius_m, half_span_m / radius_m);
  r.toughness = ScbToughness(r.peak_force, radius_m, thickness_m, notch_m, half_span_m);
  return r;
}

// Damped log-space secant step of one micro parameter.
SecantStep SecantUpdate(const SecantRule& rule, const SecantPoint& now,
                        const std::optional<SecantPoint>& prev, double target) {
  if (!(now.x > 0))
    throw std::invalid_argument(fmt::format("SecantUpdate: parameter must be > 0, got {}", now.x));
  auto resp = [&](double y) {
    if (!rule.log_response) return y;
    if (!(y > 0))
      throw std::invalid_argument(fmt::format("SecantUpdate: response must be > 0, got {}", y));
    return std::log(y);
  };
  SecantStep st;
  st.slope = rule.slope_default;
  if (prev && prev->x > 0 && std::abs(std::log(now.x / prev->x)) > 1e-6 &&
      (!rule.log_response || prev->y > 0)) {
    const double s = (resp(now.y) - resp(prev->y)) / std::log(now.x / prev->x);
    st.slope = std::clamp(s, rule.slope_min, rule.slope_max);
    st.used_secant = true;
  }
  const double dlog =
      std::clamp((resp(target) - resp(now.y)) / st.slope, -rule.max_log_step, rule.max_log_step);
  st.x_new = now.x * std::exp(dlog);
  return st;
}

// |value - target| / |target|.
double RelativeError(double value, double target) {
  return std::abs(value - target) / std::abs(target);
}

}  // namespace mill::post
