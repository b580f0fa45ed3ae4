// Size classes, breakage matrix, classification and the closed circuit's
// steady state; see population_balance.h and docs/population_balance.md.
#include "postprocess/population_balance.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "postprocess/distributions.h"
#include "postprocess/fragments.h"

namespace mill::post {
namespace {

// Above the diagonal, entries this small are rounding, not coarsening.
constexpr double kUpperTolerance = 1e-12;
// A column of the breakage matrix sums to 1 within this.
constexpr double kColumnTolerance = 1e-9;
// c_i b_ii above 1 - this: the class returns (all but a billionth of) its
// mass unbroken each pass, so it never leaves (circulating load > 1e9).
constexpr double kNeverLeaves = 1e-9;

std::string mm(double v) { return fmt::format("{:g} mm", v); }

void CheckClasses(const SizeClasses& classes) {
  const auto& u = classes.upper_mm;
  if (u.empty()) throw PostError("size classes: expected at least one class, got none");
  for (std::size_t i = 0; i < u.size(); ++i) {
    if (!std::isfinite(u[i]) || !(u[i] > 0.0))
      throw PostError(
          fmt::format("size classes: upper edge {} is {}; expected a size > 0 mm", i, u[i]));
    if (i > 0 && !(u[i] < u[i - 1]))
      throw PostError(
          fmt::format("size classes: upper edge {} is {} after {}; expected edges coarsest first, "
                      "strictly descending",
                      i, mm(u[i]), mm(u[i - 1])));
  }
}

// A per-class vector of the right length, finite, within [lo, hi].
void CheckPerClass(const SizeClasses& classes, const std::vector<double>& v, const char* what,
                   double lo, double hi) {
  if (v.size() != classes.size())
    throw PostError(fmt::format("{}: {} values for {} size classes; expected one per class", what,
                                v.size(), classes.size()));
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i]) || v[i] < lo || v[i] > hi)
      throw PostError(fmt::format("{} of the {} class is {}; expected a value in [{:g}, {:g}]",
                                  what, classes.name(i), v[i], lo, hi));
}

void CheckCircuitInput(const SizeClasses& classes, const BreakageMatrix& b,
                       const std::vector<double>& c, const std::vector<double>& feed) {
  CheckClasses(classes);
  ValidateBreakageMatrix(classes, b);
  CheckPerClass(classes, c, "classification", 0.0, 1.0);
  CheckPerClass(classes, feed, "feed", 0.0, HUGE_VAL);
  double total = 0.0;
  for (double f : feed) total += f;
  if (!(total > 0.0)) throw PostError("feed: expected some mass in at least one class, got none");
}

// Everything of the circuit that follows from its mill input m.
CircuitState StateFromInput(const BreakageMatrix& b, const std::vector<double>& c,
                            const std::vector<double>& feed, std::vector<double> m) {
  const std::size_t n = m.size();
  CircuitState s;
  s.mill_output.assign(n, 0.0);
  s.returned.assign(n, 0.0);
  s.product.assign(n, 0.0);
  double returned_total = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j <= i; ++j) s.mill_output[i] += b[i][j] * m[j];
    s.returned[i] = c[i] * s.mill_output[i];
    s.product[i] = (1.0 - c[i]) * s.mill_output[i];
    s.feed_total += feed[i];
    s.product_total += s.product[i];
    returned_total += s.returned[i];
  }
  s.mill_input = std::move(m);
  s.circulating_load = returned_total / s.feed_total;
  s.mass_balance_residual = std::abs(s.product_total - s.feed_total) / s.feed_total;
  return s;
}

}  // namespace

double SizeClasses::lower_mm(std::size_t i) const {
  return i + 1 < upper_mm.size() ? upper_mm[i + 1] : 0.0;
}

std::string SizeClasses::name(std::size_t i) const {
  if (i >= upper_mm.size()) return fmt::format("class {} (of {})", i, upper_mm.size());
  if (i + 1 == upper_mm.size()) return fmt::format("below-{:g} mm", upper_mm[i]);
  return fmt::format("{:g}-{:g} mm", upper_mm[i + 1], upper_mm[i]);
}

SizeClasses MakeSizeClasses(std::vector<double> upper_mm) {
  SizeClasses s{std::move(upper_mm)};
  CheckClasses(s);
  return s;
}

SizeClasses SizeClassesFromSieves(const std::vector<double>& ascending_mm) {
  return MakeSizeClasses(std::vector<double>(ascending_mm.rbegin(), ascending_mm.rend()));
}

SizeClasses GeometricSieveSeries(double top_mm, double ratio, std::size_t n) {
  if (!std::isfinite(top_mm) || !(top_mm > 0.0))
    throw PostError(fmt::format("sieve series: top size {}; expected a size > 0 mm", top_mm));
  if (!std::isfinite(ratio) || !(ratio > 1.0))
    throw PostError(fmt::format("sieve series: ratio {}; expected a ratio > 1", ratio));
  if (n == 0) throw PostError("sieve series: expected at least one class, got 0");
  std::vector<double> u(n);
  for (std::size_t i = 0; i < n; ++i) u[i] = top_mm / std::pow(ratio, static_cast<double>(i));
  return MakeSizeClasses(std::move(u));
}

double RepresentativeSize(const SizeClasses& classes, std::size_t i) {
  CheckClasses(classes);
  const auto& u = classes.upper_mm;
  if (i >= u.size())
    throw PostError(fmt::format("size class {}: expected an index below {}", i, u.size()));
  double lower = classes.lower_mm(i);
  if (i + 1 == u.size()) lower = u[i] / (u.size() > 1 ? u[i - 1] / u[i] : std::sqrt(2.0));
  return std::sqrt(u[i] * lower);
}

double RosinRammlerRetained(double d_mm, double d63_mm, double n) {
  return d_mm <= 0.0 ? 1.0 : std::exp(-std::pow(d_mm / d63_mm, n));
}

std::vector<double> RosinRammlerFractions(const std::vector<double>& ascending_mm, double d63_mm,
                                          double n) {
  if (!std::isfinite(d63_mm) || !(d63_mm > 0.0))
    throw PostError(fmt::format("Rosin-Rammler: d63 {}; expected a size > 0 mm", d63_mm));
  if (!std::isfinite(n) || !(n > 0.0))
    throw PostError(fmt::format("Rosin-Rammler: n {}; expected a uniformity > 0", n));
  SizeClassesFromSieves(ascending_mm);  // checks the sieves
  const std::size_t k = ascending_mm.size();
  std::vector<double> out(k);
  double retained_below = 1.0;  // retained on the class's lower sieve (on 0: everything)
  for (std::size_t i = 0; i < k; ++i) {
    const double retained_upper =
        i + 1 < k ? RosinRammlerRetained(ascending_mm[i], d63_mm, n) : 0.0;
    out[i] = retained_below - retained_upper;  // the top class keeps the tail above its sieve
    retained_below = retained_upper;
  }
  return out;
}

void ValidateBreakageMatrix(const SizeClasses& classes, const BreakageMatrix& b,
                            const std::string& what) {
  const std::size_t n = classes.size();
  if (b.size() != n)
    throw PostError(
        fmt::format("{}: {} rows for {} size classes; expected {} x {}", what, b.size(), n, n, n));
  for (std::size_t i = 0; i < n; ++i)
    if (b[i].size() != n)
      throw PostError(
          fmt::format("{}: row {} has {} entries; expected {}", what, i, b[i].size(), n));
  for (std::size_t j = 0; j < n; ++j) {
    double sum = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double v = b[i][j];
      if (!std::isfinite(v) || v < 0.0 || v > 1.0)
        throw PostError(fmt::format(
            "{}: b[{}][{}] (from the {} class into the {} class) is {}; expected a mass "
            "fraction in [0, 1]",
            what, i, j, classes.name(j), classes.name(i), v));
      if (i < j && v > kUpperTolerance)
        throw PostError(
            fmt::format("{}: b[{}][{}] is {}: the {} class would make pieces of the coarser {} "
                        "class; expected 0 above the diagonal (breakage only makes pieces finer)",
                        what, i, j, v, classes.name(j), classes.name(i)));
      if (i >= j) sum += v;
    }
    if (std::abs(sum - 1.0) > kColumnTolerance)
      throw PostError(
          fmt::format("{}: column {} (the {} class) sums to {:.12g}; expected 1 within {:g} (a "
                      "column is where one pass puts the class's mass)",
                      what, j, classes.name(j), sum, kColumnTolerance));
  }
}

std::vector<double> SharpCutClassification(const SizeClasses& classes, double cut_mm) {
  CheckClasses(classes);
  if (!std::isfinite(cut_mm) || !(cut_mm > 0.0))
    throw PostError(fmt::format("cut size: {}; expected a size > 0 mm", cut_mm));
  const std::size_t n = classes.size();
  const double finest = classes.upper_mm[n - 1];
  if (cut_mm < finest)
    throw PostError(fmt::format(
        "cut size {} lies inside the finest size class (below {}): no class lies wholly "
        "below the cut; expected a cut at or above the finest sieve, {} (add finer sieves)",
        mm(cut_mm), mm(finest), mm(finest)));
  std::vector<double> c(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double upper = classes.upper_mm[i], lower = classes.lower_mm(i);
    if (upper <= cut_mm)
      c[i] = 0.0;
    else if (lower >= cut_mm)
      c[i] = 1.0;
    else  // the straddling class: mass even in log(size) between its edges
      c[i] = std::log(upper / cut_mm) / std::log(upper / lower);
  }
  return c;
}

CircuitState SolveCircuit(const SizeClasses& classes, const BreakageMatrix& b,
                          const std::vector<double>& c, const std::vector<double>& feed) {
  CheckCircuitInput(classes, b, c, feed);
  const std::size_t n = classes.size();
  std::vector<double> m(n, 0.0);
  // Forward substitution of (I - C B) m = f (Austin et al. 1984; Whiten 1974).
  for (std::size_t i = 0; i < n; ++i) {
    double from_coarser = 0.0;
    for (std::size_t j = 0; j < i; ++j) from_coarser += b[i][j] * m[j];
    const double inflow = feed[i] + c[i] * from_coarser;
    // The share of the class's input that leaves it per pass.
    const double leaves = 1.0 - c[i] * b[i][i];
    if (leaves < kNeverLeaves) {
      if (inflow > 0.0)
        throw PostError(fmt::format(
            "the {} class lies above the cut (returned {:.6g}) and does not break "
            "(b[{}][{}] = {:.12g}): its mass never leaves the mill and the circuit has no "
            "steady state; expected a breakage function that moves part of this class "
            "finer, or a cut above it",
            classes.name(i), c[i], i, i, b[i][i]));
      continue;  // nothing reaches it: m_i = 0
    }
    m[i] = inflow / leaves;
  }
  return StateFromInput(b, c, feed, std::move(m));
}

PassHistory IterateCircuit(const SizeClasses& classes, const BreakageMatrix& b,
                           const std::vector<double>& c, const std::vector<double>& feed,
                           double tolerance, int max_passes) {
  if (!(tolerance > 0.0))
    throw PostError(fmt::format("pass iteration: tolerance {}; expected > 0", tolerance));
  if (max_passes < 1)
    throw PostError(fmt::format("pass iteration: {} passes; expected at least 1", max_passes));
  // The direct solution first: it names a class that never leaves, where the
  // passes would never settle.
  const CircuitState direct = SolveCircuit(classes, b, c, feed);
  const std::size_t n = classes.size();
  double feed_total = 0.0;
  for (double f : feed) feed_total += f;
  PassHistory h;
  std::vector<double> m = feed, batch = feed, next(n);
  for (int pass = 1; pass <= max_passes; ++pass) {
    // What of the batch comes back after this pass: C B batch.
    double left = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      double out = 0.0;
      for (std::size_t j = 0; j <= i; ++j) out += b[i][j] * batch[j];
      next[i] = c[i] * out;
      left += next[i];
    }
    batch.swap(next);
    for (std::size_t i = 0; i < n; ++i) m[i] += batch[i];
    h.remaining.push_back(left / feed_total);
    if (left <= tolerance * feed_total) {
      h.passes = pass;
      h.state = StateFromInput(b, c, feed, std::move(m));
      return h;
    }
  }
  // The slowest class that carries mass sets the pace: its share rho per pass.
  std::size_t slow = 0;
  double rho = 0.0;
  for (std::size_t i = 0; i < n; ++i)
    if (direct.mill_input[i] > 0.0 && c[i] * b[i][i] >= rho) {
      slow = i;
      rho = c[i] * b[i][i];
    }
  throw PostError(
      fmt::format("pass iteration: after {} passes {:.3g} of a feed batch is still in the circuit "
                  "(expected at most {:g}); the {} class returns {:.6g} of its mass unbroken each "
                  "pass, so about {:.3g} passes are needed",
                  max_passes, h.remaining.back(), tolerance, classes.name(slow), rho,
                  std::log(tolerance) / std::log(rho)));
}

std::optional<double> SizeAtPercentPassing(const SizeClasses& classes,
                                           const std::vector<double>& mass, double percent) {
  CheckClasses(classes);
  CheckPerClass(classes, mass, "size distribution", 0.0, HUGE_VAL);
  double total = 0.0;
  for (double m : mass) total += m;
  if (!(total > 0.0))
    throw PostError("size distribution: expected some mass in at least one class, got none");
  // Finest first, as the passing curve reads: sieve k passes classes 0..k.
  const std::vector<double> sieves(classes.upper_mm.rbegin(), classes.upper_mm.rend());
  std::vector<double> fraction(mass.rbegin(), mass.rend());
  for (double& f : fraction) f /= total;
  return SizeAtPercentPassing(sieves, CumulativePassingPercent(fraction), percent);
}

TargetDecision LowestSpeedMeetingP80(std::vector<SpeedForP80> points, double target_mm) {
  if (points.empty()) throw PostError("P80 against rotor speed: no rotor speed");
  if (!std::isfinite(target_mm) || !(target_mm > 0.0))
    throw PostError(fmt::format("P80 target: {}; expected a size > 0 mm", target_mm));
  std::sort(points.begin(), points.end(),
            [](const SpeedForP80& a, const SpeedForP80& b) { return a.rpm < b.rpm; });
  for (std::size_t k = 1; k < points.size(); ++k)
    if (points[k].rpm == points[k - 1].rpm)
      throw PostError(fmt::format("P80 against rotor speed: {:g} rpm given twice", points[k].rpm));
  const auto met = [&](const SpeedForP80& p) { return p.p80_mm <= target_mm; };
  TargetDecision d;
  std::size_t k = 0;
  while (k < points.size() && !met(points[k])) ++k;
  if (k == points.size()) return d;  // not_met
  if (k == 0) {
    d.kind = TargetDecision::Kind::met_at_lowest;
    d.rpm = points[0].rpm;
  } else {
    const SpeedForP80 &lo = points[k - 1], &hi = points[k];
    d.kind = TargetDecision::Kind::crossed;
    d.below_rpm = lo.rpm;
    d.above_rpm = hi.rpm;
    d.interpolated = std::isfinite(lo.p80_mm);
    d.rpm = d.interpolated
                ? lo.rpm + (target_mm - lo.p80_mm) / (hi.p80_mm - lo.p80_mm) * (hi.rpm - lo.rpm)
                : hi.rpm;
  }
  for (std::size_t i = k + 1; i < points.size(); ++i)
    if (!met(points[i])) {
      d.met_above = false;
      d.first_unmet_above = points[i].rpm;
      break;
    }
  return d;
}

std::string DecisionSentence(const TargetDecision& d) {
  using K = TargetDecision::Kind;
  if (d.kind == K::not_met) return "not met at any simulated speed";
  std::string s;
  if (d.kind == K::met_at_lowest)
    s = d.met_above ? fmt::format("met at every simulated speed: lowest simulated {:g} rpm", d.rpm)
                    : fmt::format("met at the lowest simulated speed, {:g} rpm", d.rpm);
  else if (d.interpolated)
    s = fmt::format("met from {:.0f} rpm (interpolated between {:g} and {:g} rpm)", d.rpm,
                    d.below_rpm, d.above_rpm);
  else
    s = fmt::format("met from {:g} rpm (no steady state at {:g} rpm to interpolate from)", d.rpm,
                    d.below_rpm);
  if (!d.met_above) s += fmt::format(", but not at {:g} rpm", d.first_unmet_above);
  return s;
}

}  // namespace mill::post
