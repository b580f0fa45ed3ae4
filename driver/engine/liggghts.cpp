// LIGGGHTS deck runs.
#include "engine/liggghts.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "progress.h"

namespace mill::engine {
namespace fs = std::filesystem;

std::string liggghts_mill_path() {
  if (const char* env = std::getenv("MILL_LIGGGHTS")) return env;
  char buf[4096];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n > 0) {
    buf[n] = 0;
    const fs::path beside = fs::path(buf).parent_path() / "liggghts-mill";
    if (fs::exists(beside)) return beside.string();
  }
  return "liggghts-mill";
}

std::string num(double v) { return fmt::format("{:.17g}", v); }

Command deck_command(const DeckRun& run) {
  Command c;
  c.argv = {liggghts_mill_path(), "-in", fs::absolute(run.deck).string(), "-log", "none", "-echo", "none"};
  for (const auto& [k, v] : run.vars) {
    c.argv.push_back("-var");
    c.argv.push_back(k);
    c.argv.push_back(v);
  }
  c.cwd = run.workdir;
  c.log = run.workdir / "liggghts.log";
  c.np = run.np;
  c.engine = Engine::Liggghts;
  c.job = run.job;
  return c;
}

DeckProgress deck_progress(std::istream& in) {
  DeckProgress p;
  long total0 = 0;
  // The last two thermo lines of distinct steps: (step, time).
  long s_prev = -1, s_last = -1;
  double t_prev = 0, t_last = 0;
  std::string line;
  while (std::getline(in, line)) {
    const size_t k = line.find("nsteps ");
    if (k != std::string::npos) {
      total0 = std::atol(line.c_str() + k + 7);
      const size_t e = line.find("t_end ");
      p.t_end = e != std::string::npos ? std::atof(line.c_str() + e + 6) : 0.0;
      s_prev = s_last = -1;  // thermo lines before this one may show other columns
      p.step = -1;
      continue;
    }
    // Thermo lines: leading spaces, the step, then a number (time).
    std::istringstream ls(line);
    long s = 0;
    double t = 0;
    if (line.empty() || line[0] != ' ' || !(ls >> s >> t)) continue;
    if (s == s_last) continue;  // a run's first line repeats the last one's step
    s_prev = s_last, t_prev = t_last;
    s_last = s, t_last = t;
    p.step = s;
  }
  if (total0 <= 0 || p.step < 0) return p;
  p.total = total0;
  if (p.t_end > 0 && s_last >= 0) {
    p.time = t_last;
    // The step of the moment: from the last two lines, else the one the
    // deck started with (nsteps = ceil(t_end / dt)).
    double dt = p.t_end / static_cast<double>(total0);
    if (s_prev >= 0 && s_last > s_prev && t_last > t_prev)
      dt = (t_last - t_prev) / static_cast<double>(s_last - s_prev);
    // 1e-9: a time a rounding error short of t_end is no step to go.
    const double to_go = std::max(0.0, std::ceil((p.t_end - t_last) / dt - 1e-9));
    p.total = p.step + static_cast<long>(to_go);
  }
  p.fraction =
      p.total > 0 ? std::min(1.0, static_cast<double>(p.step) / static_cast<double>(p.total)) : -1;
  return p;
}

Result run_deck(Runner& runner, const DeckRun& run, Progress& progress, const std::string& label) {
  if (!fs::exists(run.deck)) throw std::runtime_error(fmt::format("{}: deck template {} not found", run.job, run.deck.string()));
  fs::create_directories(run.workdir);
  auto poll = [&](const fs::path& log) {
    std::ifstream in(log);
    const DeckProgress p = deck_progress(in);
    if (p.fraction >= 0)
      progress.job_step(label, fmt::format("step {}/{}", p.step, p.total), p.fraction);
  };
  return runner.run(deck_command(run), poll);
}

}  // namespace mill::engine
