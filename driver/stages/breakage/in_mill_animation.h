// The in-mill animation (breakage.in_mill.animate; docs/report.md, "The
// in-mill animation"): the first in-mill run of the plan also writes frames
// (in_mill.in.tmpl's frame_interval: every element's position and intact
// bond count, kAnimationFrames over the run's duration) into its run folder;
// postprocess/plot_animation.py draws them into the job's animation/ (GIF,
// first/middle/last frame as PNG, animation.json, animation.md), and the stage publishes
// that folder as breakage/animation/ for the report.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "geometry/mill_geometry.h"
#include "stages/stage.h"

namespace mill::breakage {

// Frames over breakage.in_mill.duration (fewer when the run stops early).
constexpr int kAnimationFrames = 60;

// The `animation` object of the inputs of an in-mill job about to be added
// to `plan`: set for the first in-mill job of the plan when
// breakage.in_mill.animate is true, else null (the job's inputs, and so its
// id, are then those of a run without frames).
nlohmann::json animation_inputs(const config::Document& d, const Plan& plan);

// True for the job that writes the frames.
bool is_animated(const JobSpec& job);

// The deck's frame_interval of an in-mill job, s (0: no frames).
double frame_interval(const nlohmann::json& inputs);

// Draws the run's frame dump (work/frames.dump) with the mill of the run
// (the STL files in stl_dir) into out_dir/animation; the frames start
// lead_s before the strike. Throws naming the dump and the log when it is
// missing or broken.
void render_animation(StageContext& ctx, const JobSpec& job, const std::filesystem::path& work,
                      const std::filesystem::path& stl_dir, const geometry::MillGeometry& g,
                      const std::filesystem::path& out_dir, double lead_s);

// The animation of an animated job's folder exists and parses: "" or the reason.
std::string damaged_animation(const std::filesystem::path& job_dir);

// Copies the animated job's animation/ to breakage/animation/ (removed when
// no job of `jobs` is animated).
void publish_animation(const StageContext& ctx, const std::vector<JobSpec>& jobs);

}  // namespace mill::breakage
