// The bond parameters' conversions, each derived from kBondParameters.
#include "lump/bond_parameters.h"

#include <fmt/format.h>

#include <cmath>
#include <functional>
#include <optional>
#include <stdexcept>

#include "config/case_config.h"
#include "engine/liggghts.h"

namespace mill {

namespace {

// The ore card's key of a name in its calibrated: section.
std::string card_key(const char* name) { return std::string(kCalibratedSection) + "." + name; }

// A row the model uses (a flat joint has no parallel-bond rows, a parallel
// bond no flat-joint rows).
bool uses(const BondParams& b, const BondParameter& p) {
  return !(p.parallel_only && b.model == BondModel::flat_joint) &&
         !(p.joint_only && b.model != BondModel::flat_joint);
}

// `base` with the model, its layout and each fitted row set from `find`
// (its value under the row's calibrated name, or none; the model under
// kModelKey, read by `find_model`); `where` names the map in messages.
BondParams read_fitted(const std::function<std::optional<double>(const char*)>& find,
                       const std::function<std::optional<std::string>()>& find_model,
                       const std::string& where, BondParams base) {
  const std::optional<std::string> model = find_model();
  try {
    base.model = model ? bond_model_from(*model) : BondModel::parallel;
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(fmt::format("{}{}: {}", where, kModelKey, e.what()));
  }
  if (base.model == BondModel::flat_joint) {
    for (auto [key, member] : {std::pair{kRingsKey, &BondParams::joint_rings},
                               std::pair{kSectorsKey, &BondParams::joint_sectors}}) {
      const std::optional<double> v = find(key);
      if (!v) throw std::runtime_error(fmt::format("{}{} is missing (a flat joint's layout)", where, key));
      base.*member = static_cast<int>(std::lround(*v));
    }
  }
  for (const BondParameter& p : kBondParameters) {
    if (!p.calibrated || !uses(base, p)) continue;
    if (const std::optional<double> v = find(p.calibrated))
      base.*p.value = *v;
    else if (p.optional)
      base.*p.value = p.start;
    else
      throw std::runtime_error(fmt::format("{}{} is missing", where, p.calibrated));
  }
  return base;
}

}  // namespace

bool bond_row_shown(const BondParams& b, const BondParameter& p) {
  return uses(b, p) && !(p.joint_only && b.*p.value == p.start);
}

const char* bond_model_name(BondModel m) {
  return m == BondModel::flat_joint ? "flat_joint" : "parallel";
}

BondModel bond_model_from(const std::string& name) {
  if (name == "parallel") return BondModel::parallel;
  if (name == "flat_joint") return BondModel::flat_joint;
  throw std::runtime_error("expected parallel or flat_joint, got '" + name + "'");
}

std::string bond_model_text(const BondParams& b) {
  return b.model == BondModel::flat_joint
             ? fmt::format("flat joint {} x {}", b.joint_rings, b.joint_sectors)
             : std::string("parallel bond");
}

// The parameters as JSON under the names `names` picks, one key per row the
// model uses, and the model (with a flat joint's layout).
nlohmann::json bond_json(const BondParams& b, BondNames names) {
  nlohmann::json j = nlohmann::json::object();
  const bool card = names == BondNames::card;
  j[card ? card_key(kModelKey) : kModelKey] = bond_model_name(b.model);
  if (b.model == BondModel::flat_joint) {
    j[card ? card_key(kRingsKey) : kRingsKey] = b.joint_rings;
    j[card ? card_key(kSectorsKey) : kSectorsKey] = b.joint_sectors;
  }
  for (const BondParameter& p : kBondParameters) {
    if (!bond_row_shown(b, p)) continue;
    if (names == BondNames::job)
      j[p.json] = b.*p.value;
    else if (names == BondNames::report)
      j[p.calibrated ? p.calibrated : p.json] = b.*p.value;
    else if (p.calibrated)
      j[card_key(p.calibrated)] = b.*p.value;
  }
  return j;
}

// calibrated: {fitted rows..., input_hash}, as calibrated.yaml writes it.
void emit_calibrated(YAML::Emitter& y, const BondParams& b, const std::string& hash,
                     const nlohmann::json& fitted_for) {
  y << YAML::Key << kCalibratedSection << YAML::Value << YAML::BeginMap;
  y << YAML::Key << kModelKey << YAML::Value << bond_model_name(b.model);
  if (b.model == BondModel::flat_joint) {
    y << YAML::Key << kRingsKey << YAML::Value << b.joint_rings;
    y << YAML::Key << kSectorsKey << YAML::Value << b.joint_sectors;
  }
  for (const BondParameter& p : kBondParameters)
    if (p.calibrated && bond_row_shown(b, p))
      y << YAML::Key << p.calibrated << YAML::Value << b.*p.value;
  y << YAML::Key << kInputHashKey << YAML::Value << hash;
  if (fitted_for.is_object()) {
    y << YAML::Key << kFittedForKey << YAML::Value << YAML::BeginMap;
    for (const auto& [k, v] : fitted_for.items()) {
      y << YAML::Key << k << YAML::Value;
      if (v.is_boolean())
        y << v.get<bool>();
      else
        y << v.get<double>();
    }
    y << YAML::EndMap;
  }
  y << YAML::EndMap;
}

// The fitted rows from a calibrated: map read as YAML (calibrated.yaml).
BondParams read_calibrated(const YAML::Node& calibrated, BondParams base) {
  return read_fitted(
      [&](const char* key) -> std::optional<double> {
        if (!calibrated[key]) return std::nullopt;
        return calibrated[key].as<double>();
      },
      [&]() -> std::optional<std::string> {
        if (!calibrated[kModelKey]) return std::nullopt;
        return calibrated[kModelKey].as<std::string>();
      },
      std::string(kCalibratedSection) + ".", std::move(base));
}

// The fitted rows from the validated ore card's calibrated.* keys.
BondParams read_calibrated(const config::Document& ore, BondParams base) {
  return read_fitted(
      [&](const char* key) -> std::optional<double> {
        if (!ore.has(card_key(key))) return std::nullopt;
        return ore.real(card_key(key));
      },
      [&]() -> std::optional<std::string> {
        if (!ore.has(card_key(kModelKey))) return std::nullopt;
        return ore.str(card_key(kModelKey));
      },
      ore.file() + ": " + kCalibratedSection + ".", std::move(base));
}

// Every required fitted row of its model (and a flat joint's layout) and the
// input hash are on the card.
bool card_has_calibration(const config::Document& ore) {
  BondParams model;
  if (ore.has(card_key(kModelKey)) && ore.str(card_key(kModelKey)) == "flat_joint") {
    model.model = BondModel::flat_joint;
    if (!ore.has(card_key(kRingsKey)) || !ore.has(card_key(kSectorsKey))) return false;
  }
  for (const BondParameter& p : kBondParameters)
    if (p.calibrated && !p.optional && uses(model, p) && !ore.has(card_key(p.calibrated)))
      return false;
  return ore.has(card_key(kInputHashKey));
}

// One -var pair per shared row, the value as engine::num writes it; the
// model's own rows and layout in bond_model_keys.
std::vector<std::pair<std::string, std::string>> bond_deck_vars(const BondParams& b) {
  std::vector<std::pair<std::string, std::string>> v;
  std::string keys;
  for (const BondParameter& p : kBondParameters) {
    if (!p.parallel_only && !p.joint_only)
      v.emplace_back(p.deck, engine::num(b.*p.value));
    else if (bond_row_shown(b, p))
      keys += fmt::format("{}{} {}", keys.empty() ? "" : " ", p.keyword, engine::num(b.*p.value));
  }
  if (b.model == BondModel::flat_joint) {
    keys += fmt::format("{}elements {} {}", keys.empty() ? "" : " ", b.joint_rings, b.joint_sectors);
    if (b.joint_friction >= 0) keys += fmt::format(" joint_friction {}", engine::num(b.joint_friction));
  }
  v.emplace_back("bond_style", b.model == BondModel::flat_joint ? "flatjoint" : "breakable");
  v.emplace_back("bond_model_keys", keys);
  return v;
}

}  // namespace mill
