// The JK t10-Ecs fit; see jk_fit.h.
#include "postprocess/jk_fit.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "postprocess/fragments.h"

namespace mill::post {
namespace {

// Sum of squared residuals of the JK relation with parameters (a, b).
double SumSquares(const std::vector<double>& e, const std::vector<double>& t, double a, double b) {
  double s = 0.0;
  for (std::size_t i = 0; i < e.size(); ++i) {
    const double r = t[i] - JkT10(a, b, e[i]);
    s += r * r;
  }
  return s;
}

// Spread of a list of values (not empty).
Spread SpreadOf(const std::vector<double>& v) {
  Spread s;
  s.min = *std::min_element(v.begin(), v.end());
  s.max = *std::max_element(v.begin(), v.end());
  double sum = 0.0;
  for (double x : v) sum += x;
  s.mean = sum / static_cast<double>(v.size());
  if (v.size() > 1) {
    double ss = 0.0;
    for (double x : v) ss += (x - s.mean) * (x - s.mean);
    s.stddev = std::sqrt(ss / static_cast<double>(v.size() - 1));
  }
  return s;
}

}  // namespace

double SpecificEnergyKWhPerTonne(double speed_m_s) {
  return 0.5 * speed_m_s * speed_m_s / kJoulePerKgPerKWhPerTonne;
}

// The JK relation: Napier-Munn et al. 1996, "Mineral Comminution Circuits", JKMRC.
double JkT10(double a_percent, double b_t_per_kwh, double ecs_kwh_t) {
  return a_percent * (1.0 - std::exp(-b_t_per_kwh * ecs_kwh_t));
}

// Levenberg-Marquardt on (A, b), b kept > 0 by rejecting steps that cross 0.
JkFit FitJk(const std::vector<double>& e, const std::vector<double>& t) {
  if (e.size() != t.size()) {
    throw PostError(fmt::format("JK fit: {} energies but {} t10 values", e.size(), t.size()));
  }
  for (std::size_t i = 0; i < e.size(); ++i) {
    if (!std::isfinite(e[i]) || !std::isfinite(t[i])) {
      throw PostError(
          fmt::format("JK fit: point {} is ({}, {}); expected finite numbers", i, e[i], t[i]));
    }
  }
  JkFit f;
  f.n_points = static_cast<int>(e.size());
  std::set<double> energies;
  for (double x : e)
    if (x > 0.0) energies.insert(x);
  const double t_max = t.empty() ? 0.0 : *std::max_element(t.begin(), t.end());
  if (e.size() < 3 || energies.size() < 2) {
    f.reason =
        fmt::format("{} points at {} distinct energies > 0: need at least 3 points at 2 energies",
                    e.size(), energies.size());
    return f;
  }
  if (!(t_max > 0.0)) {
    f.reason = "t10 is 0 at every point: no breakage to fit";
    return f;
  }

  // Start: A a little above the largest t10; b from ln(1 - t10/A) = -b Ecs.
  double a = std::min(100.0, 1.05 * t_max);
  if (a <= t_max) a = 1.01 * t_max;
  std::vector<double> b_est;
  for (std::size_t i = 0; i < e.size(); ++i)
    if (e[i] > 0.0 && t[i] > 0.0 && t[i] < a) b_est.push_back(-std::log(1.0 - t[i] / a) / e[i]);
  double b = 1.0;
  if (!b_est.empty()) {
    std::nth_element(b_est.begin(), b_est.begin() + static_cast<long>(b_est.size() / 2),
                     b_est.end());
    b = b_est[b_est.size() / 2];
  }

  double s = SumSquares(e, t, a, b);
  double lambda = 1e-3;
  constexpr int kMaxIterations = 500;
  int it = 0;
  bool converged = false;
  while (!converged && it < kMaxIterations) {
    ++it;
    // Normal equations of the linearised residuals: (J^T J + lambda diag) d = J^T r.
    double jtj[2][2] = {{0, 0}, {0, 0}}, jtr[2] = {0, 0};
    for (std::size_t i = 0; i < e.size(); ++i) {
      const double x = std::exp(-b * e[i]);
      const double g[2] = {1.0 - x, a * e[i] * x};  // d t10 / dA, d t10 / db
      const double r = t[i] - a * (1.0 - x);
      for (int p = 0; p < 2; ++p) {
        jtr[p] += g[p] * r;
        for (int q = 0; q < 2; ++q) jtj[p][q] += g[p] * g[q];
      }
    }
    // Raise lambda until a step lowers the sum of squares (or give up: at the minimum).
    bool improved = false;
    for (int tries = 0; tries < 30 && !improved; ++tries) {
      const double m00 = jtj[0][0] * (1 + lambda), m11 = jtj[1][1] * (1 + lambda), m01 = jtj[0][1];
      const double det = m00 * m11 - m01 * m01;
      if (!(std::abs(det) > 0.0)) {
        lambda *= 10;
        continue;
      }
      const double da = (m11 * jtr[0] - m01 * jtr[1]) / det;
      const double db = (m00 * jtr[1] - m01 * jtr[0]) / det;
      const double a_new = a + da, b_new = b + db;
      const double s_new = (a_new > 0.0 && b_new > 0.0) ? SumSquares(e, t, a_new, b_new) : HUGE_VAL;
      if (s_new > s) {
        lambda *= 10;
        continue;
      }
      const bool tiny_step =
          std::abs(da) <= 1e-12 * (1 + std::abs(a)) && std::abs(db) <= 1e-12 * (1 + std::abs(b));
      converged = tiny_step || s - s_new <= 1e-15 * (1 + s_new);
      a = a_new;
      b = b_new;
      s = s_new;
      lambda = std::max(1e-12, lambda / 10);
      improved = true;
    }
    if (!improved) converged = true;
  }
  f.iterations = it;
  f.ok = true;
  f.a_percent = a;
  f.b_t_per_kwh = b;
  f.rms_residual_percent = std::sqrt(s / static_cast<double>(e.size()));

  // Past saturation at every energy: once b Ecs_min > ln 20 the lowest
  // impact's t10 is within 5 % of A, and any larger b fits as well (the
  // sum of squares is flat in b): the sweep bounds b from below only, and
  // a least-squares b (and A x b) would be a number of the optimiser's, not
  // of the ore's.
  const double e_min = *energies.begin();
  if (b * e_min > kSaturatedBEcs) {
    f.ok = false;
    f.reason = fmt::format(
        "every impact is past saturation: t10 at the lowest energy ({:.3g} kWh/t) is within "
        "5 % of A ({:.3g} %), so b is only bounded from below (b > ln 20 / Ecs = {:.3g} t/kWh, "
        "A x b > {:.3g}); the sweep needs impacts below the critical speed",
        e_min, a, kSaturatedBEcs / e_min, a * kSaturatedBEcs / e_min);
    return f;
  }
  // Standard errors: s^2 (J^T J)^-1 at the optimum, s^2 = SSR / (n - 2).
  double jtj[2][2] = {{0, 0}, {0, 0}};
  for (std::size_t i = 0; i < e.size(); ++i) {
    const double x = std::exp(-b * e[i]);
    const double g[2] = {1.0 - x, a * e[i] * x};
    for (int p = 0; p < 2; ++p)
      for (int q = 0; q < 2; ++q) jtj[p][q] += g[p] * g[q];
  }
  const double det = jtj[0][0] * jtj[1][1] - jtj[0][1] * jtj[0][1];
  if (e.size() > 2 && det > 0.0) {
    const double s2 = s / static_cast<double>(e.size() - 2);
    f.a_se_percent = std::sqrt(s2 * jtj[1][1] / det);
    f.b_se_t_per_kwh = std::sqrt(s2 * jtj[0][0] / det);
  }
  if (b * *energies.rbegin() < 0.5) {
    f.note =
        "the sweep stays on the initial slope (b x largest Ecs < 0.5): A and b are poorly "
        "separated, A x b is the robust figure";
  }
  return f;
}

// Pooled fit and one fit per repeat.
JkSweepFit FitJkSweep(const std::vector<JkPoint>& points, const std::set<int>* whole) {
  JkSweepFit out;
  std::vector<double> e, t;
  std::map<int, std::pair<std::vector<double>, std::vector<double>>> by_repeat;
  for (const JkPoint& p : points) {
    e.push_back(p.ecs_kwh_t);
    t.push_back(p.t10_percent);
    if (whole && !whole->count(p.repeat)) continue;  // pooled only
    by_repeat[p.repeat].first.push_back(p.ecs_kwh_t);
    by_repeat[p.repeat].second.push_back(p.t10_percent);
  }
  out.pooled = FitJk(e, t);
  std::vector<double> as, bs, abs;
  for (const auto& [rep, xy] : by_repeat) {
    out.repeats.push_back(rep);
    out.per_repeat.push_back(FitJk(xy.first, xy.second));
    const JkFit& f = out.per_repeat.back();
    if (!f.ok) continue;
    as.push_back(f.a_percent);
    bs.push_back(f.b_t_per_kwh);
    abs.push_back(f.ab());
  }
  out.n_repeats_fitted = static_cast<int>(as.size());
  if (!as.empty()) {
    out.a_percent = SpreadOf(as);
    out.b_t_per_kwh = SpreadOf(bs);
    out.ab = SpreadOf(abs);
  }
  return out;
}

}  // namespace mill::post
