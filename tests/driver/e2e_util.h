// Helpers shared by the end-to-end tests that run the real `orchestrate`
// (with the project's liggghts-mill): scratch folders, running and spawning
// the program, reading files and job states, the tiny housing's gas field.
#pragma once

#include <fmt/format.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "jobs/job_store.h"
#include "postprocess/flow_field_io.h"
#include "temp_dir.h"

namespace mill::e2e {

namespace fs = std::filesystem;

// An empty folder under the temp dir, unique to this process: removed when
// the test (or, made in SetUpTestSuite, the suite) passes, kept if it fails.
inline test::TempDir scratch(const std::string& name) {
  return test::TempDir("mill_e2e_" + name + "_" + std::to_string(getpid()));
}

inline std::string slurp(const fs::path& f) {
  std::ifstream in(f);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

inline void spit(const fs::path& f, const std::string& text) {
  std::ofstream o(f);
  o << text;
}

// Runs orchestrate to completion (in `cwd` if given); returns its exit
// status, its output in `log`.
inline int orchestrate(const std::string& args, const fs::path& log, const fs::path& cwd = {}) {
  std::string cmd;
  if (!cwd.empty()) cmd = "cd '" + cwd.string() + "' && ";
  cmd += "MILL_LIGGGHTS='" + std::string(LIGGGHTS_MILL_EXE) + "' '" + ORCHESTRATE_EXE + "' " + args + " > '" +
         log.string() + "' 2>&1";
  const int st = std::system(cmd.c_str());
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

// Starts orchestrate with `args` (one per element) in the background (in
// `cwd` if given), output in `log`; returns its pid (reap it with finish()).
inline pid_t spawn_orchestrate(const std::vector<std::string>& args, const fs::path& log, const fs::path& cwd = {}) {
  const pid_t pid = fork();
  if (pid == 0) {
    if (!cwd.empty() && chdir(cwd.c_str()) != 0) _exit(126);
    setenv("MILL_LIGGGHTS", LIGGGHTS_MILL_EXE, 1);
    if (!freopen(log.c_str(), "w", stdout) || !freopen(log.c_str(), "a", stderr)) _exit(126);
    std::vector<char*> argv{const_cast<char*>(ORCHESTRATE_EXE)};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(ORCHESTRATE_EXE, argv.data());
    _exit(127);
  }
  return pid;
}

// Waits for `pid`; its exit status, 128+N if killed by signal N.
inline int finish(pid_t pid) {
  int st = 0;
  waitpid(pid, &st, 0);
  return WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
}

// Polls `ready` every 100 ms for at most `seconds`; true once it holds.
inline bool wait_for(const std::function<bool()>& ready, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (ready()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return ready();
}

// The scratch folder (mill_e2e_*, right under the temp dir) that holds the
// path `link` points at, a run kept by an earlier keep_run, is removed
// unless it is `now`'s.
inline void remove_kept_scratch(const fs::path& link, const test::TempPath& now) {
  std::error_code ec;
  if (!fs::is_symlink(link, ec)) return;
  const fs::path target = fs::read_symlink(link, ec);
  if (ec) return;
  const fs::path tmp = fs::temp_directory_path();
  for (fs::path p = target; p.has_relative_path(); p = p.parent_path()) {
    if (!fs::equivalent(p.parent_path(), tmp, ec)) continue;
    if (p.filename().string().rfind("mill_e2e_", 0) == 0 && !fs::equivalent(p, now.path(), ec))
      fs::remove_all(p, ec);
    return;
  }
}

// Leaves the finished run folder `run`, in the scratch folder `dir`, for
// later tests (CTest fixtures): when $MILL_E2E_KEEP_RUN is set, a symlink of
// that name points at `run` and `dir` is kept; the scratch folder of the run
// the link pointed at before is removed.
inline void keep_run(const fs::path& run, test::TempPath& dir) {
  const char* keep = std::getenv("MILL_E2E_KEEP_RUN");
  if (!keep || !*keep) return;
  const fs::path link(keep);
  fs::create_directories(link.parent_path());
  remove_kept_scratch(link, dir);
  fs::remove_all(link);
  fs::create_directory_symlink(fs::absolute(run), link);
  dir.keep();
}

// A gas field on the grid over the tiny mill's housing (x -0.4..0.4, y 0..1.2,
// z -0.15..0.15 m, 50 mm spacing) for the rotor at `rpm`, incompressible:
// U, rho and mask allocated and 0 (no gas) for the test to fill.
inline post::FlowField tiny_housing_field(double rpm, const std::string& source) {
  post::FlowField f;
  const double h = 0.05;
  f.origin = {-0.4, 0.0, -0.15};
  f.spacing = {h, h, h};
  f.dims = {17, 25, 7};
  f.allocate(false);
  f.rpm = rpm;
  f.gas_model = "incompressible";
  f.source = source;
  return f;
}

// The header of a transport stage's impacts.csv.
inline const char* kImpactsCsvHeader =
    "time_s,particle_id,surface,x_m,y_m,z_m,contact_x_m,contact_y_m,contact_z_m,normal_x,normal_y,"
    "normal_z,vrel_x_m_s,vrel_y_m_s,vrel_z_m_s,speed_m_s,normal_speed_m_s,tangential_speed_m_s,"
    "angle_deg,surface_speed_m_s,particle_speed_m_s,axis_distance_m\n";

// One impacts.csv row of a flywheel strike in the tiny mill (axis at (0,
// 0.45) m) turning at `rpm`: lump `id` at `x`, lab velocity `v`, contact
// point `c` on the flywheel, normal `n`; the relative velocity, speeds and
// angle follow from them.
inline std::string tiny_strike_row(double rpm, int id, double t, std::array<double, 3> x,
                                   std::array<double, 3> v, std::array<double, 3> c,
                                   std::array<double, 3> n) {
  const double pi = 3.14159265358979323846;
  const double w = rpm * 2 * pi / 60;
  const double rx = c[0], ry = c[1] - 0.45;
  const std::array<double, 3> vr = {v[0] + w * ry, v[1] - w * rx, v[2]};
  const double speed = std::hypot(vr[0], vr[1], vr[2]);
  const double vn = std::max(0.6, -(vr[0] * n[0] + vr[1] * n[1] + vr[2] * n[2]));
  const double vt = std::sqrt(std::max(0.0, speed * speed - vn * vn));
  return fmt::format("{},{},flywheel,{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", t,
                     id, x[0], x[1], x[2], c[0], c[1], c[2], n[0], n[1], n[2], vr[0], vr[1], vr[2],
                     speed, vn, vt, std::asin(std::min(1.0, vn / speed)) * 180 / pi,
                     w * std::hypot(rx, ry), std::hypot(v[0], v[1], v[2]), std::hypot(rx, ry));
}

// State of job `label` of the stage whose folder is `stage_dir`.
inline jobs::State job_state(const fs::path& stage_dir, const std::string& label) {
  return jobs::JobStore(stage_dir).read_status(label).state;
}

}  // namespace mill::e2e
