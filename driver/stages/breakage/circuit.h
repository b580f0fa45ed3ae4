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

// A piece of one element cannot break further, so the element size is the
// finest the lumps resolve. The sizes such a piece takes in the sizing of
// the pieces (docs/population_balance.md, "Pieces to sizes": lump diameter
// x (piece mass / lump mass)^(1/3)) for a lump of `elements` elements of
// the lump builder's radius classes r_mean (1 + spread {-1, ..., 1}): its
// smallest, mean-mass and largest element.
struct ElementPieces {
  double smallest_mm = 0, mean_mm = 0, largest_mm = 0;
};
ElementPieces element_piece_mm(double lump_mm, long elements, double spread);

// A closed-circuit P80 below this many times the largest element's piece is
// set by the element size: a shattered lump's mass sits at the element
// pieces (bench/README.md, "A class lump at the element cap": elements 1.53
// x coarser gave a P80 1.56 x coarser).
inline constexpr double kElementBoundP80Factor = 2.0;

// breakage/circuit.json and circuit.csv from the matrices per rotor speed,
// with each steady speed's energy per tonne (mill_energy.h: the runs'
// beater work, `gas_W` the gas shaft power per speed), the decision on
// feed.target_p80_mm with its kWh/t, and the band of a bootstrap over the
// runs' lumps (post::BootstrapCircuit). A speed at which a class above the
// cut never breaks has no steady state: its entry says why (steady: false)
// and the others go on. circuit.json's "resolution" gives the element
// pieces of the measured classes' lumps, and each steady speed whether its
// P80 is below kElementBoundP80Factor x the largest (p80_set_by_elements).
void write_circuit(StageContext& ctx, const std::map<double, post::AssembledMatrix>& matrices,
                   const MeasuringRuns& runs, const std::map<double, std::optional<double>>& gas_W);

}  // namespace mill::breakage
