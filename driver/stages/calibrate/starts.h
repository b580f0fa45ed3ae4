// Calibrations from several starts (docs/calibration.md, "Parameter sets
// from different starts"): where each start begins, the job of each start,
// and the table of the sets they reach (calibrate/sets.json, sets.md), which
// the breakage stage turns into a band of critical impact speeds.
#pragma once

#include <array>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "lump/bond_parameters.h"
#include "stages/stage.h"

namespace mill::calibrate {

// Most starts a case may ask for (calibrate.starts).
inline constexpr int kMaxStarts = 8;
// How far a start reaches from the closed-form estimate: each continuous
// parameter within x/÷ this factor.
inline constexpr double kStartSpread = 2.0;

// The job label of start k (1-based): "calibration" for the first (the
// closed-form start, as a single calibration), "calibration_start<k>" else.
std::string start_label(int k);
// The start of a calibrate job (1 for "calibration"), from its inputs.
int start_of(const JobSpec& job);

// The factors start k applies to the estimate's (E_b, kn/ks, sigma_b,
// c/sigma_b): 1 for k = 1; for k >= 2 the Halton point of index k in bases
// 2, 3, 5, 7 (Halton 1960), h in (0, 1), mapped to kStartSpread^(2h - 1):
// spread evenly in log space, the same for every run.
std::array<double, 4> start_factors(int k);
// Start k's bond parameters: `estimate` with start_factors(k) applied (the
// stiffness ratio and c/sigma_b kept inside the fit's bounds).
BondParams start_params(const BondParams& estimate, int k);

// One calibration of a start, as its job's report.json tells it.
struct StartResult {
  int start = 1;
  std::filesystem::path dir;  // the job folder (calibrated.yaml, report.json)
  nlohmann::json report;      // its report.json
};

// calibrate/sets.json: per start its start, result, the targets it meets,
// and the count of sets that meet every target.
nlohmann::json sets_json(const std::vector<StartResult>& starts);
// The Markdown section of report.md for the same table.
std::string sets_markdown(const nlohmann::json& sets);

}  // namespace mill::calibrate
