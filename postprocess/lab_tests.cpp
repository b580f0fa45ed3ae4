// Virtual lab tests: load curves, elastic constants, strengths, calibration step.
#include "postprocess/lab_tests.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace mill::post {

// Read the deck's curve file; comment lines start with '#'.
LoadCurve ReadLoadCurve(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file + ": cannot open the load curve");
  LoadCurve c;
  std::string line;
  int lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ss(line);
    double step, t, d, ft, fb, lat, nb, nbroken;
    if (!(ss >> step >> t >> d >> ft >> fb >> lat >> nb >> nbroken))
      throw std::runtime_error(
          fmt::format("{}:{}: expected 8 numbers (step time displacement force_top "
                      "force_bottom lateral_strain bonds broken), got '{}'",
                      file, lineno, line));
    c.time.push_back(t);
    c.displacement.push_back(d);
    c.force_top.push_back(ft);
    c.force_bottom.push_back(fb);
    c.lateral_strain.push_back(lat);
    c.broken_bonds.push_back(nbroken);
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
// Index of the largest value (first one on ties).
size_t argmax(const std::vector<double>& v) {
  return static_cast<size_t>(std::max_element(v.begin(), v.end()) - v.begin());
}
}  // namespace

// E and nu from the linear part of the loading branch, UCS from the peak.
UcsResult AnalyseUcs(const StressStrain& s, double lo_frac, double hi_frac) {
  if (s.stress.empty()) throw std::runtime_error("UCS test: empty stress-strain curve");
  UcsResult r;
  r.peak_index = argmax(s.stress);
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
  r.peak_index = argmax(f);
  r.peak_force = f[r.peak_index];
  if (!(r.peak_force > 0))
    throw std::runtime_error("Brazilian test: the disc never carried a load");
  r.displacement_at_peak = c.displacement[r.peak_index];
  r.tensile_strength = BrazilianTensileStrength(r.peak_force, diameter_m, thickness_m);
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
