// Outputs of the calibration job (docs/calibration.md, step 6):
// calibrated.yaml (read by the breakage stage), report.md, report.json,
// curves.csv and plots/, written into the job folder.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "stages/calibrate/checks.h"
#include "stages/calibrate/fitting.h"
#include "stages/calibrate/lab_runs.h"
#include "stages/calibrate/packing_check.h"
#include "stages/calibrate/sensitivity.h"
#include "stages/calibrate/specimen.h"
#include "stages/stage.h"

namespace mill::calibrate {

// A finished fit: what the outputs report.
struct Outcome {
  Specimen specimen;
  std::vector<Iteration> hist;  // every iteration, in order
  size_t best = 0;              // index in hist of the result
  std::optional<UcsRun> half;   // rate check: the result's UCS test at half the strain rate
  std::vector<LeverRun> sensitivity;  // one perturbed UCS + Brazilian pair per lever (or none)
  std::vector<PackingRun> packings;   // packing check: the result on further packings (or none)
  std::optional<PackingSpread> packing;  // their spread, with the fit's own packing
  Checks checks;                // triaxial envelope and toughness with the result's parameters
  std::vector<std::string> notes;
  double wall = 0;  // s, the whole job
};

// calibrated.yaml, report.json, report.md, curves.csv and plots in the job folder.
void write_outputs(StageContext& ctx, const std::filesystem::path& dir, const Fitting& fit,
                   const Outcome& o);

// The card's own calibrated.* section, copied (no fitting).
void copy_from_card(StageContext& ctx, const std::filesystem::path& dir);

}  // namespace mill::calibrate
