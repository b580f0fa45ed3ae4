// Writing the flow stage's OpenFOAM case (docs/flow.md, "The OpenFOAM case").
#include "stages/flow/case_files.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

#include "jobs/job_store.h"

namespace mill::flow {
namespace fs = std::filesystem;

namespace {

// Background cell count along an edge of length L for cell size h (>= 2).
int cells_along(double L, double h) { return std::max(2, static_cast<int>(std::lround(L / h))); }

// "(a b c)" for an OpenFOAM vector entry.
std::string vec(double a, double b, double c) {
  return fmt::format("({:.10g} {:.10g} {:.10g})", a, b, c);
}

// Rotor zone radius: 15% beyond the tips, kept clear of the housing walls.
double rotor_zone_radius(const geometry::MillGeometry& g) {
  const double rt = g.tip_radius();
  const double wall =
      std::min({g.axis_height, g.height - g.axis_height, 0.5 * g.width - std::abs(g.axis_x)});
  return std::min(1.15 * rt, 0.5 * (rt + wall));
}

// The numbers of caseParameters derived from the mill, the speed and the preset.
struct CaseNumbers {
  geometry::MillGeometry g;
  bool comp = false, half = false;
  double omega = 0, rr = 0, rt = 0, rim = 0;
  double x0 = 0, x1 = 0, z0 = 0, z1 = 0, eps = 0;
  double lx = 0, ly = 0, lz = 0, rim_z = 0;
  double k0 = 0, om0 = 0;
};

// The mill, rotor zone, mesh box, probe points and initial turbulence of a case.
CaseNumbers case_numbers(const config::Document& doc, double rpm, const MeshPreset& mp) {
  CaseNumbers n;
  const auto& g = n.g = geometry::MillGeometry::from_config(doc);
  n.comp = doc.str("gas.model") == "compressible";
  n.omega = rpm * 2 * kPi / 60.0;
  n.rr = rotor_zone_radius(g);
  n.rt = g.tip_radius();
  n.rim = n.rt + 0.4 * (n.rr - n.rt);
  // flow.domain = half: only z >= 0 is meshed, with a symmetryPlane patch at z = 0.
  n.half = doc.str("flow.domain") == "half";
  n.x0 = -0.5 * g.width;
  n.x1 = 0.5 * g.width;
  n.z0 = n.half ? 0.0 : -0.5 * g.depth;
  n.z1 = 0.5 * g.depth;
  n.eps = 0.01 * mp.cell;
  // A gas point between the rotor zone and the roof, off any cell face.
  n.ly = 0.5 * (g.axis_height + n.rr + g.height) + 0.0371 * mp.cell;
  n.lx = n.x0 + 0.5 * mp.cell * 1.0731 + 0.0137 * g.width;
  n.lz = 0.0917 * mp.cell;  // > 0: inside the half domain too
  // The rim circle lies in the mid-plane; for the half domain just above it
  // (points exactly on the symmetry plane may be lost by the probe).
  n.rim_z = n.half ? 0.02 * mp.cell : 0.0;
  // Initial turbulence: 5% of 30% of the rim speed, length 5% of the tip radius.
  const double u_ref = std::max(1.0, 0.3 * n.omega * n.rt);
  n.k0 = 1.5 * std::pow(0.05 * u_ref, 2);
  n.om0 = std::sqrt(n.k0) / (std::pow(0.09, 0.25) * 0.05 * n.rt);
  return n;
}

// FoamFile header, provenance, solver, decomposition and domain.
std::string head_entries(const config::Document& doc, double rpm, const MeshPreset& mp, int np,
                         const CaseNumbers& n) {
  std::string s;
  s += "/*--------------------------------*- C++ -*----------------------------------*\\\n"
       "  Beater mill: written by orchestrate (stage flow) from the case file\n"
       "\\*---------------------------------------------------------------------------*/\n"
       "FoamFile\n{\n    version     2.0;\n    format      ascii;\n    class       dictionary;\n"
       "    location    \"system\";\n    object      caseParameters;\n}\n\n";
  s += fmt::format(
      "// case file: {}, rotor.rpm = {:g}, flow.mesh_preset = {}, --np {}\n"
      "// By hand: foamDictionary -entry omega -set 157.08 system/caseParameters\n"
      "// Flywheel frozen at flow.rotor_angle = {:g} deg (constant/triSurface/flywheel.stl)\n\n",
      fs::path(doc.file()).filename().string(), rpm, mp.name, np, doc.real("flow.rotor_angle"));
  s += fmt::format("solver          {};  // gas.model = {}\n",
                   n.comp ? "rhoSimpleFoam" : "simpleFoam", doc.str("gas.model"));
  s += fmt::format("nProcs          {};\nhierarchicalN   (1 {} 1);\n\n", np, np);
  s += fmt::format(
      "// flow.domain: half = z >= 0 only, symmetryPlane patch `symmetry` at z = 0\n"
      "// (blockMeshDict, MRFProperties); full = the whole housing\n"
      "domain          {};\n\n",
      n.half ? "half" : "full");
  return s;
}

// Background mesh box, flywheel axis, rotation, rim probe and rotating zone.
std::string housing_and_rotor_entries(double rpm, const MeshPreset& mp, const CaseNumbers& n) {
  const auto& g = n.g;
  std::string s = "// Housing box = background mesh (mill.housing.*), preset " + mp.name + "\n";
  s += fmt::format(
      "xMin {:.10g}; xMax {:.10g};\nyMin 0; yMax {:.10g};\nzMin {:.10g}; zMax {:.10g};\n", n.x0,
      n.x1, g.height, n.z0, n.z1);
  s += fmt::format("nx {}; ny {}; nz {};\n\n", cells_along(g.width, mp.cell),
                   cells_along(g.height, mp.cell), cells_along(n.z1 - n.z0, mp.cell));
  s += "// Flywheel (mill.flywheel.*), rotor zone, rotation (rotor.rpm)\n";
  s += fmt::format("axisX           {:.10g};\naxisY           {:.10g};\ntipRadius       {:.10g};\n",
                   g.axis_x, g.axis_height, n.rt);
  s += fmt::format("rotorRadius     {:.10g};\nrimRadius       {:.10g};\n", n.rr, n.rim);
  s += fmt::format("omega           {:.10g};  // rad/s = {:g} rpm\n", n.omega, rpm);
  s += fmt::format("torqueCentre    {};  // on the axis, for the shaft torque\n",
                   vec(g.axis_x, g.axis_height, 0.0));
  s += fmt::format("rimZ            {:.10g};\nrimStart        {};\n", n.rim_z,
                   vec(g.axis_x + n.rim, g.axis_height, n.rim_z));
  s += fmt::format("axisPoint1      {};\naxisPoint2      {};\n",
                   vec(g.axis_x, g.axis_height, n.z0 - n.eps),
                   vec(g.axis_x, g.axis_height, n.z1 + n.eps));
  // The rotating cellZone (topoSet) ends midway between the flywheel's side
  // faces (z = +-plate_width/2) and the front/back walls: a zone reaching the
  // stationary walls made the gas in the gap oscillate and kept the layered
  // meshes from converging (docs/flow.md, "Where the rotor zone ends").
  const double zone_z = 0.25 * (g.plate_width + g.depth);
  s += fmt::format(
      "// rotating zone: rotorRadius, |z| <= {:.10g} (midway between plate sides and walls)\n"
      "zonePoint1      {};\nzonePoint2      {};\n\n",
      zone_z, vec(g.axis_x, g.axis_height, n.half ? n.z0 - n.eps : -zone_z),
      vec(g.axis_x, g.axis_height, zone_z));
  return s;
}

// Opening boxes and their refinement, snappyHexMesh levels, layers, momentum scheme.
std::string openings_and_mesh_entries(const MeshPreset& mp, const CaseNumbers& n) {
  const auto& g = n.g;
  const double eps = n.eps;
  std::string s = "// Openings (mill.inlet.*, mill.outlet.*): boxes picking roof/floor faces\n";
  const double hi = 0.5 * g.inlet_size, ho = 0.5 * g.outlet_size;
  // Face centres on the square's edge (a tie) are included: the boxes are eps wider.
  s += fmt::format("inletBoxMin     {};\ninletBoxMax     {};\n",
                   vec(g.inlet_x - hi - eps, g.height - eps, -hi - eps),
                   vec(g.inlet_x + hi + eps, g.height + eps, hi + eps));
  s += fmt::format("outletBoxMin    {};\noutletBoxMax    {};\n",
                   vec(g.outlet_x - ho - eps, -eps, -ho - eps),
                   vec(g.outlet_x + ho + eps, eps, ho + eps));
  // Refinement boxes: one background cell around and below/above each opening.
  const double c = mp.cell;
  s += fmt::format("inletRefineMin  {};\ninletRefineMax  {};\n",
                   vec(g.inlet_x - hi - c, g.height - c, -hi - c),
                   vec(g.inlet_x + hi + c, g.height + c, hi + c));
  s += fmt::format("outletRefineMin {};\noutletRefineMax {};\n\n",
                   vec(g.outlet_x - ho - c, -c, -ho - c), vec(g.outlet_x + ho + c, c, ho + c));
  s += "// snappyHexMesh (flow.mesh_preset)\n";
  s += fmt::format("locationInMesh  {};\n", vec(n.lx, n.ly, n.lz));
  s += fmt::format("openingLevel    {};\n", mp.opening_level);
  s += fmt::format(
      "rotorLevel      {};\nsurfaceLevelMin {};\nsurfaceLevelMax {};\nfeatureLevel    {};\n",
      mp.rotor_level, mp.surface_min, mp.surface_max, mp.feature_level);
  s += fmt::format(
      "addLayers       {};\nnLayers         {};\nfirstLayerThickness {:g};\nlayerExpansion  "
      "{:g};\n\n",
      mp.layers ? "true" : "false", std::max(mp.n_layers, 1),
      mp.first_layer > 0 ? mp.first_layer : 1e-3, mp.expansion);
  s += fmt::format("divU            {};\n\n",
                   mp.second_order ? "bounded Gauss linearUpwind grad(U)" : "bounded Gauss upwind");
  return s;
}

// Gas properties, temperature guard, pressures, initial turbulence, solver control.
std::string gas_and_control_entries(const config::Document& doc, const CaseNumbers& n,
                                    long end_iteration) {
  const double rho = doc.real("gas.density"), mu = doc.real("gas.viscosity");
  const double dp = doc.real("gas.outlet_pressure_drop"), pa = doc.real("gas.pressure");
  std::string s = "// Gas (gas.*)\n";
  s += fmt::format(
      "rhoRef          {:.10g};\nnu              {:.10g};\nmu              {:.10g};\nTRef          "
      "  {:.10g};\n",
      rho, mu / rho, mu, doc.real("gas.temperature"));
  // forces function object: rho from the field (rhoSimpleFoam) or rhoRef
  // times the kinematic pressure (simpleFoam)
  // limits of the start-up temperature guard (system/fvOptions, compressible)
  s += fmt::format("TMinLimit       {:.10g};\nTMaxLimit       {:.10g};\n",
                   kTGuardMin * doc.real("gas.temperature"),
                   kTGuardMax * doc.real("gas.temperature"));
  s += fmt::format("forcesRho       {};\n", n.comp ? "rho" : "rhoInf");
  if (n.comp) {
    s += "pDims           [1 -1 -2 0 0 0 0];  // Pa, absolute\n";
    s += fmt::format(
        "pInternal       {:.10g};\npInlet          {:.10g};\npOutlet         {:.10g};\n", pa, pa,
        pa - dp);
  } else {
    s += "pDims           [0 2 -2 0 0 0 0];   // kinematic: p / rho\n";
    s += fmt::format("pInternal       0;\npInlet          0;\npOutlet         {:.10g};\n",
                     dp == 0 ? 0.0 : -dp / rho);
  }
  s += fmt::format(
      "kInternal       {:.6g};\nomegaInternal   {:.6g};\ninletIntensity  0.05;\ninletMixingLength "
      "{:.6g};\n\n",
      n.k0, n.om0, 0.07 * n.g.inlet_size);
  s += "// Solver control (flow.*)\n";
  s += fmt::format("maxIterations   {};{}\nresidualTarget  {:g};\n",
                   end_iteration > 0 ? end_iteration : doc.integer("flow.max_iterations"),
                   end_iteration > 0 ? "  // first-order start (flow.first_order_iterations)" : "",
                   doc.real("flow.residual_target"));
  return s;
}

// Copy the template, skipping anything a previous hand run may have left.
void copy_template(const fs::path& from, const fs::path& to) {
  if (!fs::exists(from / "system" / "controlDict"))
    throw std::runtime_error(fmt::format(
        "OpenFOAM case template not found: {} (expected system/controlDict)", from.string()));
  fs::create_directories(to);
  for (const auto& e : fs::recursive_directory_iterator(from)) {
    const fs::path rel = fs::relative(e.path(), from);
    const std::string top = rel.begin()->string();
    const bool keep = top == "0.orig" || top == "constant" || top == "system" || top == "Allrun" ||
                      top == "Allclean" || top == "README.md";
    const std::string leaf = rel.filename().string();
    if (!keep || leaf == "polyMesh" || rel.string().find("polyMesh") != std::string::npos ||
        rel.string().find("extendedFeatureEdgeMesh") != std::string::npos ||
        rel.extension() == ".eMesh")
      continue;
    if (e.is_directory())
      fs::create_directories(to / rel);
    else
      fs::copy_file(e.path(), to / rel, fs::copy_options::overwrite_existing);
  }
}

}  // namespace

// The presets of flow.mesh_preset (cell counts for the default mill in docs/flow.md).
MeshPreset mesh_preset(const std::string& name) {
  MeshPreset p;
  p.name = name;
  if (name == "tiny") {
    p.cell = 0.2;
    p.rotor_level = 1;
    p.opening_level = 1;
    p.surface_min = p.surface_max = p.feature_level = 2;
  } else if (name == "quick") {
    p.cell = 0.1;
    p.rotor_level = 2;
    p.surface_min = p.surface_max = p.feature_level = 3;
  } else if (name == "medium" || name == "reference") {
    // medium lies between quick and reference: background cells 1.4x the
    // reference's, with the reference's layers. First-order momentum, as on
    // every preset: second order (linearUpwind, limitedLinearV) does not
    // converge on the layered meshes (the plate wakes oscillate, docs/flow.md
    // "Mesh study").
    p.cell = name == "medium" ? 0.07 : 0.05;
    p.rotor_level = 2;
    p.surface_min = p.surface_max = p.feature_level = 3;
    p.layers = true;
    p.n_layers = 3;
    p.first_layer = 0.0008;
    p.expansion = 1.3;
  } else {
    throw std::invalid_argument("flow.mesh_preset: unknown preset '" + name +
                                "' (tiny, quick, medium, reference)");
  }
  return p;
}

// All numbers of the case, with the keys they come from.
std::string case_parameters(const config::Document& doc, double rpm, const MeshPreset& mp, int np,
                            long end_iteration) {
  const CaseNumbers n = case_numbers(doc, rpm, mp);
  return head_entries(doc, rpm, mp, np, n) + housing_and_rotor_entries(rpm, mp, n) +
         openings_and_mesh_entries(mp, n) + gas_and_control_entries(doc, n, end_iteration);
}

// The settings of one rotor speed's job, when it starts.
JobSettings job_settings(const config::Document& doc, const JobSpec& job, int np) {
  JobSettings s(doc);
  s.label = job.label;
  s.tag = "flow/" + job.label;
  s.rpm = job.inputs.at("rotor.rpm").get<double>();
  s.np = np;
  s.geo = geometry::MillGeometry::from_config(doc);
  s.geo.rotor_angle = doc.real("flow.rotor_angle") * kPi / 180.0;  // frozen-rotor position
  s.preset = mesh_preset(doc.str("flow.mesh_preset"));
  if (doc.str("flow.momentum_scheme") != "preset")
    s.preset.second_order = doc.str("flow.momentum_scheme") == "linearUpwind";
  s.comp = doc.str("gas.model") == "compressible";
  s.solver = s.comp ? "rhoSimpleFoam" : "simpleFoam";
  s.omega = s.rpm * 2 * kPi / 60.0;
  s.max_it = doc.integer("flow.max_iterations");
  s.target = doc.real("flow.residual_target");
  s.half = doc.str("flow.domain") == "half";
  s.mirror = s.half ? 2.0 : 1.0;
  return s;
}

// caseParameters of the job, written atomically (at the start, and around a first-order start).
void write_case_parameters(const fs::path& work, const JobSettings& s, const MeshPreset& preset,
                           long end_iteration) {
  jobs::atomic_write(work / "system" / "caseParameters",
                     case_parameters(s.doc, s.rpm, preset, s.np, end_iteration));
}

// A fresh case folder for a job, before meshing.
void write_case(const fs::path& template_dir, const fs::path& work, const JobSettings& s) {
  fs::remove_all(work);
  copy_template(template_dir, work);
  write_case_parameters(work, s, s.preset);
  geometry::write_stl_set(s.geo, work / "constant" / "triSurface");
  std::ofstream(work / "case.foam").close();
}

}  // namespace mill::flow
