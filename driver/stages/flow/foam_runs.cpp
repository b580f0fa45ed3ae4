// Meshing and solving a flow case with OpenFOAM (docs/flow.md, "The OpenFOAM
// case" and "Convergence in practice").
#include "stages/flow/foam_runs.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <stdexcept>

#include "progress.h"

namespace mill::flow {
namespace fs = std::filesystem;

namespace {

// One run of the solver with its progress line; a floating-point exception
// or NaN becomes an error that names the log and what to try.
void run_solver(StageContext& ctx, const JobSettings& s, const fs::path& work) {
  const fs::path log = work / ("log." + s.solver);
  auto poll = [&](const fs::path& lg) {
    const auto l = parse_solver_log(lg);
    ctx.progress.job_step(s.label,
                          fmt::format("{} iter {}/{} p {:.1e} U {:.1e}", s.solver, l.iterations,
                                      s.max_it, p_residual(l), u_residual(l)),
                          static_cast<double>(l.iterations) / s.max_it);
  };
  try {
    run_foam(ctx, s.tag, work, {s.solver}, s.np, poll);
  } catch (const engine::EngineError& e) {
    const auto l = parse_solver_log(log);
    if (l.fpe || l.nan || e.result.signal == SIGFPE)
      throw std::runtime_error(fmt::format(
          "the flow diverged at iteration {} (floating-point exception / NaN in {}); try a finer "
          "flow.mesh_preset or check rotor.rpm and gas.outlet_pressure_drop; log: {}",
          l.iterations, s.solver, log.string()));
    throw;
  }
}

// The first-order start of a second-order preset: upwind momentum for
// `iterations`, its log kept as log.<solver>.firstOrder, then caseParameters
// back to the preset's scheme (the next solve restarts from latestTime).
struct FirstOrderRun {
  int iterations = 0;      // done
  double cpu_seconds = 0;  // of the solver's rank 0
};
FirstOrderRun first_order_start(StageContext& ctx, const JobSettings& s, const fs::path& work,
                                long iterations) {
  const fs::path log = work / ("log." + s.solver);
  auto upwind = s.preset;
  upwind.second_order = false;
  write_case_parameters(work, s, upwind, iterations);
  run_solver(ctx, s, work);
  const auto s1 = parse_solver_log(log);
  fs::rename(log, work / ("log." + s.solver + ".firstOrder"));
  write_case_parameters(work, s, s.preset);
  ctx.progress.info(fmt::format("{}: first-order start: {} iterations (p {:.2g}); now {}", s.tag,
                                s1.iterations, p_residual(s1), "second-order momentum"));
  return {s1.iterations, s1.cpu_seconds};
}

}  // namespace

// One OpenFOAM program of the job, shown as its step.
engine::Result run_foam(StageContext& ctx, const std::string& job, const fs::path& case_dir,
                        std::vector<std::string> argv, int np, const engine::Runner::Poll& poll) {
  engine::Command c;
  c.job = job;
  c.cwd = case_dir;
  c.log = case_dir / ("log." + argv[0]);
  c.env = engine::openfoam_env();
  c.engine = engine::Engine::OpenFoam;
  c.np = np;
  if (np > 1) argv.push_back("-parallel");
  c.argv = std::move(argv);
  ctx.progress.job_step(job.substr(job.find('/') + 1), c.argv[0], -1);
  return ctx.runner.run(c, poll);
}

// The mesh of a freshly written case, checked.
long mesh_case(StageContext& ctx, const JobSettings& s, const fs::path& work) {
  run_foam(ctx, s.tag, work, {"blockMesh"});
  run_foam(ctx, s.tag, work, {"surfaceFeatureExtract"});
  run_foam(ctx, s.tag, work, {"snappyHexMesh", "-overwrite"});
  run_foam(ctx, s.tag, work, {"topoSet"});
  run_foam(ctx, s.tag, work, {"createPatch", "-overwrite"});
  run_foam(ctx, s.tag, work, {"checkMesh", "-constant"});
  const std::string cm = read_text(work / "log.checkMesh");
  if (cm.find("Mesh OK.") == std::string::npos)
    throw std::runtime_error(fmt::format("checkMesh reports mesh errors (lines with ***); log: {}",
                                         (work / "log.checkMesh").string()));
  const long cells = checkmesh_count(cm, "cells");
  for (const char* patch : {"inlet", "outlet", "flywheel"})
    if (checkmesh_patch_faces(cm, patch) <= 0)
      throw std::runtime_error(fmt::format(
          "the mesh has no '{}' faces (opening or flywheel smaller than the {} "
          "preset's {:g} m cells?); "
          "choose a finer flow.mesh_preset or a larger mill.{}.size; log: {}",
          patch, s.preset.name, s.preset.cell, patch, (work / "log.checkMesh").string()));
  return cells;
}

// The solve of a meshed case, from 0.orig to the reconstructed last iteration.
Solution solve_case(StageContext& ctx, const JobSettings& s, const fs::path& work) {
  fs::remove_all(work / "0");
  fs::copy(work / "0.orig", work / "0", fs::copy_options::recursive);
  if (s.np > 1) run_foam(ctx, s.tag, work, {"decomposePar", "-force"});
  const fs::path log = work / ("log." + s.solver);
  const auto t1 = std::chrono::steady_clock::now();
  Solution sol;
  // Second-order presets start with first-order upwind momentum for
  // flow.first_order_iterations, then restart from that state (the solver's
  // startFrom latestTime) with the preset's scheme.
  sol.first_order = s.preset.second_order
                        ? std::min<long>(s.doc.integer("flow.first_order_iterations"), s.max_it)
                        : 0;
  FirstOrderRun start;
  if (sol.first_order > 0) start = first_order_start(ctx, s, work, sol.first_order);
  sol.first_order_done = start.iterations;
  if (sol.first_order < s.max_it)
    run_solver(ctx, s, work);
  else
    fs::rename(work / ("log." + s.solver + ".firstOrder"), log);
  sol.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  if (s.np > 1) run_foam(ctx, s.tag, work, {"reconstructPar", "-latestTime"});

  sol.log = parse_solver_log(log);
  sol.log.cpu_seconds += sol.first_order < s.max_it ? start.cpu_seconds : 0.0;
  sol.p_res = p_residual(sol.log);
  sol.u_res = u_residual(sol.log);
  if (sol.log.nan || !(sol.p_res < 1.0) || !(sol.u_res < 1.0))
    throw std::runtime_error(fmt::format(
        "the flow diverged: initial residuals p {:.3g}, U {:.3g} after {} iterations; log: {}",
        sol.p_res, sol.u_res, sol.log.iterations, log.string()));
  sol.converged = sol.log.converged || (sol.p_res < s.target && sol.u_res < s.target);
  return sol;
}

}  // namespace mill::flow
