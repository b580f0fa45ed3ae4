// The cuts of fix balance/weighted (docs/styles/fix_balance_weighted.md):
// where to cut a set of weighted points along one axis into parts of equal
// weight, and how far a cut may move in one re-balance. No LIGGGHTS here: the
// unit tests check it against hand counts.
#ifndef MILL_BALANCE_CUTS_H
#define MILL_BALANCE_CUTS_H

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace mill::balance {

struct Point {
  double x = 0;  // coordinate along the axis
  double w = 0;  // weight (> 0)
};

// The parts - 1 cuts that split `points` into parts groups of consecutive
// points (sorted by x) whose weights are as near total / parts as a whole
// point allows: cut k lies midway between the last point of the first k
// groups and the next point, the first k groups holding the prefix of
// points whose weight is nearest k / parts of the total. Fewer points than
// parts, or none: no cuts (an empty vector).
inline std::vector<double> weighted_cuts(std::vector<Point> points, int parts) {
  const std::size_t n = points.size();
  if (parts < 2 || n < static_cast<std::size_t>(parts)) return {};
  std::sort(points.begin(), points.end(), [](const Point &a, const Point &b) { return a.x < b.x; });
  std::vector<double> prefix(n + 1, 0.0);  // prefix[b] = weight of the first b points
  for (std::size_t i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + points[i].w;
  const double total = prefix[n];
  std::vector<double> cuts;
  std::size_t b_prev = 0;
  for (int k = 1; k < parts; ++k) {
    const double target = total * k / parts;
    // The first prefix at or above the target, or the one before it.
    std::size_t b = static_cast<std::size_t>(
        std::lower_bound(prefix.begin(), prefix.end(), target) - prefix.begin());
    if (b > 0 && target - prefix[b - 1] <= prefix[std::min(b, n)] - target) --b;
    // Every group keeps at least one point.
    b = std::clamp(b, b_prev + 1, n - static_cast<std::size_t>(parts - k));
    cuts.push_back(0.5 * (points[b - 1].x + points[b].x));
    b_prev = b;
  }
  return cuts;
}

// Cut k (1..parts-1, absolute coordinates) moved to `wanted`, but no further
// than `margin` short of the previous cuts k - 1 and k + 1 (old[k - 1] and
// old[k + 1], the ends -inf and +inf): then no point owned under the old cuts
// (and moved less than margin since) is owned more than one part away under
// the new, so the ordinary exchange with the neighbouring ranks moves it.
// old holds parts + 1 values: old[0] and old[parts] are the box ends (not used).
inline double limited_cut(const std::vector<double> &old, int k, double wanted, double margin) {
  const int parts = static_cast<int>(old.size()) - 1;
  const double lo = k - 1 >= 1 ? old[k - 1] + margin : -std::numeric_limits<double>::infinity();
  const double hi =
      k + 1 <= parts - 1 ? old[k + 1] - margin : std::numeric_limits<double>::infinity();
  if (lo > hi) return old[k];
  return std::clamp(wanted, lo, hi);
}

}  // namespace mill::balance

#endif
