// Stage 'flow': one OpenFOAM run per rotor speed. The job writes the case
// (flow/case_files), meshes and solves it (flow/foam_runs), reads OpenFOAM's
// results into flow_report.json (flow/foam_results, flow/report); this file
// plans, orchestrates and publishes.
#include "stages/flow_stage.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>

#include "geometry/mill_geometry.h"
#include "jobs/job_store.h"
#include "jobs/output_checks.h"
#include "progress.h"
#include "stages/flow/case_files.h"
#include "stages/flow/foam_results.h"
#include "stages/flow/foam_runs.h"
#include "stages/flow/report.h"
#include "stages/stage_util.h"

namespace mill {
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

// Wall-clock seconds since t.
double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// The declared outputs of a solved job: assembled in a temp folder (geometry,
// report, the case moved there), then renamed over the old output.
void publish(const StageContext& ctx, const flow::JobSettings& s, const fs::path& work,
             const nlohmann::json& rep) {
  const fs::path out = flow::output_dir(ctx.run_dir, s.label);
  const fs::path tmp = out.string() + ".tmp." + std::to_string(getpid());
  fs::remove_all(tmp);
  fs::create_directories(tmp);
  geometry::write_stl_set(s.geo, tmp / "geometry");
  jobs::atomic_write(tmp / "flow_report.json", rep.dump(2) + "\n");
  fs::rename(work, tmp / "case");
  fs::remove_all(out);
  fs::rename(tmp, out);
}

}  // namespace

// Declared output folder of one rotor speed.
fs::path flow::output_dir(const fs::path& run_dir, const std::string& label) {
  return run_dir / "flow" / label;
}

// One job per rotor speed; inputs are the mill.*, gas.*, flow.* keys and the rpm.
Plan FlowStage::plan(const StageContext& ctx) const {
  Plan p;
  for (double rpm : ctx.cfg.doc.reals("rotor.rpm")) {
    nlohmann::json in = case_keys(ctx.cfg.doc, {"mill.", "gas.", "flow."});
    in["rotor.rpm"] = rpm;
    p.jobs.push_back({rpm_label(rpm), in,
                      "mesh (" + ctx.cfg.doc.str("flow.mesh_preset") + " preset) and solve at " +
                          rpm_label(rpm)});
  }
  return p;
}

// Case -> mesh -> solve -> report -> publish.
void FlowStage::run_job(StageContext& ctx, const JobSpec& job, const fs::path& job_dir) {
  flow::WallTimes times;
  times.start = Clock::now();
  const auto s = flow::job_settings(ctx.cfg.doc, job, std::max(1, ctx.opts.np));
  const fs::path work = job_dir / "case";
  flow::write_case(ctx.cfg.project_dir / "foam_case", work, s);

  const long cells = flow::mesh_case(ctx, s, work);
  times.mesh_seconds = seconds_since(times.start);
  ctx.progress.info(fmt::format("{}: mesh of {} cells ({} preset) in {}", s.tag, cells,
                                s.preset.name, Progress::duration(times.mesh_seconds)));

  const flow::Solution sol = flow::solve_case(ctx, s, work);
  times.solve_seconds = sol.seconds;

  const nlohmann::json rep = flow::flow_report(ctx, s, work, cells, sol, times);
  publish(ctx, s, work, rep);
  flow::announce_result(ctx, s, rep, sol,
                        flow::output_dir(ctx.run_dir, s.label) / "case" / ("log." + s.solver));
}

// The declared outputs of one rotor speed: report, solved case, geometry.
std::string FlowStage::damaged_outputs(const StageContext& ctx, const JobSpec& job) const {
  const fs::path out = flow::output_dir(ctx.run_dir, job.label);
  std::vector<std::string> r = {jobs::check_json(out / "flow_report.json"),
                                jobs::check_exists(out / "case" / "case.foam")};
  for (const char* stl : {"housing.stl", "flywheel.stl", "inlet.stl", "outlet.stl"})
    r.push_back(jobs::check_file(out / "geometry" / stl));
  return jobs::first_problem(r);
}

// flow_summary.json: a JSON array (the report reads it).
std::string FlowStage::damaged_merged_outputs(const StageContext& ctx,
                                              const std::vector<JobSpec>& jobs) const {
  return jobs.empty() ? "" : jobs::check_json(ctx.stage_dir / "flow_summary.json", true);
}

// One summary of all rotor speeds: <run>/flow/flow_summary.json.
void FlowStage::finalize(StageContext& ctx, const std::vector<JobSpec>& jobs) {
  nlohmann::json all = nlohmann::json::array();
  for (const auto& j : jobs) {
    const fs::path f = flow::output_dir(ctx.run_dir, j.label) / "flow_report.json";
    if (!fs::exists(f)) continue;
    nlohmann::json r = nlohmann::json::parse(flow::read_text(f), nullptr, false);
    if (!r.is_object())
      throw std::runtime_error(
          fmt::format("{}: not a JSON object (damaged?); rerun --stage flow --force", f.string()));
    r["label"] = j.label;
    all.push_back(r);
  }
  jobs::atomic_write(ctx.stage_dir / "flow_summary.json", all.dump(2) + "\n");
}

}  // namespace mill
