// The bond (micro) parameters of fix bond/breakable and their one table of
// keys: per parameter its name in the ore card's calibrated: section and in
// calibrated.yaml, the deck variable, the style's keyword, the key in a job's
// JSON, the unit, the admissible range and the starting value. The ore
// card's schema (config/schema.cpp), the JSON, the calibrated: map and the
// decks' -var pairs are all derived from kBondParameters: a new parameter is
// one member of BondParams and one row (plus its deck variable and the
// style's keyword). This header includes nothing of driver/, so that the
// config schema can read the table.
#pragma once

#include <yaml-cpp/yaml.h>

#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace mill {
namespace config {
class Document;
}

// The bonded contact of the lump and the specimens (the case's
// lump.bond_model): the parallel bond of fix bond/breakable (Potyondy &
// Cundall 2004) or the flat joint of fix bond/flatjoint (Potyondy 2012).
enum class BondModel { parallel, flat_joint };
// Its name in the case (lump.bond_model), calibrated.yaml and the job JSON.
const char* bond_model_name(BondModel m);
// The model named `name`; throws std::runtime_error for another name.
BondModel bond_model_from(const std::string& name);

// One set of bond parameters; each number is a row of kBondParameters, and
// the model with its layout, which the case sets (lump.bond_model,
// lump.joint_rings, lump.joint_sectors) and a calibration records.
struct BondParams {
  double modulus = 0;             // bond modulus E_b, Pa
  double stiffness_ratio = 0;     // kn/ks
  double tensile = 0;             // bond tensile strength, Pa
  double cohesion = 0;            // bond shear cohesion, Pa
  double friction_angle_deg = 0;  // bond Mohr-Coulomb friction angle, deg
  double moment_factor = 1.0;     // beta: share of the bond moments in the bond stresses
  double radius_multiplier = 1.0;
  BondModel model = BondModel::parallel;
  int joint_rings = 1;    // flat joint: rings of elements per interface
  int joint_sectors = 3;  // flat joint: sectors of elements per interface
  // flat joint: friction coefficient of the broken elements (lump.joint_friction);
  // negative: the style's default, tan of friction_angle_deg
  double joint_friction = -1;
  // flat joint: tension softening lambda of its elements (fix bond/flatjoint
  // softening; 1: brittle), a fitted row
  double softening = 1.0;
  std::string origin;     // where they come from, for reports
};

// True when two sets are of the same model and (flat joint) element layout:
// a calibration applies only to the model and layout it was fitted with.
inline bool same_model(const BondParams& a, const BondParams& b) {
  return a.model == b.model &&
         (a.model == BondModel::parallel ||
          (a.joint_rings == b.joint_rings && a.joint_sectors == b.joint_sectors));
}
// "parallel bond" or "flat joint 1 x 3", for messages and reports.
std::string bond_model_text(const BondParams& b);

// Admissible values: min < v (or <=), v < max (or <=).
struct BondRange {
  double min;
  bool min_exclusive;
  double max;
  bool max_exclusive;
};
inline constexpr double kNoBound = std::numeric_limits<double>::infinity();
inline constexpr BondRange kPositive{0, true, kNoBound, false};

// A start that is not a constant: estimate_bond_params derives it from the
// ore card (or the case).
inline constexpr double kFromCard = std::numeric_limits<double>::quiet_NaN();

// One parameter: a row of the table.
struct BondParameter {
  double BondParams::*value;
  const char* json;        // key in a job's JSON and result.json: bond.<json>
  const char* calibrated;  // key in calibrated.yaml and the ore card's calibrated.<key>;
                           // nullptr: not fitted, the case sets it
  const char* deck;        // deck variable (-var), passed to the style's keyword
  const char* keyword;     // fix bond/breakable keyword (liggghts_inputs/lump_bonds.in)
  const char* unit;        // "" = dimensionless
  BondRange range;
  double start;   // the closed-form estimate (kFromCard: derived from the card)
  bool optional;  // may be absent from a calibration (one made before it existed): then `start`
  bool parallel_only;  // a keyword of the parallel bond only (fix bond/flatjoint refuses it)
  const char* doc;
  // A keyword of the flat joint only (fix bond/breakable refuses it), left
  // out of every map while at its start: the jobs and calibrations made
  // before the row existed keep their ids and read the same.
  bool joint_only = false;
};

// The table. The names differ between columns only for history (the
// calibrated.yaml names came with the calibrate stage, the deck names with
// the first impact deck, the job JSON names are the C++ members'); renaming
// any of them changes the user's files, decks or job ids, so they stay.
// Row order is the order of the calibrated: map and of the card's schema.
// clang-format off
inline constexpr BondParameter kBondParameters[] = {
//  member                           json                  calibrated               deck               keyword              unit   range                        start      optional parallel_only
  {&BondParams::modulus,            "modulus",            "bond_modulus",          "bond_modulus",    "modulus",           "Pa",  kPositive,                   kFromCard, false, false,
   "Bond modulus E_b (k_n = E_b / L)"},
  {&BondParams::stiffness_ratio,    "stiffness_ratio",    "stiffness_ratio",       "stiffness_ratio", "stiffness_ratio",   "",    kPositive,                   2.5,       false, false,
   "Bond normal/shear stiffness ratio"},
  {&BondParams::tensile,            "tensile",            "bond_tensile_strength", "bond_tensile",    "tensile_strength",  "Pa",  kPositive,                   kFromCard, false, false,
   "Bond tensile strength"},
  {&BondParams::cohesion,           "cohesion",           "bond_cohesion",         "bond_cohesion",   "cohesion",          "Pa",  kPositive,                   kFromCard, false, false,
   "Bond shear cohesion"},
  {&BondParams::friction_angle_deg, "friction_angle_deg", "bond_friction_angle",   "bond_friction",   "friction_angle",    "deg", {0, false, 90, true},        30.0,      false, false,
   "Bond Mohr-Coulomb friction angle"},
  {&BondParams::moment_factor,      "moment_factor",      "bond_moment_factor",    "moment_factor",   "moment_factor",     "",    {0, false, 1, false},        1.0,       true, true,
   "Share of the bond moments in the bond stresses (absent: 1)"},
  {&BondParams::radius_multiplier,  "radius_multiplier",  nullptr,                 "radius_mult",     "radius_multiplier", "",    {0, true, 2, false},         kFromCard, false, false,
   "Bond disc radius = multiplier x min(Ri, Rj); at most 2, a disc twice the smaller element (Potyondy & Cundall 2004 use 1)"},  // the case's lump.bond_radius_multiplier
  {&BondParams::softening,          "softening",          "joint_softening",       "joint_softening", "softening",         "",    {1, false, 1000, false},     1.0,       true, false,
   "Flat joint: tension softening lambda of its elements, the opening at which an element's tension has fallen to zero over the opening at its peak (a linear cohesive law; fracture energy x lambda at the same strength; absent: 1, brittle)", true},
};
// clang-format on

// The ore card's section of fitted parameters, and the key in it (and in
// calibrated.yaml) that ties them to the card's macro properties.
inline constexpr const char* kCalibratedSection = "calibrated";
inline constexpr const char* kInputHashKey = "input_hash";
// Its keys of the model and the flat joint's layout (absent: a parallel bond,
// from a calibration made before the flat joint existed).
inline constexpr const char* kModelKey = "bond_model";
inline constexpr const char* kRingsKey = "joint_rings";
inline constexpr const char* kSectorsKey = "joint_sectors";
// Its map of the lump scale the parameters were fitted for (lump/material.h,
// lump_scale): informative, the input_hash already covers it; it names what
// differs when a section does not apply to a case.
inline constexpr const char* kFittedForKey = "fitted_for";

// True when the row is one of model b's (a flat joint has no parallel-bond
// rows, a parallel bond no flat-joint rows) and, for a flat-joint row, off
// its start: the rows a map of b carries.
bool bond_row_shown(const BondParams& b, const BondParameter& p);

// The row whose job JSON key is `json`; throws std::logic_error for none.
inline const BondParameter& bond_parameter(std::string_view json) {
  for (const BondParameter& p : kBondParameters)
    if (json == p.json) return p;
  throw std::logic_error("no bond parameter '" + std::string(json) + "' in kBondParameters");
}

// Which names a JSON object of the parameters uses.
enum class BondNames {
  job,     // every row under its json name (job JSON, result.json)
  report,  // every row under its calibrated name, else its json name (report.json)
  card,    // the fitted rows under calibrated.<calibrated> (the card's keys)
};
nlohmann::json bond_json(const BondParams& b, BondNames names);

// The calibrated: map of calibrated.yaml (and of the ore card) as a YAML map
// entry: the fitted rows in table order, then the input hash `hash` (the
// calibration_hash of the card and lump they were fitted to) and, when not
// null, `fitted_for` (a flat JSON map of numbers and booleans: the lump's
// scale, lump_scale).
void emit_calibrated(YAML::Emitter& y, const BondParams& b, const std::string& hash,
                     const nlohmann::json& fitted_for = nullptr);

// `base` with the fitted rows replaced by those of a calibrated: map (a YAML
// node, or the card's calibrated.* keys); an optional row that is absent
// takes its start. Throws std::runtime_error naming the key a required row
// misses, YAML::Exception for a value that is no number.
BondParams read_calibrated(const YAML::Node& calibrated, BondParams base);
BondParams read_calibrated(const config::Document& ore, BondParams base);

// True when the ore card's calibrated: section is complete: every required
// fitted row and the input hash.
bool card_has_calibration(const config::Document& ore);

// -var pairs of the decks: every shared row's deck variable, formatted for
// LIGGGHTS; `bond_style` (breakable or flatjoint: the style is
// bond/${bond_style}) and `bond_model_keys`, the model's own keywords (a
// parallel bond's moment_factor, a flat joint's elements), which the decks
// put on their fix line as they are.
std::vector<std::pair<std::string, std::string>> bond_deck_vars(const BondParams& b);

}  // namespace mill
