// The energy ledger of a bonded-lump run; see energy_ledger.h.
#include "postprocess/energy_ledger.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "postprocess/breakage_results.h"
#include "postprocess/fragments.h"

namespace mill::post {
namespace {

namespace fs = std::filesystem;

constexpr const char* kComment =
    "# fix energy/ledger: energy of the run [J] (docs/styles/fix_energy_ledger.md)";

// How closely a row's columns must add up, as a share of input + |work_other|:
// the fix writes 10 significant digits, so a sound row closes to ~1e-9.
constexpr double kBalanceTolerance = 1e-6;

// Joins strings with commas.
std::string JoinFields(const std::vector<std::string>& cells) {
  std::string out;
  for (std::size_t k = 0; k < cells.size(); ++k) out += (k ? "," : "") + cells[k];
  return out;
}

// The next line that is neither blank nor a '#' comment; false at the end.
bool NextDataLine(std::istream& in, std::string& line, long& line_no) {
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto first = line.find_first_not_of(" \t");
    if (first != std::string::npos && line[first] != '#') return true;
  }
  return false;
}

// The names of every column LedgerColumns() requires, comma-joined.
std::string RequiredNames() {
  std::vector<std::string> names;
  for (const LedgerColumn& c : LedgerColumns()) names.emplace_back(c.name);
  return JoinFields(names);
}

// Checks the header: no empty or repeated name, every required column present.
void CheckHeader(const std::string& path, long line_no, const std::vector<std::string>& header) {
  std::set<std::string> seen;
  for (const std::string& name : header) {
    if (name.empty()) {
      throw PostError(fmt::format("{}:{}: header has an empty column name", path, line_no));
    }
    if (!seen.insert(name).second) {
      throw PostError(fmt::format("{}:{}: header names column '{}' twice", path, line_no, name));
    }
  }
  for (const LedgerColumn& c : LedgerColumns()) {
    if (!seen.count(c.name)) {
      throw PostError(
          fmt::format("{}:{}: header lacks column '{}'; expected fix energy/ledger's columns {} "
                      "(docs/styles/fix_energy_ledger.md)",
                      path, line_no, c.name, RequiredNames()));
    }
  }
}

// input + |work_other| of row k: the energy the balance is measured against.
double Scale(const EnergyLedger& l, std::size_t k) {
  return l.column("input_J")[k] + std::abs(l.column("work_other_J")[k]);
}

// Throws when row k's columns do not add up: input + work_other must equal
// the held terms plus the residual.
void CheckBalance(const EnergyLedger& l, std::size_t k) {
  double held = 0.0;
  for (const LedgerColumn& c : LedgerColumns())
    if (c.role == LedgerRole::kHeld) held += l.column(c.name)[k];
  const double given = l.column("input_J")[k] + l.column("work_other_J")[k];
  const double accounted = held + l.column("residual_J")[k];
  if (std::abs(given - accounted) > kBalanceTolerance * std::max(Scale(l, k), 1e-300)) {
    throw PostError(fmt::format(
        "{}:{}: the balance does not close: input_J + work_other_J = {:.10g} J, but the terms "
        "and residual_J add up to {:.10g} J (a ledger of another layout? "
        "docs/styles/fix_energy_ledger.md)",
        l.path, l.lines[k], given, accounted));
  }
}

}  // namespace

// The columns of fix energy/ledger.
const std::vector<LedgerColumn>& LedgerColumns() {
  using R = LedgerRole;
  static const std::vector<LedgerColumn> columns = {
      {"step", "1", R::kStep},
      {"time_s", "s", R::kTime},
      {"ke_trans_J", "J", R::kHeld},
      {"ke_rot_J", "J", R::kHeld},
      {"numerical_J", "J", R::kHeld},
      {"bond_elastic_J", "J", R::kHeld},
      {"bond_released_J", "J", R::kHeld},
      {"bond_damping_J", "J", R::kHeld},
      {"bond_friction_J", "J", R::kHeld},
      {"wall_elastic_J", "J", R::kHeld},
      {"wall_damping_J", "J", R::kHeld},
      {"wall_friction_J", "J", R::kHeld},
      {"contact_elastic_J", "J", R::kHeld},
      {"contact_damping_J", "J", R::kHeld},
      {"contact_friction_J", "J", R::kHeld},
      {"work_other_J", "J", R::kWorkOther},
      {"input_J", "J", R::kInput},
      {"residual_J", "J", R::kResidual},
      {"max_speed_m_s", "m/s", R::kDiagnostic},
      {"wall_overlap", "1", R::kDiagnostic},
  };
  return columns;
}

// A column's unit, from the table or the name's suffix.
std::string LedgerUnit(const std::string& column) {
  for (const LedgerColumn& c : LedgerColumns())
    if (column == c.name) return c.unit;
  auto ends = [&](const std::string& tail) {
    return column.size() > tail.size() &&
           column.compare(column.size() - tail.size(), tail.size(), tail) == 0;
  };
  if (ends("_m_s")) return "m/s";
  if (ends("_J")) return "J";
  if (ends("_s")) return "s";
  return "1";
}

// A column by name.
const std::vector<double>& EnergyLedger::column(const std::string& name) const {
  const auto it = std::find(columns.begin(), columns.end(), name);
  if (it == columns.end()) throw PostError(fmt::format("{}: no column '{}'", path, name));
  return values[static_cast<std::size_t>(it - columns.begin())];
}

// ledger.csv into columns.
EnergyLedger ReadEnergyLedger(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw PostError(fmt::format("{}: cannot open the energy ledger", path));
  EnergyLedger l;
  l.path = path;
  std::string line;
  long line_no = 0;
  if (!NextDataLine(in, line, line_no)) {
    throw PostError(fmt::format("{}: no header line, expected '{}'", path, RequiredNames()));
  }
  l.columns = SplitCsv(line);
  CheckHeader(path, line_no, l.columns);
  l.values.assign(l.columns.size(), {});
  while (NextDataLine(in, line, line_no)) {
    const auto cells = SplitCsv(line);
    if (cells.size() != l.columns.size()) {
      throw PostError(fmt::format("{}:{}: {} values, the header has {}", path, line_no,
                                  cells.size(), l.columns.size()));
    }
    for (std::size_t c = 0; c < cells.size(); ++c)
      l.values[c].push_back(ParseCsvNumber(path, line_no, l.columns[c], cells[c], true));
    l.lines.push_back(line_no);
  }
  if (l.lines.empty()) {
    throw PostError(fmt::format(
        "{}: no rows after the header (the run ended before the ledger's first sample?)", path));
  }
  return l;
}

// The ledger back into its CSV format.
void WriteEnergyLedgerCsv(const std::string& path, const EnergyLedger& l) {
  std::ostringstream out;
  out << kComment << '\n' << JoinFields(l.columns) << '\n';
  for (std::size_t k = 0; k < l.rows(); ++k) {
    for (std::size_t c = 0; c < l.columns.size(); ++c)
      out << (c ? "," : "") << fmt::format("{}", l.values[c][k]);
    out << '\n';
  }
  WriteTextAtomically(path, out.str());
}

// The last row's terms, the extremes and the efficiency.
LedgerSummary SummariseLedger(const EnergyLedger& l) {
  if (l.rows() == 0) throw PostError(fmt::format("{}: no rows", l.path));
  LedgerSummary s;
  for (std::size_t k = 0; k < l.rows(); ++k) {
    CheckBalance(l, k);
    const double scale = Scale(l, k);
    if (scale > 0.0) {
      s.residual_fraction_max =
          std::max(s.residual_fraction_max, std::abs(l.column("residual_J")[k]) / scale);
    }
  }
  const std::size_t end = l.rows() - 1;
  const double given = l.last("input_J") + std::max(l.last("work_other_J"), 0.0);
  if (!(given > 0.0)) {
    throw PostError(fmt::format(
        "{}:{}: input_J + max(work_other_J, 0) is {:g} J at the end of the run: no energy was "
        "put in, so the comminution efficiency is undefined",
        l.path, l.lines[end], given));
  }
  for (std::size_t c = 0; c < l.columns.size(); ++c)
    if (LedgerUnit(l.columns[c]) == "J")
      s.final_energy.emplace_back(l.columns[c], l.values[c][end]);
  s.end_time_s = l.last("time_s");
  s.input_J = l.last("input_J");
  s.work_other_J = l.last("work_other_J");
  s.residual_J = l.last("residual_J");
  s.bond_released_J = l.last("bond_released_J");
  s.residual_fraction = s.residual_J / Scale(l, end);
  const auto& speed = l.column("max_speed_m_s");
  const std::size_t fastest =
      static_cast<std::size_t>(std::max_element(speed.begin(), speed.end()) - speed.begin());
  s.max_speed_m_s = speed[fastest];
  s.max_speed_time_s = l.column("time_s")[fastest];
  const auto& overlap = l.column("wall_overlap");
  s.wall_overlap_max = *std::max_element(overlap.begin(), overlap.end());
  s.comminution_efficiency = s.bond_released_J / given;
  return s;
}

// Sphere-equivalent surface of the pieces less that of the lump.
double NewSurfaceArea(const std::vector<double>& piece_diameters_m, double lump_diameter_m) {
  double pieces = 0.0;
  for (double d : piece_diameters_m) pieces += kPi * d * d;
  return pieces - kPi * lump_diameter_m * lump_diameter_m;
}

// Energy per new surface, when there is new surface.
std::optional<double> EnergyPerNewSurface(double energy_J, double new_surface_m2) {
  if (!(new_surface_m2 > 0.0)) return std::nullopt;
  return energy_J / new_surface_m2;
}

}  // namespace mill::post
