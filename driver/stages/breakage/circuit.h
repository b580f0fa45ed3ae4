// The steady state of the closed mill circuit per rotor speed, for a case
// with a feed: the feed (feed.*), the breakage matrix of the in-mill runs
// (breakage_matrix.h) and the sharp cut at feed.cut_size_mm solved by
// post::SolveCircuit into the product, its P50 and P80, the circulating load
// and the mass-balance residual (docs/population_balance.md, "The circuit
// per rotor speed"). Writes breakage/circuit.json and circuit.csv.
#pragma once

#include <map>

#include "postprocess/breakage_matrix.h"
#include "stages/breakage/breakage_matrix.h"
#include "stages/breakage/mill_energy.h"
#include "stages/stage.h"

namespace mill::breakage {

// A residual above this is a fault of the balance, not rounding: the stage
// fails naming the rotor speed.
inline constexpr double kCircuitResidualLimit = 1e-9;

// breakage/circuit.json and circuit.csv from the matrices per rotor speed,
// with each steady speed's energy per tonne (mill_energy.h: the runs'
// beater work, `gas_W` the gas shaft power per speed), the decision on
// feed.target_p80_mm with its kWh/t, and the band of a bootstrap over the
// runs' lumps (post::BootstrapCircuit). A speed at which a class above the
// cut never breaks has no steady state: its entry says why (steady: false)
// and the others go on.
void write_circuit(StageContext& ctx, const std::map<double, post::AssembledMatrix>& matrices,
                   const MeasuringRuns& runs, const std::map<double, std::optional<double>>& gas_W);

}  // namespace mill::breakage
