// The energy of the closed mill circuit per tonne of fresh feed: the ore
// power, the beater's work per kg of each class's in-mill lumps weighted by
// that class's steady mill input (fresh feed plus returned load, every pass
// through the rotor counted), plus the gas's shaft power, over the feed
// rate; and its value at the decided rotor speed. docs/population_balance.md,
// "Energy per tonne". Classes are numbered coarsest first, as in
// population_balance.h.
#pragma once

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "postprocess/population_balance.h"

namespace mill::post {

// The beater's work on one in-mill lump over its run (its energy ledger's
// work_beater_J) and the lump's mass.
struct LumpWork {
  double work_J = 0;
  double mass_kg = 0;
};

// w of a set of lumps: their summed work over their summed mass, J/kg.
// Throws PostError when there is no lump, no mass or a work that is not finite.
double BeaterWorkPerKg(const std::vector<LumpWork>& lumps);

// The beater work per kg that a class's mill input is charged.
struct ClassWork {
  double J_per_kg = 0;
  bool measured = false;  // from the class's own lumps
  std::size_t from = 0;   // the class whose lumps gave it (itself when measured)
};

// w for every class from the measured ones (class -> J/kg): a measured class
// keeps its own; every other class (no lumps of its own: a scaled column, or
// the finest class) takes the w of the measured class nearest in
// log(representative size), the coarser of two equally near
// (NearestMeasuredClass of breakage_matrix.h). Throws PostError when nothing
// is measured.
std::vector<ClassWork> BeaterWorkPerClass(const SizeClasses& classes,
                                          const std::map<std::size_t, double>& measured_J_per_kg);

// The energy of one rotor speed.
struct CircuitEnergy {
  std::vector<double> ore_power_W;  // per class: m_i [kg/s] x w_i
  double ore_W = 0;                 // sum of ore_power_W
  std::optional<double> gas_W;      // the gas's shaft power, when the flow ran
  double ore_kWh_t = 0;             // ore_W [kW] / feed [t/h]
  double total_kWh_t = 0;           // (gas + ore) [kW] / feed [t/h]; the ore's alone without gas
  double passes_per_tonne = 0;      // sum(m) / sum(f) = 1 + circulating load
};

// P_ore = sum_i m_i w_i with m_i the steady mill input of class i
// (mill_input_t_h, t/h, from SolveCircuit), kWh/t = (P_gas + P_ore) [kW] /
// feed [t/h], per tonne of fresh feed (feed_t_h: its total). Throws
// PostError on sizes that differ or a feed that is not > 0.
CircuitEnergy MillEnergyPerTonne(const std::vector<double>& mill_input_t_h,
                                 const std::vector<ClassWork>& work, std::optional<double> gas_W,
                                 double feed_t_h);

// A quantity known at the simulated rotor speeds, read at the decision's
// speed: for `crossed` interpolated linearly in rpm between below_rpm and
// above_rpm with the weights that gave the decided rpm (the faster speed's
// own when not interpolated), for `met_at_lowest` that speed's own;
// nullopt when the target is not met or a speed it needs has no value.
std::optional<double> ValueAtDecision(const TargetDecision& d,
                                      const std::map<double, double>& value_by_rpm);

// The energy at the decided speed (ValueAtDecision of by_rpm): the total
// kWh/t when with_gas (every simulated speed has the gas's shaft power),
// else the ore's alone (ore_only), so that the decision never mixes a speed
// with gas and one without.
struct DecisionEnergy {
  std::optional<double> kWh_t;  // nullopt: not met, or a speed it needs has no energy
  bool ore_only = false;
};
DecisionEnergy EnergyAtDecision(const TargetDecision& d,
                                const std::map<double, CircuitEnergy>& by_rpm, bool with_gas);

// The decision in one sentence with its energy: DecisionSentence(d), then
// ", at 3.1 kWh/t" when kWh_t has a value (" (ore only: not every speed
// has a gas flow run)" when ore_only).
std::string DecisionSentence(const TargetDecision& d, std::optional<double> kWh_t, bool ore_only);

}  // namespace mill::post
