// Stage 'breakage': bonded-lump impacts and their fragment statistics.
#include "stages/breakage_stage.h"

#include <fmt/format.h>
#include <vtkCellArray.h>
#include <vtkDoubleArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataWriter.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <unordered_map>

#include "engine/liggghts.h"
#include "jobs/job_store.h"
#include "jobs/output_checks.h"
#include "postprocess/breakage_results.h"
#include "postprocess/distributions.h"
#include "postprocess/impact_conditions.h"
#include "postprocess/impact_stats.h"
#include "postprocess/lammps_dump.h"
#include "progress.h"
#include "stages/breakage_summaries.h"
#include "stages/lump_builder.h"
#include "stages/material.h"
#include "stages/stage_util.h"

namespace mill {
namespace fs = std::filesystem;
using engine::num;

namespace {

// Most an element may move in one impact step, as a share of the smallest
// element radius.
constexpr double kStepMove = 0.1;

nlohmann::json bond_json(const BondParams& b) {
  return {{"modulus", b.modulus},   {"stiffness_ratio", b.stiffness_ratio},       {"tensile", b.tensile},
          {"cohesion", b.cohesion}, {"friction_angle_deg", b.friction_angle_deg}, {"radius_multiplier", b.radius_multiplier},
          {"moment_factor", b.moment_factor}};
}

// A uniformly random rotation (Shoemake 1992, "Uniform random rotations",
// Graphics Gems III) as axis and angle in degrees, from a seed.
std::array<double, 4> random_rotation(unsigned long long seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double u1 = u(rng), u2 = u(rng), u3 = u(rng);
  const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
  const double q[4] = {b * std::cos(2 * M_PI * u3), a * std::sin(2 * M_PI * u2), a * std::cos(2 * M_PI * u2),
                       b * std::sin(2 * M_PI * u3)};  // w, x, y, z
  const double w = std::min(1.0, std::abs(q[0]));
  const double s = q[0] < 0 ? -1.0 : 1.0;
  const double angle = 2 * std::acos(w) * 180.0 / M_PI;
  const double n = std::sqrt(q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (n < 1e-12) return {0, 0, 1, 0};
  return {s * q[1] / n, s * q[2] / n, s * q[3] / n, angle};
}

// Elements as points for ParaView, coloured by fragment (0 = largest piece).
void write_fragments_vtp(const fs::path& file, const post::DumpSnapshot& snap, const post::ImpactResult& r) {
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
  for (vtkDataArray* a : std::initializer_list<vtkDataArray*>{frag, size, ids, radius, vel}) pd->GetPointData()->AddArray(a);
  pd->GetPointData()->SetActiveScalars("fragment");
  const fs::path tmp = file.string() + ".tmp.vtp";
  vtkNew<vtkXMLPolyDataWriter> w;
  w->SetFileName(tmp.c_str());
  w->SetInputData(pd);
  w->SetDataModeToBinary();
  if (w->Write() != 1) throw std::runtime_error("cannot write " + tmp.string());
  fs::rename(tmp, file);
}

long read_long(const fs::path& f) {
  std::ifstream in(f);
  double v = -1;
  if (!(in >> v)) throw std::runtime_error(f.string() + ": no number (the deck did not reach its first run)");
  return std::lround(v);
}

// Inputs every impact of the case shares.
nlohmann::json impact_base_inputs(const StageContext& ctx) {
  nlohmann::json base =
      case_keys(ctx.cfg.doc, {"lump.", "breakage.duration_after_contact", "breakage.timestep", "breakage.quiet_time"});
  base["ore"] = ore_keys(ctx.cfg.ore);
  base["bond"] = bond_json(bond_params_for(ctx.cfg, ctx.run_dir));
  // 4: bond/breakable with the signed tension criterion, the moment factor and
  // the exact critical step (Nov 2026): earlier results are not comparable.
  // 5: the time step also bounded by the impact speed (issue 15).
  base["deck_version"] = 5;
  return base;
}

}  // namespace

nlohmann::json impact_inputs(const StageContext& ctx, double velocity, double angle, int repeat) {
  nlohmann::json in = impact_base_inputs(ctx);
  in["velocity"] = velocity;
  in["angle"] = angle;
  in["repeat"] = repeat;
  return in;
}

std::string damaged_impact_outputs(const fs::path& dir) {
  if (auto r = jobs::first_problem({jobs::check_file(dir / "summary.csv"), jobs::check_file(dir / "fractions.csv"),
                                    jobs::check_json(dir / "result.json"), jobs::check_hdf5(dir / "impact.h5"),
                                    jobs::check_file(dir / "fragments.vtp")});
      !r.empty())
    return r;
  try {
    const auto rows = post::ReadSummaryCsv((dir / "summary.csv").string());
    if (rows.size() != 1) return fmt::format("{}: {} rows, expected 1", (dir / "summary.csv").string(), rows.size());
    if (post::ReadFractionsCsv((dir / "fractions.csv").string()).empty())
      return (dir / "fractions.csv").string() + ": no rows";
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

std::string impact_line(const nlohmann::json& r) {
  auto num = [&](const char* k) { return r.contains(k) && r[k].is_number() ? r[k].get<double>() : NAN; };
  return fmt::format(
      "{:g} m/s at {:g} deg: {} pieces ({} single, {} multi), largest {:.1f}%, single-element mass {:.1f}%, "
      "broken bonds {:.1f}%, {:.3g} kWh/t, t10 {:.1f}%{} [{:.1f} s]",
      num("velocity_m_s"), num("angle_deg"), num("n_pieces"), num("n_single"), num("n_multi"),
      100 * num("largest_mass_fraction"), 100 * num("single_mass_fraction"), 100 * num("broken_bond_fraction"),
      num("specific_energy_kWh_t"), num("t10_percent"), r.value("t10_resolved", true) ? "" : " (unresolved)",
      num("wall_seconds"));
}

std::string BreakageStage::damaged_outputs(const StageContext& ctx, const JobSpec& job) const {
  return damaged_impact_outputs(jobs::JobStore(ctx.stage_dir).job_dir(job.label));
}

std::vector<std::string> BreakageStage::reads(const config::CaseConfig& cfg) const {
  if (cfg.doc.str("breakage.conditions") == "transport") return {"transport", "calibrate"};
  return {"calibrate"};
}

std::vector<std::string> BreakageStage::jobs_from(const config::CaseConfig& cfg) const {
  if (cfg.doc.str("breakage.conditions") == "transport") return {"transport"};
  return {};
}

Plan BreakageStage::plan(const StageContext& ctx) const {
  Plan p;
  const auto& d = ctx.cfg.doc;
  const nlohmann::json base = impact_base_inputs(ctx);
  const long repeats = d.integer("breakage.repeats");
  if (d.str("breakage.conditions") == "transport") {
    // Conditions from stage 1: flywheel (and wall) impacts binned by normal speed.
    std::vector<std::string> surfaces = {"flywheel"};
    if (d.boolean("breakage.include_wall_impacts")) surfaces.push_back("housing");
    for (double rpm : d.reals("rotor.rpm")) {
      const fs::path f = ctx.run_dir / "transport" / rpm_label(rpm) / "impacts.csv";
      if (!fs::exists(f)) {
        p.note += (p.note.empty() ? "" : "; ") + fmt::format("waits for {} (orchestrate --stage transport)", f.string());
        continue;
      }
      const auto conds = post::BinImpacts(post::ReadImpactsCsv(f.string()), surfaces,
                                          static_cast<int>(d.integer("breakage.velocity_bins")));
      for (const auto& c : conds)
        for (long r = 0; r < repeats; ++r) {
          const double v = std::round(c.velocity_m_s * 10) / 10;
          const double a = std::clamp(std::round(c.angle_deg * 10) / 10, 1.0, 90.0);
          nlohmann::json in = base;
          in["velocity"] = v;
          in["angle"] = a;
          in["repeat"] = r;
          in["rpm"] = rpm;
          in["bin"] = c.bin;
          in["weight"] = c.weight;
          p.jobs.push_back({fmt::format("{}_b{}_{}", rpm_label(rpm), c.bin, impact_label(v, a, static_cast<int>(r))), in,
                            fmt::format("{} bin {} ({:.0f}% of impacts, normal {:.1f}-{:.1f} m/s): {:g} m/s at {:g} deg, "
                                        "repeat {}",
                                        rpm_label(rpm), c.bin, 100 * c.weight, c.normal_low_m_s, c.normal_high_m_s, v, a,
                                        r)});
        }
    }
    return p;
  }
  for (double v : d.reals("breakage.velocities"))
    for (double a : d.reals("breakage.angles"))
      for (long r = 0; r < repeats; ++r) {
        nlohmann::json in = base;
        in["velocity"] = v;
        in["angle"] = a;
        in["repeat"] = static_cast<int>(r);
        p.jobs.push_back({impact_label(v, a, static_cast<int>(r)), in,
                          fmt::format("{}-element lump at {:g} m/s, {:g} deg, repeat {}", d.integer("lump.n_elements"), v,
                                      a, r)});
      }
  return p;
}

std::string run_impact(StageContext& ctx, double velocity, double angle, int repeat, const fs::path& out_dir,
                       const std::string& label) {
  const auto& d = ctx.cfg.doc;
  const LumpSpec spec = lump_spec(ctx.cfg);
  const int packing = static_cast<int>(repeat % d.integer("lump.n_packings"));
  const LumpInfo lump = ensure_lump(ctx, spec, packing, label);
  const BondParams bond = bond_params_for(ctx.cfg, ctx.run_dir);

  // Start just short of contact: a gap of a tenth of an element radius.
  const double gap = 0.1 * lump.mean_radius;
  const double t_contact = gap / (velocity * std::sin(angle * M_PI / 180.0));
  const double t_end = t_contact + d.real("breakage.duration_after_contact");
  const auto rot = random_rotation(1469598103ULL * static_cast<unsigned long long>(d.integer("lump.seed")) + 7919ULL * repeat);

  // The time step bounds how far an element moves per step: at most a tenth
  // of the smallest element radius (half the neighbour skin is 0.15 of the
  // mean radius), or the lump passes through the surface between two steps.
  const double r_min = (1.0 - d.real("lump.radius_spread")) * lump.mean_radius;
  const double dt_speed = kStepMove * r_min / velocity;
  const double dt_given = d.real("breakage.timestep");
  if (dt_given > dt_speed)
    throw std::runtime_error(fmt::format(
        "{}: at {:g} m/s an element moves {:.3g} m per step of {:g} s, more than {:g} of the smallest element radius "
        "({:.3g} m); expected breakage.timestep <= {:.3g} s, or 0 (automatic)",
        d.where("breakage.timestep"), velocity, velocity * dt_given, dt_given, kStepMove, r_min, dt_speed));

  const fs::path work = out_dir / "run";
  fs::remove_all(work);
  engine::DeckRun run;
  run.deck = ctx.cfg.project_dir / "liggghts_inputs" / "impact.in.tmpl";
  run.workdir = work;
  run.np = ctx.opts.np;
  run.job = "breakage/" + label;
  run.vars = {{"lump_file", fs::absolute(lump.data).string()},
              {"velocity", num(velocity)},
              {"angle", num(angle)},
              {"z_plane", num(-(lump.outer_radius + gap))},
              {"rot_x", num(rot[0])},
              {"rot_y", num(rot[1])},
              {"rot_z", num(rot[2])},
              {"rot_angle", num(rot[3])},
              {"t_end", num(t_end)},
              {"t_contact", num(t_contact)},
              {"quiet_time", num(d.real("breakage.quiet_time"))},
              {"dt", num(dt_given)},
              {"dt_speed", num(dt_speed)},
              {"skin", num(0.3 * lump.mean_radius)},
              {"binsize", num(4.0 * lump.mean_radius)},
              {"dump_interval", num(d.real("breakage.dump_interval"))},
              {"bond_gap", num(d.real("lump.bond_gap"))},
              {"max_bonds", std::to_string(d.integer("lump.max_bonds"))}};
  for (const auto& kv : material_vars(ctx.cfg.ore, bond, ctx.cfg.doc)) run.vars.push_back(kv);
  const engine::Result res = engine::run_deck(ctx.runner, run, ctx.progress, label);

  // Fragment analysis of the final state.
  post::ImpactSpec is;
  is.conditions = {velocity, angle, repeat};
  is.initial_bonds = read_long(work / "bonds_initial.txt");
  is.lump_diameter_m = 2 * lump.outer_radius;
  is.density_kg_m3 = ctx.cfg.ore.real("density");
  is.fraction_edges = d.reals("breakage.size_fraction_edges");
  is.wall_seconds = res.seconds;
  if (is.initial_bonds != lump.bonds)
    ctx.progress.warn(fmt::format("{}: {} bonds at impact but {} when the lump was built (same rule): check lump.bond_gap",
                                  label, is.initial_bonds, lump.bonds));
  const post::DumpSnapshot snap = post::ReadDumpLastSnapshot((work / "final.dump").string(), is.density_kg_m3);
  if (static_cast<long>(snap.elements.size()) != lump.elements)
    throw std::runtime_error(fmt::format("{}: {} elements in the final state, {} in the lump: elements were lost", label,
                                         snap.elements.size(), lump.elements));
  // The surface is impenetrable: an element centre behind it means the run
  // stepped through the contact (the result would read as an intact bounce).
  const double z_plane = -(lump.outer_radius + gap);
  const long behind = std::count_if(snap.elements.begin(), snap.elements.end(),
                                    [&](const post::Element& e) { return e.x[2] < z_plane; });
  if (behind > 0)
    throw std::runtime_error(fmt::format(
        "{}: {} of {} elements ended behind the impact surface: the lump passed through it between time steps, the run "
        "is invalid (speed {:g} m/s, step bound {:.3g} s); log: {}",
        label, behind, snap.elements.size(), velocity, dt_speed, (work / "liggghts.log").string()));
  const auto bonds = post::ReadIntactBonds((work / "bonds_final.txt").string());
  const post::ImpactResult r = post::AnalyseImpact(snap.elements, bonds, is, (work / "bonds_final.txt").string());
  for (const auto& w : r.warnings) ctx.progress.warn(label + ": " + w);

  // Outputs, each complete or absent (temporary name, then rename).
  for (const char* f : {"summary.csv", "fractions.csv"}) fs::remove(out_dir / f);
  const fs::path stmp = out_dir / "summary.csv.part", ftmp = out_dir / "fractions.csv.part";
  fs::remove(stmp);
  fs::remove(ftmp);
  post::AppendSummaryCsv(stmp.string(), r.summary);
  post::AppendFractionsCsv(ftmp.string(), r);
  post::WriteBreakageH5((out_dir / "impact.h5").string(), {r});
  write_fragments_vtp(out_dir / "fragments.vtp", snap, r);
  const auto& s = r.summary;
  nlohmann::json j = {{"velocity_m_s", velocity},
                      {"angle_deg", angle},
                      {"repeat", repeat},
                      {"lump", {{"label", lump.label},
                                {"elements", lump.elements},
                                {"outer_diameter_m", 2 * lump.outer_radius},
                                {"mean_element_radius_m", lump.mean_radius},
                                {"coordination", lump.coordination}}},
                      {"bond_parameters", bond_json(bond)},
                      {"bond_parameters_origin", bond.origin},
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
                      {"wall_seconds", res.seconds}};
  jobs::atomic_write(out_dir / "result.json", j.dump(2) + "\n");
  fs::rename(stmp, out_dir / "summary.csv");
  fs::rename(ftmp, out_dir / "fractions.csv");
  // The raw run stays for inspection (dumps for ParaView, logs); it is small
  // next to the VTK dumps a user asks for.
  return impact_line(j);
}

void BreakageStage::run_job(StageContext& ctx, const JobSpec& job, const fs::path& job_dir) {
  const std::string line = run_impact(ctx, job.inputs.at("velocity").get<double>(), job.inputs.at("angle").get<double>(),
                                      job.inputs.at("repeat").get<int>(), job_dir, job.label);
  ctx.progress.info("[breakage] " + job.label + ": " + line);
}

void BreakageStage::finalize(StageContext& ctx, const std::vector<JobSpec>& jobs) {
  if (jobs.empty()) return;
  const fs::path dir = ctx.stage_dir;
  const jobs::JobStore store(dir);
  std::vector<std::string> h5;
  std::vector<post::ImpactSummary> rows;
  std::vector<post::FractionRow> fraction_rows;
  std::string fractions_text;
  for (const auto& j : jobs) {
    const fs::path jd = store.job_dir(j.label);
    h5.push_back((jd / "impact.h5").string());
    for (const auto& s : post::ReadSummaryCsv((jd / "summary.csv").string())) rows.push_back(s);
    for (const auto& f : post::ReadFractionsCsv((jd / "fractions.csv").string())) {
      fractions_text += post::FractionsCsvLine(f) + "\n";
      fraction_rows.push_back(f);
    }
  }
  std::string header;
  for (const auto& c : post::FractionsCsvColumns()) header += (header.empty() ? "" : ",") + c;
  fractions_text = header + "\n" + fractions_text;
  const fs::path stmp = dir / "summary.csv.part";
  fs::remove(stmp);
  for (const auto& s : rows) post::AppendSummaryCsv(stmp.string(), s);
  fs::rename(stmp, dir / "summary.csv");
  jobs::atomic_write(dir / "fractions.csv", fractions_text);
  post::MergeBreakageH5Files((dir / "breakage.h5").string(), h5);

  // Critical velocity per angle: largest piece falls below the threshold.
  // Conditions binned from transport each have their own speed and angle, so
  // they are pooled into one curve over impact speed (angle_deg null).
  const bool pooled = ctx.cfg.doc.str("breakage.conditions") == "transport";
  constexpr double kPooled = -1.0;
  const double thr = ctx.cfg.doc.real("breakage.critical_largest_fraction");
  nlohmann::json crit = nlohmann::json::array();
  std::map<double, std::vector<post::SweepPoint>> by_angle;
  for (const auto& s : rows)
    by_angle[pooled ? kPooled : s.angle_deg].push_back({s.velocity_m_s, s.repeat, s.largest_mass_fraction});
  for (const auto& [angle, pts] : by_angle) {
    const auto c = post::FindCriticalVelocity(pts, thr);
    const std::string where = pooled ? "over all conditions, angles pooled," : fmt::format("at {:g} deg", angle);
    nlohmann::json e = {{"angle_deg", pooled ? nlohmann::json(nullptr) : nlohmann::json(angle)},
                        {"threshold", thr},
                        {"repeats_crossing", c.n_crossed}};
    if (pooled) e["note"] = "conditions binned from transport: every bin has its own speed and angle; pooled";
    e["critical_velocity_m_s"] = c.of_mean_curve ? nlohmann::json(*c.of_mean_curve) : nlohmann::json(nullptr);
    e["min_m_s"] = c.min ? nlohmann::json(*c.min) : nlohmann::json(nullptr);
    e["max_m_s"] = c.max ? nlohmann::json(*c.max) : nlohmann::json(nullptr);
    crit.push_back(e);
    ctx.progress.info(c.of_mean_curve
                          ? fmt::format("[breakage] critical velocity {} (largest piece < {:g}%): {:.1f} m/s{}", where,
                                        100 * thr, *c.of_mean_curve,
                                        c.min && c.max && *c.min != *c.max
                                            ? fmt::format(" (repeats {:.1f}-{:.1f} m/s)", *c.min, *c.max)
                                            : "")
                          : fmt::format("[breakage] {} the largest piece never fell below {:g}% in the sweep", where,
                                        100 * thr));
  }
  jobs::atomic_write(dir / "critical_velocity.json", crit.dump(2) + "\n");

  // In the mill engineer's terms: JK A and b, passing curves in mm.
  write_size_distributions(ctx, fraction_rows);
  write_jk_fit(ctx, rows, pooled);

  // Plots from the merged CSVs (matplotlib, Debian's python3).
  engine::Command c;
  c.argv = {"/usr/bin/python3", (ctx.cfg.project_dir / "postprocess" / "plot_breakage.py").string(),
            "--summary", (dir / "summary.csv").string(), "--passing", (dir / "size_distributions.csv").string(),
            "--out", (dir / "plots").string(), "--threshold", num(thr)};
  if (pooled) c.argv.push_back("--pool-angles");
  c.cwd = dir;
  c.log = dir / "plots.log";
  c.job = "breakage/plots";
  ctx.runner.run(c);
  if (ctx.cfg.doc.str("breakage.conditions") == "transport") write_mill_product(ctx, jobs);
  ctx.progress.info(fmt::format(
      "[breakage] results: {}/summary.csv, fractions.csv, size_distributions.csv, jk_fit.json, breakage.h5, plots/*.png",
      dir.string()));
}

void BreakageStage::write_mill_product(StageContext& ctx, const std::vector<JobSpec>& jobs) {
  // Per rotor speed: average each bin over its repeats, weight bins by their
  // share of impacts (postprocess/impact_conditions.h).
  const fs::path dir = ctx.stage_dir;
  const jobs::JobStore store(dir);
  const auto edges = ctx.cfg.doc.reals("breakage.size_fraction_edges");
  struct Acc {
    post::ConditionBreakage c;
    int n = 0;
  };
  std::map<double, std::map<int, Acc>> by_rpm;
  for (const auto& j : jobs) {
    const fs::path jd = store.job_dir(j.label);
    const auto rows = post::ReadSummaryCsv((jd / "summary.csv").string());
    if (rows.empty()) throw std::runtime_error((jd / "summary.csv").string() + ": no row");
    std::vector<double> frac(edges.size() - 1, 0.0);
    for (const auto& f : post::ReadFractionsCsv((jd / "fractions.csv").string())) {
      if (f.index >= static_cast<int>(frac.size()))
        throw std::runtime_error(fmt::format("{}: fraction {} beyond the case's {} size fractions",
                                             (jd / "fractions.csv").string(), f.index, frac.size()));
      frac[f.index] = f.mass_fraction;
    }
    Acc& a = by_rpm[j.inputs.at("rpm").get<double>()][j.inputs.at("bin").get<int>()];
    a.c.weight = j.inputs.at("weight").get<double>();
    if (a.c.fraction_mass.empty()) a.c.fraction_mass.assign(frac.size(), 0.0);
    for (size_t k = 0; k < frac.size(); ++k) a.c.fraction_mass[k] += frac[k];
    a.c.single_mass_fraction += rows[0].single_mass_fraction;
    a.c.largest_mass_fraction += rows[0].largest_mass_fraction;
    a.c.t10_percent += rows[0].t10_percent;
    ++a.n;
  }
  nlohmann::json out = nlohmann::json::array();
  const double d_mm = 1000 * ctx.cfg.doc.real("lump.diameter");
  const auto sieves = sieves_mm(edges, d_mm);
  std::string csv = "rpm,fraction_index,d_low_rel,d_high_rel,mass_fraction,d_high_mm,passing_percent\n";
  for (auto& [rpm, bins] : by_rpm) {
    std::vector<post::ConditionBreakage> conds;
    for (auto& [bin, a] : bins) {
      for (auto& f : a.c.fraction_mass) f /= a.n;
      a.c.single_mass_fraction /= a.n;
      a.c.largest_mass_fraction /= a.n;
      a.c.t10_percent /= a.n;
      conds.push_back(a.c);
    }
    const auto prod = post::CombineProduct(conds);
    const nlohmann::json pass = passing_json(sieves, prod.fraction_mass);
    for (size_t k = 0; k < prod.fraction_mass.size(); ++k)
      csv += fmt::format("{:g},{},{:g},{:g},{:.9g},{:.6g},{:.6g}\n", rpm, k, edges[k], edges[k + 1], prod.fraction_mass[k],
                         sieves[k], pass["passing_percent"][k].get<double>());
    nlohmann::json e = {{"rpm", rpm},
                        {"conditions", conds.size()},
                        {"fraction_edges_rel", edges},
                        {"fraction_mass", prod.fraction_mass},
                        {"fully_shredded_mass_fraction", prod.single_mass_fraction},
                        {"largest_piece_mass_fraction", prod.largest_mass_fraction},
                        {"t10_percent", prod.t10_percent},
                        {"lump_diameter_mm", d_mm}};
    e.update(pass);
    out.push_back(e);
    const auto mm = [&](const char* k) {
      return pass[k].is_number() ? fmt::format("{:.3g} mm", pass[k].get<double>())
                                 : fmt::format("< {:.3g} mm", sieves.front());
    };
    ctx.progress.info(fmt::format("[breakage] mill product at {:g} rpm ({} conditions): P80 {}, P50 {}, fully shredded "
                                  "{:.1f}% of the mass, largest piece {:.1f}%, t10 {:.1f}%",
                                  rpm, conds.size(), mm("p80_mm"), mm("p50_mm"), 100 * prod.single_mass_fraction,
                                  100 * prod.largest_mass_fraction, prod.t10_percent));
  }
  jobs::atomic_write(dir / "product.csv", csv);
  jobs::atomic_write(dir / "product.json", out.dump(2) + "\n");

  // The product against rotor speed (matplotlib, Debian's python3).
  engine::Command c;
  c.argv = {"/usr/bin/python3", (ctx.cfg.project_dir / "postprocess" / "plot_product.py").string(), "--product",
            (dir / "product.json").string(), "--out", (dir / "plots").string()};
  c.cwd = dir;
  c.log = dir / "plot_product.log";
  c.job = "breakage/product plot";
  ctx.runner.run(c);
}

}  // namespace mill
