// The bond parameters' conversions, each derived from kBondParameters.
#include "lump/bond_parameters.h"

#include <fmt/format.h>

#include <functional>
#include <optional>
#include <stdexcept>

#include "config/case_config.h"
#include "engine/liggghts.h"

namespace mill {

namespace {

// The ore card's key of a name in its calibrated: section.
std::string card_key(const char* name) { return std::string(kCalibratedSection) + "." + name; }

// `base` with each fitted row set from `find` (its value under the row's
// calibrated name, or none); `where` names the map in messages.
BondParams read_fitted(const std::function<std::optional<double>(const char*)>& find,
                       const std::string& where, BondParams base) {
  for (const BondParameter& p : kBondParameters) {
    if (!p.calibrated) continue;
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

// The parameters as JSON under the names `names` picks, one key per row.
nlohmann::json bond_json(const BondParams& b, BondNames names) {
  nlohmann::json j = nlohmann::json::object();
  for (const BondParameter& p : kBondParameters) {
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
void emit_calibrated(YAML::Emitter& y, const BondParams& b, const std::string& hash) {
  y << YAML::Key << kCalibratedSection << YAML::Value << YAML::BeginMap;
  for (const BondParameter& p : kBondParameters)
    if (p.calibrated) y << YAML::Key << p.calibrated << YAML::Value << b.*p.value;
  y << YAML::Key << kInputHashKey << YAML::Value << hash;
  y << YAML::EndMap;
}

// The fitted rows from a calibrated: map read as YAML (calibrated.yaml).
BondParams read_calibrated(const YAML::Node& calibrated, BondParams base) {
  return read_fitted(
      [&](const char* key) -> std::optional<double> {
        if (!calibrated[key]) return std::nullopt;
        return calibrated[key].as<double>();
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
      ore.file() + ": " + kCalibratedSection + ".", std::move(base));
}

// Every required fitted row and the input hash are on the card.
bool card_has_calibration(const config::Document& ore) {
  for (const BondParameter& p : kBondParameters)
    if (p.calibrated && !p.optional && !ore.has(card_key(p.calibrated))) return false;
  return ore.has(card_key(kInputHashKey));
}

// One -var pair per row, the value as engine::num writes it.
std::vector<std::pair<std::string, std::string>> bond_deck_vars(const BondParams& b) {
  std::vector<std::pair<std::string, std::string>> v;
  for (const BondParameter& p : kBondParameters) v.emplace_back(p.deck, engine::num(b.*p.value));
  return v;
}

}  // namespace mill
