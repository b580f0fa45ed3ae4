// Running a LIGGGHTS deck template with liggghts-mill: the program's path,
// `-var` overrides, and progress from the thermo output.
#pragma once

#include <filesystem>
#include <istream>
#include <string>
#include <utility>
#include <vector>

#include "engine/runner.h"

namespace mill {
class Progress;
}

namespace mill::engine {

// liggghts-mill: $MILL_LIGGGHTS, else next to the running orchestrate, else $PATH.
std::string liggghts_mill_path();

struct DeckRun {
  std::filesystem::path deck;     // template (plain LIGGGHTS deck with index variables)
  std::filesystem::path workdir;  // run folder; the log goes to workdir/liggghts.log
  std::vector<std::pair<std::string, std::string>> vars;  // -var name value
  int np = 1;
  std::string job;  // "breakage/v150_a90_r0"
};

// The Command that runs a deck (used by run_deck; exposed for tests and logs).
Command deck_command(const DeckRun& run);

// Run a deck; progress (step/total) is shown through `progress` under `label`
// (deck_progress below).
Result run_deck(Runner& runner, const DeckRun& run, Progress& progress, const std::string& label);

// How far a running deck is, from its log: the deck prints "nsteps N" (the
// steps to its end at the step it starts with) and, if it stops by
// simulated time, "t_end T s" on the same line; its thermo lines (after that
// line) start with the step and the simulated time. With t_end the steps
// still to go are re-estimated from the last step length seen (the time and
// step between the last two thermo lines): a deck whose step changes
// between chunks (breakage.adaptive_step) would otherwise report the steps
// of its first step length, and the job's ETA (Progress::eta_seconds: time
// so far x steps to go / steps done) would keep the first chunk's pace.
// Without t_end: step / N.
struct DeckProgress {
  long step = -1;        // last thermo step (-1: none yet)
  long total = 0;        // steps in all: N, or the steps done + those to go at the step now
  double time = -1;      // simulated time of that step [s] (-1: not known)
  double t_end = 0;      // the deck's end time [s] (0: not printed)
  double fraction = -1;  // step / total, or < 0 if not known yet
};
DeckProgress deck_progress(std::istream& log);

// Number formatting for -var values: full precision, no locale surprises.
std::string num(double v);

}  // namespace mill::engine
