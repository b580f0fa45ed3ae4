// Stage 'breakage': plans the impacts (and in-mill runs), runs one per job,
// and publishes the campaign's results from the steps in stages/breakage/.
#include "stages/breakage_stage.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "engine/runner.h"
#include "jobs/job_store.h"
#include "jobs/output_checks.h"
#include "lump/material.h"
#include "postprocess/impact_conditions.h"
#include "progress.h"
#include "stages/breakage/breakage_matrix.h"
#include "stages/breakage/calibration_sets.h"
#include "stages/breakage/campaign.h"
#include "stages/breakage/circuit.h"
#include "stages/breakage/impact_runs.h"
#include "stages/breakage/in_mill_animation.h"
#include "stages/breakage/in_mill_runs.h"
#include "stages/breakage/mill_product.h"
#include "stages/breakage/summaries.h"
#include "stages/stage_util.h"

namespace mill {
namespace fs = std::filesystem;
using namespace breakage;  // the stage's steps (stages/breakage/)

namespace {

// The impacts of one rotor speed with breakage.conditions = transport: its
// transport impacts (flywheel, and housing with
// breakage.include_wall_impacts) binned by normal speed, each bin
// breakage.repeats times; false when the transport's impacts are missing.
bool plan_binned(const StageContext& ctx, const nlohmann::json& base, double rpm, Plan& p) {
  const auto& d = ctx.cfg.doc;
  std::vector<std::string> surfaces = {"flywheel"};
  if (d.boolean("breakage.include_wall_impacts")) surfaces.push_back("housing");
  const fs::path f = ctx.run_dir / "transport" / rpm_label(rpm) / "impacts.csv";
  if (!fs::exists(f)) {
    p.note += (p.note.empty() ? "" : "; ") +
              fmt::format("waits for {} (orchestrate --stage transport)", f.string());
    return false;
  }
  const auto conds = post::BinImpacts(post::ReadImpactsCsv(f.string()), surfaces,
                                      static_cast<int>(d.integer("breakage.velocity_bins")));
  for (const auto& c : conds)
    for (long r = 0; r < d.integer("breakage.repeats"); ++r) {
      engine::throw_if_interrupted();  // a plan of many jobs stops on SIGINT/SIGTERM
      const double v = std::round(c.velocity_m_s * 10) / 10;
      const double a = std::clamp(std::round(c.angle_deg * 10) / 10, 1.0, 90.0);
      nlohmann::json in = base;
      in["velocity"] = v;
      in["angle"] = a;
      in["repeat"] = r;
      in["rpm"] = rpm;
      in["bin"] = c.bin;
      in["weight"] = c.weight;
      p.jobs.push_back(
          {fmt::format("{}_b{}_{}", rpm_label(rpm), c.bin, impact_label(v, a, static_cast<int>(r))),
           in,
           fmt::format("{} bin {} ({:.0f}% of impacts, normal {:.1f}-{:.1f} m/s): {:g} m/s at {:g} "
                       "deg, repeat {}",
                       rpm_label(rpm), c.bin, 100 * c.weight, c.normal_low_m_s, c.normal_high_m_s,
                       v, a, r)});
    }
  return true;
}

// The impacts of the case's own sweep: breakage.velocities x breakage.angles
// x breakage.repeats, breakage.crossing_repeats at breakage.crossing_velocities.
void plan_sweep(const StageContext& ctx, const nlohmann::json& base, Plan& p) {
  const auto& d = ctx.cfg.doc;
  const std::vector<double> crossing = d.has("breakage.crossing_velocities")
                                           ? d.reals("breakage.crossing_velocities")
                                           : std::vector<double>{};
  for (double v : d.reals("breakage.velocities"))
    for (double a : d.reals("breakage.angles")) {
      const bool at_crossing = std::find(crossing.begin(), crossing.end(), v) != crossing.end();
      const long repeats =
          d.integer(at_crossing ? "breakage.crossing_repeats" : "breakage.repeats");
      for (long r = 0; r < repeats; ++r) {
        engine::throw_if_interrupted();  // a plan of many jobs stops on SIGINT/SIGTERM
        nlohmann::json in = base;
        in["velocity"] = v;
        in["angle"] = a;
        in["repeat"] = static_cast<int>(r);
        p.jobs.push_back({impact_label(v, a, static_cast<int>(r)), in,
                          fmt::format("{}-element lump at {:g} m/s, {:g} deg, repeat {}",
                                      d.integer("lump.n_elements"), v, a, r)});
      }
    }
}

// With transport conditions, the strength impacts
// (breakage.strength_velocities): normal single impacts at each speed,
// breakage.repeats each, beside stage 1's; labelled strength_<impact>.
void plan_strength(const StageContext& ctx, const nlohmann::json& base, Plan& p) {
  const auto& d = ctx.cfg.doc;
  if (!d.has("breakage.strength_velocities")) return;
  for (double v : d.reals("breakage.strength_velocities"))
    for (long r = 0; r < d.integer("breakage.repeats"); ++r) {
      engine::throw_if_interrupted();
      nlohmann::json in = base;
      in["velocity"] = v;
      in["angle"] = 90.0;
      in["repeat"] = static_cast<int>(r);
      in["strength"] = true;
      p.jobs.push_back(
          {std::string(kStrengthPrefix) + impact_label(v, 90.0, static_cast<int>(r)), in,
           fmt::format("strength impact: {}-element lump at {:g} m/s, 90 deg, repeat {}",
                       d.integer("lump.n_elements"), v, r)});
    }
}

// With a feed: the breakage matrix per rotor speed from the in-mill runs and
// the closed circuit's steady state, or a warning that says what the
// population balance needs.
void write_population_balance(StageContext& ctx, const std::vector<JobSpec>& in_mill,
                              const std::vector<JobSpec>& class_runs) {
  const auto& d = ctx.cfg.doc;
  if (d.str("breakage.conditions") != "transport" || d.integer("breakage.in_mill.lumps") <= 0 ||
      (in_mill.empty() && class_runs.empty())) {
    ctx.progress.warn(fmt::format(
        "{}: the feed's population balance needs in-mill runs (breakage.conditions: transport "
        "and breakage.in_mill.lumps >= 1); none ran, so there is no breakage matrix",
        d.file()));
    return;
  }
  const MeasuringRuns runs = collect_measuring_runs(ctx, in_mill, class_runs);
  std::vector<double> rpms;
  for (const auto& [rpm, by_class] : runs) rpms.push_back(rpm);
  write_circuit(ctx, write_breakage_matrices(ctx, runs), runs, read_gas_shaft_power(ctx, rpms));
}

}  // namespace

std::string BreakageStage::damaged_outputs(const StageContext& ctx, const JobSpec& job) const {
  const fs::path dir = jobs::JobStore(ctx.stage_dir).job_dir(job.label);
  return is_in_mill_job(job) ? damaged_in_mill_outputs(job, dir) : damaged_impact_outputs(dir);
}

// The merged tables and summaries of the impacts (and the mill product of
// conditions from transport), each parsed the way the report reads it.
std::string BreakageStage::damaged_merged_outputs(const StageContext& ctx,
                                                  const std::vector<JobSpec>& jobs) const {
  // The primary set's impacts make the merged tables (calibration_sets.json
  // holds the other sets' critical speeds).
  const size_t n_impacts =
      static_cast<size_t>(std::count_if(jobs.begin(), jobs.end(), [](const JobSpec& j) {
        return !is_in_mill_job(j) && calibration_set_of(j) == 1;
      }));
  if (n_impacts == 0) return "";
  const fs::path dir = ctx.stage_dir;
  std::vector<std::string> r = {jobs::check_file(dir / "summary.csv"),
                                jobs::check_file(dir / "fractions.csv")};
  if (r[0].empty()) try {
      const size_t rows = post::ReadSummaryCsv((dir / "summary.csv").string()).size();
      if (rows != n_impacts)
        r[0] = fmt::format("{}: {} row(s), expected {} (one per impact)",
                           (dir / "summary.csv").string(), rows, n_impacts);
    } catch (const std::exception& e) {
      r[0] = e.what();
    }
  if (r[1].empty()) try {
      post::ReadFractionsCsv((dir / "fractions.csv").string());
    } catch (const std::exception& e) {
      r[1] = e.what();
    }
  r.push_back(jobs::check_hdf5(dir / "breakage.h5"));
  for (const char* f : {"critical_velocity.json", "comminution_efficiency.json",
                        "size_distributions.json", "jk_fit.json"})
    r.push_back(jobs::check_json(dir / f, true));
  if (std::any_of(jobs.begin(), jobs.end(),
                  [](const JobSpec& j) { return calibration_set_of(j) > 1; }))
    r.push_back(jobs::check_json(dir / "calibration_sets.json", true));
  if (ctx.cfg.doc.str("breakage.conditions") == "transport") {
    r.push_back(jobs::check_file(dir / "product.csv"));
    r.push_back(jobs::check_json(dir / "product.json", true));
    if (std::any_of(jobs.begin(), jobs.end(), is_animated)) r.push_back(damaged_animation(dir));
    if (ctx.cfg.feed && std::any_of(jobs.begin(), jobs.end(), is_in_mill_job)) {
      r.push_back(jobs::check_file(dir / "breakage_matrix.csv"));
      r.push_back(jobs::check_json(dir / "breakage_matrix.json", true));
      r.push_back(jobs::check_file(dir / "circuit.csv"));
      r.push_back(jobs::check_json(dir / "circuit.json", true));
    }
  }
  return jobs::first_problem(r);
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
  const nlohmann::json base = impact_base_inputs(ctx);
  if (const std::string why = uncalibrated_reason(ctx.cfg, ctx.run_dir); !why.empty())
    p.warnings.push_back(fmt::format(
        "[breakage] the lumps' bonds are the closed-form estimate, not a calibration of this card "
        "and lump ({}): a weak rock whose figures mean little; run `orchestrate --case {} --stage "
        "calibrate-breakage --output {}` first",
        why, ctx.cfg.file.string(), ctx.run_dir.string()));
  if (ctx.cfg.doc.str("breakage.conditions") != "transport") {
    plan_sweep(ctx, base, p);
  } else {
    // Conditions from stage 1, and the in-mill runs, per rotor speed; with
    // a feed, the in-mill runs of each feed class too, and lump.diameter's
    // own in-mill runs only when its class has none (they would measure the
    // same class at nearly the same size twice).
    std::vector<config::FeedClassRuns> classes;
    bool lump_runs = true;
    if (ctx.cfg.feed) {
      classes = config::plan_feed_classes(ctx.cfg.doc, *ctx.cfg.feed);
      if (ctx.cfg.doc.integer("breakage.in_mill.lumps") > 0)
        lump_runs = !classes.at(config::lump_feed_class(ctx.cfg.doc, *ctx.cfg.feed)).in_mill;
    }
    for (double rpm : ctx.cfg.doc.reals("rotor.rpm"))
      if (plan_binned(ctx, base, rpm, p)) {
        if (lump_runs) plan_in_mill(ctx, rpm, p);
        for (const auto& c : classes)
          if (c.in_mill) plan_in_mill(ctx, rpm, p, &c);
      }
    plan_strength(ctx, base, p);
  }
  // The same impacts with every further calibration set (calibrate.starts).
  plan_calibration_sets(ctx, p);
  return p;
}

void BreakageStage::run_job(StageContext& ctx, const JobSpec& job, const fs::path& job_dir) {
  if (is_in_mill_job(job)) {
    ctx.progress.info("[breakage] " + job.label + ": " + run_in_mill(ctx, job, job_dir));
    return;
  }
  const std::string line =
      run_impact(ctx, job.inputs.at("velocity").get<double>(), job.inputs.at("angle").get<double>(),
                 job.inputs.at("repeat").get<int>(), job_dir, job.label,
                 calibration_set_of(job));
  ctx.progress.info("[breakage] " + job.label + ": " + line);
}

void BreakageStage::finalize(StageContext& ctx, const std::vector<JobSpec>& all_jobs) {
  // The single impacts make the sweep's results; the in-mill runs of
  // lump.diameter their own, the feed classes' runs the breakage matrix.
  std::vector<JobSpec> jobs, in_mill, class_runs, set_jobs;
  for (const auto& j : all_jobs)
    (is_in_mill_job(j)           ? (in_mill_class(j) ? class_runs : in_mill)
     : calibration_set_of(j) > 1 ? set_jobs
                                 : jobs)
        .push_back(j);
  if (jobs.empty()) return;
  // Conditions binned from transport each have their own speed and angle:
  // they are pooled into one curve over impact speed.
  const bool from_transport = ctx.cfg.doc.str("breakage.conditions") == "transport";
  const Campaign c = merge_impacts(ctx, jobs);
  const nlohmann::json crit = write_critical_velocity(ctx, c.rows, from_transport);
  write_comminution_efficiency(ctx, c.rows, crit);
  write_calibration_sets(ctx, set_jobs, c.rows, crit, from_transport);
  // In the mill engineer's terms: JK A and b, passing curves in mm.
  write_size_distributions(ctx, c.fractions);
  write_jk_fit(ctx, c.rows, from_transport);
  plot_campaign(ctx, c, from_transport);
  if (from_transport) {
    std::vector<JobSpec> all_in_mill = in_mill;
    all_in_mill.insert(all_in_mill.end(), class_runs.begin(), class_runs.end());
    publish_animation(ctx, all_in_mill);
    // The in-mill product of product.json: lump.diameter's runs or, when
    // its feed class ran instead (plan), that class's runs.
    std::vector<JobSpec> lump_runs = in_mill;
    if (lump_runs.empty() && ctx.cfg.feed && !class_runs.empty()) {
      const std::size_t lc = config::lump_feed_class(ctx.cfg.doc, *ctx.cfg.feed);
      for (const auto& j : class_runs)
        if (in_mill_class(j) == lc) lump_runs.push_back(j);
    }
    // The strength impacts are no mill condition: the product reads stage 1's bins only.
    std::vector<JobSpec> binned;
    for (const auto& j : jobs)
      if (!is_strength_job(j)) binned.push_back(j);
    write_mill_product(ctx, binned, write_in_mill_results(ctx, lump_runs));
  }
  // lump.diameter's runs measure its class only where it has none of its
  // own (collect_measuring_runs); the class runs are passed as they are.
  if (ctx.cfg.feed) write_population_balance(ctx, in_mill, class_runs);
  ctx.progress.info(fmt::format(
      "[breakage] results: {}/summary.csv, fractions.csv, size_distributions.csv, jk_fit.json, "
      "comminution_efficiency.json, breakage.h5, plots/*.png",
      ctx.stage_dir.string()));
}

}  // namespace mill
