// Results of the breakage stage: the per-impact analysis (fragments, size
// distribution, t10) and its outputs, summary.csv, fractions.csv and
// breakage.h5. The breakage stage calls AnalyseImpactFiles once per finished
// LIGGGHTS run, appends the CSV rows, and merges the HDF5 at the end.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "postprocess/distributions.h"
#include "postprocess/energy_ledger.h"
#include "postprocess/fragments.h"
#include "postprocess/jk_fit.h"

namespace mill::post {

// Splits one CSV line on commas (the project's CSVs hold numbers and names only,
// no quoting); a trailing comma gives an empty last cell.
std::vector<std::string> SplitCsv(const std::string& line);

// The number in one CSV cell, or a PostError naming the file, line and column;
// with finite, NaN and infinities are refused too.
double ParseCsvNumber(const std::string& path, long line_no, const std::string& column,
                      const std::string& cell, bool finite = false);

// Writes text to path.tmp, then renames it over path: whole or absent.
// Throws PostError naming the file when it cannot be written.
void WriteTextAtomically(const std::string& path, const std::string& text);

// Which impact of a sweep this is.
struct ImpactConditions {
  double velocity_m_s = 0.0;  // impact speed V
  double angle_deg = 90.0;    // angle to the surface, 90 = normal
  int repeat = 0;             // repeat index (random lump orientation)
};

// What the analysis needs besides the dump and the bond file.
struct ImpactSpec {
  ImpactConditions conditions;
  long long initial_bonds = 0;                                  // bonds when the lump was built
  double lump_diameter_m = 0.0;                                 // nominal lump diameter D
  double density_kg_m3 = 0.0;                                   // ore (solid) density rho
  std::vector<double> fraction_edges = DefaultFractionEdges();  // d/D_solid, ascending
  double wall_seconds = 0.0;                                    // wall time of the LIGGGHTS run, s
};

// One row of summary.csv. Masses are relative to the lump mass, the sum of the
// element masses in the dump.
struct ImpactSummary {
  double velocity_m_s = 0.0;
  double angle_deg = 90.0;
  int repeat = 0;
  long long n_elements = 0;
  long long n_pieces = 0;
  long long n_single = 0;  // single-element pieces ("fully shredded")
  long long n_multi = 0;   // pieces of more elements ("partially shredded")
  double largest_mass_fraction = 0.0;
  double single_mass_fraction = 0.0;
  double broken_bond_fraction = 0.0;  // 1 - intact / initial
  double specific_energy_J_kg = 0.0;  // V^2 / 2
  double t10_percent = 0.0;           // mass % with d < D/10, exact from the pieces
  double wall_seconds = 0.0;
  double specific_energy_kWh_t = 0.0;  // V^2 / 2 / 3600
  double lump_mass_kg = 0.0;
  double lump_diameter_m = 0.0;
  double density_kg_m3 = 0.0;
  long long initial_bonds = 0;
  long long intact_bonds = 0;
  double element_d_rel_max = 0.0;  // coarsest single element, d/D
  bool t10_resolved = true;        // every element is finer than D/10
  // From the run's energy ledger (energy_ledger.h); NaN when there is none.
  double comminution_efficiency = std::numeric_limits<double>::quiet_NaN();    // at the end
  double ledger_residual_fraction = std::numeric_limits<double>::quiet_NaN();  // at the end, signed
  double max_element_speed_m_s = std::numeric_limits<double>::quiet_NaN();     // over the run
};

// Everything known about one impact.
struct ImpactResult {
  ImpactSummary summary;
  std::vector<Fragment> fragments;     // heaviest first
  std::vector<double> fraction_edges;  // d/D
  std::vector<double> fraction_mass;   // mass fraction per size fraction, sums to 1
  std::vector<std::string> warnings;   // e.g. t10 cannot resolve
  double new_surface_m2 = 0.0;         // sphere-equivalent surface created (NewSurfaceArea)
};

// Analyses one impact from elements and intact bonds (duplicate bonds, in
// either order, count once). Throws PostError on inconsistent input.
ImpactResult AnalyseImpact(const std::vector<Element>& elements, const std::vector<Bond>& bonds,
                           const ImpactSpec& spec, const std::string& bond_source = "bond list");

// Reads the dump's last snapshot and the bond file, then AnalyseImpact.
ImpactResult AnalyseImpactFiles(const std::string& dump_path, const std::string& bond_path,
                                const ImpactSpec& spec);

// Column names of summary.csv in order: the 13 required ones, then extras.
const std::vector<std::string>& SummaryCsvColumns();

// Column names of fractions.csv in order.
const std::vector<std::string>& FractionsCsvColumns();

// Appends one row to summary.csv, writing the header if the file is new.
// Rewrites via FILE.tmp + rename. Throws if an existing header differs.
void AppendSummaryCsv(const std::string& path, const ImpactSummary& summary);

// Appends the impact's size-fraction rows to fractions.csv (same rules).
void AppendFractionsCsv(const std::string& path, const ImpactResult& result);

// Reads summary.csv back; columns by name, the required ones must be present.
std::vector<ImpactSummary> ReadSummaryCsv(const std::string& path);

// One row of fractions.csv: the mass fraction of one size fraction of one impact.
struct FractionRow {
  ImpactConditions conditions;
  int index = 0;            // fraction index, 0 = finest
  double d_low_rel = 0.0;   // lower edge, d/D
  double d_high_rel = 0.0;  // upper edge, d/D
  double mass_fraction = 0.0;
};

// Reads fractions.csv back. The header must be FractionsCsvColumns(); throws
// PostError naming file, line and column on anything else.
std::vector<FractionRow> ReadFractionsCsv(const std::string& path);

// One fractions.csv line (no newline), formatted as AppendFractionsCsv does.
std::string FractionsCsvLine(const FractionRow& row);

// The HDF5 group name of an impact, e.g. "v150.0_a90_r0".
std::string ImpactGroupName(const ImpactConditions& c);

// Writes breakage.h5 with one group /impacts/<name>/ per result (fragment
// datasets, fraction datasets, summary values as group attributes) and the
// /summary/<column> datasets; every dataset has a `unit` attribute. Writes
// path.tmp, then renames. Throws on duplicate impact names.
void WriteBreakageH5(const std::string& path, const std::vector<ImpactResult>& results);

// Merges per-impact breakage.h5 files into one: copies every /impacts group
// and rebuilds /summary. An input's /energy (its one impact's ledger,
// WriteEnergyLedgerH5) is copied to /impacts/<name>/energy. Summary
// attributes past the required columns may be missing (files from before
// they existed: NaN, or the field's default). Writes path.tmp, then renames.
void MergeBreakageH5Files(const std::string& path, const std::vector<std::string>& inputs);

// The pieces of the one impact in a file of one impact (impact.h5): their
// relative size d/D and mass (kg), heaviest first. Throws PostError naming
// the file unless it holds exactly one impact with as many sizes as masses.
struct ImpactPieces {
  std::vector<double> d_rel;
  std::vector<double> mass_kg;
};
ImpactPieces ReadImpactPieces(const std::string& path);

// Adds the group /energy to an existing file of one impact (impact.h5): one
// dataset per ledger column, each with its `unit` attribute (LedgerUnit), and
// the attribute `balance`. Replaces /energy if present.
void WriteEnergyLedgerH5(const std::string& path, const EnergyLedger& ledger);

// The JK fit of one group of impacts (one angle, or all conditions pooled),
// with every point it considered: `used` is 1 where t10 was resolved.
struct JkFitRecord {
  std::string name;  // HDF5 group name, e.g. "a90" or "all"
  std::vector<double> ecs_kwh_t, t10_percent;
  std::vector<long long> repeat, used;
  JkSweepFit fit;
};

// Adds /jk_fit/<name>/ to an existing breakage.h5 (the group is replaced if
// present): datasets ecs (kWh/t), t10 (%), repeat, used, and, when the fit
// succeeded, scalar datasets A (%), b (t/kWh), A_times_b, their standard
// errors and, over repeats, A_min/A_max, b_min/b_max, A_times_b_min/_max.
// Every dataset has a `unit` attribute; the group has `relation`.
void WriteJkFitH5(const std::string& path, const std::vector<JkFitRecord>& records);

}  // namespace mill::post
