// The energy ledger of a bonded-lump run: ledger.csv, written in the run
// folder by fix energy/ledger (docs/styles/fix_energy_ledger.md), one row per
// sample, the last at the end of the run. The breakage stage reads it after
// every impact and in-mill run; its summary (comminution efficiency, residual,
// fastest element) goes into result.json and summary.csv, its columns into
// impact.h5 /energy (docs/breakage.md, "Energy ledger"). No driver/ includes.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace mill::post {

// A column's place in the balance
//   input + work_other = held terms + residual,
// or what else it is.
enum class LedgerRole { kStep, kTime, kHeld, kInput, kWorkOther, kResidual, kDiagnostic };

// One column of ledger.csv: name, unit (as in HDF5 `unit` attributes), role.
struct LedgerColumn {
  const char* name;
  const char* unit;
  LedgerRole role;
};

// The columns fix energy/ledger writes, in its order. A ledger must hold every
// one (in any order); further columns are kept as they are.
const std::vector<LedgerColumn>& LedgerColumns();

// The unit of a column: from LedgerColumns(), else from the name's suffix
// (_J: J, _s: s, _m_s: m/s, anything else 1).
std::string LedgerUnit(const std::string& column);

// A ledger as read: column-major, every value finite.
struct EnergyLedger {
  std::string path;                         // the file it was read from
  std::vector<std::string> columns;         // header names, file order
  std::vector<std::vector<double>> values;  // values[column][row]
  std::vector<long> lines;                  // file line of each row, for messages

  std::size_t rows() const { return lines.size(); }
  // The values of a column; throws PostError naming the file and the column.
  const std::vector<double>& column(const std::string& name) const;
  // The column's value in the last row.
  double last(const std::string& name) const { return column(name).back(); }
};

// Reads ledger.csv: '#' lines are comments, the first other line is the
// header, then one row per sample. Throws PostError naming the file (and the
// line) on a missing file, a header without a column of LedgerColumns(), a row
// with the wrong number of fields, a value that is not a finite number, or no
// rows.
EnergyLedger ReadEnergyLedger(const std::string& path);

// Writes a ledger in the same format (a comment line, the header, the rows)
// via path.tmp and a rename: the CSV mirror of impact.h5 /energy.
void WriteEnergyLedgerCsv(const std::string& path, const EnergyLedger& ledger);

// What a ledger says about its run, from its last row and its extremes.
struct LedgerSummary {
  std::vector<std::pair<std::string, double>>
      final_energy;  // every column in J, last row, file order
  double end_time_s = 0.0;
  double input_J = 0.0;       // energy at the start, kinetic and stored
  double work_other_J = 0.0;  // moving walls, gas, gravity, platens
  double residual_J = 0.0;
  double bond_released_J = 0.0;
  double residual_fraction = 0.0;      // residual / (input + |work_other|), last row, signed
  double residual_fraction_max = 0.0;  // largest |residual| / (input + |work_other|) of any row
  double max_speed_m_s = 0.0;          // fastest element of the run
  double max_speed_time_s = 0.0;       // end of the sampling interval it was seen in
  double wall_overlap_max = 0.0;       // largest overlap / radius on the rigid surface
  // bond_released / (input + max(work_other, 0)) at the end: the share of the
  // energy given to the lump that went into breaking bonds (method.md, the
  // global efficiency of the comminution process).
  double comminution_efficiency = 0.0;
};

// The summary of a ledger. Throws PostError naming the file and line where a
// row's balance does not close (the columns do not add up to within 1e-6 of
// input + |work_other|: a ledger of another layout), or when no energy was
// put in (input + max(work_other, 0) <= 0 at the end: the efficiency would be
// undefined).
LedgerSummary SummariseLedger(const EnergyLedger& ledger);

// The new surface of a broken lump: the sphere-equivalent surfaces pi d^2 of
// its pieces (d, the equal-volume diameter of each piece's solid) minus that
// of the whole lump, m2. 0 for an intact lump.
double NewSurfaceArea(const std::vector<double>& piece_diameters_m, double lump_diameter_m);

// Energy per unit of new surface, J/m2: energy / new surface, nullopt unless
// the new surface is > 0.
std::optional<double> EnergyPerNewSurface(double energy_J, double new_surface_m2);

}  // namespace mill::post
