// Binning of transport impacts and the weighted mill product.
#include "postprocess/impact_conditions.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "postprocess/fragments.h"

namespace mill::post {

std::vector<ImpactCondition> BinImpacts(const std::vector<ImpactRecord>& impacts,
                                        const std::vector<std::string>& surfaces, int n_bins,
                                        double min_normal_m_s) {
  if (n_bins < 1) throw PostError(fmt::format("number of velocity bins must be >= 1, got {}", n_bins));
  std::vector<const ImpactRecord*> use;
  for (const auto& r : impacts)
    if (std::find(surfaces.begin(), surfaces.end(), r.surface) != surfaces.end() &&
        r.normal_speed_m_s >= min_normal_m_s)
      use.push_back(&r);
  if (use.empty())
    throw PostError(fmt::format("no impact on the chosen surfaces with a normal speed of at least {:g} m/s",
                                min_normal_m_s));
  double lo = use.front()->normal_speed_m_s, hi = lo;
  for (const auto* r : use) lo = std::min(lo, r->normal_speed_m_s), hi = std::max(hi, r->normal_speed_m_s);
  const double width = hi > lo ? (hi - lo) / n_bins : 1.0;
  std::vector<ImpactCondition> bins(n_bins);
  for (int b = 0; b < n_bins; ++b) {
    bins[b].bin = b;
    bins[b].normal_low_m_s = lo + b * width;
    bins[b].normal_high_m_s = lo + (b + 1) * width;
  }
  for (const auto* r : use) {
    const int b = std::min(n_bins - 1, static_cast<int>((r->normal_speed_m_s - lo) / width));
    auto& c = bins[b];
    ++c.count;
    c.velocity_m_s += r->speed_m_s;
    c.angle_deg += r->angle_deg;
    c.normal_speed_m_s += r->normal_speed_m_s;
  }
  std::vector<ImpactCondition> out;
  for (auto& c : bins) {
    if (c.count == 0) continue;
    c.velocity_m_s /= c.count;
    c.angle_deg /= c.count;
    c.normal_speed_m_s /= c.count;
    c.weight = static_cast<double>(c.count) / use.size();
    out.push_back(c);
  }
  return out;
}

MillProduct CombineProduct(const std::vector<ConditionBreakage>& conditions) {
  if (conditions.empty()) throw PostError("no breakage conditions to combine");
  double wsum = 0;
  for (const auto& c : conditions) {
    if (!(c.weight >= 0)) throw PostError(fmt::format("condition weight must be >= 0, got {}", c.weight));
    if (c.fraction_mass.size() != conditions.front().fraction_mass.size())
      throw PostError(fmt::format("size distributions differ in length: {} and {} fractions",
                                  c.fraction_mass.size(), conditions.front().fraction_mass.size()));
    wsum += c.weight;
  }
  if (!(wsum > 0)) throw PostError("condition weights sum to zero");
  MillProduct p;
  p.fraction_mass.assign(conditions.front().fraction_mass.size(), 0.0);
  for (const auto& c : conditions) {
    const double w = c.weight / wsum;
    for (size_t i = 0; i < c.fraction_mass.size(); ++i) p.fraction_mass[i] += w * c.fraction_mass[i];
    p.single_mass_fraction += w * c.single_mass_fraction;
    p.largest_mass_fraction += w * c.largest_mass_fraction;
    p.t10_percent += w * c.t10_percent;
  }
  return p;
}

}  // namespace mill::post
