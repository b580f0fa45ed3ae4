// End to end on the tiny mesh: the flow stage meshes and runs a few dozen
// iterations of simpleFoam (1 rank) and rhoSimpleFoam (2 ranks, hierarchical)
// on the half domain z >= 0 (flow.domain = half, the default), and simpleFoam
// on the full housing (2 ranks); then the sample stage writes
// field.h5/.vti/.png with the right shape, mask and units, mirrored about
// z = 0 for the half. Also the user errors of the sample stage.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "engine/runner.h"
#include "geometry/mill_geometry.h"
#include "postprocess/flow_field_io.h"
#include "progress.h"
#include "stages/flow_stage.h"
#include "stages/sample_stage.h"
#include "stages/transport_stage.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using namespace mill;

namespace {

const fs::path kData = MILL_FLOW_TEST_DATA;

struct StageRun {
  config::CaseConfig cfg;
  test::TempPath run_dir;  // the run folder, removed when the test passes
  RunOptions opts;
  engine::Runner runner;
  std::ostringstream out;
  Progress progress{out, false};

  StageRun(const fs::path& yaml, int np)
      : cfg(config::load_case(yaml, MILL_PROJECT_DIR)),
        run_dir("mill_flow_" + cfg.name + "_" + std::to_string(getpid())) {
    opts.np = np;
    opts.output = run_dir;
  }
  StageContext ctx(const std::string& stage) {
    return StageContext{cfg, opts, opts.output, opts.output / stage, runner, progress};
  }
  // Plan the stage and run its only job.
  void run(Stage& s) {
    auto c = ctx(s.name());
    const auto plan = s.plan(c);
    ASSERT_EQ(plan.jobs.size(), 1u);
    const fs::path job_dir = c.stage_dir / "jobs" / plan.jobs[0].label;
    fs::create_directories(job_dir);
    s.run_job(c, plan.jobs[0], job_dir);
  }
};

nlohmann::json read_json(const fs::path& f) {
  std::ifstream in(f);
  return nlohmann::json::parse(in);
}

// Last "sum(phi)" of a surfaceFieldValue function object of the solved case.
double raw_flux(const fs::path& case_dir, const std::string& fo) {
  std::ifstream in(case_dir / "postProcessing" / fo / "0" / "surfaceFieldValue.dat");
  std::string l, last;
  while (std::getline(in, l))
    if (!l.empty() && l[0] != '#') last = l;
  std::istringstream ss(last);
  double t = NAN, v = NAN;
  ss >> t >> v;
  return v;
}

// A half-domain run: the report is whole-mill (2 x the solved half) and says
// so; the sampled field covers the whole housing, mirror-symmetric about z = 0.
void check_half_domain(const fs::path& run, double to_mass) {
  const fs::path flow = run / "flow" / "rpm2000";
  const auto rep = read_json(flow / "flow_report.json");
  EXPECT_EQ(rep["domain"], "half");
  EXPECT_EQ(rep["mirrored"], true);
  const double in_half = -raw_flux(flow / "case", "inletFlow") * to_mass;
  const double out_half = raw_flux(flow / "case", "outletFlow") * to_mass;
  ASSERT_TRUE(std::isfinite(in_half) && std::isfinite(out_half));
  EXPECT_NE(in_half, 0.0);
  EXPECT_NEAR(rep["mass_flow_kg_s"]["inlet_in"].get<double>(), 2 * in_half,
              1e-9 * std::abs(in_half));
  EXPECT_NEAR(rep["mass_flow_kg_s"]["outlet_out"].get<double>(), 2 * out_half,
              1e-9 * std::abs(out_half));
  EXPECT_DOUBLE_EQ(rep["solved_half"]["mass_flow_kg_s"]["inlet_in"].get<double>(), in_half);
  EXPECT_DOUBLE_EQ(rep["patch_area_m2"]["inlet"].get<double>(),
                   2 * rep["solved_half"]["patch_area_m2"]["inlet"].get<double>());
  // Whole-mill opening areas: the staircase squares are close to nominal.
  EXPECT_NEAR(rep["patch_area_m2"]["outlet"].get<double>(),
              rep["patch_area_m2"]["outlet_nominal"].get<double>(),
              0.5 * rep["patch_area_m2"]["outlet_nominal"].get<double>());
  EXPECT_GT(rep["rim"]["z_m"].get<double>(), 0.0) << "rim circle inside the half";
  // The mesh is the half: z >= 0, symmetry plane at z = 0.
  std::ifstream b(flow / "case" / "constant" / "polyMesh" / "boundary");
  std::stringstream bs;
  bs << b.rdbuf();
  EXPECT_NE(bs.str().find("symmetryPlane"), std::string::npos);

  const fs::path s = run / "sample" / "rpm2000";
  const auto srep = read_json(s / "sample_report.json");
  EXPECT_EQ(srep["mirrored_about_z0"], true);
  const auto f = post::read_flow_field(s / "field.h5");
  const int nz = f.dims[2];
  size_t gas_lower = 0, gas_upper = 0;
  double uz_max = 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < f.dims[1]; ++j)
      for (int i = 0; i < f.dims[0]; ++i) {
        const size_t p = f.point(i, j, k), m = f.point(i, j, nz - 1 - k);
        ASSERT_EQ(f.mask[p], f.mask[m]) << i << " " << j << " " << k;
        ASSERT_EQ(f.U[3 * p], f.U[3 * m]) << "U_x even in z";
        ASSERT_EQ(f.U[3 * p + 1], f.U[3 * m + 1]) << "U_y even in z";
        ASSERT_EQ(f.U[3 * p + 2], -f.U[3 * m + 2]) << "U_z odd in z";
        ASSERT_EQ(f.rho[p], f.rho[m]);
        if (!f.k.empty()) {
          ASSERT_EQ(f.k[p], f.k[m]);
        }
        (2 * k < nz - 1 ? gas_lower : gas_upper) += f.mask[p];
        uz_max = std::max(uz_max, std::abs(f.U[3 * p + 2]));
      }
  EXPECT_GT(gas_lower, 0u);
  EXPECT_EQ(gas_lower, gas_upper);
  EXPECT_GT(uz_max, 0.0) << "the flow is 3D: the mirror must flip a non-zero U_z";
}

// Checks shared by both solvers on the default mill sampled at 0.1 m.
void check_outputs(const fs::path& run, bool turbulence, double rho_lo, double rho_hi) {
  const auto rep = read_json(run / "flow" / "rpm2000" / "flow_report.json");
  EXPECT_GT(rep["cells"].get<long>(), 1000);
  EXPECT_LT(rep["cells"].get<long>(), 20000);
  EXPECT_EQ(rep["iterations"].get<int>(), 30);
  EXPECT_TRUE(rep["y_plus"].contains("flywheel"));
  EXPECT_TRUE(rep["y_plus"].contains("housing"));
  EXPECT_TRUE(std::isfinite(rep["mass_flow_kg_s"]["inlet_in"].get<double>()));
  EXPECT_GT(rep["rim"]["gas_speed_mean_m_s"].get<double>(), 1.0) << "the rotor drags the gas along";
  for (const char* f : {"housing.stl", "flywheel.stl", "inlet.stl", "outlet.stl"})
    EXPECT_TRUE(fs::exists(run / "flow" / "rpm2000" / "geometry" / f)) << f;
  EXPECT_TRUE(fs::exists(run / "flow" / "rpm2000" / "case" / "case.foam"));

  const fs::path s = run / "sample" / "rpm2000";
  for (const char* f : {"field.h5", "field.vti", "midplane_speed.png", "sample_report.json"})
    EXPECT_TRUE(fs::exists(s / f)) << f;
  const auto fld = post::read_flow_field(s / "field.h5");
  EXPECT_EQ(fld.dims, (std::array<int, 3>{17, 41, 6}));
  EXPECT_EQ(fld.spacing[0], 0.1);
  EXPECT_NEAR(fld.origin[0], -0.8, 1e-12);
  EXPECT_NEAR(fld.origin[1], 0.0, 1e-12);
  EXPECT_NEAR(fld.origin[2], -0.25, 1e-12);
  EXPECT_EQ(post::dataset_unit(s / "field.h5", "U"), "m/s");
  EXPECT_EQ(post::dataset_unit(s / "field.h5", "rho"), "kg/m^3");
  EXPECT_EQ(post::dataset_unit(s / "field.h5", "mask"), "1");
  EXPECT_EQ(fld.k.empty(), !turbulence);
  size_t gas = 0;
  double umax = 0;
  for (size_t i = 0; i < fld.size(); ++i) {
    gas += fld.mask[i];
    if (fld.mask[i]) {
      EXPECT_GE(fld.rho[i], rho_lo);
      EXPECT_LE(fld.rho[i], rho_hi);
    } else {
      EXPECT_EQ(fld.U[3 * i], 0.0);
    }
    umax = std::max(umax, std::hypot(fld.U[3 * i], fld.U[3 * i + 1], fld.U[3 * i + 2]));
  }
  const double frac = static_cast<double>(gas) / fld.size();
  EXPECT_GT(frac, 0.9) << "most of the housing is gas";
  EXPECT_LT(frac, 1.0) << "flywheel points are masked";
  // A point inside the hub (on the axis, mid-depth) is solid.
  const int i = static_cast<int>(std::lround((0.0 - fld.origin[0]) / 0.1));
  const int j = static_cast<int>(std::lround((1.2 - fld.origin[1]) / 0.1));
  const int k = static_cast<int>(std::lround((0.05 - fld.origin[2]) / 0.1));
  EXPECT_EQ(fld.mask[fld.point(i, j, k)], 0) << "hub centre must be masked";
  const double tip = 2000 * 2 * M_PI / 60 * 0.5;
  EXPECT_LT(umax, 2 * tip);
  EXPECT_GT(umax, 0.3 * tip);
}

}  // namespace

TEST(FlowTiny, IncompressibleMeshRunSample) {
  StageRun r(kData / "tiny.yaml", 1);
  FlowStage flow;
  SampleStage sample;
  r.run(flow);
  r.run(sample);
  check_outputs(r.opts.output, true, 1.2, 1.2);
  check_half_domain(r.opts.output, 1.2);
  EXPECT_NE(r.out.str().find("mass flow"), std::string::npos) << r.out.str();
  const auto rep = read_json(r.opts.output / "flow" / "rpm2000" / "flow_report.json");
  // The gas resists the turning rotor: the shaft supplies a positive torque,
  // and the power is torque x omega.
  const double torque = rep["shaft"]["torque_Nm"].get<double>();
  EXPECT_GT(torque, 0.0);
  EXPECT_NEAR(rep["shaft"]["power_W"].get<double>(), torque * rep["omega_rad_s"].get<double>(),
              1e-12 * std::abs(torque) * rep["omega_rad_s"].get<double>());
  EXPECT_NE(r.out.str().find("shaft power"), std::string::npos) << r.out.str();
  // Backflow of each opening: between 0 and the sum of |phi| through it.
  for (const auto& [k, abs_key] : {std::pair{"inlet_out", "inlet_abs_flux"}, {"outlet_in", "outlet_abs_flux"}}) {
    const double b = rep["backflow_kg_s"][k].get<double>(), a = rep["backflow_kg_s"][abs_key].get<double>();
    EXPECT_GE(b, -1e-12 * a) << k;
    EXPECT_LE(b, a * (1 + 1e-12)) << k;
  }
  // 30 iterations do not converge: without flow.allow_unconverged the sample
  // stage stops, naming the key, the residuals and the run.
  EXPECT_EQ(rep["converged"], false);
  {
    const test::TempPath strict("mill_flow_strict_" + std::to_string(getpid()) + ".yaml");
    std::ifstream in(kData / "tiny.yaml");
    std::stringstream ss;
    ss << in.rdbuf();
    std::string t = ss.str();
    t.replace(t.find("allow_unconverged: true"), 23, "allow_unconverged: false");
    t.replace(t.find("name: flow_tiny"), 15, "name: flow_tiny_strict");  // StageRun clears its own folder
    std::ofstream(strict.path()) << t;
    StageRun r2(strict, 1);
    r2.opts.output = r.opts.output;
    auto c = r2.ctx("sample");
    const auto plan = sample.plan(c);
    try {
      sample.run_job(c, plan.jobs[0], c.stage_dir / "jobs" / "rpm2000");
      FAIL() << "expected the unconverged flow to stop the sample stage";
    } catch (const std::runtime_error& e) {
      const std::string m = e.what();
      for (const char* want : {"flow/rpm2000 did not converge", "flow.allow_unconverged: true",
                               "after 30 iterations", "flow.residual_target"})
        EXPECT_NE(m.find(want), std::string::npos) << want << " not in: " << m;
    }
    // The transport stage refuses the field sampled from it (with the
    // override) just as well, before any lump moves.
    TransportStage transport;
    auto ct = r2.ctx("transport");
    try {
      transport.run_job(ct, transport.plan(ct).jobs[0], ct.stage_dir / "jobs" / "rpm2000");
      FAIL() << "expected the unconverged flow to stop the transport stage";
    } catch (const std::runtime_error& e) {
      const std::string m = e.what();
      for (const char* want : {"flow/rpm2000, which did not converge", "flow.allow_unconverged: true",
                               "sample_report.json"})
        EXPECT_NE(m.find(want), std::string::npos) << want << " not in: " << m;
    }
  }
  // Sampling is repeatable: the same case resampled gives bit-identical fields
  // (a threaded probe picked cells on shared faces by thread timing, up to
  // 0.4 m/s apart on this mesh, before the sampler was made sequential).
  const fs::path field = r.opts.output / "sample" / "rpm2000" / "field.h5";
  const auto first = post::read_flow_field(field);
  r.run(sample);
  const auto second = post::read_flow_field(field);
  EXPECT_EQ(first.U, second.U);
  EXPECT_EQ(first.mask, second.mask);
}

TEST(FlowTiny, CompressibleOnTwoRanksMeshRunSample) {
  StageRun r(kData / "tiny_compressible.yaml", 2);
  FlowStage flow;
  SampleStage sample;
  r.run(flow);
  const auto rep = read_json(r.opts.output / "flow" / "rpm2000" / "flow_report.json");
  EXPECT_EQ(rep["solver"], "rhoSimpleFoam");
  EXPECT_EQ(rep["np"], 2);
  EXPECT_TRUE(fs::exists(r.opts.output / "flow" / "rpm2000" / "case" / "processor1"));
  // The energy balance of the openings is reported: temperatures near the
  // gas.temperature of 293.15 K (within 30 K after 30 iterations) and the
  // rise the shaft power would give.
  ASSERT_TRUE(rep.contains("energy_balance")) << rep.dump(2);
  const auto& eb = rep["energy_balance"];
  for (const char* k : {"inlet_T_K", "outlet_T_K"})
    EXPECT_NEAR(eb[k].get<double>(), 293.15, 30.0) << k;
  EXPECT_TRUE(std::isfinite(eb["total_temperature_rise_K"].get<double>()));
  EXPECT_TRUE(std::isfinite(eb["expected_rise_from_shaft_power_K"].get<double>()));
  // The gas's temperature range and the start-up guard (system/fvOptions):
  // limits TRef / 2 and 3 TRef, and the guard does not clip at the end.
  ASSERT_TRUE(rep.contains("temperature_K")) << rep.dump(2);
  const auto& tk = rep["temperature_K"];
  EXPECT_NEAR(tk["guard_limits"][0].get<double>(), 0.5 * 293.15, 1e-9);
  EXPECT_NEAR(tk["guard_limits"][1].get<double>(), 3.0 * 293.15, 1e-9);
  EXPECT_LE(tk["min"].get<double>(), tk["max"].get<double>());
  EXPECT_NEAR(tk["min"].get<double>(), 293.15, 30.0);
  EXPECT_NEAR(tk["max"].get<double>(), 293.15, 30.0);
  EXPECT_FALSE(tk["guard_clipping_at_end"].get<bool>());
  r.run(sample);
  check_outputs(r.opts.output, false, 1.0, 1.4);
  check_half_domain(r.opts.output, 1.0);  // rhoSimpleFoam's phi is kg/s
}

// Second-order momentum started with first-order upwind: two solver runs,
// the second restarting from the first's state, the scheme switched in
// caseParameters; the report's history spans both; the flywheel is meshed
// at flow.rotor_angle (the published STL is the angle-0 flywheel turned by
// 20 deg about the axis, to 1e-9 m).
TEST(FlowTiny, SecondOrderStartsWithFirstOrderAtAFrozenRotorAngle) {
  StageRun r(kData / "tiny_second_order.yaml", 1);
  FlowStage flow;
  r.run(flow);
  const fs::path out = r.opts.output / "flow" / "rpm2000";
  const auto rep = read_json(out / "flow_report.json");
  EXPECT_EQ(rep["iterations"].get<int>(), 30);
  EXPECT_EQ(rep["momentum_scheme"], "upwind for 12 iterations, then linearUpwind");
  EXPECT_EQ(rep["rotor_angle_deg"].get<double>(), 20.0);
  auto last_time = [](const fs::path& log, bool first) {
    std::ifstream in(log);
    std::string l;
    int t = -1;
    while (std::getline(in, l))
      if (l.rfind("Time = ", 0) == 0) {
        t = std::stoi(l.substr(7));
        if (first) return t;
      }
    return t;
  };
  EXPECT_EQ(last_time(out / "case" / "log.simpleFoam.firstOrder", false), 12);
  EXPECT_EQ(last_time(out / "case" / "log.simpleFoam", true), 13);
  std::ifstream cp(out / "case" / "system" / "caseParameters");
  std::stringstream cps;
  cps << cp.rdbuf();
  EXPECT_NE(cps.str().find("divU            bounded Gauss linearUpwind grad(U)"), std::string::npos);
  const auto& h = rep["history_last_tenth"]["mass_flow_inlet_kg_s"];
  EXPECT_EQ(h["to_iteration"].get<double>(), 30.0);
  EXPECT_EQ(h["from_iteration"].get<double>(), 11.0) << "20 values over both runs";
  EXPECT_LE(h["min"].get<double>(), rep["mass_flow_kg_s"]["inlet_in"].get<double>());
  EXPECT_GE(h["max"].get<double>(), rep["mass_flow_kg_s"]["inlet_in"].get<double>());
  EXPECT_EQ(rep["history_last_tenth"]["shaft_torque_Nm"]["to_iteration"].get<double>(), 30.0);

  auto g = geometry::MillGeometry::from_config(r.cfg.doc);
  const auto flat = geometry::flywheel_surface(g);
  const auto meshed = geometry::read_stl(out / "geometry" / "flywheel.stl");
  ASSERT_EQ(meshed.size(), flat.size());
  const double a = 20 * M_PI / 180, c = std::cos(a), sn = std::sin(a);
  for (size_t k = 0; k < flat.size(); k += 7) {
    const double dx = flat[k].a[0] - g.axis_x, dy = flat[k].a[1] - g.axis_height;
    EXPECT_NEAR(meshed[k].a[0], g.axis_x + c * dx - sn * dy, 1e-9);
    EXPECT_NEAR(meshed[k].a[1], g.axis_height + sn * dx + c * dy, 1e-9);
  }
}

// flow.domain = full: today's whole-housing case (no symmetry plane, nothing
// doubled, nothing mirrored), simpleFoam on 2 ranks.
TEST(FlowTiny, FullDomainOnTwoRanksMeshRunSample) {
  StageRun r(kData / "tiny_full.yaml", 2);
  FlowStage flow;
  SampleStage sample;
  r.run(flow);
  const fs::path out = r.opts.output / "flow" / "rpm2000";
  const auto rep = read_json(out / "flow_report.json");
  EXPECT_EQ(rep["domain"], "full");
  EXPECT_EQ(rep["mirrored"], false);
  EXPECT_FALSE(rep.contains("solved_half"));
  EXPECT_DOUBLE_EQ(rep["mass_flow_kg_s"]["inlet_in"].get<double>(),
                   -raw_flux(out / "case", "inletFlow") * 1.2);
  std::ifstream b(out / "case" / "constant" / "polyMesh" / "boundary");
  std::stringstream bs;
  bs << b.rdbuf();
  EXPECT_EQ(bs.str().find("symmetry"), std::string::npos) << "no symmetry plane in the full case";
  EXPECT_EQ(rep["rim"]["z_m"].get<double>(), 0.0);
  r.run(sample);
  check_outputs(r.opts.output, false, 1.2, 1.2);
  EXPECT_EQ(
      read_json(r.opts.output / "sample" / "rpm2000" / "sample_report.json")["mirrored_about_z0"],
      false);
}

TEST(FlowTiny, SampleWithoutFlowSaysWhatIsMissing) {
  StageRun r(kData / "tiny.yaml", 1);
  SampleStage sample;
  auto c = r.ctx("sample");
  const auto plan = sample.plan(c);
  try {
    sample.run_job(c, plan.jobs[0], c.stage_dir / "jobs" / "rpm2000");
    FAIL() << "expected MissingInput";
  } catch (const MissingInput& e) {
    EXPECT_NE(std::string(e.what()).find("--stage flow"), std::string::npos) << e.what();
  }
}

TEST(FlowTiny, CoarseSamplingSpacingNamesTheKey) {
  const test::TempPath yaml("mill_flow_coarse_" + std::to_string(getpid()) + ".yaml");
  {
    std::ifstream in(kData / "tiny.yaml");
    std::stringstream ss;
    ss << in.rdbuf();
    std::string t = ss.str();
    t.replace(t.find("spacing: 0.1"), 12, "spacing: 0.4");
    std::ofstream(yaml.path()) << t;
  }
  // Checked with the case, before any stage runs: file, line, key, limit.
  try {
    config::load_case(yaml, MILL_PROJECT_DIR);
    FAIL() << "expected a spacing error";
  } catch (const config::ConfigError& e) {
    const std::string m = e.what();
    for (const char* s : {".yaml:21: sample.spacing", "half the narrowest housing side (0.25 m of 0.5 m)", "got 0.4 m"})
      EXPECT_NE(m.find(s), std::string::npos) << s << " not in: " << m;
  }
}

TEST(FlowTiny, DivergenceIsAnErrorNamingTheLog) {
  StageRun r(kData / "bad_flow_diverges.yaml", 1);
  FlowStage flow;
  auto c = r.ctx("flow");
  const auto plan = flow.plan(c);
  const fs::path job_dir = c.stage_dir / "jobs" / plan.jobs[0].label;
  fs::create_directories(job_dir);
  try {
    flow.run_job(c, plan.jobs[0], job_dir);
    FAIL() << "expected the flow to diverge";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("diverged"), std::string::npos) << m;
    EXPECT_NE(m.find("log.rhoSimpleFoam"), std::string::npos) << m;
  }
  EXPECT_FALSE(fs::exists(r.opts.output / "flow" / plan.jobs[0].label))
      << "a failed run publishes nothing";
}
