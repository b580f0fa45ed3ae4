// Small helpers shared by the stage files: canonical job inputs, labels, a
// run's energy ledger.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "config/case_config.h"
#include "postprocess/energy_ledger.h"

namespace mill {

// The case keys under the given prefixes ("mill.", "gas."), as canonical JSON.
nlohmann::json case_keys(const config::Document& doc, const std::vector<std::string>& prefixes);
// "rpm2000", "rpm1500.5": folder label of a rotor speed.
std::string rpm_label(double rpm);
// Where a transport run at `rpm` leaves its outputs (impacts.csv,
// summary.json, ...): transport/<rpm label>/ for the lumps of
// injection.lump_diameter, transport/class_<k>/<rpm label>/ for those of
// feed class k (config/feed_classes.h).
std::filesystem::path transport_dir(const std::filesystem::path& run_dir, double rpm,
                                    std::optional<std::size_t> feed_class = std::nullopt);
// "v150_a90_r0", "v4.5_a45_r2": folder label of an impact condition.
std::string impact_label(double velocity, double angle, int repeat);
// The energy ledger a bonded-lump deck wrote in its run folder (ledger.csv,
// fix energy/ledger), read after the run. Throws naming the file and the
// run's log when the deck wrote none, PostError naming the file (and line)
// when it does not parse.
post::EnergyLedger read_run_ledger(const std::filesystem::path& workdir);

// Runs independent tasks (engine runs of one job, each writing its own
// folder) on up to `lanes` threads, in order of their index; with lanes <= 1
// one after the other on this thread. After a task throws no further task
// starts; once the running ones have ended, the exception of the first task
// (by index) that threw is rethrown as it was (Interrupted stays Interrupted).
void run_concurrently(const std::vector<std::function<void()>>& tasks, int lanes);

}  // namespace mill
