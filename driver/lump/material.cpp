// Ore material and bond parameters for the decks.
#include "lump/material.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cmath>

#include "engine/liggghts.h"
#include "jobs/job_store.h"

namespace mill {
namespace fs = std::filesystem;

std::string ore_hash(const config::Document& ore) { return jobs::job_id(config::ore_keys(ore)); }

bool fits_toughness(const config::CaseConfig& cfg) {
  return cfg.doc.boolean("calibrate.fit_toughness") &&
         estimate_bond_params(cfg.ore, cfg.doc).model == BondModel::flat_joint &&
         cfg.ore.has("fracture_toughness");
}

std::string calibration_hash(const config::CaseConfig& cfg) {
  if (!fits_toughness(cfg)) return ore_hash(cfg.ore);
  nlohmann::json keys = config::ore_keys(cfg.ore);
  keys["fracture_toughness"] = cfg.ore.real("fracture_toughness");
  return jobs::job_id(keys);
}

BondParams estimate_bond_params(const config::Document& ore, const config::Document& doc) {
  // Starting point only; `--stage calibrate` replaces it. Potyondy & Cundall
  // (2004, sec. 3 and table 1) report macro E close to the bond modulus for
  // radius multiplier 1 and kn/ks = 2.5 for nu ~ 0.2; a parallel-bond packing's
  // macro tensile strength is a fraction (~0.5) of the bond tensile strength.
  // The Mohr-Coulomb shear strength (cohesion + tan(phi) sigma_c) lets the
  // compressive/tensile ratio exceed what pure tension/shear bonds reach.
  BondParams b;
  for (const BondParameter& p : kBondParameters)
    if (!std::isnan(p.start)) b.*p.value = p.start;  // the rows with a constant start
  b.modulus = ore.real("youngs_modulus");
  b.tensile = 2.0 * ore.real("tensile_strength");
  b.cohesion = 2.0 * b.tensile;
  b.radius_multiplier = doc.real("lump.bond_radius_multiplier");
  b.model = bond_model_from(doc.str("lump.bond_model"));
  if (b.model == BondModel::flat_joint) {
    // Flat joints at bond gap 1.0 (coordination ~10, the 400-element
    // specimen; bench/README.md, "Strength ratio: coordination and cohesion
    // with the flat joint"): E_b 99.9 GPa, sigma_c 24.9 MPa, c = 10 sigma_c
    // gave E 50.4 GPa, tensile 30.6 MPa and UCS/T 9.68: start there, scaled.
    b.modulus = 2.0 * ore.real("youngs_modulus");
    b.tensile = 0.8 * ore.real("tensile_strength");
    b.cohesion = 10.0 * b.tensile;
  }
  b.joint_rings = static_cast<int>(doc.integer("lump.joint_rings"));
  b.joint_sectors = static_cast<int>(doc.integer("lump.joint_sectors"));
  b.origin = "closed-form estimate (not calibrated: run --stage calibrate)";
  return b;
}

namespace {
// Read the calibrated: map of a YAML file (calibrated.yaml or the ore card)
// if fitted to `hash` with the model and layout of `b`; false otherwise.
bool read_calibrated_file(const fs::path& file, const std::string& hash, BondParams& b) {
  if (!fs::exists(file)) return false;
  try {
    YAML::Node root = YAML::LoadFile(file.string());
    YAML::Node c = root.IsMap() ? root[kCalibratedSection] : YAML::Node();
    if (!c || !c.IsMap() || !c[kInputHashKey] || c[kInputHashKey].as<std::string>() != hash)
      return false;
    const BondParams fitted = read_calibrated(c, b);
    if (!same_model(fitted, b)) return false;  // fitted with another bond model
    b = fitted;
  } catch (const std::exception& e) {
    throw std::runtime_error(
        fmt::format("{}: damaged calibration ({}); rerun `orchestrate --stage calibrate` (or "
                    "repair the file)",
                    file.string(), e.what()));
  }
  b.origin = "calibrated (" + file.string() + ")";
  return true;
}
}  // namespace

BondParams bond_params_for(const config::CaseConfig& cfg, const fs::path& run_dir) {
  BondParams b = estimate_bond_params(cfg.ore, cfg.doc);
  const std::string hash = calibration_hash(cfg);
  BondParams c = b;
  if (read_calibrated_file(run_dir / "calibrate" / "calibrated.yaml", hash, c)) return c;
  if (read_calibrated_file(cfg.ore_file, hash, c)) return c;
  return b;
}

fs::path set_calibration_file(const fs::path& run_dir, int k) {
  return run_dir / "calibrate" / "sets" / ("start" + std::to_string(k)) / "calibrated.yaml";
}

BondParams bond_params_for_set(const config::CaseConfig& cfg, const fs::path& run_dir, int k) {
  if (k <= 1) return bond_params_for(cfg, run_dir);
  BondParams c = estimate_bond_params(cfg.ore, cfg.doc);
  const fs::path f = set_calibration_file(run_dir, k);
  if (!read_calibrated_file(f, calibration_hash(cfg), c))
    throw std::runtime_error(fmt::format(
        "{}: no calibration of start {} fitted to this ore card with the case's bond model "
        "({}); run `orchestrate --stage calibrate` with calibrate.starts >= {}",
        f.string(), k, fs::exists(f) ? "fitted to other properties or another model" : "missing",
        k));
  c.origin = fmt::format("calibration set {} ({})", k, f.string());
  return c;
}

std::vector<std::pair<std::string, std::string>> material_vars(const config::Document& ore,
                                                               const BondParams& b,
                                                               const config::Document& doc) {
  using engine::num;
  std::vector<std::pair<std::string, std::string>> v = {
      {"E", num(ore.real("youngs_modulus"))},
      {"nu", num(ore.real("poisson_ratio"))},
      {"density", num(ore.real("density"))},
      {"restitution", num(ore.real("restitution"))},
      {"friction", num(ore.real("friction"))}};
  for (auto& kv : bond_deck_vars(b)) {
    // The parallel bond's broken contacts are the case's (lump.broken_contact).
    if (kv.first == "bond_model_keys" && b.model == BondModel::parallel)
      kv.second += doc.boolean("lump.broken_contact") ? " broken_contact yes" : " broken_contact no";
    v.push_back(std::move(kv));
  }
  return v;
}

}  // namespace mill
