// The single impacts of the breakage stage: one bonded lump on a flat
// surface per (velocity, angle, repeat) with liggghts_inputs/impact.in.tmpl,
// then the fragment analysis and the energy ledger (docs/breakage.md, "What
// runs"). Used by the stage's jobs and by `orchestrate impact`.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "stages/stage.h"

namespace mill::breakage {

// Inputs every impact of the case shares: case keys of the lump and the run,
// the ore, the bond parameters, the deck version.
nlohmann::json impact_base_inputs(const StageContext& ctx);

// The canonical inputs of one impact (the job id is their hash): the shared
// inputs and the condition.
nlohmann::json impact_inputs(const StageContext& ctx, double velocity, double angle, int repeat);

// The strength impacts of a case with transport conditions
// (breakage.strength_velocities): their labels start with kStrengthPrefix and
// their inputs carry "strength": true; the mill's product does not read them.
inline constexpr const char* kStrengthPrefix = "strength_";
bool is_strength_job(const JobSpec& job);

// The outputs run_impact writes into `dir` exist and parse: "" or the reason.
std::string damaged_impact_outputs(const std::filesystem::path& dir);

// The one-line summary of an impact from its result.json.
std::string impact_line(const nlohmann::json& result);

// One impact into `out_dir`: runs the deck, analyses the fragments and the
// energy ledger, writes summary.csv, fractions.csv, impact.h5,
// energy_ledger.csv, energy_ledger.png, fragments.vtp and result.json there.
// Returns the summary line. `set`: the calibration set whose bond
// parameters the lump takes (1: the primary; calibrate.starts).
std::string run_impact(StageContext& ctx, double velocity, double angle, int repeat,
                       const std::filesystem::path& out_dir, const std::string& label,
                       int set = 1);

}  // namespace mill::breakage
