// Stage 'breakage': bonded-lump impacts and their fragment statistics.
#include "stages/breakage_stage.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

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
#include "stages/in_mill_runs.h"
#include "stages/lump_builder.h"
#include "stages/lump_run.h"
#include "stages/material.h"
#include "stages/stage_util.h"

namespace mill {
namespace fs = std::filesystem;
using engine::num;

namespace {

// Most an element may move in one impact step, as a share of the smallest
// element radius.
constexpr double kStepMove = 0.1;

// Inputs every impact of the case shares.
nlohmann::json impact_base_inputs(const StageContext& ctx) {
  nlohmann::json base =
      case_keys(ctx.cfg.doc, {"lump.", "breakage.duration_after_contact", "breakage.timestep", "breakage.quiet_time"});
  base["ore"] = ore_keys(ctx.cfg.ore);
  base["bond"] = bond_json(bond_params_for(ctx.cfg, ctx.run_dir), BondNames::job);
  // Bumped whenever the impact deck or the bond style changes what a run
  // gives (git log of this line: what each version changed); results of
  // other versions are not comparable.
  base["deck_version"] = 6;
  return base;
}

// The new surface of the impact's pieces and the energy released by broken
// bonds per unit of it (null for an intact lump), into result.json's `energy`.
void add_new_surface(nlohmann::json& energy, const LumpRunResult& a) {
  const auto per_surface =
      post::EnergyPerNewSurface(a.energy.bond_released_J, a.result.new_surface_m2);
  energy["new_surface_m2"] = a.result.new_surface_m2;
  energy["energy_per_new_surface_J_m2"] =
      per_surface ? nlohmann::json(*per_surface) : nlohmann::json(nullptr);
  energy["definitions"]["new_surface_m2"] =
      "sum over pieces of pi d^2 (d: equal-volume diameter of the piece's solid) minus that of "
      "the whole lump";
  energy["definitions"]["energy_per_new_surface_J_m2"] = "bond_released_J / new_surface_m2";
}

// <out_dir>/energy_ledger.png: the impact's ledger over time, stacked
// (postprocess/plot_energy_ledger.py, matplotlib, Debian's python3).
void plot_energy_ledger(StageContext& ctx, const fs::path& out_dir, double velocity, double angle,
                        int repeat, const std::string& label) {
  engine::Command c;
  c.argv = {"/usr/bin/python3",
            (ctx.cfg.project_dir / "postprocess" / "plot_energy_ledger.py").string(),
            "--ledger",
            (out_dir / "energy_ledger.csv").string(),
            "--out",
            (out_dir / "energy_ledger.png").string(),
            "--title",
            fmt::format("{:g} m/s at {:g} deg, repeat {}", velocity, angle, repeat)};
  c.cwd = out_dir;
  c.log = out_dir / "energy_ledger_plot.log";
  c.job = "breakage/" + label + " ledger plot";
  ctx.runner.run(c);
}

// The comminution efficiency of the impacts of one entry of
// critical_velocity.json `c` (an angle, or all conditions pooled): on the
// repeat-averaged curve at the critical speed (null when the sweep does not
// reach it), mean, min and max over the impacts, and the largest |residual|
// of their ledgers as a share of the energy given.
nlohmann::json efficiency_entry(const std::vector<post::ImpactSummary>& rows, const nlohmann::json& c) {
  std::vector<post::SweepPoint> pts;
  double residual = 0, sum = 0, lo = INFINITY, hi = -INFINITY;
  for (const auto& s : rows) {
    if (!(c["angle_deg"].is_null() || s.angle_deg == c["angle_deg"].get<double>())) continue;
    if (!std::isfinite(s.comminution_efficiency)) continue;
    pts.push_back({s.velocity_m_s, s.repeat, s.comminution_efficiency});
    sum += s.comminution_efficiency;
    lo = std::min(lo, s.comminution_efficiency);
    hi = std::max(hi, s.comminution_efficiency);
    if (std::isfinite(s.ledger_residual_fraction)) residual = std::max(residual, std::abs(s.ledger_residual_fraction));
  }
  const nlohmann::json none = nullptr;
  std::optional<double> at;
  if (c["critical_velocity_m_s"].is_number()) at = post::MeanCurveAt(pts, c["critical_velocity_m_s"].get<double>());
  return {{"angle_deg", c["angle_deg"]},
          {"critical_velocity_m_s", c["critical_velocity_m_s"]},
          {"impacts", pts.size()},
          {"at_critical_speed", at ? nlohmann::json(*at) : none},
          {"mean", pts.empty() ? none : nlohmann::json(sum / pts.size())},
          {"min", pts.empty() ? none : nlohmann::json(lo)},
          {"max", pts.empty() ? none : nlohmann::json(hi)},
          {"ledger_residual_fraction_max", pts.empty() ? none : nlohmann::json(residual)},
          {"definition",
           "bond_released_J / (input_J + max(work_other_J, 0)) at the end of each impact (its energy ledger); at "
           "the critical speed: the repeat-averaged curve, linear between sweep speeds"}};
}

// breakage/comminution_efficiency.json: efficiency_entry per entry of
// critical_velocity.json.
void write_comminution_efficiency(StageContext& ctx, const std::vector<post::ImpactSummary>& rows,
                                  const nlohmann::json& crit) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& c : crit) {
    out.push_back(efficiency_entry(rows, c));
    const auto& e = out.back();
    if (e["at_critical_speed"].is_number())
      ctx.progress.info(fmt::format("[breakage] comminution efficiency at the critical speed {:.1f} m/s: {:.2g}%",
                                    c["critical_velocity_m_s"].get<double>(),
                                    100 * e["at_critical_speed"].get<double>()));
  }
  jobs::atomic_write(ctx.stage_dir / "comminution_efficiency.json", out.dump(2) + "\n");
}

// plots/energy_ledger_fastest.png: the energy ledger plot of the fastest
// impact of the sweep (the first repeat of it), for the report.
void publish_fastest_ledger_plot(StageContext& ctx, const std::vector<post::ImpactSummary>& rows,
                                 const std::vector<fs::path>& row_dirs) {
  const auto fastest = std::max_element(rows.begin(), rows.end(), [](const auto& a, const auto& b) {
    return a.velocity_m_s < b.velocity_m_s;
  });
  if (fastest == rows.end()) return;
  const fs::path from = row_dirs[static_cast<size_t>(fastest - rows.begin())] / "energy_ledger.png";
  const fs::path to = ctx.stage_dir / "plots" / "energy_ledger_fastest.png";
  fs::create_directories(to.parent_path());
  fs::copy_file(from, to.string() + ".tmp", fs::copy_options::overwrite_existing);
  fs::rename(to.string() + ".tmp", to);
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
  if (auto r = damaged_lump_outputs(dir); !r.empty()) return r;
  return jobs::check_file(dir / "energy_ledger.png");
}

std::string impact_line(const nlohmann::json& r) {
  auto num = [&](const char* k) { return r.contains(k) && r[k].is_number() ? r[k].get<double>() : NAN; };
  const nlohmann::json e = r.value("energy", nlohmann::json::object());
  const std::string efficiency =
      e.contains("comminution_efficiency") && e["comminution_efficiency"].is_number()
          ? fmt::format(", comminution efficiency {:.2g}%", 100 * e["comminution_efficiency"].get<double>())
          : "";
  return fmt::format(
      "{:g} m/s at {:g} deg: {} pieces ({} single, {} multi), largest {:.1f}%, single-element mass {:.1f}%, "
      "broken bonds {:.1f}%, {:.3g} kWh/t, t10 {:.1f}%{}{} [{:.1f} s]",
      num("velocity_m_s"), num("angle_deg"), num("n_pieces"), num("n_single"), num("n_multi"),
      100 * num("largest_mass_fraction"), 100 * num("single_mass_fraction"), 100 * num("broken_bond_fraction"),
      num("specific_energy_kWh_t"), num("t10_percent"), r.value("t10_resolved", true) ? "" : " (unresolved)",
      efficiency, num("wall_seconds"));
}

std::string BreakageStage::damaged_outputs(const StageContext& ctx, const JobSpec& job) const {
  const fs::path dir = jobs::JobStore(ctx.stage_dir).job_dir(job.label);
  return is_in_mill_job(job) ? damaged_in_mill_outputs(dir) : damaged_impact_outputs(dir);
}

std::vector<std::string> BreakageStage::reads(const config::CaseConfig& cfg) const {
  if (cfg.doc.str("breakage.conditions") == "transport") {
    // In-mill runs with gas drag read the sampled field too.
    if (cfg.doc.integer("breakage.in_mill.lumps") > 0 && cfg.doc.boolean("breakage.in_mill.gas"))
      return {"sample", "transport", "calibrate"};
    return {"transport", "calibrate"};
  }
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
      plan_in_mill(ctx, rpm, p);
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
  const LumpRun lr = prepare_lump_run(ctx, repeat, out_dir, label);
  const LumpInfo& lump = lr.lump;

  // Start just short of contact: a gap of a tenth of an element radius.
  const double gap = 0.1 * lump.mean_radius;
  const double t_contact = gap / (velocity * std::sin(angle * M_PI / 180.0));
  const double t_end = t_contact + d.real("breakage.duration_after_contact");

  // The time step bounds how far an element moves per step: at most a tenth
  // of the smallest element radius (half the neighbour skin is 0.15 of the
  // mean radius), or the lump passes through the surface between two steps.
  const double r_min = lr.r_min;
  const double dt_speed = kStepMove * r_min / velocity;
  const double dt_given = d.real("breakage.timestep");
  if (dt_given > dt_speed)
    throw std::runtime_error(fmt::format(
        "{}: at {:g} m/s an element moves {:.3g} m per step of {:g} s, more than {:g} of the smallest element radius "
        "({:.3g} m); expected breakage.timestep <= {:.3g} s, or 0 (automatic)",
        d.where("breakage.timestep"), velocity, velocity * dt_given, dt_given, kStepMove, r_min, dt_speed));

  engine::DeckRun run;
  run.deck = ctx.cfg.project_dir / "liggghts_inputs" / "impact.in.tmpl";
  run.workdir = lr.work;
  run.np = ctx.opts.np;
  run.job = "breakage/" + label;
  run.vars = {{"velocity", num(velocity)},
              {"angle", num(angle)},
              {"z_plane", num(-(lump.outer_radius + gap))},
              {"t_end", num(t_end)},
              {"t_contact", num(t_contact)},
              {"quiet_time", num(d.real("breakage.quiet_time"))},
              {"dt", num(dt_given)},
              {"dt_speed", num(dt_speed)},
              {"skin", num(0.3 * lump.mean_radius)},
              {"binsize", num(4.0 * lump.mean_radius)},
              {"dump_interval", num(d.real("breakage.dump_interval"))}};
  for (const auto& kv : lump_deck_vars(ctx, lr)) run.vars.push_back(kv);
  const engine::Result res = engine::run_deck(ctx.runner, run, ctx.progress, label);

  // Fragment analysis of the final state.
  const LumpRunResult a = analyse_lump_run(ctx, lr, {velocity, angle, repeat}, res.seconds, label);
  // The surface is impenetrable: an element centre behind it means the run
  // stepped through the contact (the result would read as an intact bounce).
  const double z_plane = -(lump.outer_radius + gap);
  const long behind = std::count_if(a.snap.elements.begin(), a.snap.elements.end(),
                                    [&](const post::Element& e) { return e.x[2] < z_plane; });
  if (behind > 0)
    throw std::runtime_error(fmt::format(
        "{}: {} of {} elements ended behind the impact surface: the lump passed through it between time steps, the run "
        "is invalid (speed {:g} m/s, step bound {:.3g} s); log: {}",
        label, behind, a.snap.elements.size(), velocity, dt_speed, (lr.work / "liggghts.log").string()));

  // Outputs, each complete or absent. The raw run stays for inspection
  // (dumps for ParaView, logs); it is small next to the VTK dumps a user asks for.
  nlohmann::json j = lump_result_json(lr, a, res.seconds);
  add_new_surface(j["energy"], a);
  write_lump_outputs(out_dir, a, j);
  plot_energy_ledger(ctx, out_dir, velocity, angle, repeat, label);
  return impact_line(j);
}

void BreakageStage::run_job(StageContext& ctx, const JobSpec& job, const fs::path& job_dir) {
  if (is_in_mill_job(job)) {
    ctx.progress.info("[breakage] " + job.label + ": " + run_in_mill(ctx, job, job_dir));
    return;
  }
  const std::string line = run_impact(ctx, job.inputs.at("velocity").get<double>(), job.inputs.at("angle").get<double>(),
                                      job.inputs.at("repeat").get<int>(), job_dir, job.label);
  ctx.progress.info("[breakage] " + job.label + ": " + line);
}

void BreakageStage::finalize(StageContext& ctx, const std::vector<JobSpec>& all_jobs) {
  // The single impacts make the sweep's results; the in-mill runs their own.
  std::vector<JobSpec> jobs, in_mill;
  for (const auto& j : all_jobs) (is_in_mill_job(j) ? in_mill : jobs).push_back(j);
  if (jobs.empty()) return;
  const fs::path dir = ctx.stage_dir;
  const jobs::JobStore store(dir);
  std::vector<std::string> h5;
  std::vector<post::ImpactSummary> rows;
  std::vector<fs::path> row_dirs;  // the job folder of each row
  std::vector<post::FractionRow> fraction_rows;
  std::string fractions_text;
  for (const auto& j : jobs) {
    const fs::path jd = store.job_dir(j.label);
    h5.push_back((jd / "impact.h5").string());
    for (const auto& s : post::ReadSummaryCsv((jd / "summary.csv").string())) {
      rows.push_back(s);
      row_dirs.push_back(jd);
    }
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
  write_comminution_efficiency(ctx, rows, crit);

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
  publish_fastest_ledger_plot(ctx, rows, row_dirs);
  if (ctx.cfg.doc.str("breakage.conditions") == "transport")
    write_mill_product(ctx, jobs, write_in_mill_results(ctx, in_mill));
  ctx.progress.info(fmt::format(
      "[breakage] results: {}/summary.csv, fractions.csv, size_distributions.csv, jk_fit.json, "
      "comminution_efficiency.json, breakage.h5, plots/*.png",
      dir.string()));
}

void BreakageStage::write_mill_product(StageContext& ctx, const std::vector<JobSpec>& jobs,
                                       const std::map<double, nlohmann::json>& in_mill) {
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
    if (auto it = in_mill.find(rpm); it != in_mill.end()) e["in_mill"] = it->second;
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
