// Reading what OpenFOAM wrote in a flow case: the solver log, checkMesh's
// log and the function objects' postProcessing/ files (docs/flow.md,
// "The OpenFOAM case" and "flow_report.json").
#pragma once

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "geometry/mill_geometry.h"

namespace mill::flow {

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
// Last initial residual of p; NaN before the first.
double p_residual(const SolverLog& s);
// Largest last initial residual of Ux, Uy, Uz; 0 before the first.
double u_residual(const SolverLog& s);

// Whole file as a string ("" if unreadable).
std::string read_text(const std::filesystem::path& f);

// Number after "key" on a checkMesh line "    cells:            61684"; -1 if absent.
long checkmesh_count(const std::string& text, const std::string& key);
// Faces of a patch in checkMesh's patch table ("inlet  12  20  ok ..."); -1 if absent.
long checkmesh_patch_faces(const std::string& text, const std::string& patch);

// Column `col` of every data line of a function object's output over all its
// time folders (a restarted solve starts a new folder), ordered by time
// (brackets are ignored). `ext` is an extension (".dat") or a file name
// ("moment.dat"). Used for the history of mass flow and torque.
std::vector<std::pair<double, double>> function_object_series(const std::filesystem::path& case_dir,
                                                              const std::string& fo,
                                                              const std::string& ext, size_t col);
// Fields of the last data line of a function object's .dat file, newest time
// folder (e.g. time, value); empty if none.
std::vector<std::string> last_values(const std::filesystem::path& case_dir, const std::string& fo);

// Min/max/average of y+ per patch from the yPlus function object.
nlohmann::json read_yplus(const std::filesystem::path& case_dir);
// "# Area : 6.6e-02" header of a surfaceFieldValue output; NaN if missing.
double read_patch_area(const std::filesystem::path& case_dir, const std::string& fo);
// Last value of a surfaceFieldValue sum(phi) output; NaN if missing.
double read_flux(const std::filesystem::path& case_dir, const std::string& fo);
// Total moment (pressure + viscous) of the gas on the flywheel about the axis
// point at the last iteration (x, y, z); empty if missing.
std::vector<double> read_moment(const std::filesystem::path& case_dir);
// Mean |U| and mean tangential U on the rim circle (sets function object).
nlohmann::json read_rim(const std::filesystem::path& case_dir, const geometry::MillGeometry& g,
                        double omega);

}  // namespace mill::flow
