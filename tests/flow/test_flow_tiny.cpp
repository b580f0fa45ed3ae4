// End to end on the tiny mesh: the flow stage meshes and runs a few dozen
// iterations of simpleFoam (1 rank) and rhoSimpleFoam (2 ranks, hierarchical),
// then the sample stage writes field.h5/.vti/.png with the right shape, mask
// and units. Also the user errors of the sample stage.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "engine/runner.h"
#include "postprocess/flow_field_io.h"
#include "progress.h"
#include "stages/flow_stage.h"
#include "stages/sample_stage.h"

namespace fs = std::filesystem;
using namespace mill;

namespace {

const fs::path kData = MILL_FLOW_TEST_DATA;

struct StageRun {
  config::CaseConfig cfg;
  RunOptions opts;
  engine::Runner runner;
  std::ostringstream out;
  Progress progress{out, false};

  StageRun(const fs::path& yaml, int np) : cfg(config::load_case(yaml, MILL_PROJECT_DIR)) {
    opts.np = np;
    opts.output =
        fs::temp_directory_path() / ("mill_flow_" + cfg.name + "_" + std::to_string(getpid()));
    fs::remove_all(opts.output);
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
  EXPECT_NE(r.out.str().find("mass flow"), std::string::npos) << r.out.str();
  // Sampling is repeatable: the same case resampled gives bit-identical fields
  // (a threaded probe picked cells on shared faces by thread timing, up to
  // 0.4 m/s apart on this mesh, before the sampler was made sequential).
  const fs::path field = r.opts.output / "sample" / "rpm2000" / "field.h5";
  const auto first = post::read_flow_field(field);
  r.run(sample);
  const auto second = post::read_flow_field(field);
  EXPECT_EQ(first.U, second.U);
  EXPECT_EQ(first.mask, second.mask);
  fs::remove_all(r.opts.output);
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
  r.run(sample);
  check_outputs(r.opts.output, false, 1.0, 1.4);
  fs::remove_all(r.opts.output);
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
  const fs::path yaml =
      fs::temp_directory_path() / ("mill_flow_coarse_" + std::to_string(getpid()) + ".yaml");
  {
    std::ifstream in(kData / "tiny.yaml");
    std::stringstream ss;
    ss << in.rdbuf();
    std::string t = ss.str();
    t.replace(t.find("spacing: 0.1"), 12, "spacing: 0.4");
    std::ofstream(yaml) << t;
  }
  StageRun r(yaml, 1);
  fs::create_directories(r.opts.output / "flow" / "rpm2000");
  std::ofstream(r.opts.output / "flow" / "rpm2000" / "flow_report.json") << "{}";
  SampleStage sample;
  auto c = r.ctx("sample");
  const auto plan = sample.plan(c);
  try {
    sample.run_job(c, plan.jobs[0], c.stage_dir / "jobs" / "rpm2000");
    FAIL() << "expected a spacing error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sample.spacing"), std::string::npos) << e.what();
  }
  fs::remove_all(r.opts.output);
  fs::remove(yaml);
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
  fs::remove_all(r.opts.output);
}
