// Stage 'flow': mesh the mill and solve the steady MRF gas flow (OpenFOAM).
//
// One job per rotor speed. Work happens in <run>/flow/jobs/<rpm label>/case;
// on success the declared outputs appear at once (rename of a temp folder):
//   <run>/flow/<rpm label>/case/              the solved OpenFOAM case (case.foam inside)
//   <run>/flow/<rpm label>/geometry/*.stl     housing, flywheel, inlet, outlet (m)
//   <run>/flow/<rpm label>/flow_report.json   mass flows, y+, rim speed, cells, iterations
// docs/flow.md describes the case and the report.
#pragma once

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "stages/stage.h"

namespace mill {

class FlowStage : public Stage {
 public:
  std::string name() const override { return "flow"; }
  std::string description() const override {
    return "mesh the mill and solve the steady MRF gas flow (OpenFOAM)";
  }
  Plan plan(const StageContext& ctx) const override;
  void run_job(StageContext& ctx, const JobSpec& job,
               const std::filesystem::path& job_dir) override;
  void finalize(StageContext& ctx, const std::vector<JobSpec>& jobs) override;
  std::string damaged_outputs(const StageContext& ctx, const JobSpec& job) const override;
};

namespace flow {

// Declared output folder of one rotor speed: <run>/flow/<label>.
std::filesystem::path output_dir(const std::filesystem::path& run_dir, const std::string& label);

// Mesh settings of a flow.mesh_preset.
struct MeshPreset {
  std::string name;
  double cell = 0.1;      // background cell size, m
  int rotor_level = 2;    // refinement inside the rotor cylinder
  int opening_level = 2;  // refinement around the inlet and outlet squares
  int surface_min = 3, surface_max = 3, feature_level = 3;
  bool layers = false;        // boundary layers on flywheel and housing
  bool second_order = false;  // linearUpwind momentum (else upwind: robust on coarse meshes)
  int n_layers = 0;
  double first_layer = 0;  // m
  double expansion = 1.2;
};
MeshPreset mesh_preset(const std::string& name);

// What the solver log says so far.
struct SolverLog {
  int iterations = 0;                              // last "Time = N"
  bool converged = false;                          // "SIMPLE solution converged"
  bool fpe = false;                                // floating-point exception trapped
  bool nan = false;                                // a residual printed as nan/inf
  std::map<std::string, double> initial_residual;  // last initial residual per field (Ux, p, ...)
  double max_initial_residual_pU = 0;              // largest ever of p and U components
  double cpu_seconds = 0;                          // last "ExecutionTime" (CPU of rank 0)
};
// Parse an OpenFOAM steady solver log (simpleFoam / rhoSimpleFoam).
SolverLog parse_solver_log(const std::filesystem::path& log);

// Text of system/caseParameters for this case and rotor speed (all SI).
// end_iteration > 0 replaces flow.max_iterations (the first-order start of a
// second-order preset runs to flow.first_order_iterations).
std::string case_parameters(const config::Document& doc, double rpm, const MeshPreset& preset,
                            int np, long end_iteration = -1);

}  // namespace flow
}  // namespace mill
