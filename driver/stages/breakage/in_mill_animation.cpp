// The in-mill animation: which run writes frames, their drawing, publishing.
#include "stages/breakage/in_mill_animation.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>

#include "engine/liggghts.h"
#include "engine/runner.h"
#include "jobs/job_store.h"
#include "jobs/output_checks.h"
#include "stages/stage_util.h"

namespace mill::breakage {
namespace fs = std::filesystem;
using engine::num;

namespace {

const char* const kStills[] = {"animation_first.png", "animation_middle.png", "animation_last.png"};

}  // namespace

nlohmann::json animation_inputs(const config::Document& d, const Plan& plan) {
  if (!d.boolean("breakage.in_mill.animate")) return nullptr;
  for (const auto& j : plan.jobs)
    if (j.inputs.value("mode", "") == "in_mill") return nullptr;
  const double duration = d.real("breakage.in_mill.duration");
  return {{"frames", kAnimationFrames}, {"frame_interval_s", duration / kAnimationFrames}};
}

bool is_animated(const JobSpec& job) {
  return job.inputs.contains("animation") && job.inputs.at("animation").is_object();
}

double frame_interval(const nlohmann::json& inputs) {
  if (!inputs.contains("animation") || !inputs.at("animation").is_object()) return 0.0;
  return inputs.at("animation").at("frame_interval_s").get<double>();
}

void render_animation(StageContext& ctx, const JobSpec& job, const fs::path& work,
                      const fs::path& stl_dir, const geometry::MillGeometry& g,
                      const fs::path& out_dir, double lead_s) {
  const auto& in = job.inputs;
  const fs::path dump = work / "frames.dump";
  if (!fs::exists(dump))
    throw std::runtime_error(fmt::format(
        "{}: {}: missing: the run wrote no animation frames (in_mill.in.tmpl's frame_interval {} "
        "s); log: {}",
        job.label, dump.string(), num(frame_interval(in)), (work / "liggghts.log").string()));
  const double rpm = in.at("rpm").get<double>();
  const double lead_ms = 1e3 * lead_s;
  const std::string caption = fmt::format(
      "Lump {} at {:g} rpm ({}): t = 0 is {:g} ms before its first flywheel strike ({:.1f} m/s)",
      in.at("particle_id").get<long long>(), rpm, job.label, lead_ms,
      in.at("strike_speed_m_s").get<double>());
  const fs::path tmp = out_dir / "animation.tmp", dst = out_dir / "animation";
  fs::remove_all(tmp);
  const double omega = rpm * 2 * M_PI / 60.0;
  engine::run_python(
      ctx.runner, ctx.cfg.project_dir / "postprocess" / "plot_animation.py",
      {"--frames", dump.string(), "--housing", (stl_dir / "housing.stl").string(), "--flywheel",
       (stl_dir / "flywheel.stl").string(), "--axis", num(g.axis_x) + "," + num(g.axis_height),
       "--omega", num(omega), "--caption", caption, "--out", tmp.string()},
      out_dir / "animation_plot.log", "breakage/" + job.label + " animation");
  // What the report's caption needs beside what was drawn.
  std::ifstream f(tmp / "animation.json");
  nlohmann::json j = nlohmann::json::parse(f, nullptr, false);
  if (!j.is_object() || j.value("frames", 0) < 2)
    throw std::runtime_error(
        fmt::format("{}: {}: expected an animation of at least 2 frames; log: {}", job.label,
                    (tmp / "animation.json").string(), (out_dir / "animation_plot.log").string()));
  j["job"] = job.label;
  j["rpm"] = rpm;
  j["particle_id"] = in.at("particle_id");
  j["strike_speed_m_s"] = in.at("strike_speed_m_s");
  j["lead_time_ms"] = lead_ms;
  j["frame_dump"] = fs::relative(dump, out_dir).string();
  jobs::atomic_write(tmp / "animation.json", j.dump(2) + "\n");
  fs::remove_all(dst);
  fs::rename(tmp, dst);
}

std::string damaged_animation(const fs::path& job_dir) {
  const fs::path dir = job_dir / "animation";
  std::vector<std::string> r = {jobs::check_json(dir / "animation.json"),
                                jobs::check_file(dir / "animation.gif"),
                                jobs::check_file(dir / "animation.md")};
  for (const char* s : kStills) r.push_back(jobs::check_file(dir / s));
  return jobs::first_problem(r);
}

void publish_animation(const StageContext& ctx, const std::vector<JobSpec>& jobs) {
  const fs::path dst = ctx.stage_dir / "animation", tmp = ctx.stage_dir / "animation.tmp";
  fs::remove_all(tmp);
  fs::remove_all(dst);
  const jobs::JobStore store(ctx.stage_dir);
  for (const auto& job : jobs) {
    if (!is_animated(job)) continue;
    fs::copy(store.job_dir(job.label) / "animation", tmp, fs::copy_options::recursive);
    fs::rename(tmp, dst);
    return;
  }
}

}  // namespace mill::breakage
