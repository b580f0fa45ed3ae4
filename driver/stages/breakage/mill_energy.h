// The energy of the mill per tonne of fresh feed, per rotor speed, for a
// case with a feed: the gas's shaft power (the flow stage's
// flow_report.json `shaft`, when that rotor speed's flow ran) plus the ore
// power, each class's steady mill input times the beater work per kg of the
// in-mill runs that measure it (post::MillEnergyPerTonne), over the feed
// rate (docs/population_balance.md, "Energy per tonne"). Goes into
// breakage/circuit.json.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "postprocess/circuit_energy.h"
#include "stages/breakage/breakage_matrix.h"
#include "stages/stage.h"

namespace mill::breakage {

// The gas shaft power (W) of flow/<rpm>/flow_report.json (shaft.power_W)
// per rotor speed of `rpms`; nullopt where that flow did not run.
std::map<double, std::optional<double>> read_gas_shaft_power(const StageContext& ctx,
                                                             const std::vector<double>& rpms);

// The beater work per kg of every class at one rotor speed from the runs
// that measure it (post::BeaterWorkPerKg, post::BeaterWorkPerClass).
std::vector<post::ClassWork> class_work(const post::SizeClasses& classes,
                                        const std::map<std::size_t, ClassRuns>& runs);

// circuit.json's `energy` of one rotor speed: the totals and, per class
// (finest first, as circuit.json's lists), the mill input, the w it was
// charged and where that came from, and its ore power.
nlohmann::json circuit_energy_json(const post::SizeClasses& classes, const post::CircuitEnergy& e,
                                   const std::vector<post::ClassWork>& work,
                                   const std::vector<double>& mill_input_t_h,
                                   const std::map<std::size_t, ClassRuns>& runs);

}  // namespace mill::breakage
