// The closed circuit of each rotor speed from its in-mill lumps, and the
// band that the lumps give: a bootstrap over the lumps (Efron & Tibshirani
// 1993, "An Introduction to the Bootstrap": resampling with replacement,
// percentile interval). Per draw, each measured class's lumps are resampled
// at each rotor speed, the breakage matrix and the beater work per kg are
// rebuilt from the drawn lumps, the circuit is re-solved and the decision
// redone; the band is the 10th to 90th percentile over the draws of P80 and
// kWh/t per speed, the decided rpm and its kWh/t. docs/population_balance.md,
// "The band the lumps give". Classes are numbered coarsest first.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "postprocess/breakage_matrix.h"
#include "postprocess/circuit_energy.h"
#include "postprocess/population_balance.h"

namespace mill::post {

// One in-mill lump: its pieces and the beater's work on it.
struct LumpRun {
  LumpPieces pieces;
  LumpWork work;
};

// The lumps of one rotor speed per measured class.
struct SpeedLumps {
  double rpm = 0;
  std::map<std::size_t, std::vector<LumpRun>> by_class;
  std::optional<double> gas_W;  // the gas's shaft power, when the flow ran
};

// What every rotor speed shares: the classes, the classification at the
// cut, the fresh feed per class (t/h) and the P80 target, if any.
struct CircuitSetup {
  SizeClasses classes;
  std::vector<double> c;
  std::vector<double> feed_t_h;
  std::optional<double> target_p80_mm;
};

// One rotor speed from its lumps.
struct SpeedOutcome {
  AssembledMatrix matrix;
  std::vector<ClassWork> work;
  bool steady = false;
  std::string problem;  // when not steady: SolveCircuit's message
  CircuitState state;
  // P80 for the decision: finer than the finest sieve counts as that sieve,
  // no steady state as +inf.
  double p80_mm = HUGE_VAL;
  CircuitEnergy energy;  // when steady
};

// The matrix (MeasuredBreakageColumn per measured class,
// AssembleBreakageMatrix), the beater work per class (BeaterWorkPerKg of
// each class's lumps, BeaterWorkPerClass), the steady state (SolveCircuit),
// P80 and the energy per tonne (MillEnergyPerTonne).
SpeedOutcome EvaluateSpeed(const CircuitSetup& setup, const SpeedLumps& speed);

// The decision of the target from the outcomes of the speeds (in the order
// of `speeds`): LowestSpeedMeetingP80 on their p80_mm. setup must have a target.
TargetDecision DecideFromOutcomes(const CircuitSetup& setup, const std::vector<SpeedLumps>& speeds,
                                  const std::vector<SpeedOutcome>& outcomes);

struct BootstrapOptions {
  int draws = 400;
  std::uint64_t seed = 12345;
  double low_percent = 10;
  double high_percent = 90;
};

// A percentile interval; +inf where the draws at that percentile did not
// meet the target or had no steady state.
struct Interval {
  double low = 0;
  double high = 0;
};

struct SpeedBand {
  double rpm = 0;
  Interval p80_mm;                // over all draws (no steady state: +inf)
  std::optional<Interval> kWh_t;  // over the draws with a steady state
  int steady_draws = 0;
};

struct CircuitBand {
  bool defined = false;
  std::string reason;  // when not defined
  int draws = 0;
  std::uint64_t seed = 0;
  double low_percent = 0, high_percent = 0;
  std::vector<SpeedBand> speeds;  // in the order given
  // With a target:
  bool has_target = false;
  Interval rpm;                   // over all draws, a draw that meets it nowhere as +inf
  int met_draws = 0;              // draws in which some speed meets the target
  std::optional<Interval> kWh_t;  // at the decided speed, over the draws with it
  int kWh_t_draws = 0;
};

// The bootstrap: per draw, for each speed in order and each measured class
// (coarsest first), as many lumps as the class has, drawn with replacement
// (std::mt19937_64 seeded with options.seed, index = draw mod count; each
// lump's pieces binned on the classes once beforehand, which gives the same
// columns to rounding); each
// speed evaluated as EvaluateSpeed does, the decision as
// DecideFromOutcomes, its kWh/t as EnergyAtDecision (with the gas when
// every speed has it). Percentiles: linear
// between order statistics at (N - 1) p / 100 (Hyndman & Fan 1996, type 7).
// Not defined, with the reason "1 lump per class: no band", when no measured
// class at any speed has two lumps or more. The same seed gives the same band.
CircuitBand BootstrapCircuit(const CircuitSetup& setup, const std::vector<SpeedLumps>& speeds,
                             const BootstrapOptions& options = {});

// The percentile p (0-100) of values, linear between order statistics at
// (N - 1) p / 100; +inf when a neighbour is +inf. Throws PostError when empty.
double Percentile(std::vector<double> values, double p);

// "10-90 % of 400 lump resamples: 2100-2400 rpm, 2.9-3.3 kWh/t", or the
// reason there is no band.
std::string BandSentence(const CircuitBand& band);

}  // namespace mill::post
