// Size distributions of broken lumps and sweep-level measures: mass per size
// fraction, t10, and the critical velocity. Used per impact and per sweep.
#pragma once

#include <optional>
#include <set>
#include <vector>

namespace mill::post {

// The reference grouping: 13 edges of relative piece size d/D, 12 fractions.
std::vector<double> DefaultFractionEdges();

// Checks edges: at least 2, finite, >= 0, strictly ascending. Throws PostError.
void ValidateFractionEdges(const std::vector<double>& edges);

// Mass fraction of pieces in each size fraction [edges[k], edges[k+1]), over
// the total mass. A piece with d/D at or above the top edge goes into the top
// fraction, one below the bottom edge into the bottom one, so the result sums
// to 1 (for any positive total mass). `d_rel` and `mass` are per piece.
std::vector<double> SizeFractionMass(const std::vector<double>& d_rel,
                                     const std::vector<double>& mass,
                                     const std::vector<double>& edges);

// Exact mass fraction (0..1) of the pieces with d/D strictly below `cut`,
// from the piece list itself (no interpolation across fraction edges).
double MassFractionFinerThan(const std::vector<double>& d_rel, const std::vector<double>& mass,
                             double cut);

// t10: the mass percent of pieces finer than D/10, exact from the piece list.
double T10Percent(const std::vector<double>& d_rel, const std::vector<double>& mass);

// Cumulative mass percent passing each sieve, from the mass per size
// fraction: fraction k holds sizes in [edges[k], edges[k+1]), so the sieve
// at edges[k+1] passes fractions 0..k. Returns one value per fraction (the
// sieves are edges[1..n]); the last is 100 when the masses sum to 1.
std::vector<double> CumulativePassingPercent(const std::vector<double>& fraction_mass);

// The size through which `percent` of the mass passes (P80 for 80), read off
// a cumulative passing curve by interpolating log-linearly between sieves:
// passing is taken as linear in log(size) between adjacent sieves (the usual
// reading of a sieve analysis). `sieves` are sizes > 0 ascending, `passing`
// the percent passing each. nullopt when even the finest sieve passes more
// than `percent` (the answer is finer than the finest sieve) or the curve
// never reaches it. Throws PostError on mismatched or unsorted input.
std::optional<double> SizeAtPercentPassing(const std::vector<double>& sieves,
                                           const std::vector<double>& passing, double percent);

// The velocity where y(v) first falls below `threshold`, walking up in
// velocity and interpolating linearly between the last point at or above it
// and the first point below it. Points are sorted by velocity here; several
// values at one velocity are averaged first. If the first point is already
// below, its velocity is returned (an upper bound). nullopt if never below.
std::optional<double> FirstCrossingBelow(const std::vector<double>& velocity,
                                         const std::vector<double>& y, double threshold);

// One (velocity, repeat, largest piece fraction) point of a sweep at one angle.
struct SweepPoint {
  double velocity_m_s = 0.0;
  int repeat = 0;
  double value = 0.0;
};

// The critical velocity of a sweep: from the repeat-averaged curve, and its
// spread over the repeats (each repeat's own curve).
struct CriticalVelocity {
  std::optional<double> of_mean_curve;            // m/s
  std::vector<int> repeats;                       // repeat ids, ascending
  std::vector<std::optional<double>> per_repeat;  // m/s, same order
  std::optional<double> min, max, mean, stddev;   // over repeats that cross, m/s
  int n_crossed = 0;                              // repeats whose curve falls below
};

// The repeat ids present at every velocity of the points: the repeats whose
// own curve spans the sweep. A sweep with more repeats at some speeds
// (breakage.crossing_velocities) has further repeats only there.
std::set<int> RepeatsAtEveryVelocity(const std::vector<SweepPoint>& points);

// The critical velocity where the largest-piece fraction first falls below
// `threshold` (method.md: "shattered"), for the points of one impact angle:
// the repeat-averaged curve from every point; the per-repeat curves (and
// their spread) of the repeats at every velocity only.
// stddev is the sample standard deviation (n-1), absent for fewer than two.
CriticalVelocity FindCriticalVelocity(const std::vector<SweepPoint>& points, double threshold);

// True when the repeat-averaged curve is already below `threshold` at the
// slowest velocity of the sweep: FindCriticalVelocity then returns that
// velocity, an upper bound of the critical one, not a crossing.
bool BelowAtSlowest(const std::vector<SweepPoint>& points, double threshold);

// The repeat-averaged curve of a sweep's points read at `velocity`: values at
// one velocity are averaged, and the curve is linear between the velocities
// around it. nullopt outside the swept velocities or without points. Used for
// a quantity at the critical velocity (the comminution efficiency there).
std::optional<double> MeanCurveAt(const std::vector<SweepPoint>& points, double velocity);

}  // namespace mill::post
