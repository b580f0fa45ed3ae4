// Running OpenFOAM on a written flow case: the meshing chain with checkMesh's
// verdict, and the steady solve with its first-order start (docs/flow.md,
// "The OpenFOAM case" and "Convergence in practice").
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "engine/runner.h"
#include "stages/flow/case_files.h"
#include "stages/flow/foam_results.h"
#include "stages/stage.h"

namespace mill::flow {

// Start one OpenFOAM program in the case folder with its log.<name> beside it.
engine::Result run_foam(StageContext& ctx, const std::string& job,
                        const std::filesystem::path& case_dir, std::vector<std::string> argv,
                        int np = 1, const engine::Runner::Poll& poll = nullptr);

// blockMesh to checkMesh in `work`; throws when checkMesh finds errors or an
// opening or the flywheel has no faces. Returns the cell count.
long mesh_case(StageContext& ctx, const JobSettings& s, const std::filesystem::path& work);

// What the solve ended with.
struct Solution {
  SolverLog log;           // the final solver log (cpu_seconds includes a first-order start)
  double p_res = 0;        // last initial residual of p
  double u_res = 0;        // of U, worst component
  bool converged = false;  // the solver said so, or both are below flow.residual_target
  long first_order = 0;    // iterations planned with first-order momentum (0: none)
  int first_order_done = 0;
  double seconds = 0;  // wall time of the solver runs
};

// Initial fields, decomposition, solve (first-order start for a
// second-order preset), reconstruction; throws when the flow diverged.
Solution solve_case(StageContext& ctx, const JobSettings& s, const std::filesystem::path& work);

}  // namespace mill::flow
