// Ore material for the LIGGGHTS decks: contact properties from the ore card,
// bond (micro) parameters (lump/bond_parameters.h) from a calibration or
// closed-form estimates.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
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

// Perras & Diederichs (2014, Geotech. Geol. Eng. 32, abstract and sec. 6):
// the direct tensile strength over the Brazilian one, DTS = f BTS, by the
// ore card's rock_class (0.7 sedimentary, 0.8 igneous, 0.9 metamorphic).
// Throws ConfigError naming the card and the key for any other class.
double direct_over_brazilian(const config::Document& ore);

// True when the fit aims its tensile strength at a direct tension test
// (calibrate.tensile_test direct): docs/calibration.md, "The direct tension
// test".
bool fits_direct_tension(const config::CaseConfig& cfg);

// The tensile strength the fit aims at: the card's tensile_strength
// (Brazilian), or with fits_direct_tension its direct_tensile_strength,
// else tensile_strength x direct_over_brazilian. Throws ConfigError naming
// the keys when the direct test has neither.
double tensile_target(const config::CaseConfig& cfg);

// The lump's material scale, which a calibration holds for and no other:
// the mean element radius (lump.n_elements in lump.diameter with
// lump.radius_spread: a bonded packing's strengths and toughness follow it,
// bench/README.md, "K_IC over the element sizes"), the spread, the bonding
// range (lump.bond_gap: the coordination), the bond radius multiplier and,
// for the parallel bond, lump.broken_contact. The JSON map that
// calibration_hash and calibrated.yaml's `fitted_for` carry.
nlohmann::json lump_scale(const config::CaseConfig& cfg);

// The input_hash that ties a calibration to what it was fitted to: the
// card's macro properties (ore_hash), its fracture_toughness when the fit
// aimed at it (fits_toughness), so that a section fitted to another K_IC is
// not taken for this card's, the direct tensile strength when the fit aimed
// at it (fits_direct_tension), and the lump's scale (lump_scale), so that a
// section fitted at another element size or bonding range is not either.
std::string calibration_hash(const config::CaseConfig& cfg);

// Why a run of this case has no calibration (bond_params_for falls back to
// the closed-form estimate), in one sentence naming the files looked at and,
// for a card section fitted to another lump scale, what differs; empty when
// a calibration applies.
std::string uncalibrated_reason(const config::CaseConfig& cfg,
                                const std::filesystem::path& run_dir);

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
