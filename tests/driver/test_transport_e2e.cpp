// The transport stage end to end with real LIGGGHTS runs, on a synthetic gas
// field (solid-body rotation plus a downdraft inside a small housing) written
// with write_flow_field where the sample stage would put it, beside a
// sample_report.json that says the flow behind it did not converge (as the
// tiny flow's 30 iterations do not): the stage stops unless the case sets
// flow.allow_unconverged, and records the override.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "e2e_util.h"
#include "postprocess/flow_field_io.h"
#include "postprocess/impact_stats.h"

namespace fs = std::filesystem;

namespace {

using namespace mill::e2e;

constexpr double kPi = 3.14159265358979323846;

// A small mill: 1.2 m housing, 0.5 m flywheel at 2000 rpm, 6 lumps of 30 mm.
const char* kCase = R"(name: tiny_transport
mill:
  housing: {height: 1.2, width: 0.8, depth: 0.3}
  flywheel: {diameter: 0.5, hub_diameter: 0.15, n_plates: 4, plate_width: 0.2, plate_thickness: 0.02, axis_height: 0.45}
  inlet: {center_x: -0.15, size: 0.15}
  outlet: {center_x: 0.0, size: 0.3}
rotor: {rpm: [2000]}
injection: {n_lumps: 6, lump_diameter: 0.03, duration: 0.02, time_limit: 0.2, timestep: 5.0e-6}
transport: {trajectory_interval: 2.0e-3, vtk_interval: 0.05}
ore: {card: sandstone}
resources: {np: 1, jobs: 1}
)";

// What the sample stage writes beside the field of an unconverged flow (the
// keys the transport stage reads).
void write_unconverged_sample_report(const fs::path& file) {
  fs::create_directories(file.parent_path());
  std::ofstream(file) << R"({"rpm": 2000, "flow_converged": false, "flow_domain": "half"})"
                      << "\n";
}

// Solid-body rotation at a tenth of the rotor speed about the rotor axis plus
// a 2 m/s downdraft, inside the housing; no gas inside the hub.
void write_synthetic_field(const fs::path& file) {
  mill::post::FlowField f = tiny_housing_field(
      2000,
      "synthetic: solid-body rotation at 0.1 x rotor speed plus a 2 m/s downdraft "
      "(test_transport_e2e)");
  const double h = f.spacing[0];
  const double omega = 0.1 * 2000 * 2 * kPi / 60, ax = 0.0, ay = 0.45;
  for (int k = 0; k < f.dims[2]; ++k)
    for (int j = 0; j < f.dims[1]; ++j)
      for (int i = 0; i < f.dims[0]; ++i) {
        const size_t p = f.point(i, j, k);
        const double x = f.origin[0] + i * h, y = f.origin[1] + j * h;
        const double rx = x - ax, ry = y - ay;
        const bool gas = std::hypot(rx, ry) > 0.075;
        f.mask[p] = gas ? 1 : 0;
        if (!gas) continue;
        f.U[3 * p + 0] = -omega * ry;
        f.U[3 * p + 1] = omega * rx - 2.0;
        f.rho[p] = 1.2;
      }
  mill::post::write_flow_field(file, f);
}

class TinyTransport : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new mill::test::TempDir(scratch("transport"));
    std::ofstream(*dir_ / "case.yaml") << kCase << "flow: {allow_unconverged: true}\n";
    write_synthetic_field(*dir_ / "run" / "sample" / "rpm2000" / "field.h5");
    write_unconverged_sample_report(*dir_ / "run" / "sample" / "rpm2000" / "sample_report.json");
    status_ = orchestrate("--case " + (*dir_ / "case.yaml").string() +
                              " --stage transport --output " + (*dir_ / "run").string(),
                          *dir_ / "transport.log");
  }
  static void TearDownTestSuite() { delete dir_; }  // removed if every test passed
  static mill::test::TempDir* dir_;
  static int status_;
};
mill::test::TempDir* TinyTransport::dir_ = nullptr;
int TinyTransport::status_ = -1;

TEST_F(TinyTransport, RunsAndWritesEveryOutput) {
  ASSERT_EQ(status_, 0) << slurp(*dir_ / "transport.log");
  const fs::path out = *dir_ / "run" / "transport" / "rpm2000";
  for (const char* f :
       {"impacts.csv", "contact_ends.csv", "transport.h5", "summary.json", "plots/trajectories.png",
        "plots/flywheel_impact_speed.png", "plots/flywheel_normal_speed.png",
        "plots/flywheel_angle.png", "plots/collisions_per_particle.png",
        "plots/flywheel_first_strike_speed.png", "plots/flywheel_rebound_speed_lab.png",
        "plots/strike_to_housing_speed.png", "plots/strike_to_housing_angle.png",
        "plots/strike_to_housing_flight_time.png", "plots/impacts_per_part.png"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  EXPECT_EQ(mill::post::dataset_unit(out / "transport.h5", "impacts/speed"), "m/s");
  EXPECT_EQ(mill::post::dataset_unit(out / "transport.h5", "impacts/angle"), "deg");
  EXPECT_EQ(mill::post::dataset_unit(out / "transport.h5", "trajectories/position"), "m");
  const std::string log = slurp(*dir_ / "transport.log");
  EXPECT_NE(log.find("cross-check: rim speed 52.4 m/s"), std::string::npos) << log;
}

// Lumps fall onto the spinning flywheel: impacts relative to the beaters are
// of the order of the rim speed (52 m/s), and the summary is consistent with
// the impact list.
TEST_F(TinyTransport, ImpactStatisticsArePlausible) {
  ASSERT_EQ(status_, 0);
  const fs::path out = *dir_ / "run" / "transport" / "rpm2000";
  const auto j = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(j.at("n_particles").get<long>(), 6);
  const long nfly = j.at("n_flywheel_impacts").get<long>();
  EXPECT_GE(nfly, 3);
  const double rim = 2000 * 2 * kPi / 60 * 0.25;
  const double v = j.at("flywheel_impact_speed_mean_m_s").get<double>();
  EXPECT_GT(v, 0.2 * rim);
  EXPECT_LT(v, 1.5 * rim);
  // Sliding contacts are counted apart from the impacts; every record names its part.
  const auto rec = mill::post::ReadImpactsCsv((out / "impacts.csv").string());
  long n = 0, sliding = 0, first = 0, later = 0;
  std::map<std::string, long> parts;
  for (const auto& r : rec) {
    EXPECT_NE(r.part, "") << r.time_s;
    EXPECT_NE(r.part, "other") << r.time_s;
    EXPECT_EQ(r.sliding, r.normal_speed_m_s < 1.0) << r.time_s;
    sliding += r.sliding;
    if (r.sliding) continue;
    ++parts[r.part];
    n += r.surface == "flywheel";
    first += r.strike == 1;
    later += r.strike == 2;
  }
  EXPECT_EQ(n, nfly);
  EXPECT_EQ(sliding, j.at("sliding_contacts").get<long>());
  EXPECT_EQ(static_cast<long>(rec.size()), nfly + j.at("n_wall_impacts").get<long>() + sliding);
  EXPECT_EQ(first, j.at("n_flywheel_first_strikes").get<long>());
  EXPECT_EQ(later, j.at("n_flywheel_later_strikes").get<long>());
  EXPECT_LE(first, 6);
  EXPECT_EQ(first + later, nfly);
  for (const auto& [p, c] : parts) EXPECT_EQ(j.at("impacts_per_part").at(p).get<long>(), c) << p;
  // Lumps leave the beaters at up to about twice the rim speed (lab frame).
  const double lab = j.at("flywheel_rebound_speed_lab_mean_m_s").get<double>();
  EXPECT_GT(j.at("n_flywheel_strikes_with_contact_end").get<long>(), 0);
  EXPECT_GT(lab, 0.2 * rim);
  EXPECT_LT(lab, 2.5 * rim);
  const auto ends = mill::post::ReadContactEndsCsv((out / "contact_ends.csv").string());
  EXPECT_GE(ends.size(),
            static_cast<size_t>(j.at("n_flywheel_strikes_with_contact_end").get<long>()));
  for (const char* k :
       {"flywheel_impact_speed_std_m_s", "flywheel_normal_speed_mean_m_s",
        "flywheel_angle_mean_deg", "impacts_per_particle_mean", "first_impact_time_mean_s",
        "flywheel_first_strike_speed_mean_m_s", "flywheel_rebound_speed_lab_std_m_s",
        "strike_to_housing_speed_mean_m_s", "strike_to_housing_speed_std_m_s",
        "strike_to_housing_angle_mean_deg", "strike_to_housing_flight_time_mean_s",
        "n_strike_to_housing", "sliding_threshold_m_s", "n_flywheel_contacts_below_1m_s"})
    EXPECT_TRUE(j.contains(k)) << k;
  std::printf(
      "tiny transport: %ld flywheel impacts (%ld first strikes), %ld sliding; lab rebound %.1f "
      "m/s; %ld strikes reach the housing at %.1f m/s after %.2f ms\n",
      nfly, first, sliding, lab, j.at("n_strike_to_housing").get<long>(),
      j.at("strike_to_housing_speed_mean_m_s").get<double>(),
      1e3 * j.at("strike_to_housing_flight_time_mean_s").get<double>());
}

// The run went on with an unconverged flow because the case said so: the
// summary records it, and the report says so at the top.
TEST_F(TinyTransport, UnconvergedFlowOverrideIsRecorded) {
  ASSERT_EQ(status_, 0);
  const auto j =
      nlohmann::json::parse(slurp(*dir_ / "run" / "transport" / "rpm2000" / "summary.json"));
  EXPECT_EQ(j.at("flow_converged"), false);
  EXPECT_EQ(j.at("flow_allow_unconverged"), true);
  const int st = orchestrate("--case " + (*dir_ / "case.yaml").string() +
                                 " --stage report --output " + (*dir_ / "run").string(),
                             *dir_ / "report.log");
  ASSERT_EQ(st, 0) << slurp(*dir_ / "report.log");
  const std::string page = slurp(*dir_ / "run" / "report" / "index.html");
  EXPECT_NE(page.find("The gas flow did not converge"), std::string::npos);
  EXPECT_NE(page.find("speed of the lumps leaving the beaters"), std::string::npos);
}

// With a feed, each fed class's lumps (its representative size, 26.6 mm here)
// go through the mill in the run of injection.lump_diameter's lumps, the
// sizes taking turns at the inlet; the stage splits the run's records by
// size (IDs renumbered 1..n per size) and gathers the classes' impact
// statistics in transport/feed_classes.{json,csv}.
TEST(TinyTransportFeed, FedClassesShareTheRunAndKeepTheirOwnStatistics) {
  const auto dir = scratch("transport_feed");
  std::ofstream(dir / "case.yaml")
      << kCase << "flow: {allow_unconverged: true}\n"
      << "feed: {sizes_mm: [16, 22.4, 31.5], mass_fractions: [0, 0, 1], rate_tph: 5, "
         "cut_size_mm: 16}\n";
  write_synthetic_field(dir / "run" / "sample" / "rpm2000" / "field.h5");
  write_unconverged_sample_report(dir / "run" / "sample" / "rpm2000" / "sample_report.json");
  const int st = orchestrate("--case " + (dir / "case.yaml").string() +
                                 " --stage transport --output " + (dir / "run").string(),
                             dir / "transport.log");
  ASSERT_EQ(st, 0) << slurp(dir / "transport.log");
  const fs::path t = dir / "run" / "transport";
  // One run for both sizes: 12 lumps, half of each, alternating at the inlet.
  EXPECT_TRUE(fs::is_directory(t / "jobs" / "rpm2000"));
  EXPECT_FALSE(fs::exists(t / "jobs" / "rpm2000_class0"));
  const std::string insert = slurp(t / "jobs" / "rpm2000" / "run" / "insert.in");
  std::vector<std::string> diameters;
  for (size_t at = insert.find("diameter "); at != std::string::npos;
       at = insert.find("diameter ", at + 1))
    diameters.push_back(insert.substr(at + 9, insert.find(' ', at + 9) - at - 9));
  ASSERT_EQ(diameters.size(), 12u) << insert;
  for (size_t i = 0; i < diameters.size(); ++i)
    EXPECT_NEAR(std::stod(diameters[i]), i % 2 ? 1e-3 * std::sqrt(22.4 * 31.5) : 0.03, 1e-9) << i;

  const fs::path c0 = t / "class_0" / "rpm2000", l = t / "rpm2000";
  for (const fs::path& o : {c0, l})
    for (const char* f : {"impacts.csv", "contact_ends.csv", "transport.h5", "summary.json"})
      EXPECT_TRUE(fs::exists(o / f)) << o / f;
  const auto s = nlohmann::json::parse(slurp(c0 / "summary.json"));
  const auto sl = nlohmann::json::parse(slurp(l / "summary.json"));
  EXPECT_EQ(s.at("n_particles").get<long>(), 6);
  EXPECT_EQ(sl.at("n_particles").get<long>(), 6);
  EXPECT_EQ(s.at("feed_class").at("class").get<int>(), 0);
  EXPECT_FALSE(sl.contains("feed_class"));
  EXPECT_NEAR(s.at("feed_class").at("lump_diameter_mm").get<double>(), std::sqrt(22.4 * 31.5),
              1e-9);
  EXPECT_GT(s.at("n_flywheel_impacts").get<long>(), 0) << s.dump(2);
  // Every lump of the run is counted once: exited and not exited per size
  // add up to the run's.
  const auto& run = s.at("shared_run");
  EXPECT_EQ(run.at("n_lumps").get<long>(), 12);
  ASSERT_EQ(run.at("sizes").size(), 2u);
  ASSERT_TRUE(s.at("n_remaining").is_number()) << s.dump(2);
  for (const auto* x : {&s, &sl})
    EXPECT_EQ(x->at("n_exited").get<long>() + x->at("n_remaining").get<long>() +
                  x->at("n_lost_elsewhere").get<long>(),
              6);
  EXPECT_EQ(s.at("n_remaining").get<long>() + sl.at("n_remaining").get<long>(),
            run.at("n_remaining").get<long>());
  EXPECT_EQ(s.at("n_lost_elsewhere").get<long>() + sl.at("n_lost_elsewhere").get<long>(),
            run.at("n_lost_elsewhere").get<long>());
  // The records split by size: IDs within 1..6 per size, and together every
  // record of the run's own files.
  const auto rec0 = mill::post::ReadImpactsCsv((c0 / "impacts.csv").string());
  const auto recl = mill::post::ReadImpactsCsv((l / "impacts.csv").string());
  const auto rec_all =
      mill::post::ReadImpactsCsv((t / "jobs" / "rpm2000" / "run" / "impacts.csv").string());
  EXPECT_EQ(rec0.size() + recl.size(), rec_all.size());
  for (const auto* v : {&rec0, &recl})
    for (const auto& r : *v) {
      EXPECT_GE(r.particle_id, 1);
      EXPECT_LE(r.particle_id, 6);
    }
  // A class record is the run's record of atom 2 k (the class's k-th lump).
  ASSERT_FALSE(rec0.empty());
  bool found = false;
  for (const auto& r : rec_all)
    if (r.particle_id == 2 * rec0.front().particle_id && r.time_s == rec0.front().time_s)
      found = true;
  EXPECT_TRUE(found);
  const auto ends0 = mill::post::ReadContactEndsCsv((c0 / "contact_ends.csv").string());
  const auto endsl = mill::post::ReadContactEndsCsv((l / "contact_ends.csv").string());
  const auto ends_all =
      mill::post::ReadContactEndsCsv((t / "jobs" / "rpm2000" / "run" / "contact_ends.csv").string());
  EXPECT_EQ(ends0.size() + endsl.size(), ends_all.size());

  const auto j = nlohmann::json::parse(slurp(t / "feed_classes.json"));
  ASSERT_EQ(j.at("classes").size(), 3u);
  const auto& k0 = j.at("classes")[0];
  EXPECT_TRUE(k0.at("transport").get<bool>());
  ASSERT_EQ(k0.at("rotor_speeds").size(), 1u);
  EXPECT_EQ(k0.at("rotor_speeds")[0].at("n_flywheel_impacts"), s.at("n_flywheel_impacts"));
  EXPECT_EQ(k0.at("rotor_speeds")[0].at("flywheel_impact_speed_mean_m_s"),
            s.at("flywheel_impact_speed_mean_m_s"));
  for (size_t k : {1u, 2u}) {
    EXPECT_FALSE(j.at("classes")[k].at("transport").get<bool>());
    EXPECT_NE(j.at("classes")[k].at("without_runs").get<std::string>().find("of the feed"),
              std::string::npos);
  }
  const std::string csv = slurp(t / "feed_classes.csv");
  EXPECT_EQ(csv.rfind("rpm,class,lower_mm,upper_mm,lump_diameter_mm,n_particles", 0), 0u) << csv;
  EXPECT_NE(csv.find("\n2000,0,22.4,31.5,26.5631,6,"), std::string::npos) << csv;
}

// With a feed the sizes take turns at the inlet, each over m x
// injection.duration: a time limit that does not outlast that is refused,
// naming the key and the sizes.
TEST(TransportBadInput, SharedInjectionMustEndBeforeTheTimeLimit) {
  const auto dir = scratch("transport_feed_badtime");
  std::string text = kCase;
  const std::string from = "time_limit: 0.2", to = "time_limit: 0.03";
  ASSERT_NE(text.find(from), std::string::npos);
  text.replace(text.find(from), from.size(), to);
  std::ofstream(dir / "case.yaml")
      << text << "feed: {sizes_mm: [16, 22.4, 31.5], mass_fractions: [0, 0, 1], rate_tph: 5, "
                 "cut_size_mm: 16}\n";
  const int st = orchestrate("--case " + (dir / "case.yaml").string() + " --stage transport --output " +
                                 (dir / "run").string(),
                             dir / "log");
  EXPECT_NE(st, 0);
  const std::string log = slurp(dir / "log");
  EXPECT_NE(log.find("injection.time_limit"), std::string::npos) << log;
  EXPECT_NE(log.find("2 x injection.duration = 0.04 s"), std::string::npos) << log;
}

// Without the sample stage's field the stage fails and names the file and the command.
TEST(TransportMissingField, NamesFileAndCommand) {
  const auto dir = scratch("transport_missing");
  std::ofstream(dir / "case.yaml") << kCase;
  const int st = orchestrate("--case " + (dir / "case.yaml").string() +
                                 " --stage transport --output " + (dir / "run").string(),
                             dir / "log");
  EXPECT_NE(st, 0);
  const std::string log = slurp(dir / "log");
  EXPECT_NE(log.find("sample/rpm2000/field.h5"), std::string::npos) << log;
  EXPECT_NE(log.find("--stage sample"), std::string::npos) << log;
}

}  // namespace

namespace {

// A field sampled from an unconverged flow stops the stage when the case does
// not allow it, with a message that names the run, the key and what to do.
TEST(TransportUnconvergedFlow, StopsWithTheMessage) {
  const auto dir = scratch("transport_unconverged");
  std::ofstream(dir / "case.yaml") << kCase;
  write_synthetic_field(dir / "run" / "sample" / "rpm2000" / "field.h5");
  write_unconverged_sample_report(dir / "run" / "sample" / "rpm2000" / "sample_report.json");
  const int st = orchestrate("--case " + (dir / "case.yaml").string() +
                                 " --stage transport --output " + (dir / "run").string(),
                             dir / "log");
  EXPECT_NE(st, 0);
  const std::string log = slurp(dir / "log");
  for (const char* want : {"flow/rpm2000, which did not converge", "flow.allow_unconverged: true",
                           "sample_report.json", "flow.max_iterations"})
    EXPECT_NE(log.find(want), std::string::npos) << want << " not in: " << log;
  EXPECT_FALSE(fs::exists(dir / "run" / "transport" / "rpm2000" / "summary.json"));
}

// A time limit shorter than the injection is refused, naming the key.
TEST(TransportBadInput, TimeLimitBelowDurationNamesKey) {
  const auto dir = scratch("transport_badtime");
  std::string text = kCase;
  text.replace(text.find("time_limit: 0.2"), 15, "time_limit: 0.01");
  std::ofstream(dir / "case.yaml") << text;
  write_synthetic_field(dir / "run" / "sample" / "rpm2000" / "field.h5");
  const int st = orchestrate("--case " + (dir / "case.yaml").string() +
                                 " --stage transport --output " + (dir / "run").string(),
                             dir / "log");
  EXPECT_NE(st, 0);
  const std::string log = slurp(dir / "log");
  EXPECT_NE(log.find("injection.time_limit"), std::string::npos) << log;
}

}  // namespace
