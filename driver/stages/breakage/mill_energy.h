// The energy of the mill per tonne of feed, per rotor speed, for a case with
// a feed: the gas's shaft power (the flow stage's flow_report.json `shaft`,
// when that rotor speed's flow ran) plus the ore power, the work the beater
// gave the in-mill lumps (their energy ledgers' work_beater_J) per kg of
// lump times the feed rate, over the feed rate (docs/population_balance.md,
// "Energy per tonne"). Goes into breakage/circuit.json.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <vector>

#include "stages/stage.h"

namespace mill::breakage {

// What the energy per tonne of one rotor speed is made of.
struct MillEnergy {
  double beater_work_J = 0;  // summed over the in-mill runs
  double lump_mass_kg = 0;   // summed over the in-mill runs
  int lumps = 0;
  bool has_gas = false;  // flow/<rpm>/flow_report.json has shaft.power_W
  double gas_shaft_power_W = 0;
};

// Per rotor speed, the in-mill runs' beater work and mass among `jobs`
// (in_mill.json) and the gas shaft power of flow/<rpm>/flow_report.json.
std::map<double, MillEnergy> read_mill_energy(const StageContext& ctx,
                                              const std::vector<JobSpec>& jobs);

// circuit.json's `energy` of one rotor speed at the feed rate rate_tph:
//   ore power P_ore = (beater work / lump mass) x rate [kg/s],
//   kWh/t = (P_gas + P_ore) [kW] / rate [t/h];
// without a flow report the gas part is null and kWh/t is the ore's alone.
nlohmann::json energy_json(const MillEnergy& e, double rate_tph);

}  // namespace mill::breakage
