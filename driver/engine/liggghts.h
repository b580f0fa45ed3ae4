// Running a LIGGGHTS deck template with liggghts-mill: the program's path,
// `-var` overrides, and progress from the thermo output.
#pragma once

#include <filesystem>
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

// Run a deck; progress (step/total) is shown through `progress` under `label`.
// The total step count is read from the deck's own "nsteps N" print line.
Result run_deck(Runner& runner, const DeckRun& run, Progress& progress, const std::string& label);

// Number formatting for -var values: full precision, no locale surprises.
std::string num(double v);

}  // namespace mill::engine
