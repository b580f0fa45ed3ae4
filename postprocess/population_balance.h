// The population balance of a closed mill circuit: size classes, a breakage
// matrix, the mill's classification at its cut, and the steady state of the
// circuit (what leaves, what goes round again). The matrix form follows the
// classification-breakage model of a closed circuit (Whiten 1974, Chem. Eng.
// Sci. 29; Lynch 1977, "Mineral Crushing and Grinding Circuits") in the notation of Austin,
// Klimpel & Luckie (1984), "Process Engineering of Size Reduction: Ball
// Milling": docs/population_balance.md holds the equations. Called once per
// rotor speed, after the breakage of each size class is known.
//
// Convention: every vector and matrix here numbers the classes coarsest first
// (class 0 is the coarsest), so that breakage, which only makes pieces finer,
// gives a lower-triangular matrix. Masses are in any one unit (t/h, kg or
// fractions of the feed); results carry the unit of the feed.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace mill::post {

// Size classes, coarsest first: class i holds the pieces in
// [upper_mm[i+1], upper_mm[i]) (they pass sieve upper_mm[i] and stay on
// sieve upper_mm[i+1]); the finest class, the last, runs down to 0.
struct SizeClasses {
  std::vector<double> upper_mm;  // strictly descending, > 0

  std::size_t size() const { return upper_mm.size(); }
  // Lower edge of class i: the next finer sieve, 0 for the finest class.
  double lower_mm(std::size_t i) const;
  // "class 2 (20-31.5 mm)": a class in messages.
  std::string name(std::size_t i) const;
};

// Size classes from their upper edges, coarsest first. Throws PostError
// unless there is at least one, each finite and > 0, strictly descending.
SizeClasses MakeSizeClasses(std::vector<double> upper_mm);

// Size classes from sieve sizes in ascending order (as a case file lists
// them, feed.sizes_mm): the same sieves, numbered coarsest first.
SizeClasses SizeClassesFromSieves(const std::vector<double>& ascending_mm);

// A geometric sieve series of n classes: upper edges top_mm, top_mm / ratio,
// top_mm / ratio^2, ... (ratio > 1; sqrt(2) is the Tyler series).
SizeClasses GeometricSieveSeries(double top_mm, double ratio, std::size_t n);

// The representative size of class i: the geometric mean of its edges. The
// finest class, whose lower edge is 0, takes the lower edge the series would
// give it (its upper edge over the ratio of the two finest sieves; over
// sqrt(2) when there is one class).
double RepresentativeSize(const SizeClasses& classes, std::size_t i);

// Mass fractions of a Rosin-Rammler distribution (Rosin & Rammler 1933,
// J. Inst. Fuel 7: passing F(d) = 1 - exp(-(d/d63)^n)) over the classes:
// class i gets F(upper) - F(lower); the top class also takes the tail above
// the top sieve, exp(-(top/d63)^n), so that the fractions sum to 1.
// `ascending_mm` are the sieves ascending; the result is in the same order.
std::vector<double> RosinRammlerFractions(const std::vector<double>& ascending_mm, double d63_mm,
                                          double n);

// Rosin-Rammler: the mass fraction coarser than d_mm, exp(-(d/d63)^n).
double RosinRammlerRetained(double d_mm, double d63_mm, double n);

// A breakage matrix: b[i][j] is the mass fraction of class j's mill input
// that leaves one pass through the rotor in class i (Austin et al. 1984:
// column j is the breakage function of class j, its diagonal the part that
// stays in its class). Lower-triangular (nothing gets coarser), each column
// sums to 1 (mass is conserved), entries in [0, 1].
using BreakageMatrix = std::vector<std::vector<double>>;

// Throws PostError naming the entry unless `b` is n x n, finite, in [0, 1],
// zero above the diagonal (within 1e-12) and its columns sum to 1 within
// 1e-9; `what` names the matrix in messages.
void ValidateBreakageMatrix(const SizeClasses& classes, const BreakageMatrix& b,
                            const std::string& what = "breakage matrix");

// The classification at a sharp cut (the outlet grate or classifier of
// aperture cut_mm): c[i] is the mass fraction of class i in the mill's output
// that is returned to the rotor. A class wholly above the cut (lower edge >=
// cut) returns all (1); one wholly below (upper edge <= cut) none (0); the
// class that straddles the cut returns the part above it, its mass taken as
// spread evenly over log(size): c = ln(upper/cut) / ln(upper/lower). Throws
// PostError when the cut is not above the finest class's upper edge (then no
// class lies wholly below the cut, and the finest class has no lower edge to
// interpolate to).
std::vector<double> SharpCutClassification(const SizeClasses& classes, double cut_mm);

// The steady state of the closed circuit (Whiten 1974; Austin et al. 1984):
// with fresh feed f, mill input m, one pass O = B m, returned C O, product
// P = (I - C) O and C = diag(c):
//     m = f + C B m   =>   (I - C B) m = f,    P = (I - C) B m.
struct CircuitState {
  std::vector<double> mill_input;   // m: fresh feed plus returned, per class
  std::vector<double> mill_output;  // B m: what one pass makes of it
  std::vector<double> returned;     // C B m: above the cut, back to the rotor
  std::vector<double> product;      // (I - C) B m: leaves through the cut
  double feed_total = 0;
  double product_total = 0;
  // Mass returned per mass of fresh feed (sum C B m / sum f).
  double circulating_load = 0;
  // |product_total - feed_total| / feed_total: 0 but for rounding.
  double mass_balance_residual = 0;
};

// The steady state solved exactly: I - C B is lower triangular (B is, C is
// diagonal), so m follows by forward substitution from the coarsest class:
//     m_i = (f_i + c_i sum_{j<i} b_ij m_j) / (1 - c_i b_ii).
// Throws PostError on bad input (sizes that differ, c outside [0, 1], a
// negative feed or none at all) and, naming the class, when a class that
// receives mass returns all of it unbroken (c_i b_ii = 1: it never leaves).
CircuitState SolveCircuit(const SizeClasses& classes, const BreakageMatrix& b,
                          const std::vector<double>& c, const std::vector<double>& feed);

// The circuit pass by pass: m(0) = f, m(k+1) = f + C B m(k). m(k+1) - m(k) =
// (C B)^(k+1) f is what is left in the circuit of a batch of feed after k+1
// passes, so the iteration is also the history of one batch.
struct PassHistory {
  CircuitState state;             // after the last pass
  int passes = 0;                 // passes until converged
  std::vector<double> remaining;  // per pass: a feed batch's mass still in the circuit / feed
};

// Iterates until a batch's remaining mass falls to `tolerance` x the feed.
// Throws PostError as SolveCircuit does, and naming the slowest class when
// max_passes are not enough.
PassHistory IterateCircuit(const SizeClasses& classes, const BreakageMatrix& b,
                           const std::vector<double>& c, const std::vector<double>& feed,
                           double tolerance = 1e-12, int max_passes = 100000);

// The size through which `percent` of the mass of a distribution over the
// classes passes (P80 for 80), by the convention of the breakage stage's
// product: cumulative passing at each class's upper edge, log-linear between
// adjacent sieves (CumulativePassingPercent and SizeAtPercentPassing of
// distributions.h). nullopt when the answer is finer than the finest sieve.
// `mass` is per class, coarsest first, in any unit (normalised here).
std::optional<double> SizeAtPercentPassing(const SizeClasses& classes,
                                           const std::vector<double>& mass, double percent);

// The lowest rotor speed at which the product's P80 meets a target (P80 at
// or below it), from the P80 at each simulated speed.
struct SpeedForP80 {
  double rpm = 0;     // a speed: simulated or interpolated
  double p80_mm = 0;  // P80 (mm); +inf: no steady state at that speed
};
struct TargetDecision {
  // crossed: P80 crosses the target between two simulated speeds, `rpm`
  // interpolated linearly in rpm between them (or the faster of them when
  // the slower has no steady state: nothing to interpolate from);
  // met_at_lowest: met already at the lowest simulated speed, `rpm` (no
  // crossing below it); not_met: met at no simulated speed.
  enum class Kind { crossed, met_at_lowest, not_met } kind = Kind::not_met;
  double rpm = 0;
  double below_rpm = 0;          // crossed: the slower speed of the pair
  double above_rpm = 0;          // crossed: the faster speed of the pair
  bool interpolated = false;     // crossed: between two P80s (else the faster speed)
  bool met_above = true;         // met at every simulated speed above `rpm` too
  double first_unmet_above = 0;  // when not met_above: the slowest such speed
};

// Walks up in rotor speed (the points are sorted here; at least one, speeds
// distinct) to the first speed whose P80 is at or below target_mm and
// interpolates between it and the speed before: rpm = r0 + (target - p0) /
// (p1 - p0) (r1 - r0). A P80 finer than the finest sieve is passed as that
// sieve (an upper bound, which meets any target at or above it). Throws
// PostError on no point, a repeated speed or a target that is not > 0.
TargetDecision LowestSpeedMeetingP80(std::vector<SpeedForP80> points, double target_mm);

// The decision in one sentence, e.g. "met from 2240 rpm (interpolated
// between 2000 and 2500 rpm)", "met at every simulated speed: lowest
// simulated 2000 rpm", "not met at any simulated speed".
std::string DecisionSentence(const TargetDecision& d);

}  // namespace mill::post
