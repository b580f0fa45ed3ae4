// In-mill breakage end to end on the tiny mill with a 40-element lump:
// stage 1's impacts are written by hand (one lump the beater strikes, one
// flying above the rotor into the housing wall); the campaign is killed
// while the second in-mill run is going, and resumed. Then: the struck lump
// broke at the strike, the other only against the housing (and the record
// says none broke at the strike), element mass is conserved, and
// product.json and in_mill.csv hold the in-mill product. The early stop
// (breakage.in_mill.early_stop, on by default): the lump that flies past the
// rotor into the housing stops at the end of the first chunk after it has
// reached the housing, well before the 8 ms; the struck lump's fragments are
// still in the rotor region at 8 ms (they are struck again and again for
// over 30 ms on this small mill), so it runs to the end. The animation
// (breakage.in_mill.animate, on by default): the first run of the plan
// writes 60 frames over its 8 ms, drawn into breakage/animation/ and shown
// in the report; the lump moves between its first and last frame.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "e2e_util.h"
#include "postprocess/breakage_results.h"
#include "postprocess/flow_field_io.h"
#include "postprocess/lammps_dump.h"

namespace fs = std::filesystem;

namespace {

using namespace mill::e2e;
using mill::jobs::State;

const std::string kData = MILL_TEST_DATA;
constexpr double kPi = 3.14159265358979323846;

// One impacts.csv row of the tiny mill at 2000 rpm (tiny_strike_row).
std::string row(int id, double t, std::array<double, 3> x, std::array<double, 3> v,
                std::array<double, 3> c, std::array<double, 3> n) {
  return tiny_strike_row(2000, id, t, x, v, c, n);
}

// Lump 1: falling at 5 m/s onto plate 0's leading face, which points up at
// t = (pi/2) / omega. Lump 2: flying at 60 m/s well above the rotor (tip at
// y = 0.70 m) towards the housing wall at x = 0.4 m.
void write_transport_impacts(const fs::path& run) {
  fs::create_directories(run / "transport/rpm2000");
  const double t = 0.5 * kPi / (2000 * 2 * kPi / 60);
  spit(run / "transport/rpm2000/impacts.csv",
       std::string(kImpactsCsvHeader) +
           row(1, t, {-0.021, 0.62, 0}, {0, -5, 0}, {-0.01, 0.62, 0}, {-1, 0, 0}) +
           row(2, t, {0.2, 0.95, 0}, {60, 0, 0}, {0.2, 0.94, 0}, {0, 1, 0}));
}

// The snapshots of a `dump custom` text file: per snapshot, the mean x and
// y of its elements (the columns named in its ITEM: ATOMS line).
std::vector<std::array<double, 2>> dump_centroids(const fs::path& f) {
  std::istringstream in(slurp(f));
  std::vector<std::array<double, 2>> out;
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("ITEM: NUMBER OF ATOMS", 0) != 0) continue;
    std::getline(in, line);
    const long n = std::stol(line);
    while (std::getline(in, line) && line.rfind("ITEM: ATOMS", 0) != 0) {
    }
    std::istringstream head(line.substr(12));
    std::vector<std::string> names;
    for (std::string w; head >> w;) names.push_back(w);
    const auto col = [&](const char* c) {
      return std::find(names.begin(), names.end(), c) - names.begin();
    };
    const long ix = col("x"), iy = col("y");
    std::array<double, 2> c{0, 0};
    for (long k = 0; k < n && std::getline(in, line); ++k) {
      std::istringstream row(line);
      std::vector<double> v;
      for (double x; row >> x;) v.push_back(x);
      c[0] += v.at(ix) / n;
      c[1] += v.at(iy) / n;
    }
    out.push_back(c);
  }
  return out;
}

// Mass of the elements of a LIGGGHTS granular data file (id type diameter density x y z).
double data_file_mass(const fs::path& f) {
  std::istringstream in(slurp(f));
  std::string line;
  bool atoms = false;
  double m = 0;
  while (std::getline(in, line)) {
    if (line.rfind("Atoms", 0) == 0) {
      atoms = true;
      continue;
    }
    if (atoms && (line.rfind("Velocities", 0) == 0 || line.rfind("Bonds", 0) == 0)) break;
    std::istringstream ls(line);
    double id, type, d, rho;
    if (atoms && (ls >> id >> type >> d >> rho)) m += rho * kPi / 6 * d * d * d;
  }
  return m;
}

TEST(InMill, StruckLumpBreaksUnreachableOneOnlyOnTheHousingAndARunResumesAfterAKill) {
  const auto dir = scratch("in_mill");
  write_transport_impacts(dir);
  const std::string yaml = kData + "/tiny_in_mill.yaml";
  ASSERT_EQ(
      orchestrate("--case " + yaml + " --stage breakage --list-tasks --output " + dir.string(),
                  dir / "tasks.log"),
      0)
      << slurp(dir / "tasks.log");
  for (const char* l : {"rpm2000_mill_p1", "rpm2000_mill_p2"})
    EXPECT_NE(slurp(dir / "tasks.log").find(l), std::string::npos) << slurp(dir / "tasks.log");

  // Killed while the second in-mill run is going.
  const std::vector<std::string> args = {"--case", yaml, "--stage",  "breakage",
                                         "--jobs", "1",  "--output", dir.string()};
  const pid_t pid = spawn_orchestrate(args, dir / "killed.log");
  const fs::path stage = dir / "breakage";
  const bool ready = wait_for(
      [&] {
        return job_state(stage, "rpm2000_mill_p1") == State::Done &&
               job_state(stage, "rpm2000_mill_p2") == State::Running;
      },
      600);
  if (!ready) kill(pid, SIGKILL);
  ASSERT_TRUE(ready) << slurp(dir / "killed.log");
  kill(pid, SIGTERM);
  EXPECT_EQ(finish(pid), 128 + SIGTERM) << slurp(dir / "killed.log");
  EXPECT_EQ(job_state(stage, "rpm2000_mill_p2"), State::Failed);
  EXPECT_FALSE(fs::exists(stage / "jobs/rpm2000_mill_p2/in_mill.json"));
  const auto t_first = fs::last_write_time(stage / "jobs/rpm2000_mill_p1/STATUS");
  std::string line;
  for (const auto& a : args) line += "'" + a + "' ";
  ASSERT_EQ(orchestrate(line, dir / "resumed.log"), 0) << slurp(dir / "resumed.log");
  EXPECT_EQ(fs::last_write_time(stage / "jobs/rpm2000_mill_p1/STATUS"), t_first)
      << "the finished run was redone";
  EXPECT_NE(slurp(dir / "resumed.log").find("2 already done"), std::string::npos)
      << slurp(dir / "resumed.log");

  // The struck lump: the beater broke it.
  const auto struck = nlohmann::json::parse(slurp(stage / "jobs/rpm2000_mill_p1/in_mill.json"));
  EXPECT_GT(struck.at("flywheel").at("contacts").get<long>(), 0) << struck.dump(2);
  EXPECT_GT(struck.at("bonds_broken_at_strike").get<long>(), 0) << struck.dump(2);
  EXPECT_LT(struck.at("largest_mass_fraction").get<double>(), 1.0) << struck.dump(2);
  // The unreachable lump: no beater contact, nothing broken at a strike.
  const auto missed = nlohmann::json::parse(slurp(stage / "jobs/rpm2000_mill_p2/in_mill.json"));
  EXPECT_EQ(missed.at("flywheel").at("contacts").get<long>(), 0) << missed.dump(2);
  EXPECT_EQ(missed.at("bonds_broken_at_strike").get<long>(), 0) << missed.dump(2);
  EXPECT_GT(missed.at("housing").at("contacts").get<long>(), 0) << missed.dump(2);
  // The free flight (breakage.in_mill.skip_free_flight, on by default): the
  // lump flying above the rotor has no surface within reach over the whole
  // lead time (2 ms), which is skipped whole; the struck lump is the animated
  // run (the first of the plan), which keeps its lead time.
  EXPECT_DOUBLE_EQ(missed.at("start").at("free_flight_skipped_s").get<double>(), 2.0e-3)
      << missed.dump(2);
  EXPECT_EQ(struck.at("start").at("free_flight_skipped_s").get<double>(), 0.0) << struck.dump(2);
  // The early stop: each run says when and why it stopped.
  const auto& gone = missed.at("stop");
  EXPECT_EQ(gone.at("reason").get<std::string>(), "work_done") << missed.dump(2);
  EXPECT_TRUE(gone.at("early_stop").get<bool>());
  EXPECT_LT(gone.at("time_s").get<double>(), 8.0e-3 - 2.5e-4) << missed.dump(2);
  EXPECT_GT(gone.at("time_s").get<double>(), missed.at("first_housing_contact_s").get<double>())
      << missed.dump(2);
  EXPECT_EQ(missed.at("mass_places").at("rotor").get<double>(), 0.0) << missed.dump(2);
  const auto& busy = struck.at("stop");
  EXPECT_EQ(busy.at("reason").get<std::string>(), "t_end") << struck.dump(2);
  EXPECT_GE(busy.at("time_s").get<double>(), 8.0e-3 - 1e-9) << struck.dump(2);
  EXPECT_GT(struck.at("mass_places").at("rotor").get<double>(), 0.0) << struck.dump(2);
  for (const char* l : {"rpm2000_mill_p1", "rpm2000_mill_p2"}) {
    const std::string log = slurp(stage / "jobs" / l / "run/liggghts.log");
    EXPECT_NE(log.find("in_mill: stopped at t = "), std::string::npos) << l;
  }
  // The energy ledger of each run: the struck lump's broken bonds took part of
  // the energy given (the rotor's work included); the balance closes.
  EXPECT_GT(struck.at("energy").at("comminution_efficiency").get<double>(), 0.0) << struck.dump(2);
  EXPECT_GT(struck.at("energy").at("work_other_J").get<double>(), 0.0) << struck.dump(2);
  // Its parts (fix energy/work): the walls' and gravity's work add up to the
  // other work (the bond forces between are booked by the ledger, not by the
  // parts): 1e-6 of the energy. The beater gave energy; the resting housing
  // (walls - beater) only took it, to 1e-3 of the energy (the beater's work
  // comes from the torque on the mesh, a trapezoid without Verlet's end term).
  EXPECT_GT(struck.at("energy").at("work_beater_J").get<double>(), 0.0) << struck.dump(2);
  EXPECT_EQ(missed.at("energy").at("work_beater_J").get<double>(), 0.0) << missed.dump(2);
  for (const auto& j : {struck, missed}) {
    const auto& e = j.at("energy");
    const double walls = e.at("work_walls_J").get<double>();
    const double scale =
        e.at("input_J").get<double>() + std::abs(e.at("work_other_J").get<double>());
    EXPECT_LE(walls - e.at("work_beater_J").get<double>(), 1e-3 * scale) << j.dump(2);
    EXPECT_NEAR(walls + e.at("work_gravity_J").get<double>(), e.at("work_other_J").get<double>(),
                1e-6 * scale)
        << j.dump(2);
  }
  for (const auto& j : {struck, missed}) {
    EXPECT_LT(std::abs(j.at("energy").at("residual_fraction").get<double>()), 0.01) << j.dump(2);
    EXPECT_FALSE(j.at("energy").contains("energy_per_new_surface_J_m2"));  // impacts only
  }

  // Element mass is conserved over the fragments.
  for (const char* l : {"rpm2000_mill_p1", "rpm2000_mill_p2"}) {
    const fs::path jd = stage / "jobs" / l;
    const auto j = nlohmann::json::parse(slurp(jd / "in_mill.json"));
    const fs::path lump_file =
        mill::jobs::JobStore(stage / "lumps").job_dir(j.at("lump").at("label").get<std::string>()) /
        "lump.data";
    ASSERT_TRUE(fs::exists(lump_file)) << lump_file;
    const double m0 = data_file_mass(lump_file);
    // The data file and the dump carry about 7 significant digits.
    EXPECT_NEAR(j.at("element_mass_kg").get<double>(), m0, 1e-6 * m0) << l;
    double sum = 0;
    for (const auto& f : mill::post::ReadFractionsCsv((jd / "fractions.csv").string()))
      sum += f.mass_fraction;
    EXPECT_NEAR(sum, 1.0, 1e-9) << l;
    const auto& places = j.at("mass_places");
    EXPECT_NEAR(places.at("rotor").get<double>() + places.at("housing").get<double>() +
                    places.at("outlet").get<double>() + places.at("inlet").get<double>(),
                1.0, 1e-9)
        << l;
  }

  // The product: the single impact's entries and the in-mill object.
  const auto product = nlohmann::json::parse(slurp(stage / "product.json"));
  ASSERT_EQ(product.size(), 1u);
  const auto& m = product[0].at("in_mill");
  EXPECT_EQ(m.at("lumps").get<int>(), 2);
  for (const char* k :
       {"fully_shredded_mass_fraction", "largest_piece_mass_fraction", "t10_percent",
        "t10_resolved", "bonds_broken_at_strike_fraction", "passing_percent"})
    EXPECT_TRUE(m.contains(k)) << k;
  EXPECT_TRUE(product[0].contains("fully_shredded_mass_fraction"));
  std::istringstream csv(slurp(stage / "in_mill.csv"));
  int rows = 0;
  while (std::getline(csv, line)) ++rows;
  EXPECT_EQ(rows, 3);  // header and two runs
  const std::string table = slurp(stage / "in_mill.csv");
  EXPECT_NE(table.find(",stop_time_s,stop_reason\n"), std::string::npos) << table;
  EXPECT_NE(table.find(",work_done\n"), std::string::npos) << table;
  EXPECT_NE(table.find(",t_end\n"), std::string::npos) << table;

  // The animation: only the first run of the plan writes frames, 60 over
  // its duration (fewer when it stops early), one every 8 ms / 60 rounded up
  // to whole steps; the GIF holds them all, and the lump moved.
  const std::string tasks = slurp(dir / "tasks.log");
  const std::string first = tasks.find("rpm2000_mill_p1") < tasks.find("rpm2000_mill_p2")
                                ? "rpm2000_mill_p1"
                                : "rpm2000_mill_p2";
  const std::string other = first == "rpm2000_mill_p1" ? "rpm2000_mill_p2" : "rpm2000_mill_p1";
  EXPECT_NE(tasks.find("animated (60 frames)"), std::string::npos) << tasks;
  EXPECT_FALSE(fs::exists(stage / "jobs" / other / "run/frames.dump")) << other;
  const auto anim = nlohmann::json::parse(slurp(stage / "animation/animation.json"));
  const auto run = nlohmann::json::parse(slurp(stage / "jobs" / first / "in_mill.json"));
  EXPECT_EQ(anim.at("job").get<std::string>(), first);
  const double every_ms = anim.at("frame_interval_ms").get<double>();
  EXPECT_GE(every_ms, 8.0 / 60 - 1e-9) << anim.dump(2);
  EXPECT_LT(every_ms, 8.0 / 60 * 1.05) << anim.dump(2);
  const double stop_ms = 1e3 * run.at("stop").at("time_s").get<double>();
  const int frames = anim.at("frames").get<int>();
  EXPECT_EQ(frames, static_cast<int>(std::floor(stop_ms / every_ms + 1e-6)) + 1)
      << "stopped at " << stop_ms << " ms; " << anim.dump(2);
  if (run.at("stop").at("reason") == "t_end") {
    EXPECT_GE(frames, 60) << anim.dump(2);
    EXPECT_LE(frames, 61) << anim.dump(2);
  }
  const auto centroids = dump_centroids(stage / "jobs" / first / "run/frames.dump");
  ASSERT_EQ(static_cast<int>(centroids.size()), frames);
  EXPECT_NEAR(anim.at("centroid_first_m")[0].get<double>(), centroids.front()[0], 1e-6);
  EXPECT_NEAR(anim.at("centroid_last_m")[1].get<double>(), centroids.back()[1], 1e-6);
  const double moved = std::hypot(centroids.back()[0] - centroids.front()[0],
                                  centroids.back()[1] - centroids.front()[1]);
  EXPECT_GT(moved, 0.02) << "the lump's centroid moved " << moved << " m (one lump diameter: 0.02)";
  EXPECT_GT(anim.at("first_last_pixel_difference").get<double>(), 0.5) << anim.dump(2);
  const std::string n_frames =
      "/usr/bin/python3 -c 'import sys; from PIL import Image; "
      "print(Image.open(sys.argv[1]).n_frames)' " +
      (stage / "animation/animation.gif").string() + " > " + (dir / "gif_frames.txt").string();
  ASSERT_EQ(std::system(n_frames.c_str()), 0);
  EXPECT_EQ(std::stoi(slurp(dir / "gif_frames.txt")), frames);
  EXPECT_LT(fs::file_size(stage / "animation/animation.gif"), 5u << 20);
  for (const char* s : {"animation_first.png", "animation_middle.png", "animation_last.png"})
    EXPECT_EQ(slurp(stage / "animation" / s), slurp(stage / "jobs" / first / "animation" / s)) << s;

  // The report's headline has the in-mill row beside the single impact's,
  // and the breakage section shows the animation with its caption.
  ASSERT_EQ(orchestrate("--case " + yaml + " --stage report --output " + dir.string(),
                        dir / "report.log"),
            0)
      << slurp(dir / "report.log");
  const std::string page = slurp(dir / "report/index.html");
  EXPECT_NE(page.find("in the mill (2 lumps, strike and housing impacts), 2000 rpm"),
            std::string::npos);
  EXPECT_NE(page.find("<h3>One lump in the mill</h3>"), std::string::npos);
  EXPECT_NE(page.find("src=\"data:image/gif;base64,R0lGOD"), std::string::npos);  // "GIF8"
  const std::string caption =
      fmt::format("Lump {} at 2000 rpm ({}): t = 0 is 2 ms before its first flywheel strike",
                  run.at("start").at("particle_id").get<long long>(), first);
  EXPECT_NE(page.find(caption), std::string::npos) << caption;
  EXPECT_NE(page.find(fmt::format("{} frames from t = 0.00 to {:.2f} ms", frames,
                                  anim.at("time_last_ms").get<double>())),
            std::string::npos);
  for (const char* s : {"first frame, t = 0.00 ms", "middle frame, t = ", "last frame, t = "})
    EXPECT_NE(page.find(s), std::string::npos) << s;
  const auto summary = nlohmann::json::parse(slurp(dir / "report/summary.json"));
  EXPECT_EQ(summary.at("in_mill_animation").at("frames").get<int>(), frames);
}

// breakage.in_mill.animate: false: no run writes frames, and every in-mill
// job keeps the id it has with the animation on, but the animated one.
TEST(InMill, AnimationOffWritesNoFramesAndKeepsTheOtherJobIds) {
  const auto dir = scratch("in_mill_no_animation");
  write_transport_impacts(dir);
  std::string yaml = slurp(kData + "/tiny_in_mill.yaml");
  const std::string from = "gas: false}";
  ASSERT_NE(yaml.find(from), std::string::npos);
  spit(dir / "on.yaml", yaml);
  yaml.replace(yaml.find(from), from.size(), "gas: false, animate: false}");
  spit(dir / "off.yaml", yaml);
  std::map<std::string, std::string> ids[2];
  for (int k = 0; k < 2; ++k) {
    const fs::path log = dir / (k ? "off.log" : "on.log");
    ASSERT_EQ(orchestrate("--case " + (dir / (k ? "off.yaml" : "on.yaml")).string() +
                              " --stage breakage --dry-run --output " + dir.string(),
                          log),
              0)
        << slurp(log);
    std::istringstream in(slurp(log));
    for (std::string line; std::getline(in, line);) {
      const auto at = line.rfind(", id ");
      if (at == std::string::npos) continue;
      std::istringstream w(line.substr(line.find(']') + 1));
      std::string index, label;
      w >> index >> label;
      ids[k][label] = line.substr(at + 5, line.find(')', at) - at - 5);
    }
  }
  ASSERT_TRUE(ids[0].count("rpm2000_mill_p1") && ids[0].count("rpm2000_mill_p2"))
      << slurp(dir / "on.log");
  int differ = 0;
  for (const auto& [label, id] : ids[0]) {
    ASSERT_TRUE(ids[1].count(label)) << label;
    differ += id != ids[1][label];
  }
  EXPECT_EQ(differ, 1) << slurp(dir / "on.log") << slurp(dir / "off.log");
  EXPECT_EQ(slurp(dir / "off.log").find("animated"), std::string::npos) << slurp(dir / "off.log");
}

// The struck lump's free flight skipped (breakage.in_mill.skip_free_flight)
// and simulated: the engine run starts later, with the lump's bounding sphere
// at least half its radius from the mill, on the ballistic path (closed
// form); its first flywheel contact comes at the same time on the job's
// clock, to two steps (the flight between is exact but for round-off in
// both runs), after the deck's start.
TEST(InMill, FreeFlightSkippedMeetsTheBeaterWhenTheFullLeadTimeDoes) {
  const auto dir = scratch("in_mill_free_flight");
  std::string yaml = slurp(kData + "/tiny_in_mill.yaml");
  const std::string from = "duration: 8.0e-3, lead_time: 2.0e-3, gas: false}";
  ASSERT_NE(yaml.find(from), std::string::npos);
  nlohmann::json runs[2];
  for (int skip = 0; skip < 2; ++skip) {
    const fs::path run = dir / (skip ? "skip" : "full");
    write_transport_impacts(run);
    std::string y = yaml;
    y.replace(y.find(from), from.size(),
              std::string("duration: 3.0e-3, lead_time: 2.0e-3, gas: false, animate: false, "
                          "skip_free_flight: ") +
                  (skip ? "true}" : "false}"));
    spit(run / "case.yaml", y);
    ASSERT_EQ(orchestrate("--case " + (run / "case.yaml").string() +
                              " --stage breakage --task 1 --output " + run.string(),
                          run / "run.log"),
              0)
        << slurp(run / "run.log");
    runs[skip] = nlohmann::json::parse(slurp(run / "breakage/jobs/rpm2000_mill_p1/in_mill.json"));
  }
  const auto& full = runs[0];
  const auto& skip = runs[1];
  EXPECT_EQ(full.at("start").at("free_flight_skipped_s").get<double>(), 0.0) << full.dump(2);
  const auto& s = skip.at("start");
  const double t = s.at("free_flight_skipped_s").get<double>();
  EXPECT_GT(t, 1.0e-3) << skip.dump(2);
  EXPECT_LT(t, 2.0e-3) << skip.dump(2);
  const double r = 0.5 * skip.at("lump").at("outer_diameter_m").get<double>();
  EXPECT_GE(s.at("deck_start").at("gap_to_mill_m").get<double>(), 0.5 * r) << skip.dump(2);
  const auto& x0 = s.at("position_m");
  const auto& v0 = s.at("velocity_m_s");
  EXPECT_NEAR(s.at("deck_start").at("position_m")[1].get<double>(),
              x0[1].get<double>() + v0[1].get<double>() * t - 0.5 * 9.81 * t * t, 1e-12);
  EXPECT_NEAR(s.at("deck_start").at("velocity_m_s")[1].get<double>(),
              v0[1].get<double>() - 9.81 * t, 1e-12);
  EXPECT_NEAR(s.at("deck_start").at("rotor_angle_deg").get<double>(),
              s.at("rotor_angle_deg").get<double>() + 2000 * 2 * kPi / 60 * t * 180 / kPi, 1e-9);
  const double first_full = full.at("first_flywheel_contact_s").get<double>();
  const double first_skip = skip.at("first_flywheel_contact_s").get<double>();
  EXPECT_GT(first_skip, t) << skip.dump(2);
  const std::string log = slurp(dir / "skip/breakage/jobs/rpm2000_mill_p1/run/liggghts.log");
  const auto at = log.find("in_mill: dt ");
  ASSERT_NE(at, std::string::npos);
  const double dt = std::stod(log.substr(at + 12));
  EXPECT_NEAR(first_skip, first_full, 2 * dt) << full.dump(2) << skip.dump(2);
  // Both ran to the same end on the job's clock (3 ms, to a 0.25 ms chunk).
  EXPECT_GE(skip.at("stop").at("time_s").get<double>(), 3.0e-3 - 1e-9) << skip.dump(2);
  EXPECT_LT(skip.at("stop").at("time_s").get<double>(), 3.0e-3 + 2.5e-4) << skip.dump(2);
}

// With gas: still air of 1.2 kg/m3 over the tiny housing (a field where the
// sample stage puts it); the run takes the drag and says so. One lump of the
// two is chosen: the one of the median strike normal speed, lump 2 (41.9 m/s
// against 35.7), the one the beater cannot reach. With the early stop off
// it runs its whole 4 ms, and its record says so; with the free flight
// simulated (skip_free_flight false) the drag acts over all of it.
TEST(InMill, GasDragFromTheSampledField) {
  const auto dir = scratch("in_mill_gas");
  write_transport_impacts(dir);
  mill::post::FlowField f = tiny_housing_field(2000, "synthetic: still air (test_in_mill_e2e)");
  for (size_t p = 0; p < f.mask.size(); ++p) {
    f.mask[p] = 1;
    f.rho[p] = 1.2;
  }
  mill::post::write_flow_field(dir / "sample/rpm2000/field.h5", f);
  std::string yaml = slurp(kData + "/tiny_in_mill.yaml");
  const std::string from = "in_mill: {lumps: 2, duration: 8.0e-3, lead_time: 2.0e-3, gas: false}";
  ASSERT_NE(yaml.find(from), std::string::npos);
  yaml.replace(yaml.find(from), from.size(),
               "in_mill: {lumps: 1, duration: 4.0e-3, lead_time: 2.0e-3, gas: true, "
               "early_stop: false, skip_free_flight: false}");
  spit(dir / "case.yaml", yaml);
  ASSERT_EQ(orchestrate("--case " + (dir / "case.yaml").string() + " --stage breakage --output " +
                            dir.string(),
                        dir / "run.log"),
            0)
      << slurp(dir / "run.log");
  const auto j = nlohmann::json::parse(slurp(dir / "breakage/jobs/rpm2000_mill_p2/in_mill.json"));
  EXPECT_TRUE(j.at("gas").get<bool>());
  EXPECT_FALSE(j.at("stop").at("early_stop").get<bool>()) << j.dump(2);
  EXPECT_EQ(j.at("stop").at("reason").get<std::string>(), "t_end") << j.dump(2);
  EXPECT_GE(j.at("stop").at("time_s").get<double>(), 4.0e-3 - 1e-9) << j.dump(2);
  EXPECT_EQ(j.at("bonds_broken_at_strike").get<long>(), 0) << j.dump(2);
  EXPECT_EQ(j.at("start").at("free_flight_skipped_s").get<double>(), 0.0) << j.dump(2);
  EXPECT_EQ(j.at("start").at("deck_start").at("position_m"), j.at("start").at("position_m"));
  // Still air only takes energy from the lump, and it took some.
  EXPECT_LT(j.at("energy").at("work_gas_J").get<double>(), 0.0) << j.dump(2);
  EXPECT_NE(
      slurp(dir / "breakage/jobs/rpm2000_mill_p2/run/liggghts.log").find("in_mill: gas drag from"),
      std::string::npos);
}

// With gas but no sampled field the in-mill run fails and says what makes it.
TEST(InMill, MissingFieldNamesFileCommandAndKey) {
  const auto dir = scratch("in_mill_nofield");
  write_transport_impacts(dir);
  std::string yaml = slurp(kData + "/tiny_in_mill.yaml");
  const std::string from = "gas: false}";
  ASSERT_NE(yaml.find(from), std::string::npos);
  yaml.replace(yaml.find(from), from.size(), "gas: true}");
  spit(dir / "case.yaml", yaml);
  const int st = orchestrate("--case " + (dir / "case.yaml").string() +
                                 " --stage breakage --task 1 --output " + dir.string(),
                             dir / "log");
  EXPECT_NE(st, 0);
  const std::string log = slurp(dir / "log");
  EXPECT_NE(log.find("sample/rpm2000/field.h5"), std::string::npos) << log;
  EXPECT_NE(log.find("--stage sample"), std::string::npos) << log;
  EXPECT_NE(log.find("breakage.in_mill.gas: false"), std::string::npos) << log;
}

}  // namespace
