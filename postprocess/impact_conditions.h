// From stage 1 to stage 2 and back: the impact conditions a breakage
// campaign runs (transport impacts binned by normal speed, each bin weighted
// by its share of impacts), and the mill product (the breakage size
// distributions of those conditions weighted by the same shares).
// No driver/ includes.
#pragma once

#include <string>
#include <vector>

#include "postprocess/impact_stats.h"

namespace mill::post {

// One bin of impacts: the breakage condition that stands for it.
struct ImpactCondition {
  int bin = 0;
  double normal_low_m_s = 0, normal_high_m_s = 0;  // bin edges of the normal speed
  long long count = 0;                             // impacts in the bin
  double weight = 0;                               // count / all counted impacts
  double velocity_m_s = 0;                         // mean impact speed (relative to the surface)
  double angle_deg = 0;                            // mean angle to the surface, 90 = normal
  double normal_speed_m_s = 0;                     // mean normal speed
};

// Bin the impacts on the given surfaces ("flywheel", optionally "housing")
// into `n_bins` equal-width bins of normal speed between the smallest and
// largest; empty bins are dropped and the weights of the rest sum to 1.
// Impacts slower than `min_normal_m_s` (resting contacts) are ignored.
// Throws PostError when no impact qualifies.
std::vector<ImpactCondition> BinImpacts(const std::vector<ImpactRecord>& impacts,
                                        const std::vector<std::string>& surfaces, int n_bins,
                                        double min_normal_m_s = 0.5);

// The breakage result of one condition, averaged over its repeats.
struct ConditionBreakage {
  double weight = 0;                  // share of impacts
  std::vector<double> fraction_mass;  // size-fraction mass distribution (sums to 1)
  double single_mass_fraction = 0;
  double largest_mass_fraction = 0;
  double t10_percent = 0;
};

// The product of one pass: weighted sums over conditions (weights are
// normalised; every distribution must have the same number of fractions).
struct MillProduct {
  std::vector<double> fraction_mass;  // sums to 1
  double single_mass_fraction = 0;    // "fully shredded" share of the mass
  double largest_mass_fraction = 0;   // impact-weighted largest piece
  double t10_percent = 0;
};
MillProduct CombineProduct(const std::vector<ConditionBreakage>& conditions);

}  // namespace mill::post
