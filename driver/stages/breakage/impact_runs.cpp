// Single impacts of the breakage stage: inputs, the run, its outputs.
#include "stages/breakage/impact_runs.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "engine/liggghts.h"
#include "jobs/output_checks.h"
#include "lump/material.h"
#include "postprocess/impact_stats.h"
#include "progress.h"
#include "stages/breakage/lump_run.h"
#include "stages/stage_util.h"

namespace mill::breakage {
namespace fs = std::filesystem;
using engine::num;

namespace {

// Most an element may move in one impact step, as a share of the smallest
// element radius.
constexpr double kStepMove = 0.1;

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
  engine::run_python(ctx.runner, ctx.cfg.project_dir / "postprocess" / "plot_energy_ledger.py",
                     {"--ledger", (out_dir / "energy_ledger.csv").string(), "--out",
                      (out_dir / "energy_ledger.png").string(), "--title",
                      fmt::format("{:g} m/s at {:g} deg, repeat {}", velocity, angle, repeat)},
                     out_dir / "energy_ledger_plot.log", "breakage/" + label + " ledger plot");
}

// Inputs every impact of the case shares.
}  // namespace

nlohmann::json impact_base_inputs(const StageContext& ctx) {
  nlohmann::json base = case_keys(ctx.cfg.doc, {"lump.", "breakage.duration_after_contact",
                                                "breakage.timestep", "breakage.quiet_time"});
  // The adaptive step is an input only when in effect: impacts with the
  // fixed step keep their job ids.
  if (adaptive_step_on(ctx.cfg.doc)) base["breakage.adaptive_step"] = true;
  base["ore"] = config::ore_keys(ctx.cfg.ore);
  base["bond"] = bond_json(bond_params_for(ctx.cfg, ctx.run_dir), BondNames::job);
  // Bumped whenever the impact deck or the bond style changes what a run
  // gives (git log of this line: what each version changed); results of
  // other versions are not comparable.
  base["deck_version"] = 8;
  return base;
}

bool is_strength_job(const JobSpec& job) {
  return job.inputs.contains("strength") && job.inputs.at("strength").get<bool>();
}

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
  auto num = [&](const char* k) {
    return r.contains(k) && r[k].is_number() ? r[k].get<double>() : NAN;
  };
  const nlohmann::json e = r.value("energy", nlohmann::json::object());
  const std::string efficiency =
      e.contains("comminution_efficiency") && e["comminution_efficiency"].is_number()
          ? fmt::format(", comminution efficiency {:.2g}%",
                        100 * e["comminution_efficiency"].get<double>())
          : "";
  return fmt::format(
      "{:g} m/s at {:g} deg: {} pieces ({} single, {} multi), largest {:.1f}%, single-element mass "
      "{:.1f}%, "
      "broken bonds {:.1f}%, {:.3g} kWh/t, t10 {:.1f}%{}{} [{:.1f} s]",
      num("velocity_m_s"), num("angle_deg"), num("n_pieces"), num("n_single"), num("n_multi"),
      100 * num("largest_mass_fraction"), 100 * num("single_mass_fraction"),
      100 * num("broken_bond_fraction"), num("specific_energy_kWh_t"), num("t10_percent"),
      r.value("t10_resolved", true) ? "" : " (unresolved)", efficiency, num("wall_seconds"));
}

std::string run_impact(StageContext& ctx, double velocity, double angle, int repeat,
                       const fs::path& out_dir, const std::string& label, int set) {
  const auto& d = ctx.cfg.doc;
  const LumpRun lr = prepare_lump_run(ctx, repeat, out_dir, label, set);
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
    throw std::runtime_error(
        fmt::format("{}: at {:g} m/s an element moves {:.3g} m per step of {:g} s, more than {:g} "
                    "of the smallest element radius "
                    "({:.3g} m); expected breakage.timestep <= {:.3g} s, or 0 (automatic)",
                    d.where("breakage.timestep"), velocity, velocity * dt_given, dt_given,
                    kStepMove, r_min, dt_speed));

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
              {"adaptive_step", adaptive_step_on(d) ? "1" : "0"},
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
    throw std::runtime_error(
        fmt::format("{}: {} of {} elements ended behind the impact surface: the lump passed "
                    "through it between time steps, the run "
                    "is invalid (speed {:g} m/s, step bound {:.3g} s); log: {}",
                    label, behind, a.snap.elements.size(), velocity, dt_speed,
                    (lr.work / "liggghts.log").string()));

  // Outputs, each complete or absent. The raw run stays for inspection
  // (dumps for ParaView, logs); it is small next to the VTK dumps a user asks for.
  nlohmann::json j = lump_result_json(lr, a, res.seconds);
  add_new_surface(j["energy"], a);
  write_lump_outputs(out_dir, a, j);
  plot_energy_ledger(ctx, out_dir, velocity, angle, repeat, label);
  return impact_line(j);
}

}  // namespace mill::breakage
