// Ore material for the LIGGGHTS decks: contact properties from the ore card,
// bond (micro) parameters (lump/bond_parameters.h) from a calibration or
// closed-form estimates.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "config/case_config.h"
#include "lump/bond_parameters.h"

namespace mill {

// Hash of an ore card's macro properties (what a calibration was fitted to).
std::string ore_hash(const config::Document& ore);

// Closed-form starting estimates of the micro parameters (docs/breakage.md),
// with the case's bond model, its layout and radius multiplier (lump.*).
BondParams estimate_bond_params(const config::Document& ore, const config::Document& doc);

// The bond parameters a run uses, first found of: <run>/calibrate/calibrated.yaml,
// the ore card's calibrated.* section (both only if fitted to this card's
// properties with the case's bond model and layout), the closed-form estimates.
BondParams bond_params_for(const config::CaseConfig& cfg, const std::filesystem::path& run_dir);

// -var pairs of the impact and lab-test decks: contacts, bonds
// (bond_deck_vars), and the bond model's options from the case
// (lump.broken_contact).
std::vector<std::pair<std::string, std::string>> material_vars(const config::Document& ore,
                                                               const BondParams& b,
                                                               const config::Document& doc);

}  // namespace mill
