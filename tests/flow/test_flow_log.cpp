// Solver-log parsing (progress, convergence, divergence) and presets.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "geometry/mill_geometry.h"
#include "stages/flow/case_files.h"
#include "stages/flow/foam_results.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using namespace mill::flow;

namespace {

// A log file holding `text`, removed when the test passes.
mill::test::TempPath write_log(const std::string& name, const std::string& text) {
  mill::test::TempPath f("mill_flowlog_" + std::to_string(getpid()) + "_" + name);
  std::ofstream(f.path()) << text;
  return f;
}

const char* kIter =
    "Time = {T}\n\n"
    "smoothSolver:  Solving for Ux, Initial residual = {U}, Final residual = 1e-05, No Iterations "
    "2\n"
    "smoothSolver:  Solving for Uy, Initial residual = 0.001, Final residual = 1e-05, No "
    "Iterations 2\n"
    "GAMG:  Solving for p, Initial residual = {P}, Final residual = 1e-06, No Iterations 3\n"
    "GAMG:  Solving for p, Initial residual = 1e-09, Final residual = 1e-10, No Iterations 3\n"
    "ExecutionTime = 1 s  ClockTime = 1 s\n\n";

std::string iter(int t, const std::string& u, const std::string& p) {
  std::string s = kIter;
  s.replace(s.find("{T}"), 3, std::to_string(t));
  s.replace(s.find("{U}"), 3, u);
  s.replace(s.find("{P}"), 3, p);
  return s;
}

}  // namespace

TEST(FlowLog, ConvergedRun) {
  const auto f =
      write_log("conv", iter(1, "1", "1") + iter(2, "0.01", "0.02") + iter(3, "5e-05", "8e-05") +
                            "\nSIMPLE solution converged in 3 iterations\n\nEnd\n");
  const auto s = parse_solver_log(f);
  EXPECT_EQ(s.iterations, 3);
  EXPECT_TRUE(s.converged);
  EXPECT_FALSE(s.nan);
  EXPECT_DOUBLE_EQ(s.initial_residual.at("p"), 8e-05)
      << "the first p solve of the iteration, not the corrector";
  EXPECT_DOUBLE_EQ(s.initial_residual.at("Ux"), 5e-05);
}

TEST(FlowLog, NanAndFpeAreSeen) {
  const auto f = write_log(
      "nan",
      iter(1, "1", "1") + iter(2, "nan", "-nan") +
          "#0  Foam::error::printStack(Foam::Ostream&)\n#1  Foam::sigFpe::sigHandler(int)\n");
  const auto s = parse_solver_log(f);
  EXPECT_EQ(s.iterations, 2);
  EXPECT_TRUE(s.nan);
  EXPECT_TRUE(s.fpe);
  EXPECT_FALSE(s.converged);
}

TEST(FlowLog, PresetsGrowInResolution) {
  const auto t = mesh_preset("tiny"), q = mesh_preset("quick"), r = mesh_preset("reference");
  EXPECT_GT(t.cell, q.cell);
  EXPECT_GE(q.cell, r.cell);
  EXPECT_TRUE(r.layers);
  EXPECT_FALSE(t.layers);
  EXPECT_THROW(mesh_preset("huge"), std::invalid_argument);
}

// foam_case/ ships the parameters and surfaces of cases/default.yaml so that
// its Allrun works by hand. MILL_UPDATE_TEMPLATE=1 rewrites them.
TEST(FlowTemplate, MatchesTheDefaultCase) {
  const fs::path project = MILL_PROJECT_DIR;
  const auto cfg = mill::config::load_case(project / "cases" / "default.yaml", project);
  const auto preset = mesh_preset(cfg.doc.str("flow.mesh_preset"));
  const std::string params = case_parameters(cfg.doc, cfg.doc.reals("rotor.rpm").at(0), preset, 1);
  const fs::path tmpl = project / "foam_case";
  const auto geo = mill::geometry::MillGeometry::from_config(cfg.doc);
  if (getenv("MILL_UPDATE_TEMPLATE")) {
    std::ofstream(tmpl / "system" / "caseParameters") << params;
    mill::geometry::write_stl_set(geo, tmpl / "constant" / "triSurface");
  }
  std::ifstream in(tmpl / "system" / "caseParameters");
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(), params)
      << "foam_case/system/caseParameters is stale: rerun this test with MILL_UPDATE_TEMPLATE=1";
  const mill::test::TempPath d("mill_tmpl_" + std::to_string(getpid()));
  const auto set = mill::geometry::write_stl_set(geo, d);
  for (const auto& f : {set.housing, set.flywheel, set.inlet, set.outlet}) {
    std::ifstream a(f), b(tmpl / "constant" / "triSurface" / f.filename());
    std::stringstream sa, sb;
    sa << a.rdbuf();
    sb << b.rdbuf();
    EXPECT_EQ(sa.str(), sb.str()) << f.filename() << " is stale: rerun with MILL_UPDATE_TEMPLATE=1";
  }
}

namespace {
// The z of "zonePoint1/2 (x y z);" in a caseParameters text.
double zone_z(const std::string& params, const std::string& entry) {
  const auto at = params.find("\n" + entry);
  EXPECT_NE(at, std::string::npos) << entry;
  if (at == std::string::npos) return NAN;
  std::istringstream in(params.substr(params.find('(', at) + 1));
  double x = 0, y = 0, z = 0;
  in >> x >> y >> z;
  return z;
}
}  // namespace

// The rotating zone covers the flywheel (|z| <= plate_width / 2) and ends
// midway to the front/back walls, so no stationary wall lies in it (a zone
// reaching the walls kept the layered meshes from converging; docs/flow.md).
TEST(FlowTemplate, RotorZoneEndsBetweenFlywheelAndWalls) {
  const fs::path project = MILL_PROJECT_DIR;
  for (const char* domain : {"half", "full"})
    for (const char* width : {"0.3", "0.45"}) {
      const auto cfg =
          mill::config::load_case(project / "cases" / "default.yaml", project,
                                  {{"flow.domain", domain}, {"mill.flywheel.plate_width", width}});
      const double pw = cfg.doc.real("mill.flywheel.plate_width");
      const double wall = 0.5 * cfg.doc.real("mill.housing.depth");
      const std::string p = case_parameters(cfg.doc, 2000, mesh_preset("quick"), 1);
      const double z2 = zone_z(p, "zonePoint2"), z1 = zone_z(p, "zonePoint1");
      SCOPED_TRACE(std::string(domain) + " domain, plate width " + width);
      EXPECT_NEAR(z2, 0.5 * (0.5 * pw + wall), 1e-9);
      EXPECT_GT(z2, 0.5 * pw);
      EXPECT_LT(z2, wall);
      if (std::string(domain) == "full")
        EXPECT_NEAR(z1, -z2, 1e-9);
      else
        EXPECT_LT(z1, 0.0);  // the half domain's zone reaches through the symmetry plane
      // The refinement cylinder still spans the whole depth.
      EXPECT_GT(zone_z(p, "axisPoint2"), wall);
    }
}
