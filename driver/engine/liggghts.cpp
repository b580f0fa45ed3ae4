// LIGGGHTS deck runs.
#include "engine/liggghts.h"

#include <fmt/format.h>
#include <unistd.h>

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

Result run_deck(Runner& runner, const DeckRun& run, Progress& progress, const std::string& label) {
  if (!fs::exists(run.deck)) throw std::runtime_error(fmt::format("{}: deck template {} not found", run.job, run.deck.string()));
  fs::create_directories(run.workdir);
  // Progress: the deck prints "nsteps N"; thermo lines start with the step.
  auto poll = [&](const fs::path& log) {
    std::ifstream in(log);
    std::string line;
    long total = 0, step = -1;
    while (std::getline(in, line)) {
      const size_t k = line.find("nsteps ");
      if (k != std::string::npos) {
        total = std::atol(line.c_str() + k + 7);
        continue;
      }
      // Thermo lines: leading spaces, the step, then a number (time).
      std::istringstream ls(line);
      long s = 0;
      double t = 0;
      if (!line.empty() && line[0] == ' ' && (ls >> s >> t)) step = s;
    }
    if (total > 0 && step >= 0)
      progress.job_step(label, fmt::format("step {}/{}", step, total), static_cast<double>(step) / total);
  };
  return runner.run(deck_command(run), poll);
}

}  // namespace mill::engine
