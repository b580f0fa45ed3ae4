// Size fractions, t10 and critical velocity; see distributions.h.
#include "postprocess/distributions.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>

#include "postprocess/fragments.h"

namespace mill::post {
namespace {

// Throws unless per-piece arrays have the same length and masses are >= 0.
void CheckPieces(const std::vector<double>& d_rel, const std::vector<double>& mass) {
  if (d_rel.size() != mass.size()) {
    throw PostError(fmt::format("piece lists differ in length: {} sizes, {} masses", d_rel.size(),
                                mass.size()));
  }
  for (std::size_t k = 0; k < mass.size(); ++k) {
    if (!(mass[k] >= 0.0)) {
      throw PostError(fmt::format("piece {} has mass {} kg; expected >= 0", k, mass[k]));
    }
  }
}

}  // namespace

// The reference 12-fraction grouping.
std::vector<double> DefaultFractionEdges() {
  return {0.0, 0.05, 0.075, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.85, 1.0};
}

// Rejects edge lists that do not define ascending fractions.
void ValidateFractionEdges(const std::vector<double>& edges) {
  if (edges.size() < 2) {
    throw PostError(fmt::format("breakage.size_fraction_edges: expected at least 2 edges, got {}",
                                edges.size()));
  }
  for (std::size_t k = 0; k < edges.size(); ++k) {
    if (!std::isfinite(edges[k]) || edges[k] < 0.0) {
      throw PostError(fmt::format(
          "breakage.size_fraction_edges[{}]: expected a relative size >= 0, got {}", k, edges[k]));
    }
    if (k > 0 && !(edges[k] > edges[k - 1])) {
      throw PostError(
          fmt::format("breakage.size_fraction_edges[{}]: edges must ascend, got {} after {}", k,
                      edges[k], edges[k - 1]));
    }
  }
}

// Mass per size fraction, normalised by the total mass.
std::vector<double> SizeFractionMass(const std::vector<double>& d_rel,
                                     const std::vector<double>& mass,
                                     const std::vector<double>& edges) {
  ValidateFractionEdges(edges);
  CheckPieces(d_rel, mass);
  const std::size_t n_fractions = edges.size() - 1;
  std::vector<double> out(n_fractions, 0.0);
  double total = 0.0;
  for (std::size_t p = 0; p < d_rel.size(); ++p) {
    // First edge strictly above d_rel; the fraction is the one below that edge.
    const auto above = std::upper_bound(edges.begin(), edges.end(), d_rel[p]);
    std::size_t k =
        above == edges.begin() ? 0 : static_cast<std::size_t>(above - edges.begin()) - 1;
    k = std::min(k, n_fractions - 1);
    out[k] += mass[p];
    total += mass[p];
  }
  if (total > 0.0) {
    for (double& m : out) m /= total;
  }
  return out;
}

// Exact mass fraction of pieces finer than `cut`.
double MassFractionFinerThan(const std::vector<double>& d_rel, const std::vector<double>& mass,
                             double cut) {
  CheckPieces(d_rel, mass);
  double finer = 0.0, total = 0.0;
  for (std::size_t p = 0; p < d_rel.size(); ++p) {
    total += mass[p];
    if (d_rel[p] < cut) finer += mass[p];
  }
  return total > 0.0 ? finer / total : 0.0;
}

// t10 in percent.
double T10Percent(const std::vector<double>& d_rel, const std::vector<double>& mass) {
  return 100.0 * MassFractionFinerThan(d_rel, mass, 0.1);
}

// Running sum of the fraction masses, in percent.
std::vector<double> CumulativePassingPercent(const std::vector<double>& fraction_mass) {
  std::vector<double> out;
  out.reserve(fraction_mass.size());
  double sum = 0.0;
  for (double m : fraction_mass) {
    sum += m;
    out.push_back(100.0 * sum);
  }
  return out;
}

// Pxx by log-linear interpolation between the two sieves around it.
std::optional<double> SizeAtPercentPassing(const std::vector<double>& sieves,
                                           const std::vector<double>& passing, double percent) {
  if (sieves.size() != passing.size() || sieves.empty()) {
    throw PostError(fmt::format("passing curve: {} sieves but {} passing values", sieves.size(),
                                passing.size()));
  }
  for (std::size_t k = 0; k < sieves.size(); ++k) {
    if (!(sieves[k] > 0.0) || (k > 0 && !(sieves[k] > sieves[k - 1]))) {
      throw PostError(fmt::format(
          "passing curve: sieve {} is {}; expected sizes > 0 in ascending order", k, sieves[k]));
    }
  }
  // Percent passing is a running sum: a small dip from rounding is levelled.
  double prev_p = 0.0;
  for (std::size_t k = 0; k < sieves.size(); ++k) {
    const double p = std::max(passing[k], prev_p);
    if (p >= percent) {
      if (k == 0) {
        if (p == percent) return sieves[0];
        return std::nullopt;  // finer than the finest sieve
      }
      const double t = (percent - prev_p) / (p - prev_p);
      return std::exp(std::log(sieves[k - 1]) +
                      t * (std::log(sieves[k]) - std::log(sieves[k - 1])));
    }
    prev_p = p;
  }
  return std::nullopt;
}

// First downward crossing of `threshold`, linearly interpolated.
std::optional<double> FirstCrossingBelow(const std::vector<double>& velocity,
                                         const std::vector<double>& y, double threshold) {
  if (velocity.size() != y.size()) {
    throw PostError(
        fmt::format("critical velocity: {} velocities but {} values", velocity.size(), y.size()));
  }
  std::map<double, std::pair<double, int>> by_v;  // velocity -> (sum, count)
  for (std::size_t k = 0; k < velocity.size(); ++k) {
    auto& acc = by_v[velocity[k]];
    acc.first += y[k];
    acc.second += 1;
  }
  bool have_prev = false;
  double v_prev = 0.0, y_prev = 0.0;
  for (const auto& [v, acc] : by_v) {
    const double yv = acc.first / acc.second;
    if (yv < threshold) {
      if (!have_prev) return v;
      return v_prev + (threshold - y_prev) * (v - v_prev) / (yv - y_prev);
    }
    have_prev = true;
    v_prev = v;
    y_prev = yv;
  }
  return std::nullopt;
}

bool BelowAtSlowest(const std::vector<SweepPoint>& points, double threshold) {
  if (points.empty()) return false;
  double vmin = points.front().velocity_m_s;
  for (const auto& p : points) vmin = std::min(vmin, p.velocity_m_s);
  double sum = 0.0;
  int n = 0;
  for (const auto& p : points)
    if (p.velocity_m_s == vmin) {
      sum += p.value;
      ++n;
    }
  return sum / n < threshold;
}

// Critical velocity of the mean curve and of each repeat.
std::set<int> RepeatsAtEveryVelocity(const std::vector<SweepPoint>& points) {
  std::map<double, std::set<int>> at;  // velocity -> its repeat ids
  for (const SweepPoint& p : points) at[p.velocity_m_s].insert(p.repeat);
  if (at.empty()) return {};
  std::set<int> every = at.begin()->second;
  for (const auto& [v, ids] : at) {
    std::set<int> both;
    std::set_intersection(every.begin(), every.end(), ids.begin(), ids.end(),
                          std::inserter(both, both.begin()));
    every = std::move(both);
  }
  return every;
}

CriticalVelocity FindCriticalVelocity(const std::vector<SweepPoint>& points, double threshold) {
  CriticalVelocity out;
  const std::set<int> whole = RepeatsAtEveryVelocity(points);
  std::vector<double> v_all, y_all;
  std::map<int, std::pair<std::vector<double>, std::vector<double>>> by_repeat;
  for (const SweepPoint& p : points) {
    v_all.push_back(p.velocity_m_s);
    y_all.push_back(p.value);
    if (!whole.count(p.repeat)) continue;  // a repeat at some speeds only: the mean curve's
    by_repeat[p.repeat].first.push_back(p.velocity_m_s);
    by_repeat[p.repeat].second.push_back(p.value);
  }
  out.of_mean_curve = FirstCrossingBelow(v_all, y_all, threshold);
  std::vector<double> crossed;
  for (const auto& [repeat, curve] : by_repeat) {
    out.repeats.push_back(repeat);
    out.per_repeat.push_back(FirstCrossingBelow(curve.first, curve.second, threshold));
    if (out.per_repeat.back()) crossed.push_back(*out.per_repeat.back());
  }
  out.n_crossed = static_cast<int>(crossed.size());
  if (!crossed.empty()) {
    out.min = *std::min_element(crossed.begin(), crossed.end());
    out.max = *std::max_element(crossed.begin(), crossed.end());
    double sum = 0.0;
    for (double c : crossed) sum += c;
    out.mean = sum / crossed.size();
    if (crossed.size() > 1) {
      double ss = 0.0;
      for (double c : crossed) ss += (c - *out.mean) * (c - *out.mean);
      out.stddev = std::sqrt(ss / (crossed.size() - 1));
    }
  }
  return out;
}

// The mean curve at one velocity, linear between sweep velocities.
std::optional<double> MeanCurveAt(const std::vector<SweepPoint>& points, double velocity) {
  std::map<double, std::pair<double, int>> by_v;  // velocity -> (sum, count)
  for (const SweepPoint& p : points) {
    auto& acc = by_v[p.velocity_m_s];
    acc.first += p.value;
    acc.second += 1;
  }
  const auto above = by_v.lower_bound(velocity);
  if (above == by_v.end()) return std::nullopt;
  const double y1 = above->second.first / above->second.second;
  if (above->first == velocity) return y1;
  if (above == by_v.begin()) return std::nullopt;
  const auto below = std::prev(above);
  const double y0 = below->second.first / below->second.second;
  return y0 + (y1 - y0) * (velocity - below->first) / (above->first - below->first);
}

}  // namespace mill::post
