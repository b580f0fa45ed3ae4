// Writing the flow stage's OpenFOAM case: the settings of one job, the mesh
// presets, system/caseParameters and the fresh case folder (docs/flow.md,
// "The OpenFOAM case" and "Mesh presets").
#pragma once

#include <filesystem>
#include <string>

#include "config/case_config.h"
#include "geometry/mill_geometry.h"
#include "stages/stage.h"

namespace mill::flow {

constexpr double kPi = 3.14159265358979323846;
// Start-up temperature guard (system/fvOptions limitT): these multiples of
// gas.temperature, written to caseParameters and checked in the report.
constexpr double kTGuardMin = 0.5, kTGuardMax = 3.0;

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

// Text of system/caseParameters for this case and rotor speed (all SI).
// end_iteration > 0 replaces flow.max_iterations (the first-order start of a
// second-order preset runs to flow.first_order_iterations).
std::string case_parameters(const config::Document& doc, double rpm, const MeshPreset& preset,
                            int np, long end_iteration = -1);

// What one flow job (one rotor speed) is run with, read from the case once.
struct JobSettings {
  explicit JobSettings(const config::Document& d) : doc(d) {}
  const config::Document& doc;
  std::string label;  // the job's folder label, "rpm2000"
  std::string tag;    // "flow/<label>", shown in progress lines
  double rpm = 0;
  double omega = 0;  // rad/s
  int np = 1;
  geometry::MillGeometry geo;  // the flywheel frozen at flow.rotor_angle
  MeshPreset preset;           // flow.mesh_preset, its scheme set by flow.momentum_scheme
  bool comp = false;           // gas.model = compressible
  std::string solver;          // rhoSimpleFoam or simpleFoam
  long max_it = 0;             // flow.max_iterations
  double target = 0;           // flow.residual_target
  // flow.domain = half: the solved case is z >= 0 with a symmetry plane at
  // z = 0; mass flows and opening areas are doubled to whole-mill values.
  bool half = false;
  double mirror = 1;
};
JobSettings job_settings(const config::Document& doc, const JobSpec& job, int np);

// Write system/caseParameters of `work` for these settings and this preset.
void write_case_parameters(const std::filesystem::path& work, const JobSettings& s,
                           const MeshPreset& preset, long end_iteration = -1);

// A fresh case in `work`: the template folder copied (without a previous hand
// run's mesh), caseParameters, the STL surfaces and case.foam for ParaView.
void write_case(const std::filesystem::path& template_dir, const std::filesystem::path& work,
                const JobSettings& s);

}  // namespace mill::flow
