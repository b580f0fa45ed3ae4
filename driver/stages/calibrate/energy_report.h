// The energy ledgers of the calibration's lab runs in its reports
// (docs/calibration.md, "Energy ledger"): each run's `energy` object in
// report.json, the worst residual over the runs, and report.md's section.
// Built only from post::LedgerSummary, whatever columns the ledger holds.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "postprocess/energy_ledger.h"
#include "stages/calibrate/lab_runs.h"
#include "stages/calibrate/outputs.h"

namespace mill::calibrate {

// report.json's `energy` object of one lab run, from its ledger's summary.
nlohmann::json lab_energy_json(const post::LedgerSummary& e);

// Every lab run of a fit in the order they ran: each iteration's UCS and
// Brazilian tests, the rate check's UCS, each lever's sensitivity UCS and
// Brazilian tests, then the checks' triaxial and semi-circular bend tests.
std::vector<const LabRun*> lab_runs(const Outcome& o);

// report.json's top-level `energy` object: the worst |residual_fraction_max|
// over the lab runs, the run it came from, and what the figures mean.
nlohmann::json energy_summary_json(const Outcome& o);

// report.md's "Energy ledger" section: one row per lab run (the result's runs
// marked), then the worst residual.
std::string energy_markdown(const Outcome& o);

}  // namespace mill::calibrate
