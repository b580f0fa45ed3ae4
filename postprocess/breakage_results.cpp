// Per-impact analysis and its CSV and HDF5 outputs; see breakage_results.h.
#include "postprocess/breakage_results.h"

#include <fmt/format.h>
#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <type_traits>
#include <utility>

#include "postprocess/h5_util.h"
#include "postprocess/jk_fit.h"
#include "postprocess/lammps_dump.h"

namespace mill::post {
namespace {

namespace fs = std::filesystem;

constexpr const char* kFormat = "mill-breakage-1";

// One summary column: name, unit, whether it is an integer, and accessors.
struct Column {
  const char* name;
  const char* unit;
  bool integer;
  std::function<double(const ImpactSummary&)> get;
  std::function<void(ImpactSummary&, double)> set;
};

// A column bound to a field of ImpactSummary; integer unless the field is real.
template <typename T>
Column MakeColumn(const char* name, const char* unit, T ImpactSummary::*field) {
  constexpr bool kInteger = !std::is_floating_point_v<T>;
  return {name, unit, kInteger,
          [field](const ImpactSummary& s) { return static_cast<double>(s.*field); },
          [field](ImpactSummary& s, double v) {
            if constexpr (kInteger) {
              s.*field = static_cast<T>(std::llround(v));
            } else {
              s.*field = v;
            }
          }};
}

// The summary columns, in CSV order; the first 13 are the required ones.
const std::vector<Column>& Columns() {
  using S = ImpactSummary;
  static const std::vector<Column> columns = {
      MakeColumn("velocity_m_s", "m/s", &S::velocity_m_s),
      MakeColumn("angle_deg", "deg", &S::angle_deg),
      MakeColumn("repeat", "1", &S::repeat),
      MakeColumn("n_elements", "1", &S::n_elements),
      MakeColumn("n_pieces", "1", &S::n_pieces),
      MakeColumn("n_single", "1", &S::n_single),
      MakeColumn("n_multi", "1", &S::n_multi),
      MakeColumn("largest_mass_fraction", "1", &S::largest_mass_fraction),
      MakeColumn("single_mass_fraction", "1", &S::single_mass_fraction),
      MakeColumn("broken_bond_fraction", "1", &S::broken_bond_fraction),
      MakeColumn("specific_energy_J_kg", "J/kg", &S::specific_energy_J_kg),
      MakeColumn("t10_percent", "%", &S::t10_percent),
      MakeColumn("wall_seconds", "s", &S::wall_seconds),
      MakeColumn("specific_energy_kWh_t", "kWh/t", &S::specific_energy_kWh_t),
      MakeColumn("lump_mass_kg", "kg", &S::lump_mass_kg),
      MakeColumn("lump_diameter_m", "m", &S::lump_diameter_m),
      MakeColumn("density_kg_m3", "kg/m3", &S::density_kg_m3),
      MakeColumn("initial_bonds", "1", &S::initial_bonds),
      MakeColumn("intact_bonds", "1", &S::intact_bonds),
      MakeColumn("element_d_rel_max", "1", &S::element_d_rel_max),
      MakeColumn("t10_resolved", "1", &S::t10_resolved),
      MakeColumn("comminution_efficiency", "1", &S::comminution_efficiency),
      MakeColumn("ledger_residual_fraction", "1", &S::ledger_residual_fraction),
      MakeColumn("max_element_speed_m_s", "m/s", &S::max_element_speed_m_s),
  };
  return columns;
}

constexpr std::size_t kRequiredColumns = 13;

// Formats a value for CSV: integers plainly, reals in shortest round-trip form.
std::string CsvValue(const Column& c, const ImpactSummary& s) {
  const double v = c.get(s);
  return c.integer ? fmt::format("{}", std::llround(v)) : fmt::format("{}", v);
}

// Joins strings with commas.
std::string JoinCsv(const std::vector<std::string>& cells) {
  std::string out;
  for (std::size_t k = 0; k < cells.size(); ++k) {
    if (k) out += ',';
    out += cells[k];
  }
  return out;
}

}  // namespace

// Splits one CSV line on commas (the files hold numbers and names only).
std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  std::istringstream ss(line);
  while (std::getline(ss, cell, ',')) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

namespace {

// Appends rows to a CSV with the given header: copies the existing file (whose
// header must match) plus the rows to path.tmp, then renames it over path.
void AppendCsvRows(const std::string& path, const std::string& header,
                   const std::vector<std::string>& rows) {
  std::string existing;
  if (fs::exists(path)) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw PostError(fmt::format("{}: cannot read", path));
    std::ostringstream ss;
    ss << in.rdbuf();
    existing = ss.str();
    const std::string first = existing.substr(0, existing.find('\n'));
    if (!existing.empty() && first != header) {
      throw PostError(fmt::format(
          "{}: header is '{}', expected '{}' (a file from another version? move it away)", path,
          first, header));
    }
    if (!existing.empty() && existing.back() != '\n') existing += '\n';
  }
  std::string text = existing.empty() ? header + '\n' : existing;
  for (const std::string& r : rows) text += r + '\n';
  WriteTextAtomically(path, text);
}

}  // namespace

// Writes text to path.tmp and renames it over path: the file is whole or absent.
void WriteTextAtomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw PostError(fmt::format("{}: cannot write", tmp));
    out << text;
    out.flush();
    if (!out) {
      out.close();
      std::error_code ignored;
      fs::remove(tmp, ignored);
      throw PostError(fmt::format("{}: write failed (disk full?)", tmp));
    }
  }
  fs::rename(tmp, path);
}

namespace {

// Attaches a scalar numeric attribute: int64 when `integer`, else double.
void WriteNumberAttr(hid_t obj, const char* name, double value, bool integer) {
  if (integer) {
    const long long v = std::llround(value);
    h5::WriteAttr(obj, name, H5T_STD_I64LE, H5T_NATIVE_LLONG, &v);
  } else {
    h5::WriteAttr(obj, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &value);
  }
}

// Reads a scalar numeric attribute as double.
double ReadNumberAttr(hid_t obj, const char* name) {
  if (H5Aexists(obj, name) <= 0) {
    throw PostError(fmt::format("{}: attribute '{}' is missing", h5::Where(obj), name));
  }
  h5::Handle attr(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose, obj,
                  fmt::format("open attribute '{}'", name));
  double v = 0.0;
  h5::Check(H5Aread(attr, H5T_NATIVE_DOUBLE, &v), obj, fmt::format("read attribute '{}'", name));
  return v;
}

// Creates the group `name` of a file, replacing one already there.
h5::Handle ReplaceGroup(hid_t file, const char* name) {
  if (H5Lexists(file, name, H5P_DEFAULT) > 0) {
    h5::Check(H5Ldelete(file, name, H5P_DEFAULT), file,
              fmt::format("delete the old group '{}'", name));
  }
  return h5::CreateGroup(file, name);
}

// Writes the /summary/<column> datasets for a list of summaries.
void WriteSummaryGroup(hid_t file, const std::vector<ImpactSummary>& rows) {
  const h5::Handle group = h5::CreateGroup(file, "summary");
  const std::vector<hsize_t> dims = {rows.size()};
  for (const Column& c : Columns()) {
    if (c.integer) {
      std::vector<long long> v;
      for (const auto& r : rows) v.push_back(std::llround(c.get(r)));
      h5::WriteDataset(group, c.name, v, dims, c.unit);
    } else {
      std::vector<double> v;
      for (const auto& r : rows) v.push_back(c.get(r));
      h5::WriteDataset(group, c.name, v, dims, c.unit);
    }
  }
}

// Writes one impact's group under /impacts.
void WriteImpactGroup(hid_t impacts, const ImpactResult& r) {
  const std::string name =
      ImpactGroupName({r.summary.velocity_m_s, r.summary.angle_deg, r.summary.repeat});
  const h5::Handle g = h5::CreateGroup(impacts, name);
  const hsize_t n = r.fragments.size();
  std::vector<long long> count;
  std::vector<double> mass, diameter, d_rel, velocity;
  const double d_ref = EquivalentDiameter(r.summary.lump_mass_kg, r.summary.density_kg_m3);
  for (const Fragment& f : r.fragments) {
    count.push_back(static_cast<long long>(f.n_elements()));
    mass.push_back(f.mass);
    diameter.push_back(f.diameter);
    d_rel.push_back(f.diameter / d_ref);
    velocity.insert(velocity.end(), f.velocity.begin(), f.velocity.end());
  }
  h5::WriteDataset(g, "n_elements", count, {n}, "1");
  h5::WriteDataset(g, "mass", mass, {n}, "kg");
  h5::WriteDataset(g, "diameter", diameter, {n}, "m");
  h5::WriteDataset(g, "d_rel", d_rel, {n}, "1");
  h5::WriteDataset(g, "velocity", velocity, {n, 3}, "m/s");
  h5::WriteDataset(g, "fraction_edges", r.fraction_edges, {r.fraction_edges.size()}, "1");
  h5::WriteDataset(g, "fraction_mass", r.fraction_mass, {r.fraction_mass.size()}, "1");
  for (const Column& c : Columns()) WriteNumberAttr(g, c.name, c.get(r.summary), c.integer);
  std::string warnings;
  for (const auto& w : r.warnings) warnings += (warnings.empty() ? "" : "\n") + w;
  h5::WriteStringAttr(g, "warnings", warnings);
  h5::WriteStringAttr(g, "diameter_definition",
                      "equal-volume sphere of the solid: d = (6 m / (pi rho))^(1/3)");
}

// An impact group's summary attributes. Columns past the required ones may be
// missing (a file from before they existed): they keep the field's default.
ImpactSummary ReadSummaryAttrs(hid_t g) {
  ImpactSummary s;
  const auto& cols = Columns();
  for (std::size_t c = 0; c < cols.size(); ++c) {
    if (c >= kRequiredColumns && H5Aexists(g, cols[c].name) <= 0) continue;
    cols[c].set(s, ReadNumberAttr(g, cols[c].name));
  }
  return s;
}

// The names of the links in a group, in name order.
std::vector<std::string> LinkNames(hid_t group) {
  H5G_info_t info;
  h5::Check(H5Gget_info(group, &info), group, "list the group");
  std::vector<std::string> names;
  for (hsize_t k = 0; k < info.nlinks; ++k) {
    const ssize_t len =
        H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, k, nullptr, 0, H5P_DEFAULT);
    if (len < 0) h5::Fail(h5::Where(group), "list the group");
    std::string name(static_cast<std::size_t>(len) + 1, '\0');
    H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, k, name.data(), name.size(),
                       H5P_DEFAULT);
    name.resize(static_cast<std::size_t>(len));
    names.push_back(name);
  }
  return names;
}

// An impact file's /energy (the ledger of its one impact) into the merged
// file's group of that impact, /impacts/<name>/energy.
void CopyEnergyGroup(hid_t in, const std::string& in_path, const std::vector<std::string>& names,
                     hid_t out_impacts) {
  if (H5Lexists(in, "energy", H5P_DEFAULT) <= 0) return;
  if (names.size() != 1) {
    throw PostError(fmt::format(
        "{}: /energy beside {} impacts: a ledger belongs to a file of one impact (impact.h5)",
        in_path, names.size()));
  }
  const std::string to = names[0] + "/energy";
  h5::Check(H5Ocopy(in, "energy", out_impacts, to.c_str(), H5P_DEFAULT, H5P_DEFAULT), out_impacts,
            fmt::format("copy /energy of {} to '{}'", in_path, to));
}

}  // namespace

// Group name with the velocity to 0.1 m/s when that is exact, else in full.
std::string ImpactGroupName(const ImpactConditions& c) {
  const double tenth = std::round(c.velocity_m_s * 10.0) / 10.0;
  const std::string v = tenth == c.velocity_m_s ? fmt::format("{:.1f}", c.velocity_m_s)
                                                : fmt::format("{}", c.velocity_m_s);
  return fmt::format("v{}_a{}_r{}", v, c.angle_deg, c.repeat);
}

// Per-impact analysis.
ImpactResult AnalyseImpact(const std::vector<Element>& elements, const std::vector<Bond>& bonds,
                           const ImpactSpec& spec, const std::string& bond_source) {
  if (elements.empty()) throw PostError("no elements to analyse (empty dump?)");
  if (!(spec.lump_diameter_m > 0.0)) {
    throw PostError(fmt::format("lump diameter must be > 0 m, got {}", spec.lump_diameter_m));
  }
  if (spec.initial_bonds <= 0) {
    throw PostError(fmt::format("initial number of bonds must be > 0, got {}", spec.initial_bonds));
  }
  if (!(spec.conditions.velocity_m_s >= 0.0)) {
    throw PostError(
        fmt::format("impact speed must be >= 0 m/s, got {}", spec.conditions.velocity_m_s));
  }
  ValidateFractionEdges(spec.fraction_edges);

  std::set<std::pair<long long, long long>> unique;
  for (const Bond& b : bonds) unique.emplace(std::min(b.i, b.j), std::max(b.i, b.j));
  if (static_cast<long long>(unique.size()) > spec.initial_bonds) {
    throw PostError(fmt::format("{}: {} intact bonds but only {} initial bonds (wrong lump?)",
                                bond_source, unique.size(), spec.initial_bonds));
  }

  ImpactResult r;
  r.fragments = FindFragments(elements, bonds, spec.density_kg_m3, bond_source);
  r.fraction_edges = spec.fraction_edges;

  ImpactSummary& s = r.summary;
  s.velocity_m_s = spec.conditions.velocity_m_s;
  s.angle_deg = spec.conditions.angle_deg;
  s.repeat = spec.conditions.repeat;
  s.n_elements = static_cast<long long>(elements.size());
  s.n_pieces = static_cast<long long>(r.fragments.size());
  s.lump_diameter_m = spec.lump_diameter_m;
  s.density_kg_m3 = spec.density_kg_m3;
  s.initial_bonds = spec.initial_bonds;
  s.intact_bonds = static_cast<long long>(unique.size());
  s.wall_seconds = spec.wall_seconds;

  // Relative piece size d/D_solid, with D_solid the equal-volume diameter of
  // the whole lump's solid: an intact lump is d/D = 1 whatever its packing
  // density (a random packing fills ~60% of the nominal sphere).
  for (const Fragment& f : r.fragments) s.lump_mass_kg += f.mass;
  const double d_ref = EquivalentDiameter(s.lump_mass_kg, spec.density_kg_m3);
  double single_mass = 0.0;
  std::vector<double> d_rel, mass;
  for (const Fragment& f : r.fragments) {
    if (f.n_elements() == 1) {
      ++s.n_single;
      single_mass += f.mass;
    } else {
      ++s.n_multi;
    }
    d_rel.push_back(f.diameter / d_ref);
    mass.push_back(f.mass);
  }
  s.largest_mass_fraction = r.fragments.front().mass / s.lump_mass_kg;
  s.single_mass_fraction = single_mass / s.lump_mass_kg;
  s.broken_bond_fraction =
      1.0 - static_cast<double>(s.intact_bonds) / static_cast<double>(spec.initial_bonds);
  s.specific_energy_J_kg = 0.5 * s.velocity_m_s * s.velocity_m_s;
  s.specific_energy_kWh_t = s.specific_energy_J_kg / kJoulePerKgPerKWhPerTonne;
  s.t10_percent = T10Percent(d_rel, mass);
  r.fraction_mass = SizeFractionMass(d_rel, mass, spec.fraction_edges);
  std::vector<double> diameters;
  for (const Fragment& f : r.fragments) diameters.push_back(f.diameter);
  r.new_surface_m2 = NewSurfaceArea(diameters, d_ref);

  for (const Element& e : elements) {
    s.element_d_rel_max =
        std::max(s.element_d_rel_max, EquivalentDiameter(e.mass, spec.density_kg_m3) / d_ref);
  }
  s.t10_resolved = s.element_d_rel_max < 0.1;
  if (!s.t10_resolved) {
    r.warnings.push_back(fmt::format(
        "t10 cannot resolve: the coarsest element has d/D = {:.4f} >= 0.1, so fully shredded "
        "mass is not all counted as finer than D/10; use a finer lump (more elements) for t10",
        s.element_d_rel_max));
  }
  return r;
}

// Per-impact analysis from files.
ImpactResult AnalyseImpactFiles(const std::string& dump_path, const std::string& bond_path,
                                const ImpactSpec& spec) {
  const DumpSnapshot snap = ReadDumpLastSnapshot(dump_path, spec.density_kg_m3);
  if (snap.elements.empty()) {
    throw PostError(fmt::format("{}: step {} has no atoms", dump_path, snap.timestep));
  }
  const std::vector<Bond> bonds = ReadIntactBonds(bond_path);
  return AnalyseImpact(snap.elements, bonds, spec, bond_path);
}

// summary.csv column names.
const std::vector<std::string>& SummaryCsvColumns() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const Column& c : Columns()) n.push_back(c.name);
    return n;
  }();
  return names;
}

// fractions.csv column names.
const std::vector<std::string>& FractionsCsvColumns() {
  static const std::vector<std::string> names = {"velocity_m_s",   "angle_deg", "repeat",
                                                 "fraction_index", "d_low_rel", "d_high_rel",
                                                 "mass_fraction"};
  return names;
}

// One summary row.
void AppendSummaryCsv(const std::string& path, const ImpactSummary& summary) {
  std::vector<std::string> cells;
  for (const Column& c : Columns()) cells.push_back(CsvValue(c, summary));
  AppendCsvRows(path, JoinCsv(SummaryCsvColumns()), {JoinCsv(cells)});
}

// The impact's fraction rows.
void AppendFractionsCsv(const std::string& path, const ImpactResult& result) {
  if (result.fraction_edges.size() != result.fraction_mass.size() + 1) {
    throw PostError(fmt::format("{}: {} edges do not bound {} fractions", path,
                                result.fraction_edges.size(), result.fraction_mass.size()));
  }
  const ImpactSummary& s = result.summary;
  std::vector<std::string> rows;
  for (std::size_t k = 0; k < result.fraction_mass.size(); ++k) {
    rows.push_back(FractionsCsvLine({{s.velocity_m_s, s.angle_deg, s.repeat},
                                     static_cast<int>(k),
                                     result.fraction_edges[k],
                                     result.fraction_edges[k + 1],
                                     result.fraction_mass[k]}));
  }
  AppendCsvRows(path, JoinCsv(FractionsCsvColumns()), rows);
}

// The number in one CSV cell (finite only if `finite`), or a PostError naming
// file, line and column.
double ParseCsvNumber(const std::string& path, long line_no, const std::string& column,
                      const std::string& cell, bool finite) {
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(cell, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != cell.size() || (finite && !std::isfinite(v))) {
    throw PostError(fmt::format("{}:{}: {}: expected a {}number, got '{}'", path, line_no, column,
                                finite ? "finite " : "", cell));
  }
  return v;
}

// One fractions.csv line.
std::string FractionsCsvLine(const FractionRow& r) {
  return fmt::format("{},{},{},{},{},{},{}", r.conditions.velocity_m_s, r.conditions.angle_deg,
                     r.conditions.repeat, r.index, r.d_low_rel, r.d_high_rel, r.mass_fraction);
}

// fractions.csv back into rows.
std::vector<FractionRow> ReadFractionsCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw PostError(fmt::format("{}: cannot open fractions file", path));
  std::string line;
  if (!std::getline(in, line)) throw PostError(fmt::format("{}: empty, expected a header", path));
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (SplitCsv(line) != FractionsCsvColumns()) {
    throw PostError(fmt::format("{}:1: header '{}', expected '{}'", path, line,
                                JoinCsv(FractionsCsvColumns())));
  }
  const auto& names = FractionsCsvColumns();
  std::vector<FractionRow> rows;
  long line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    const auto cells = SplitCsv(line);
    if (cells.size() != names.size()) {
      throw PostError(fmt::format("{}:{}: {} values, header has {}", path, line_no, cells.size(),
                                  names.size()));
    }
    double v[7];
    for (std::size_t c = 0; c < names.size(); ++c)
      v[c] = ParseCsvNumber(path, line_no, names[c], cells[c]);
    if (!(std::isfinite(v[2]) && v[2] >= 0 && v[2] == std::round(v[2]) && v[2] < 1e9)) {
      throw PostError(fmt::format("{}:{}: repeat: expected a whole number >= 0, got '{}'", path,
                                  line_no, cells[2]));
    }
    if (!(std::isfinite(v[3]) && v[3] >= 0 && v[3] == std::round(v[3]) && v[3] < 1e9)) {
      throw PostError(fmt::format("{}:{}: fraction_index: expected a whole number >= 0, got '{}'",
                                  path, line_no, cells[3]));
    }
    rows.push_back(
        {{v[0], v[1], static_cast<int>(v[2])}, static_cast<int>(v[3]), v[4], v[5], v[6]});
  }
  return rows;
}

// summary.csv back into structs.
std::vector<ImpactSummary> ReadSummaryCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw PostError(fmt::format("{}: cannot open summary file", path));
  std::string line;
  if (!std::getline(in, line)) throw PostError(fmt::format("{}: empty, expected a header", path));
  if (!line.empty() && line.back() == '\r') line.pop_back();
  const auto header = SplitCsv(line);
  std::map<std::string, std::size_t> at;
  for (std::size_t k = 0; k < header.size(); ++k) at.emplace(header[k], k);
  const auto& cols = Columns();
  std::vector<long> pos(cols.size(), -1);
  for (std::size_t c = 0; c < cols.size(); ++c) {
    auto it = at.find(cols[c].name);
    if (it != at.end()) {
      pos[c] = static_cast<long>(it->second);
    } else if (c < kRequiredColumns) {
      throw PostError(fmt::format("{}: header lacks required column '{}'", path, cols[c].name));
    }
  }
  std::vector<ImpactSummary> rows;
  long line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    const auto cells = SplitCsv(line);
    if (cells.size() != header.size()) {
      throw PostError(fmt::format("{}:{}: {} values, header has {}", path, line_no, cells.size(),
                                  header.size()));
    }
    ImpactSummary s;
    for (std::size_t c = 0; c < cols.size(); ++c) {
      if (pos[c] < 0) continue;
      const std::string& cell = cells[static_cast<std::size_t>(pos[c])];
      const double v = ParseCsvNumber(path, line_no, cols[c].name, cell);
      // A count or flag that is not a whole number (nan, 2.5) would turn
      // into garbage when rounded: the file is damaged.
      if (cols[c].integer && !(std::isfinite(v) && v == std::round(v) && std::abs(v) < 9e15)) {
        throw PostError(fmt::format("{}:{}: {}: expected a whole number, got '{}'", path, line_no,
                                    cols[c].name, cell));
      }
      cols[c].set(s, v);
    }
    rows.push_back(s);
  }
  return rows;
}

// breakage.h5 from in-memory results.
void WriteBreakageH5(const std::string& path, const std::vector<ImpactResult>& results) {
  std::set<std::string> names;
  for (const auto& r : results) {
    const std::string n =
        ImpactGroupName({r.summary.velocity_m_s, r.summary.angle_deg, r.summary.repeat});
    if (!names.insert(n).second) {
      throw PostError(fmt::format("{}: impact {} appears twice in the results", path, n));
    }
  }
  h5::WriteFileAtomically(path, path + ".tmp", [&](hid_t file) {
    h5::WriteStringAttr(file, "format", kFormat);
    const h5::Handle impacts = h5::CreateGroup(file, "impacts");
    std::vector<ImpactSummary> rows;
    for (const auto& r : results) {
      WriteImpactGroup(impacts, r);
      rows.push_back(r.summary);
    }
    WriteSummaryGroup(file, rows);
  });
}

// The one impact's pieces of impact.h5.
ImpactPieces ReadImpactPieces(const std::string& path) {
  const h5::Quiet quiet;
  const h5::Handle in = h5::OpenFile(path, H5F_ACC_RDONLY);
  if (H5Lexists(in, "impacts", H5P_DEFAULT) <= 0)
    throw PostError(fmt::format("{}: no /impacts group (not an impact.h5?)", path));
  const h5::Handle impacts(H5Gopen2(in, "impacts", H5P_DEFAULT), H5Gclose, in,
                           "open group 'impacts'");
  const std::vector<std::string> names = LinkNames(impacts);
  if (names.size() != 1)
    throw PostError(fmt::format("{}: {} impacts under /impacts; expected the one of its run", path,
                                names.size()));
  const h5::Handle g(H5Gopen2(impacts, names[0].c_str(), H5P_DEFAULT), H5Gclose, impacts,
                     fmt::format("open group '{}'", names[0]));
  ImpactPieces p{h5::ReadDoubles(g, "d_rel"), h5::ReadDoubles(g, "mass")};
  if (p.d_rel.size() != p.mass_kg.size() || p.mass_kg.empty())
    throw PostError(
        fmt::format("{}:/impacts/{}: {} sizes and {} masses; expected as many, at "
                    "least one",
                    path, names[0], p.d_rel.size(), p.mass_kg.size()));
  return p;
}

// breakage.h5 merged from per-impact files.
void MergeBreakageH5Files(const std::string& path, const std::vector<std::string>& inputs) {
  h5::WriteFileAtomically(path, path + ".tmp", [&](hid_t out) {
    h5::WriteStringAttr(out, "format", kFormat);
    const h5::Handle out_impacts = h5::CreateGroup(out, "impacts");
    std::map<std::string, std::string> source_of;
    std::vector<ImpactSummary> rows;
    for (const std::string& in_path : inputs) {
      const h5::Handle in = h5::OpenFile(in_path, H5F_ACC_RDONLY);
      if (H5Lexists(in, "impacts", H5P_DEFAULT) <= 0) {
        throw PostError(fmt::format("{}: no /impacts group (not a breakage.h5?)", in_path));
      }
      const h5::Handle in_impacts(H5Gopen2(in, "impacts", H5P_DEFAULT), H5Gclose, in,
                                  "open group 'impacts'");
      const std::vector<std::string> names = LinkNames(in_impacts);
      for (const std::string& name : names) {
        auto [it, fresh] = source_of.emplace(name, in_path);
        if (!fresh) {
          throw PostError(fmt::format("impact {} is in both {} and {}", name, it->second, in_path));
        }
        h5::Check(
            H5Ocopy(in_impacts, name.c_str(), out_impacts, name.c_str(), H5P_DEFAULT, H5P_DEFAULT),
            out_impacts, fmt::format("copy /impacts/{} of {}", name, in_path));
        const h5::Handle g(H5Gopen2(in_impacts, name.c_str(), H5P_DEFAULT), H5Gclose, in_impacts,
                           fmt::format("open group '{}'", name));
        rows.push_back(ReadSummaryAttrs(g));
      }
      // The ledger is copied per impact, not skipped: breakage.h5 holds every
      // impact's time series under its own group.
      CopyEnergyGroup(in, in_path, names, out_impacts);
    }
    WriteSummaryGroup(out, rows);
  });
}

// The JK fits as /jk_fit/<name> groups of an existing file.
void WriteJkFitH5(const std::string& path, const std::vector<JkFitRecord>& records) {
  const h5::Quiet quiet;
  const h5::Handle file = h5::OpenFile(path, H5F_ACC_RDWR);
  const h5::Handle top = ReplaceGroup(file, "jk_fit");
  h5::WriteStringAttr(top, "relation",
                      "t10 = A (1 - exp(-b Ecs)), Ecs = V^2/2 in kWh/t (Napier-Munn et al. 1996, "
                      "Mineral Comminution Circuits, JKMRC)");
  for (const JkFitRecord& r : records) {
    const std::size_t n = r.ecs_kwh_t.size();
    if (r.t10_percent.size() != n || r.repeat.size() != n || r.used.size() != n) {
      throw PostError(fmt::format("{}: /jk_fit/{}: point arrays differ in length", path, r.name));
    }
    const h5::Handle g = h5::CreateGroup(top, r.name);
    h5::WriteDataset(g, "ecs", r.ecs_kwh_t, {n}, "kWh/t");
    h5::WriteDataset(g, "t10", r.t10_percent, {n}, "%");
    h5::WriteDataset(g, "repeat", r.repeat, {n}, "1");
    h5::WriteDataset(g, "used", r.used, {n}, "1");
    const JkFit& f = r.fit.pooled;
    h5::WriteStringAttr(
        g, "status",
        f.ok ? (f.note.empty() ? "fitted" : "fitted: " + f.note) : "not fitted: " + f.reason);
    if (!f.ok) continue;
    auto scalar = [&](const char* name, double v, const char* unit) {
      h5::WriteDataset(g, name, std::vector<double>{v}, {1}, unit);
    };
    scalar("A", f.a_percent, "%");
    scalar("b", f.b_t_per_kwh, "t/kWh");
    scalar("A_times_b", f.ab(), "% t/kWh");
    scalar("A_se", f.a_se_percent, "%");
    scalar("b_se", f.b_se_t_per_kwh, "t/kWh");
    if (r.fit.a_percent) {
      scalar("A_min", r.fit.a_percent->min, "%");
      scalar("A_max", r.fit.a_percent->max, "%");
      scalar("b_min", r.fit.b_t_per_kwh->min, "t/kWh");
      scalar("b_max", r.fit.b_t_per_kwh->max, "t/kWh");
      scalar("A_times_b_min", r.fit.ab->min, "% t/kWh");
      scalar("A_times_b_max", r.fit.ab->max, "% t/kWh");
    }
    WriteNumberAttr(g, "repeats_fitted", r.fit.n_repeats_fitted, true);
  }
}

// The ledger's columns as /energy of an existing file.
void WriteEnergyLedgerH5(const std::string& path, const EnergyLedger& ledger) {
  const h5::Quiet quiet;
  const h5::Handle file = h5::OpenFile(path, H5F_ACC_RDWR);
  const h5::Handle g = ReplaceGroup(file, "energy");
  h5::WriteStringAttr(
      g, "balance",
      "input + work_other = ke_trans + ke_rot + numerical + bond_elastic + "
      "bond_released + bond_damping + bond_friction + wall_elastic + wall_damping + "
      "wall_friction + contact_elastic + contact_damping + contact_friction + residual "
      "(docs/styles/fix_energy_ledger.md)");
  h5::WriteStringAttr(g, "source", ledger.path);
  const std::vector<hsize_t> dims = {ledger.rows()};
  for (std::size_t c = 0; c < ledger.columns.size(); ++c) {
    const std::string& name = ledger.columns[c];
    if (name == "step") {
      std::vector<long long> steps;
      for (double v : ledger.values[c]) steps.push_back(std::llround(v));
      h5::WriteDataset(g, name, steps, dims, "1");
    } else {
      h5::WriteDataset(g, name, ledger.values[c], dims, LedgerUnit(name));
    }
  }
}

}  // namespace mill::post
