// Shared parts of the bonded-lump runs (impact and in-mill).
#include "stages/breakage/lump_run.h"

#include <fmt/format.h>
#include <vtkCellArray.h>
#include <vtkDoubleArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataWriter.h>

#include <cmath>
#include <fstream>
#include <random>
#include <unordered_map>

#include "engine/liggghts.h"
#include "jobs/job_store.h"
#include "jobs/output_checks.h"
#include "progress.h"
#include "stages/stage_util.h"

namespace mill::breakage {

bool adaptive_step_on(const config::Document& d) {
  return d.boolean("breakage.adaptive_step") && d.real("breakage.timestep") == 0.0;
}
namespace fs = std::filesystem;
using engine::num;

namespace {

// A uniformly random rotation (Shoemake 1992, "Uniform random rotations",
// Graphics Gems III) as axis and angle in degrees, from a seed.
std::array<double, 4> random_rotation(unsigned long long seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double u1 = u(rng), u2 = u(rng), u3 = u(rng);
  const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
  const double q[4] = {b * std::cos(2 * M_PI * u3), a * std::sin(2 * M_PI * u2),
                       a * std::cos(2 * M_PI * u2), b * std::sin(2 * M_PI * u3)};  // w, x, y, z
  const double w = std::min(1.0, std::abs(q[0]));
  const double s = q[0] < 0 ? -1.0 : 1.0;
  const double angle = 2 * std::acos(w) * 180.0 / M_PI;
  const double n = std::sqrt(q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (n < 1e-12) return {0, 0, 1, 0};
  return {s * q[1] / n, s * q[2] / n, s * q[3] / n, angle};
}

// Elements as points for ParaView, coloured by fragment (0 = largest piece).
void write_fragments_vtp(const fs::path& file, const post::DumpSnapshot& snap,
                         const post::ImpactResult& r) {
  std::unordered_map<long long, int> frag_of;
  for (size_t f = 0; f < r.fragments.size(); ++f)
    for (long long id : r.fragments[f].ids) frag_of[id] = static_cast<int>(f);
  vtkNew<vtkPoints> pts;
  vtkNew<vtkIntArray> frag, size, ids;
  vtkNew<vtkDoubleArray> radius, vel;
  frag->SetName("fragment");
  size->SetName("fragment_elements");
  ids->SetName("id");
  radius->SetName("radius");
  vel->SetName("velocity");
  vel->SetNumberOfComponents(3);
  vtkNew<vtkCellArray> verts;
  for (const auto& e : snap.elements) {
    const vtkIdType pid = pts->InsertNextPoint(e.x[0], e.x[1], e.x[2]);
    verts->InsertNextCell(1, &pid);
    const int f = frag_of.count(e.id) ? frag_of[e.id] : -1;
    frag->InsertNextValue(f);
    size->InsertNextValue(f >= 0 ? static_cast<int>(r.fragments[f].n_elements()) : 0);
    ids->InsertNextValue(static_cast<int>(e.id));
    radius->InsertNextValue(e.radius);
    vel->InsertNextTuple3(e.v[0], e.v[1], e.v[2]);
  }
  vtkNew<vtkPolyData> pd;
  pd->SetPoints(pts);
  pd->SetVerts(verts);
  for (vtkDataArray* a : std::initializer_list<vtkDataArray*>{frag, size, ids, radius, vel})
    pd->GetPointData()->AddArray(a);
  pd->GetPointData()->SetActiveScalars("fragment");
  const fs::path tmp = file.string() + ".tmp.vtp";
  vtkNew<vtkXMLPolyDataWriter> w;
  w->SetFileName(tmp.c_str());
  w->SetInputData(pd);
  w->SetDataModeToBinary();
  if (w->Write() != 1) throw std::runtime_error("cannot write " + tmp.string());
  fs::rename(tmp, file);
}

// The run's energy ledger (ledger.csv, fix energy/ledger) and its summary,
// whose figures also go into the impact's summary row.
void read_energy_ledger(const LumpRun& run, LumpRunResult& a) {
  a.ledger = read_run_ledger(run.work);
  a.energy = post::SummariseLedger(a.ledger);
  post::ImpactSummary& s = a.result.summary;
  s.comminution_efficiency = a.energy.comminution_efficiency;
  s.ledger_residual_fraction = a.energy.residual_fraction;
  s.max_element_speed_m_s = a.energy.max_speed_m_s;
}

long read_long(const fs::path& f) {
  std::ifstream in(f);
  double v = -1;
  if (!(in >> v))
    throw std::runtime_error(f.string() + ": no number (the deck did not reach its first run)");
  return std::lround(v);
}

}  // namespace

LumpRun prepare_lump_run(StageContext& ctx, int repeat, const fs::path& out_dir,
                         const std::string& label, int set, const LumpSpec* spec) {
  const auto& d = ctx.cfg.doc;
  LumpRun run;
  const int packing = static_cast<int>(repeat % d.integer("lump.n_packings"));
  run.lump = ensure_lump({ctx.runner, ctx.progress, ctx.cfg.project_dir},
                         ctx.run_dir / "breakage" / "lumps", spec ? *spec : lump_spec(ctx.cfg),
                         packing, label);
  run.bond = bond_params_for_set(ctx.cfg, ctx.run_dir, set);
  run.rotation = random_rotation(
      1469598103ULL * static_cast<unsigned long long>(d.integer("lump.seed")) + 7919ULL * repeat);
  run.r_min = (1.0 - d.real("lump.radius_spread")) * run.lump.mean_radius;
  run.work = out_dir / "run";
  fs::remove_all(run.work);
  return run;
}

std::vector<std::pair<std::string, std::string>> lump_deck_vars(const StageContext& ctx,
                                                                const LumpRun& run) {
  const auto& d = ctx.cfg.doc;
  std::vector<std::pair<std::string, std::string>> v = {
      {"deck_dir", fs::absolute(ctx.cfg.project_dir / "liggghts_inputs").string()},
      {"lump_file", fs::absolute(run.lump.data).string()},
      {"rot_x", num(run.rotation[0])},
      {"rot_y", num(run.rotation[1])},
      {"rot_z", num(run.rotation[2])},
      {"rot_angle", num(run.rotation[3])},
      {"bond_gap", num(d.real("lump.bond_gap"))},
      {"max_bonds", std::to_string(d.integer("lump.max_bonds"))}};
  for (const auto& kv : material_vars(ctx.cfg.ore, run.bond, d)) v.push_back(kv);
  return v;
}

LumpRunResult analyse_lump_run(StageContext& ctx, const LumpRun& run,
                               const post::ImpactConditions& conditions, double wall_seconds,
                               const std::string& label) {
  const auto& d = ctx.cfg.doc;
  post::ImpactSpec is;
  is.conditions = conditions;
  is.initial_bonds = read_long(run.work / "bonds_initial.txt");
  is.lump_diameter_m = 2 * run.lump.outer_radius;
  is.density_kg_m3 = ctx.cfg.ore.real("density");
  is.fraction_edges = d.reals("breakage.size_fraction_edges");
  is.wall_seconds = wall_seconds;
  if (is.initial_bonds != run.lump.bonds)
    ctx.progress.warn(fmt::format(
        "{}: {} bonds at impact but {} when the lump was built (same rule): check lump.bond_gap",
        label, is.initial_bonds, run.lump.bonds));
  LumpRunResult a;
  a.snap = post::ReadDumpLastSnapshot((run.work / "final.dump").string(), is.density_kg_m3);
  if (static_cast<long>(a.snap.elements.size()) != run.lump.elements)
    throw std::runtime_error(
        fmt::format("{}: {} elements in the final state, {} in the lump: elements were lost", label,
                    a.snap.elements.size(), run.lump.elements));
  const auto bonds = post::ReadIntactBonds((run.work / "bonds_final.txt").string());
  a.result =
      post::AnalyseImpact(a.snap.elements, bonds, is, (run.work / "bonds_final.txt").string());
  for (const auto& w : a.result.warnings) ctx.progress.warn(label + ": " + w);
  read_energy_ledger(run, a);
  return a;
}

nlohmann::json energy_json(const post::LedgerSummary& e) {
  nlohmann::json j = {{"end_time_s", e.end_time_s}};
  for (const auto& [column, value] : e.final_energy) j[column] = value;
  j["residual_fraction"] = e.residual_fraction;
  j["residual_fraction_max"] = e.residual_fraction_max;
  j["max_element_speed_m_s"] = e.max_speed_m_s;
  j["max_element_speed_time_s"] = e.max_speed_time_s;
  j["wall_overlap_max"] = e.wall_overlap_max;
  j["comminution_efficiency"] = e.comminution_efficiency;
  j["definitions"] = {
      {"terms", "the ledger's last row (fix energy/ledger, docs/styles/fix_energy_ledger.md)"},
      {"residual_fraction", "residual_J / (input_J + |work_other_J|), last row"},
      {"comminution_efficiency",
       "bond_released_J / (input_J + max(work_other_J, 0)) at the end of the run"}};
  return j;
}

nlohmann::json lump_result_json(const LumpRun& run, const LumpRunResult& a, double wall_seconds) {
  const post::ImpactResult& r = a.result;
  const auto& s = r.summary;
  return {{"velocity_m_s", s.velocity_m_s},
          {"angle_deg", s.angle_deg},
          {"repeat", s.repeat},
          {"lump",
           {{"label", run.lump.label},
            {"elements", run.lump.elements},
            {"outer_diameter_m", 2 * run.lump.outer_radius},
            {"mean_element_radius_m", run.lump.mean_radius},
            {"coordination", run.lump.coordination}}},
          {"bond_parameters", bond_json(run.bond, BondNames::job)},
          {"bond_parameters_origin", run.bond.origin},
          {"n_pieces", s.n_pieces},
          {"n_single", s.n_single},
          {"n_multi", s.n_multi},
          {"largest_mass_fraction", s.largest_mass_fraction},
          {"single_mass_fraction", s.single_mass_fraction},
          {"broken_bond_fraction", s.broken_bond_fraction},
          {"specific_energy_J_kg", s.specific_energy_J_kg},
          {"specific_energy_kWh_t", s.specific_energy_kWh_t},
          {"t10_percent", s.t10_percent},
          {"t10_resolved", s.t10_resolved},
          {"warnings", r.warnings},
          {"wall_seconds", wall_seconds},
          {"energy", energy_json(a.energy)}};
}

void write_lump_outputs(const fs::path& out_dir, const LumpRunResult& a,
                        const nlohmann::json& result) {
  for (const char* f : {"summary.csv", "fractions.csv"}) fs::remove(out_dir / f);
  const fs::path stmp = out_dir / "summary.csv.part", ftmp = out_dir / "fractions.csv.part";
  fs::remove(stmp);
  fs::remove(ftmp);
  post::AppendSummaryCsv(stmp.string(), a.result.summary);
  post::AppendFractionsCsv(ftmp.string(), a.result);
  const fs::path htmp = out_dir / "impact.h5.part";
  post::WriteBreakageH5(htmp.string(), {a.result});
  post::WriteEnergyLedgerH5(htmp.string(), a.ledger);
  fs::rename(htmp, out_dir / "impact.h5");
  post::WriteEnergyLedgerCsv((out_dir / "energy_ledger.csv").string(), a.ledger);
  write_fragments_vtp(out_dir / "fragments.vtp", a.snap, a.result);
  jobs::atomic_write(out_dir / "result.json", result.dump(2) + "\n");
  fs::rename(stmp, out_dir / "summary.csv");
  fs::rename(ftmp, out_dir / "fractions.csv");
}

std::string damaged_lump_outputs(const fs::path& dir) {
  if (auto r = jobs::first_problem(
          {jobs::check_file(dir / "summary.csv"), jobs::check_file(dir / "fractions.csv"),
           jobs::check_json(dir / "result.json"), jobs::check_hdf5(dir / "impact.h5"),
           jobs::check_file(dir / "energy_ledger.csv"), jobs::check_file(dir / "fragments.vtp")});
      !r.empty())
    return r;
  try {
    std::ifstream in(dir / "result.json");
    if (!nlohmann::json::parse(in).contains("energy"))
      return (dir / "result.json").string() +
             ": no 'energy' object (written before the energy ledger)";
    post::ReadEnergyLedger((dir / "energy_ledger.csv").string());
    const auto rows = post::ReadSummaryCsv((dir / "summary.csv").string());
    if (rows.size() != 1)
      return fmt::format("{}: {} rows, expected 1", (dir / "summary.csv").string(), rows.size());
    if (post::ReadFractionsCsv((dir / "fractions.csv").string()).empty())
      return (dir / "fractions.csv").string() + ": no rows";
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace mill::breakage
