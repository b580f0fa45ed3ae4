// What every bonded-lump run of the breakage stage shares, the single impact
// on a plane (impact.in.tmpl) and the lump in the turning mill
// (in_mill.in.tmpl): the lump with its calibrated bonds and random
// orientation, the decks' -var settings for them, and the fragment analysis
// of the final state and the run's energy ledger with its outputs
// (summary.csv, fractions.csv, impact.h5, energy_ledger.csv, fragments.vtp,
// result.json), each complete or absent.
#pragma once

#include <array>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "lump/lump_builder.h"
#include "lump/material.h"
#include "postprocess/breakage_results.h"
#include "postprocess/energy_ledger.h"
#include "postprocess/lammps_dump.h"
#include "stages/stage.h"

namespace mill::breakage {

struct LumpRun {
  LumpInfo lump;
  BondParams bond;
  std::array<double, 4> rotation{};  // axis x, y, z and angle (deg)
  double r_min = 0;                  // smallest element radius of the builder's classes, m
  std::filesystem::path work;        // the engine's run folder (out_dir/run), emptied
};

// Builds (or reuses) the lump of repeat `repeat` (packing repeat mod
// lump.n_packings), its random orientation (from lump.seed and the repeat)
// and an empty run folder out_dir/run, with the bond parameters of
// calibration set `set` (1: the primary; lump/material.h). The lump is the
// case's (lump_spec) unless `spec` is given (a feed class's lump).
LumpRun prepare_lump_run(StageContext& ctx, int repeat, const std::filesystem::path& out_dir,
                         const std::string& label, int set = 1, const LumpSpec* spec = nullptr);

// Whether the impact and in-mill decks re-evaluate their step between chunks
// (fix step/adaptive): breakage.adaptive_step with the automatic step
// (breakage.timestep 0); a given step stays fixed.
bool adaptive_step_on(const config::Document& d);

// -var pairs every lump deck takes: the shared deck pieces' folder, the lump
// file, its orientation, the bonding rule, the ore and the bonds.
std::vector<std::pair<std::string, std::string>> lump_deck_vars(const StageContext& ctx,
                                                                const LumpRun& run);

struct LumpRunResult {
  post::DumpSnapshot snap;
  post::ImpactResult result;  // its summary holds the ledger's figures too
  post::EnergyLedger ledger;
  post::LedgerSummary energy;
};

// Reads the run's bonds_initial.txt, final.dump, bonds_final.txt and
// ledger.csv (in run.work), analyses the fragments and summarises the ledger.
// Throws when elements were lost or the deck wrote no ledger.
LumpRunResult analyse_lump_run(StageContext& ctx, const LumpRun& run,
                               const post::ImpactConditions& conditions, double wall_seconds,
                               const std::string& label);

// result.json of a run: the conditions, the lump, the bonds, the fragment
// summary and `energy` (energy_json; callers add their own keys).
nlohmann::json lump_result_json(const LumpRun& run, const LumpRunResult& a, double wall_seconds);

// result.json's `energy` object: the ledger's last row (one key per column in
// J), input, residual fraction, fastest element, largest wall overlap and the
// comminution efficiency (docs/breakage.md, "Energy ledger").
nlohmann::json energy_json(const post::LedgerSummary& e);

// Writes summary.csv, fractions.csv, impact.h5 (with /energy),
// energy_ledger.csv, fragments.vtp and result.json into out_dir, each
// complete or absent.
void write_lump_outputs(const std::filesystem::path& out_dir, const LumpRunResult& a,
                        const nlohmann::json& result);

// The outputs write_lump_outputs writes exist and parse: "" or the reason.
std::string damaged_lump_outputs(const std::filesystem::path& dir);

}  // namespace mill::breakage
