// Stage 'flow': one OpenFOAM run per rotor speed (template copy, geometry,
// snappyHexMesh, MRF + k-omega SST steady solve, report).
#include "stages/flow_stage.h"

#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <csignal>
#include <fstream>
#include <regex>
#include <map>
#include <set>
#include <sstream>

#include "engine/runner.h"
#include "geometry/mill_geometry.h"
#include "jobs/job_store.h"
#include "jobs/output_checks.h"
#include "progress.h"
#include "stages/stage_util.h"

namespace mill {
namespace fs = std::filesystem;

namespace flow {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Start-up temperature guard (system/fvOptions limitT): these multiples of
// gas.temperature, written to caseParameters and checked in the report.
constexpr double kTGuardMin = 0.5, kTGuardMax = 3.0;

// Background cell count along an edge of length L for cell size h (>= 2).
int cells_along(double L, double h) { return std::max(2, static_cast<int>(std::lround(L / h))); }

// "(a b c)" for an OpenFOAM vector entry.
std::string vec(double a, double b, double c) {
  return fmt::format("({:.10g} {:.10g} {:.10g})", a, b, c);
}

// Last whitespace-separated numbers of the last data line of a .dat file
// (lines starting with '#' are headers); empty if none.
std::vector<std::string> last_data_line(const fs::path& file) {
  std::ifstream in(file);
  std::string l, last;
  while (std::getline(in, l))
    if (!l.empty() && l[0] != '#') last = l;
  std::istringstream ss(last);
  std::vector<std::string> out;
  std::string w;
  while (ss >> w) out.push_back(w);
  return out;
}

// True when f is the output file wanted: `ext` is an extension (".dat") or a
// file name ("moment.dat").
bool is_output_file(const fs::path& f, const std::string& ext) {
  return ext.rfind('.', 0) == 0 ? f.extension() == ext : f.filename() == ext;
}

// The single .dat (or given-name) file of a function object's output, newest time folder.
fs::path function_object_file(const fs::path& case_dir, const std::string& fo,
                              const std::string& ext) {
  const fs::path root = case_dir / "postProcessing" / fo;
  fs::path best;
  double best_t = -1;
  if (!fs::exists(root)) return best;
  for (const auto& t : fs::directory_iterator(root)) {
    if (!t.is_directory()) continue;
    double tv = 0;
    try {
      tv = std::stod(t.path().filename().string());
    } catch (...) {
      continue;
    }
    for (const auto& f : fs::directory_iterator(t.path()))
      if (is_output_file(f.path(), ext) && tv >= best_t) {
        best = f.path();
        best_t = tv;
      }
  }
  return best;
}

// Column `col` of every data line of a function object's output over all its
// time folders (a restarted solve starts a new folder), ordered by time
// (brackets are ignored). Used for the history of mass flow and torque.
std::vector<std::pair<double, double>> function_object_series(const fs::path& case_dir,
                                                              const std::string& fo,
                                                              const std::string& ext, size_t col) {
  std::map<double, double> by_time;
  const fs::path root = case_dir / "postProcessing" / fo;
  if (!fs::exists(root)) return {};
  for (const auto& t : fs::directory_iterator(root)) {
    if (!t.is_directory()) continue;
    for (const auto& f : fs::directory_iterator(t.path())) {
      if (!is_output_file(f.path(), ext)) continue;
      std::ifstream in(f.path());
      std::string l;
      while (std::getline(in, l)) {
        if (l.empty() || l[0] == '#') continue;
        for (char& c : l)
          if (c == '(' || c == ')') c = ' ';
        std::istringstream ss(l);
        std::vector<double> v;
        double x;
        while (ss >> x) v.push_back(x);
        if (v.size() > col) by_time[v[0]] = v[col];
      }
    }
  }
  return {by_time.begin(), by_time.end()};
}

// Min, max and mean of a series over its last `fraction` of iterations (at
// least 20 values), scaled: how steady a reported figure was at the end.
nlohmann::json tail_spread(const std::vector<std::pair<double, double>>& series, double scale,
                           double fraction = 0.1) {
  nlohmann::json out;
  if (series.empty()) return out;
  const size_t n = std::min(series.size(),
                            std::max<size_t>(20, static_cast<size_t>(fraction * series.size())));
  double lo = INFINITY, hi = -INFINITY, sum = 0;
  for (size_t i = series.size() - n; i < series.size(); ++i) {
    const double v = series[i].second * scale;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    sum += v;
  }
  out["from_iteration"] = series[series.size() - n].first;
  out["to_iteration"] = series.back().first;
  out["min"] = lo;
  out["max"] = hi;
  out["mean"] = sum / n;
  out["spread_relative"] = sum != 0 ? (hi - lo) / std::abs(sum / n) : 0.0;
  return out;
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

// Number after "key" on the checkMesh line "    cells:            61684".
long checkmesh_count(const std::string& text, const std::string& key) {
  std::smatch m;
  std::regex re("\\n\\s*" + key + ":\\s+([0-9]+)");
  if (std::regex_search(text, m, re)) return std::stol(m[1]);
  return -1;
}

// Faces of a patch in checkMesh's patch table ("inlet  12  20  ok ..."); -1 if absent.
long checkmesh_patch_faces(const std::string& text, const std::string& patch) {
  std::smatch m;
  std::regex re("\\n\\s*" + patch + "\\s+([0-9]+)\\s+[0-9]+");
  if (std::regex_search(text, m, re)) return std::stol(m[1]);
  return -1;
}

// Whole file as a string ("" if unreadable).
std::string read_text(const fs::path& f) {
  std::ifstream in(f);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Rotor zone radius: 15% beyond the tips, kept clear of the housing walls.
double rotor_zone_radius(const geometry::MillGeometry& g) {
  const double rt = g.tip_radius();
  const double wall =
      std::min({g.axis_height, g.height - g.axis_height, 0.5 * g.width - std::abs(g.axis_x)});
  return std::min(1.15 * rt, 0.5 * (rt + wall));
}

}  // namespace

// Declared output folder of one rotor speed.
fs::path output_dir(const fs::path& run_dir, const std::string& label) {
  return run_dir / "flow" / label;
}

// The three presets of flow.mesh_preset (cell counts for the default mill in docs/flow.md).
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
  } else if (name == "medium") {
    // Between quick and reference: background cells 1.4x the reference's,
    // with the reference's layers. First-order momentum, as on every preset:
    // second order (linearUpwind, limitedLinearV) does not converge on the
    // layered meshes (the plate wakes oscillate, docs/flow.md "Mesh study").
    p.cell = 0.07;
    p.rotor_level = 2;
    p.surface_min = p.surface_max = p.feature_level = 3;
    p.layers = true;
    p.n_layers = 3;
    p.first_layer = 0.0008;
    p.expansion = 1.3;
  } else if (name == "reference") {
    p.cell = 0.05;
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

// Incremental-free parse of the whole log (logs are small: ~12 lines/iteration).
SolverLog parse_solver_log(const fs::path& log) {
  SolverLog s;
  std::ifstream in(log);
  std::string l;
  static const std::regex time_re("^Time = ([0-9.eE+-]+)\\s*$");
  static const std::regex res_re("Solving for (\\w+), Initial residual = ([^,]+),");
  std::smatch m;
  std::set<std::string> seen;  // fields already solved in this iteration
  while (std::getline(in, l)) {
    if (l.rfind("Time = ", 0) == 0 && std::regex_match(l, m, time_re)) {
      s.iterations = static_cast<int>(std::lround(std::stod(m[1])));
      seen.clear();
    } else if (l.find("Solving for") != std::string::npos && std::regex_search(l, m, res_re)) {
      const std::string field = m[1];
      // Only the first solve of a field per iteration counts (as in
      // residualControl); later ones are non-orthogonal correctors.
      if (!seen.insert(field).second) continue;
      const std::string v = m[2];
      double r = 0;
      if (v.find("nan") != std::string::npos || v.find("inf") != std::string::npos) {
        s.nan = true;
        r = INFINITY;
      } else {
        r = std::stod(v);
      }
      s.initial_residual[field] = r;
      if (field == "p" || field == "Ux" || field == "Uy" || field == "Uz")
        s.max_initial_residual_pU = std::max(s.max_initial_residual_pU, r);
    } else if (l.rfind("ExecutionTime = ", 0) == 0) {
      s.cpu_seconds = std::atof(l.c_str() + 16);
    } else if (l.find("solution converged in") != std::string::npos) {
      s.converged = true;
    } else if (l.find("sigFpe") != std::string::npos ||
               l.find("Floating point exception") != std::string::npos) {
      s.fpe = true;
    }
  }
  return s;
}

// All numbers of the case, with the keys they come from.
std::string case_parameters(const config::Document& doc, double rpm, const MeshPreset& mp, int np,
                            long end_iteration) {
  const auto g = geometry::MillGeometry::from_config(doc);
  const bool comp = doc.str("gas.model") == "compressible";
  const double rho = doc.real("gas.density"), mu = doc.real("gas.viscosity");
  const double dp = doc.real("gas.outlet_pressure_drop"), pa = doc.real("gas.pressure");
  const double omega = rpm * 2 * kPi / 60.0;
  const double rr = rotor_zone_radius(g), rt = g.tip_radius();
  const double rim = rt + 0.4 * (rr - rt);
  // flow.domain = half: only z >= 0 is meshed, with a symmetryPlane patch at z = 0.
  const bool half = doc.str("flow.domain") == "half";
  const double x0 = -0.5 * g.width, x1 = 0.5 * g.width, z0 = half ? 0.0 : -0.5 * g.depth,
               z1 = 0.5 * g.depth;
  const double eps = 0.01 * mp.cell;
  // A gas point between the rotor zone and the roof, off any cell face.
  const double ly = 0.5 * (g.axis_height + rr + g.height) + 0.0371 * mp.cell;
  const double lx = x0 + 0.5 * mp.cell * 1.0731 + 0.0137 * g.width;
  const double lz = 0.0917 * mp.cell;  // > 0: inside the half domain too
  // The rim circle lies in the mid-plane; for the half domain just above it
  // (points exactly on the symmetry plane may be lost by the probe).
  const double rim_z = half ? 0.02 * mp.cell : 0.0;
  // Initial turbulence: 5% of 30% of the rim speed, length 5% of the tip radius.
  const double u_ref = std::max(1.0, 0.3 * omega * rt);
  const double k0 = 1.5 * std::pow(0.05 * u_ref, 2),
               om0 = std::sqrt(k0) / (std::pow(0.09, 0.25) * 0.05 * rt);

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
                   comp ? "rhoSimpleFoam" : "simpleFoam", doc.str("gas.model"));
  s += fmt::format("nProcs          {};\nhierarchicalN   (1 {} 1);\n\n", np, np);
  s += fmt::format(
      "// flow.domain: half = z >= 0 only, symmetryPlane patch `symmetry` at z = 0\n"
      "// (blockMeshDict, MRFProperties); full = the whole housing\n"
      "domain          {};\n\n",
      half ? "half" : "full");
  s += "// Housing box = background mesh (mill.housing.*), preset " + mp.name + "\n";
  s += fmt::format(
      "xMin {:.10g}; xMax {:.10g};\nyMin 0; yMax {:.10g};\nzMin {:.10g}; zMax {:.10g};\n", x0, x1,
      g.height, z0, z1);
  s += fmt::format("nx {}; ny {}; nz {};\n\n", cells_along(g.width, mp.cell),
                   cells_along(g.height, mp.cell), cells_along(z1 - z0, mp.cell));
  s += "// Flywheel (mill.flywheel.*), rotor zone, rotation (rotor.rpm)\n";
  s += fmt::format("axisX           {:.10g};\naxisY           {:.10g};\ntipRadius       {:.10g};\n",
                   g.axis_x, g.axis_height, rt);
  s += fmt::format("rotorRadius     {:.10g};\nrimRadius       {:.10g};\n", rr, rim);
  s += fmt::format("omega           {:.10g};  // rad/s = {:g} rpm\n", omega, rpm);
  s += fmt::format("torqueCentre    {};  // on the axis, for the shaft torque\n",
                   vec(g.axis_x, g.axis_height, 0.0));
  s += fmt::format("rimZ            {:.10g};\nrimStart        {};\n", rim_z,
                   vec(g.axis_x + rim, g.axis_height, rim_z));
  s += fmt::format("axisPoint1      {};\naxisPoint2      {};\n",
                   vec(g.axis_x, g.axis_height, z0 - eps), vec(g.axis_x, g.axis_height, z1 + eps));
  // The rotating cellZone (topoSet) ends midway between the flywheel's side
  // faces (z = +-plate_width/2) and the front/back walls: a zone reaching the
  // stationary walls made the gas in the gap oscillate and kept the layered
  // meshes from converging (docs/flow.md, "Where the rotor zone ends").
  const double zone_z = 0.25 * (g.plate_width + g.depth);
  s += fmt::format(
      "// rotating zone: rotorRadius, |z| <= {:.10g} (midway between plate sides and walls)\n"
      "zonePoint1      {};\nzonePoint2      {};\n\n",
      zone_z, vec(g.axis_x, g.axis_height, half ? z0 - eps : -zone_z),
      vec(g.axis_x, g.axis_height, zone_z));
  s += "// Openings (mill.inlet.*, mill.outlet.*): boxes picking roof/floor faces\n";
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
  s += fmt::format("locationInMesh  {};\n", vec(lx, ly, lz));
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
  s += "// Gas (gas.*)\n";
  s += fmt::format(
      "rhoRef          {:.10g};\nnu              {:.10g};\nmu              {:.10g};\nTRef          "
      "  {:.10g};\n",
      rho, mu / rho, mu, doc.real("gas.temperature"));
  // forces function object: rho from the field (rhoSimpleFoam) or rhoRef
  // times the kinematic pressure (simpleFoam)
  // limits of the start-up temperature guard (system/fvOptions, compressible)
  s += fmt::format("TMinLimit       {:.10g};\nTMaxLimit       {:.10g};\n",
                   kTGuardMin * doc.real("gas.temperature"), kTGuardMax * doc.real("gas.temperature"));
  s += fmt::format("forcesRho       {};\n", comp ? "rho" : "rhoInf");
  if (comp) {
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
      k0, om0, 0.07 * g.inlet_size);
  s += "// Solver control (flow.*)\n";
  s += fmt::format("maxIterations   {};{}\nresidualTarget  {:g};\n",
                   end_iteration > 0 ? end_iteration : doc.integer("flow.max_iterations"),
                   end_iteration > 0 ? "  // first-order start (flow.first_order_iterations)" : "",
                   doc.real("flow.residual_target"));

  return s;
}

}  // namespace flow

namespace {

// Start one OpenFOAM program in the case folder with its log.<name> beside it.
engine::Result run_foam(StageContext& ctx, const std::string& job, const fs::path& case_dir,
                        std::vector<std::string> argv, int np = 1,
                        const engine::Runner::Poll& poll = nullptr) {
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

// Min/max/average of y+ per patch from the yPlus function object.
nlohmann::json read_yplus(const fs::path& case_dir) {
  nlohmann::json out = nlohmann::json::object();
  const fs::path f = flow::function_object_file(case_dir, "yPlus", ".dat");
  if (f.empty()) return out;
  std::ifstream in(f);
  std::string l;
  while (std::getline(in, l)) {
    if (l.empty() || l[0] == '#') continue;
    std::istringstream ss(l);
    std::string t, patch;
    double mn, mx, av;
    if (ss >> t >> patch >> mn >> mx >> av)
      out[patch] = {{"min", mn}, {"max", mx}, {"average", av}};
  }
  return out;
}

// "# Area : 6.6e-02" header of a surfaceFieldValue output; NaN if missing.
double read_patch_area(const fs::path& case_dir, const std::string& fo) {
  const auto f = flow::function_object_file(case_dir, fo, ".dat");
  std::ifstream in(f);
  std::string l;
  while (std::getline(in, l))
    if (l.rfind("# Area", 0) == 0 && l.find(':') != std::string::npos)
      return std::stod(l.substr(l.find(':') + 1));
  return NAN;
}

// Last value of a surfaceFieldValue sum(phi) output; NaN if missing.
double read_flux(const fs::path& case_dir, const std::string& fo) {
  const auto f = flow::function_object_file(case_dir, fo, ".dat");
  if (f.empty()) return NAN;
  const auto v = flow::last_data_line(f);
  return v.size() >= 2 ? std::stod(v[1]) : NAN;
}

// Total moment (pressure + viscous) of the gas on the flywheel about the axis
// point, last line of the forces function object's moment.dat: "time total_x
// total_y total_z pressure_x ... viscous_z" (brackets, if any, are ignored).
// Empty if missing.
std::vector<double> read_moment(const fs::path& case_dir) {
  const auto f = flow::function_object_file(case_dir, "flywheelForces", "moment.dat");
  if (f.empty()) return {};
  std::ifstream in(f);
  std::string l, last;
  while (std::getline(in, l))
    if (!l.empty() && l[0] != '#') last = l;
  for (char& c : last)
    if (c == '(' || c == ')') c = ' ';
  std::istringstream ss(last);
  std::vector<double> v;
  double x;
  while (ss >> x) v.push_back(x);
  if (v.size() < 4) return {};
  return {v[1], v[2], v[3]};
}

// Mean |U| and mean tangential U on the rim circle (sets function object).
nlohmann::json read_rim(const fs::path& case_dir, const geometry::MillGeometry& g, double omega) {
  const auto f = flow::function_object_file(case_dir, "rimSpeed", ".xy");
  nlohmann::json out;
  if (f.empty()) return out;
  std::ifstream in(f);
  double x, y, z, ux, uy, uz, sum_mag = 0, sum_tan = 0, r_sum = 0, z_sum = 0;
  int n = 0;
  while (in >> x >> y >> z >> ux >> uy >> uz) {
    const double dx = x - g.axis_x, dy = y - g.axis_height, r = std::hypot(dx, dy);
    if (r <= 0) continue;
    sum_mag += std::sqrt(ux * ux + uy * uy + uz * uz);
    sum_tan += (-dy * ux + dx * uy) / r;  // positive along the rotation (anticlockwise about +z)
    r_sum += r;
    z_sum += z;
    ++n;
  }
  if (n == 0) return out;
  const double rim_speed = omega * g.tip_radius();
  out["radius_m"] = r_sum / n;
  out["z_m"] = z_sum / n;
  out["points"] = n;
  out["tip_speed_m_s"] = rim_speed;
  out["gas_speed_mean_m_s"] = sum_mag / n;
  out["gas_tangential_mean_m_s"] = sum_tan / n;
  out["ratio_speed_to_tip_speed"] = rim_speed > 0 ? sum_mag / n / rim_speed : 0.0;
  return out;
}

}  // namespace

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

// Template -> geometry -> mesh -> checkMesh -> solve -> report -> publish.
void FlowStage::run_job(StageContext& ctx, const JobSpec& job, const fs::path& job_dir) {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  const auto& doc = ctx.cfg.doc;
  const double rpm = job.inputs.at("rotor.rpm").get<double>();
  const int np = std::max(1, ctx.opts.np);
  const std::string tag = "flow/" + job.label;
  auto geo = geometry::MillGeometry::from_config(doc);
  geo.rotor_angle = doc.real("flow.rotor_angle") * flow::kPi / 180.0;  // frozen-rotor position
  auto preset = flow::mesh_preset(doc.str("flow.mesh_preset"));
  if (doc.str("flow.momentum_scheme") != "preset")
    preset.second_order = doc.str("flow.momentum_scheme") == "linearUpwind";
  const bool comp = doc.str("gas.model") == "compressible";
  const std::string solver = comp ? "rhoSimpleFoam" : "simpleFoam";
  const double omega = rpm * 2 * flow::kPi / 60.0;
  const long max_it = doc.integer("flow.max_iterations");
  const double target = doc.real("flow.residual_target");
  // flow.domain = half: the solved case is z >= 0 with a symmetry plane at
  // z = 0; mass flows and opening areas are doubled to whole-mill values.
  const bool half = doc.str("flow.domain") == "half";
  const double mirror = half ? 2.0 : 1.0;

  // 1. A fresh case in the job folder.
  const fs::path work = job_dir / "case";
  fs::remove_all(work);
  flow::copy_template(ctx.cfg.project_dir / "foam_case", work);
  jobs::atomic_write(work / "system" / "caseParameters",
                     flow::case_parameters(doc, rpm, preset, np));
  geometry::write_stl_set(geo, work / "constant" / "triSurface");
  std::ofstream(work / "case.foam").close();

  // 2. Mesh.
  run_foam(ctx, tag, work, {"blockMesh"});
  run_foam(ctx, tag, work, {"surfaceFeatureExtract"});
  run_foam(ctx, tag, work, {"snappyHexMesh", "-overwrite"});
  run_foam(ctx, tag, work, {"topoSet"});
  run_foam(ctx, tag, work, {"createPatch", "-overwrite"});
  run_foam(ctx, tag, work, {"checkMesh", "-constant"});
  const std::string cm = flow::read_text(work / "log.checkMesh");
  if (cm.find("Mesh OK.") == std::string::npos)
    throw std::runtime_error(fmt::format("checkMesh reports mesh errors (lines with ***); log: {}",
                                         (work / "log.checkMesh").string()));
  const long cells = flow::checkmesh_count(cm, "cells");
  for (const char* patch : {"inlet", "outlet", "flywheel"})
    if (flow::checkmesh_patch_faces(cm, patch) <= 0)
      throw std::runtime_error(
          fmt::format("the mesh has no '{}' faces (opening or flywheel smaller than the {} "
                      "preset's {:g} m cells?); "
                      "choose a finer flow.mesh_preset or a larger mill.{}.size; log: {}",
                      patch, preset.name, preset.cell, patch, (work / "log.checkMesh").string()));
  const double mesh_seconds = std::chrono::duration<double>(clock::now() - t0).count();
  ctx.progress.info(fmt::format("{}: mesh of {} cells ({} preset) in {}", tag, cells, preset.name,
                                Progress::duration(mesh_seconds)));

  // 3. Solve.
  fs::remove_all(work / "0");
  fs::copy(work / "0.orig", work / "0", fs::copy_options::recursive);
  if (np > 1) run_foam(ctx, tag, work, {"decomposePar", "-force"});
  const fs::path log = work / ("log." + solver);
  const auto t1 = clock::now();
  auto poll = [&](const fs::path& lg) {
    const auto s = flow::parse_solver_log(lg);
    const double p = s.initial_residual.count("p") ? s.initial_residual.at("p") : NAN;
    const double u = std::max({s.initial_residual.count("Ux") ? s.initial_residual.at("Ux") : 0.0,
                               s.initial_residual.count("Uy") ? s.initial_residual.at("Uy") : 0.0,
                               s.initial_residual.count("Uz") ? s.initial_residual.at("Uz") : 0.0});
    ctx.progress.job_step(
        job.label,
        fmt::format("{} iter {}/{} p {:.1e} U {:.1e}", solver, s.iterations, max_it, p, u),
        static_cast<double>(s.iterations) / max_it);
  };
  auto solve = [&]() {
    try {
      run_foam(ctx, tag, work, {solver}, np, poll);
    } catch (const engine::EngineError& e) {
      const auto s = flow::parse_solver_log(log);
      if (s.fpe || s.nan || e.result.signal == SIGFPE)
        throw std::runtime_error(fmt::format(
            "the flow diverged at iteration {} (floating-point exception / NaN in {}); try a finer "
            "flow.mesh_preset or check rotor.rpm and gas.outlet_pressure_drop; log: {}",
            s.iterations, solver, log.string()));
      throw;
    }
  };
  // Second-order presets start with first-order upwind momentum for
  // flow.first_order_iterations, then restart from that state (the solver's
  // startFrom latestTime) with the preset's scheme.
  const long first_order =
      preset.second_order ? std::min<long>(doc.integer("flow.first_order_iterations"), max_it) : 0;
  double first_order_cpu = 0;
  int first_order_done = 0;
  if (first_order > 0) {
    auto upwind = preset;
    upwind.second_order = false;
    jobs::atomic_write(work / "system" / "caseParameters",
                       flow::case_parameters(doc, rpm, upwind, np, first_order));
    solve();
    const auto s1 = flow::parse_solver_log(log);
    first_order_cpu = s1.cpu_seconds;
    first_order_done = s1.iterations;
    fs::rename(log, work / ("log." + solver + ".firstOrder"));
    jobs::atomic_write(work / "system" / "caseParameters",
                       flow::case_parameters(doc, rpm, preset, np));
    ctx.progress.info(fmt::format("{}: first-order start: {} iterations (p {:.2g}); now {}", tag,
                                  s1.iterations,
                                  s1.initial_residual.count("p") ? s1.initial_residual.at("p") : NAN,
                                  "second-order momentum"));
  }
  if (first_order < max_it) solve();
  else fs::rename(work / ("log." + solver + ".firstOrder"), log);
  const double solve_seconds = std::chrono::duration<double>(clock::now() - t1).count();
  if (np > 1) run_foam(ctx, tag, work, {"reconstructPar", "-latestTime"});

  auto s = flow::parse_solver_log(log);
  s.cpu_seconds += first_order < max_it ? first_order_cpu : 0.0;
  const double p_res = s.initial_residual.count("p") ? s.initial_residual.at("p") : NAN;
  double u_res = 0;
  for (const char* c : {"Ux", "Uy", "Uz"})
    if (s.initial_residual.count(c)) u_res = std::max(u_res, s.initial_residual.at(c));
  if (s.nan || !(p_res < 1.0) || !(u_res < 1.0))
    throw std::runtime_error(fmt::format(
        "the flow diverged: initial residuals p {:.3g}, U {:.3g} after {} iterations; log: {}",
        p_res, u_res, s.iterations, log.string()));
  const bool converged = s.converged || (p_res < target && u_res < target);

  // 4. Report.
  const double rho = doc.real("gas.density");
  const double to_mass = comp ? 1.0 : rho;  // simpleFoam's phi is m^3/s
  const double in_flux = read_flux(work, "inletFlow"), out_flux = read_flux(work, "outletFlow");
  const double m_in = -in_flux * to_mass * mirror, m_out = out_flux * to_mass * mirror;
  const double denom = std::max(std::abs(m_in), std::abs(m_out));
  const double imbalance = denom > 0 ? std::abs(m_in - m_out) / denom : 0.0;
  nlohmann::json rep;
  rep["rpm"] = rpm;
  rep["omega_rad_s"] = omega;
  rep["gas_model"] = doc.str("gas.model");
  rep["solver"] = solver;
  rep["mesh_preset"] = preset.name;
  rep["np"] = np;
  rep["cells"] = cells;  // of the solved mesh (the half for flow.domain = half)
  rep["domain"] = half ? "half" : "full";
  rep["mirrored"] = half;
  if (half)
    rep["mirror_note"] =
        "solved z >= 0 with a symmetryPlane at z = 0; mass_flow_kg_s and patch_area_m2 are for "
        "the whole mill (2 x the solved half, see solved_half); cells, rim and y_plus are of the "
        "solved half";
  rep["rotor_angle_deg"] = doc.real("flow.rotor_angle");
  rep["iterations"] = s.iterations;
  rep["momentum_scheme"] =
      preset.second_order
          ? (first_order > 0 ? fmt::format("upwind for {} iterations, then linearUpwind",
                                            first_order_done)
                             : std::string("linearUpwind"))
          : std::string("upwind");
  rep["max_iterations"] = max_it;
  rep["residual_target"] = target;
  rep["converged"] = converged;
  rep["final_initial_residuals"] = s.initial_residual;
  rep["mass_flow_kg_s"] = {
      {"inlet_in", m_in}, {"outlet_out", m_out}, {"imbalance_relative", imbalance}};
  // How steady the figures were at the end: min/max over the last tenth of
  // the iterations (a converged solve has a spread near 0).
  rep["history_last_tenth"] = {
      {"mass_flow_inlet_kg_s",
       flow::tail_spread(flow::function_object_series(work, "inletFlow", ".dat", 1), -to_mass * mirror)},
      {"shaft_torque_Nm",
       flow::tail_spread(flow::function_object_series(work, "flywheelForces", "moment.dat", 3),
                   -mirror)}};
  // Backflow: phi summed with its sign (net) and as |phi| (sum of both
  // directions) gives each direction: inflow through the outlet, outflow
  // through the inlet (zero when the opening passes gas one way only).
  const double in_mag = read_flux(work, "inletFlowMag"), out_mag = read_flux(work, "outletFlowMag");
  const double in_back = 0.5 * (in_mag + in_flux) * to_mass * mirror;   // leaving via the inlet
  const double out_back = 0.5 * (out_mag - out_flux) * to_mass * mirror;  // entering via the outlet
  rep["backflow_kg_s"] = {{"inlet_out", in_back},
                          {"outlet_in", out_back},
                          {"inlet_abs_flux", in_mag * to_mass * mirror},
                          {"outlet_abs_flux", out_mag * to_mass * mirror},
                          {"note",
                           "gas leaving through the inlet and entering through the outlet "
                           "(sum of |phi| beside the net flux)"}};
  // Shaft torque and power: the gas's moment on the flywheel about the axis
  // (pressure + viscous, forces function object); the rotor turns at +omega
  // about +z, so the motor supplies T = -M_z and P = T omega. For the half
  // domain the mirrored half doubles M_z.
  const auto moment = read_moment(work);
  if (moment.size() == 3) {
    const double torque = -moment[2] * mirror;
    rep["shaft"] = {{"torque_Nm", torque},
                    {"power_W", torque * omega},
                    {"power_kW", torque * omega * 1e-3},
                    {"note",
                     "aerodynamic torque of the gas on the flywheel (pressure + viscous, about "
                     "the axis) at the last iteration; the motor power the gas alone takes, "
                     "without ore, bearings or windage outside the housing"}};
  }
  // Energy balance (compressible): the rotor's work must leave as a total
  // temperature rise of the through-flow, dT0 = P / (m cp), walls adiabatic.
  if (comp && rep.contains("shaft")) {
    const auto ti = flow::last_data_line(flow::function_object_file(work, "inletTemperature", ".dat"));
    const auto to = flow::last_data_line(flow::function_object_file(work, "outletTemperature", ".dat"));
    if (ti.size() >= 3 && to.size() >= 3) {
      constexpr double cp = 1005.0;  // constant/thermophysicalProperties
      const double t_in = std::stod(ti[1]), t_out = std::stod(to[1]);
      const double t0_in = t_in + 0.5 * std::stod(ti[2]) / cp,
                   t0_out = t_out + 0.5 * std::stod(to[2]) / cp;
      const double expected = m_out > 0 ? rep["shaft"]["power_W"].get<double>() / (m_out * cp) : NAN;
      rep["energy_balance"] = {
          {"inlet_T_K", t_in},
          {"outlet_T_K", t_out},
          {"total_temperature_rise_K", t0_out - t0_in},
          {"expected_rise_from_shaft_power_K", expected},
          {"note",
           "mass-flux-weighted over each opening; expected = shaft power / (mass flow x cp 1005 "
           "J/kg/K) with adiabatic walls. OpenFOAM v1912's rhoSimpleFoam has no work term for the "
           "MRF zone, so the rotor's work does not enter the energy equation: "
           "total_temperature_rise_K stays near 0, far below expected_rise_from_shaft_power_K, "
           "and T is not a heat balance; docs/flow.md, \"Compressible gas\""}};
    }
  }
  // Temperature range of the gas (compressible) against the start-up guard
  // of system/fvOptions: a guard still clipping at the end is reported.
  if (comp) {
    const auto tmin = flow::last_data_line(flow::function_object_file(work, "minTemperature", ".dat"));
    const auto tmax = flow::last_data_line(flow::function_object_file(work, "maxTemperature", ".dat"));
    if (tmin.size() >= 2 && tmax.size() >= 2) {
      const double t_ref = doc.real("gas.temperature");
      const double lo = std::stod(tmin[1]), hi = std::stod(tmax[1]);
      const double guard_lo = flow::kTGuardMin * t_ref, guard_hi = flow::kTGuardMax * t_ref;
      const bool clipped = lo <= guard_lo * 1.0001 || hi >= guard_hi * 0.9999;
      rep["temperature_K"] = {{"min", lo},
                              {"max", hi},
                              {"guard_limits", {guard_lo, guard_hi}},
                              {"guard_clipping_at_end", clipped},
                              {"note",
                               "lowest and highest T in the gas at the last iteration; the guard "
                               "(system/fvOptions limitT) only holds the first iterations of the "
                               "layered meshes and must not clip at the end"}};
      if (clipped)
        ctx.progress.warn(fmt::format(
            "{}: the temperature guard still clips at the last iteration (T {:.1f}-{:.1f} K, "
            "limits {:.1f}-{:.1f} K): the solution is not trustworthy; see docs/flow.md",
            tag, lo, hi, guard_lo, guard_hi));
    }
  }
  const double a_in = read_patch_area(work, "inletFlow");
  const double a_out = read_patch_area(work, "outletFlow");
  rep["patch_area_m2"] = {{"inlet", a_in * mirror},
                          {"outlet", a_out * mirror},
                          {"inlet_nominal", geo.inlet_size * geo.inlet_size},
                          {"outlet_nominal", geo.outlet_size * geo.outlet_size}};
  if (half)
    rep["solved_half"] = {{"mass_flow_kg_s", {{"inlet_in", -in_flux * to_mass},
                                              {"outlet_out", out_flux * to_mass}}},
                          {"patch_area_m2", {{"inlet", a_in}, {"outlet", a_out}}}};
  rep["rim"] = read_rim(work, geo, omega);
  rep["y_plus"] = read_yplus(work);
  rep["solver_cpu_s_rank0"] = s.cpu_seconds;  // ExecutionTime: steadier than wall time on a shared machine
  rep["wall_time_s"] = {{"mesh", mesh_seconds},
                        {"solve", solve_seconds},
                        {"total", std::chrono::duration<double>(clock::now() - t0).count()}};
  rep["case"] = "case";
  rep["geometry"] = {{"dir", "geometry"},
                     {"files", {"housing.stl", "flywheel.stl", "inlet.stl", "outlet.stl"}},
                     {"units", "m"},
                     {"normals", "into the gas"}};

  // 5. Publish: assemble in a temp folder, then rename over the old output.
  const fs::path out = flow::output_dir(ctx.run_dir, job.label);
  const fs::path tmp = out.string() + ".tmp." + std::to_string(getpid());
  fs::remove_all(tmp);
  fs::create_directories(tmp);
  geometry::write_stl_set(geo, tmp / "geometry");
  jobs::atomic_write(tmp / "flow_report.json", rep.dump(2) + "\n");
  fs::rename(work, tmp / "case");
  fs::remove_all(out);
  fs::rename(tmp, out);

  const auto& yp = rep["y_plus"];
  auto ypl = [&](const char* p) {
    return yp.contains(p) ? fmt::format("{:.0f}", yp[p]["average"].get<double>())
                          : std::string("?");
  };
  const auto& rim = rep["rim"];
  ctx.progress.info(
      fmt::format("{}: {} after {} iterations (p {:.2g}, U {:.2g}; target {:g}); {}mass flow in "
                  "{:.4g} kg/s, out {:.4g} kg/s, "
                  "imbalance {:.2f}%; backflow in {:.3g} / out {:.3g} kg/s; shaft power {}; gas "
                  "speed near rim {:.1f} m/s = {:.2f} x tip speed; mean y+ "
                  "flywheel {}, housing {}; "
                  "{} cells; {}",
                  tag, converged ? "converged" : "NOT converged", s.iterations, p_res, u_res,
                  target, half ? "half domain mirrored: " : "", m_in, m_out, 100 * imbalance,
                  in_back, out_back,
                  rep.contains("shaft")
                      ? fmt::format("{:.3g} kW ({:.3g} N m)", rep["shaft"]["power_kW"].get<double>(),
                                    rep["shaft"]["torque_Nm"].get<double>())
                      : std::string("? (no moment.dat)"),
                  rim.value("gas_speed_mean_m_s", 0.0),
                  rim.value("ratio_speed_to_tip_speed", 0.0), ypl("flywheel"), ypl("housing"),
                  cells, Progress::duration(rep["wall_time_s"]["total"].get<double>())));
  if (!converged)
    ctx.progress.warn(fmt::format("{}: not converged within flow.max_iterations = {} (see {})", tag,
                                  max_it, (out / "case" / ("log." + solver)).string()));
}

// The declared outputs of one rotor speed: report, solved case, geometry.
std::string FlowStage::damaged_outputs(const StageContext& ctx, const JobSpec& job) const {
  const fs::path out = flow::output_dir(ctx.run_dir, job.label);
  std::vector<std::string> r = {jobs::check_json(out / "flow_report.json"), jobs::check_exists(out / "case" / "case.foam")};
  for (const char* stl : {"housing.stl", "flywheel.stl", "inlet.stl", "outlet.stl"})
    r.push_back(jobs::check_file(out / "geometry" / stl));
  return jobs::first_problem(r);
}

// One summary of all rotor speeds: <run>/flow/flow_summary.json.
void FlowStage::finalize(StageContext& ctx, const std::vector<JobSpec>& jobs) {
  nlohmann::json all = nlohmann::json::array();
  for (const auto& j : jobs) {
    const fs::path f = flow::output_dir(ctx.run_dir, j.label) / "flow_report.json";
    if (!fs::exists(f)) continue;
    nlohmann::json r = nlohmann::json::parse(flow::read_text(f), nullptr, false);
    if (!r.is_object())
      throw std::runtime_error(fmt::format("{}: not a JSON object (damaged?); rerun --stage flow --force", f.string()));
    r["label"] = j.label;
    all.push_back(r);
  }
  jobs::atomic_write(ctx.stage_dir / "flow_summary.json", all.dump(2) + "\n");
}

}  // namespace mill
