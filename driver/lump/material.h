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

// True when the flat joint's fit aims at the card's K_IC too
// (calibrate.fit_toughness, lump.bond_model flat_joint, the card gives
// fracture_toughness): docs/calibration.md, "The toughness as a target".
bool fits_toughness(const config::CaseConfig& cfg);

// The input_hash that ties a calibration to what it was fitted to: the
// card's macro properties (ore_hash), and its fracture_toughness when the
// fit aimed at it (fits_toughness), so that a section fitted to another
// K_IC is not taken for this card's.
std::string calibration_hash(const config::CaseConfig& cfg);

// Closed-form starting estimates of the micro parameters (docs/breakage.md),
// with the case's bond model, its layout and radius multiplier (lump.*).
BondParams estimate_bond_params(const config::Document& ore, const config::Document& doc);

// The bond parameters a run uses, first found of: <run>/calibrate/calibrated.yaml,
// the ore card's calibrated.* section (both only if fitted to this card's
// properties with the case's bond model and layout), the closed-form estimates.
BondParams bond_params_for(const config::CaseConfig& cfg, const std::filesystem::path& run_dir);

// Where a run folder keeps the calibration of start k >= 2 of the calibrate
// stage (calibrate.starts; docs/calibration.md, "Parameter sets from
// different starts"): <run>/calibrate/sets/start<k>/calibrated.yaml.
std::filesystem::path set_calibration_file(const std::filesystem::path& run_dir, int k);

// The bond parameters of calibration set k: bond_params_for for k = 1, else
// set_calibration_file(run_dir, k), which must hold a calibration of this
// card with the case's bond model (an error naming the file otherwise).
BondParams bond_params_for_set(const config::CaseConfig& cfg, const std::filesystem::path& run_dir,
                               int k);

// -var pairs of the impact and lab-test decks: contacts, bonds
// (bond_deck_vars), and the bond model's options from the case
// (lump.broken_contact).
std::vector<std::pair<std::string, std::string>> material_vars(const config::Document& ore,
                                                               const BondParams& b,
                                                               const config::Document& doc);

}  // namespace mill
