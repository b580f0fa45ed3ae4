// Ore material and bond parameters for the decks.
#include "lump/material.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cmath>

#include "engine/liggghts.h"
#include "jobs/job_store.h"
#include "lump/packing.h"

namespace mill {
namespace fs = std::filesystem;

std::string ore_hash(const config::Document& ore) { return jobs::job_id(config::ore_keys(ore)); }

bool fits_toughness(const config::CaseConfig& cfg) {
  return cfg.doc.boolean("calibrate.fit_toughness") &&
         estimate_bond_params(cfg.ore, cfg.doc).model == BondModel::flat_joint &&
         cfg.ore.has("fracture_toughness");
}

nlohmann::json lump_scale(const config::CaseConfig& cfg) {
  const config::Document& d = cfg.doc;
  // Six significant digits: the same lump gives the same radius on any
  // machine, and a lump of 8 x the elements in 2 x the diameter the same.
  const double r = target_mean_radius(d.integer("lump.n_elements"), d.real("lump.diameter"),
                                      d.real("lump.radius_spread"));
  nlohmann::json s = {{"element_radius_m", std::stod(fmt::format("{:.6g}", r))},
                      {"radius_spread", d.real("lump.radius_spread")},
                      {"bond_gap", d.real("lump.bond_gap")},
                      {"bond_radius_multiplier", d.real("lump.bond_radius_multiplier")}};
  if (bond_model_from(d.str("lump.bond_model")) == BondModel::parallel)
    s["broken_contact"] = d.boolean("lump.broken_contact");
  // Absent, the broken elements' friction follows the fitted friction angle:
  // no entry, so the calibrations made before the key still hold.
  else if (d.has("lump.joint_friction"))
    s["joint_friction"] = d.real("lump.joint_friction");
  return s;
}

double direct_over_brazilian(const config::Document& ore) {
  if (!ore.has("rock_class"))
    throw config::ConfigError(fmt::format(
        "{}: rock_class is not given: calibrate.tensile_test direct needs the card's "
        "direct_tensile_strength [Pa] or its rock_class (sedimentary, igneous or metamorphic) to "
        "convert tensile_strength (Perras & Diederichs 2014)",
        ore.file()));
  const std::string c = ore.str("rock_class");
  if (c == "sedimentary") return 0.7;
  if (c == "igneous") return 0.8;
  if (c == "metamorphic") return 0.9;
  throw config::ConfigError(
      fmt::format("{}: rock_class: expected sedimentary, igneous or metamorphic, got '{}'",
                  ore.where("rock_class"), c));
}

bool fits_direct_tension(const config::CaseConfig& cfg) {
  return cfg.doc.str("calibrate.tensile_test") == "direct";
}

double tensile_target(const config::CaseConfig& cfg) {
  const config::Document& o = cfg.ore;
  if (!fits_direct_tension(cfg)) return o.real("tensile_strength");
  if (o.has("direct_tensile_strength")) return o.real("direct_tensile_strength");
  return direct_over_brazilian(o) * o.real("tensile_strength");
}

std::string calibration_hash(const config::CaseConfig& cfg) {
  nlohmann::json keys = {{"ore", config::ore_keys(cfg.ore)}, {"lump_scale", lump_scale(cfg)}};
  if (fits_toughness(cfg)) keys["fracture_toughness"] = cfg.ore.real("fracture_toughness");
  if (fits_direct_tension(cfg)) keys["direct_tensile_strength"] = tensile_target(cfg);
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
  if (doc.has("lump.joint_friction")) b.joint_friction = doc.real("lump.joint_friction");
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

// What a calibrated: map `c` (complete, with another input_hash than the
// case's, or another model) was fitted for, against the case: one clause.
std::string mismatch(const YAML::Node& c, const config::CaseConfig& cfg) {
  const BondParams want = estimate_bond_params(cfg.ore, cfg.doc);
  const BondParams got = read_calibrated(c, want);
  if (!same_model(got, want))
    return fmt::format("fitted with the {}, the case uses the {} (lump.bond_model, lump.joint_*)",
                       bond_model_text(got), bond_model_text(want));
  const YAML::Node f = c[kFittedForKey];
  if (!f || !f.IsMap())
    return "fitted to other card properties, or by a version that did not record the lump's scale "
           "(calibrated.fitted_for)";
  const nlohmann::json scale = lump_scale(cfg);
  std::vector<std::string> diffs;
  for (const auto& [k, v] : scale.items()) {
    if (!f[k]) continue;
    const std::string mine = v.is_boolean() ? (v.get<bool>() ? "true" : "false")
                                            : fmt::format("{:.6g}", v.get<double>());
    const std::string theirs = f[k].as<std::string>();
    const bool same = v.is_boolean() ? theirs == mine
                                     : std::abs(f[k].as<double>() - v.get<double>()) <=
                                           1e-6 * std::abs(v.get<double>());
    if (!same) diffs.push_back(fmt::format("{} {} (this case: {})", k, theirs, mine));
  }
  // The broken elements' friction is recorded only when set: absent on one
  // side is "not set" (the style's tan(phi_b)), not an older format.
  const char* jf = "joint_friction";
  if (f[jf].IsDefined() != scale.contains(jf))
    diffs.push_back(f[jf] ? fmt::format("{} {} (this case: not set)", jf, f[jf].as<std::string>())
                          : fmt::format("{} not set (this case: {:.6g})", jf, scale[jf].get<double>()));
  if (diffs.empty()) return "fitted to other card properties (its input_hash is another)";
  std::string out = "fitted for another lump scale: ";
  for (size_t i = 0; i < diffs.size(); ++i) out += (i ? ", " : "") + diffs[i];
  return out +
         "; the scale follows lump.n_elements, lump.diameter, lump.radius_spread, "
         "lump.bond_gap, lump.bond_radius_multiplier, lump.broken_contact and lump.joint_friction";
}

// Why `file` gives no calibration for the case; empty when it does.
std::string file_reason(const fs::path& file, const config::CaseConfig& cfg, const char* what) {
  if (!fs::exists(file)) return fmt::format("no {} ({})", what, file.string());
  try {
    BondParams b = estimate_bond_params(cfg.ore, cfg.doc);
    if (read_calibrated_file(file, calibration_hash(cfg), b)) return "";
    // Not taken: read it again only to say why.
    const YAML::Node root = YAML::LoadFile(file.string());
    const YAML::Node c = root.IsMap() ? root[kCalibratedSection] : YAML::Node();
    if (!c || !c.IsMap() || !c[kInputHashKey])
      return fmt::format("{} {} has no complete calibrated: section", what, file.string());
    return fmt::format("{} {}: {}", what, file.string(), mismatch(c, cfg));
  } catch (const std::exception& e) {
    return fmt::format("{} {}: unreadable ({})", what, file.string(), e.what());
  }
}
}  // namespace

std::string uncalibrated_reason(const config::CaseConfig& cfg, const fs::path& run_dir) {
  const std::string run =
      file_reason(run_dir / "calibrate" / "calibrated.yaml", cfg, "calibration");
  if (run.empty()) return "";
  const std::string card = file_reason(cfg.ore_file, cfg, "ore card");
  if (card.empty()) return "";
  return run + "; " + card;
}

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
        f.string(), k,
        fs::exists(f) ? "fitted to other properties, another lump scale or another model"
                      : "missing",
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
