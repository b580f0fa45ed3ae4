// The input_hash that ties a calibration to its ore card and lump
// (lump/material.h, calibration_hash): the card's macro properties, its K_IC
// when the flat joint's fit aims at it, so that a section fitted to another
// K_IC is stale, and the lump's scale (element radius, bonding range), so
// that a section fitted at another element size is not taken either.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "config/case_config.h"
#include "lump/material.h"
#include "temp_dir.h"

namespace fs = std::filesystem;

namespace {

const fs::path kProject = MILL_PROJECT_DIR;

// A case in `dir` on a copy of the sandstone card with K_IC `kic` [Pa m^0.5].
mill::config::CaseConfig with_card(const fs::path& dir, double kic, const std::string& lump,
                                   const std::string& calibrate = "") {
  fs::create_directories(dir);
  std::ifstream in(kProject / "liggghts_inputs" / "materials" / "sandstone.yaml");
  std::stringstream card;
  card << in.rdbuf();
  const std::string text =
      std::regex_replace(card.str(), std::regex("fracture_toughness: [0-9.e+]+"),
                         "fracture_toughness: " + std::to_string(kic));
  std::ofstream(dir / "card.yaml") << text;
  std::ofstream(dir / "case.yaml") << "name: h\nore: {card: card.yaml}\nlump: " << lump << "\n"
                                   << calibrate;
  return mill::config::load_case(dir / "case.yaml", kProject);
}

}  // namespace

TEST(CalibrationHash, FlatJointToughnessFitHashesTheCardsToughness) {
  const mill::test::TempDir dir("mill_cal_hash_" + std::to_string(getpid()));
  const std::string fj = "{bond_model: flat_joint, bond_gap: 1.0, max_bonds: 32}";
  const auto a = with_card(dir / "a", 0.73e6, fj), b = with_card(dir / "b", 0.90e6, fj);
  ASSERT_TRUE(mill::fits_toughness(a));
  EXPECT_EQ(mill::ore_hash(a.ore), mill::ore_hash(b.ore));  // K_IC is a check key there
  EXPECT_NE(mill::calibration_hash(a), mill::calibration_hash(b));
  // Where K_IC is no target (the parallel bond; the key off) it is not hashed.
  const auto p = with_card(dir / "p", 0.73e6, "{n_elements: 200}"),
             q = with_card(dir / "q", 0.90e6, "{n_elements: 200}");
  EXPECT_FALSE(mill::fits_toughness(p));
  EXPECT_EQ(mill::calibration_hash(p), mill::calibration_hash(q));
  const auto off = with_card(dir / "off", 0.73e6, fj, "calibrate: {fit_toughness: false}\n"),
             off2 = with_card(dir / "off2", 0.90e6, fj, "calibrate: {fit_toughness: false}\n");
  EXPECT_FALSE(mill::fits_toughness(off));
  EXPECT_EQ(mill::calibration_hash(off), mill::calibration_hash(off2));
}

// A bonded packing's strengths and toughness follow its element size and
// coordination (bench/README.md, "K_IC over the element sizes"): the hash
// changes with the element radius (element count or diameter), the spread,
// the bonding range and the broken contacts, and with nothing that leaves
// them (the packing's seed, the number of packings, the bond slots).
TEST(CalibrationHash, FollowsTheElementSizeAndBondingRangeOnly) {
  const mill::test::TempDir dir("mill_cal_scale_" + std::to_string(getpid()));
  const auto h = [&](const std::string& name, const std::string& lump) {
    return mill::calibration_hash(with_card(dir / name, 0.73e6, lump));
  };
  const std::string base = h("base", "{n_elements: 2000, diameter: 0.04}");
  EXPECT_NE(base, h("n3344", "{n_elements: 3344, diameter: 0.04}"));
  EXPECT_NE(base, h("d50", "{n_elements: 2000, diameter: 0.05}"));
  EXPECT_NE(base, h("gap", "{n_elements: 2000, diameter: 0.04, bond_gap: 0.3}"));
  EXPECT_NE(base, h("spread", "{n_elements: 2000, diameter: 0.04, radius_spread: 0.2}"));
  EXPECT_NE(base, h("mult", "{n_elements: 2000, diameter: 0.04, bond_radius_multiplier: 0.8}"));
  EXPECT_NE(base, h("broken", "{n_elements: 2000, diameter: 0.04, broken_contact: true}"));
  EXPECT_EQ(base, h("seed", "{n_elements: 2000, diameter: 0.04, seed: 7, n_packings: 3}"));
  EXPECT_EQ(base, h("slots", "{n_elements: 2000, diameter: 0.04, max_bonds: 24}"));
}

// A card whose calibrated: section was fitted at another element size is
// not used for this lump: the run falls back to the closed-form estimate
// and says why, naming the radius it was fitted at and this lump's.
TEST(CalibrationHash, CardFittedAtAnotherElementSizeIsNotUsedAndSaysWhy) {
  const mill::test::TempDir dir("mill_cal_card_" + std::to_string(getpid()));
  const std::string fj = "{bond_model: flat_joint, bond_gap: 1.0, max_bonds: 32, n_elements: ";
  const auto at2000 = with_card(dir / "a", 0.73e6, fj + "2000}");
  // The section as the calibrate stage writes it for the 2000-element lump.
  YAML::Emitter y;
  y << YAML::BeginMap;
  mill::BondParams fitted = mill::estimate_bond_params(at2000.ore, at2000.doc);
  fitted.tensile = 11.2e6;
  mill::emit_calibrated(y, fitted, mill::calibration_hash(at2000), mill::lump_scale(at2000));
  y << YAML::EndMap;
  std::ifstream in(dir / "a" / "card.yaml");
  std::stringstream card;
  card << in.rdbuf();
  const std::string with_section = card.str() + "\n" + y.c_str() + "\n";
  const auto write_case = [&](const std::string& name, const std::string& lump) {
    fs::create_directories(dir / name);
    std::ofstream(dir / name / "card.yaml") << with_section;
    std::ofstream(dir / name / "case.yaml")
        << "name: h\nore: {card: card.yaml}\nlump: " << lump << "\n";
    return mill::config::load_case(dir / name / "case.yaml", kProject);
  };
  const auto same = write_case("same", fj + "2000}");
  EXPECT_EQ(mill::uncalibrated_reason(same, dir / "same" / "run"), "");
  EXPECT_DOUBLE_EQ(mill::bond_params_for(same, dir / "same" / "run").tensile, 11.2e6);

  const auto finer = write_case("finer", fj + "3344}");
  const mill::BondParams b = mill::bond_params_for(finer, dir / "finer" / "run");
  EXPECT_NE(b.tensile, 11.2e6);
  EXPECT_NE(b.origin.find("closed-form"), std::string::npos) << b.origin;
  const std::string why = mill::uncalibrated_reason(finer, dir / "finer" / "run");
  const auto mm = [](const mill::config::CaseConfig& c) {
    return fmt::format("{:.6g}", mill::lump_scale(c)["element_radius_m"].get<double>());
  };
  EXPECT_NE(why.find("fitted for another lump scale"), std::string::npos) << why;
  EXPECT_NE(why.find("element_radius_m " + mm(at2000) + " (this case: " + mm(finer) + ")"),
            std::string::npos)
      << why;
  EXPECT_EQ(why.find("bond_gap 1"), std::string::npos) << why;  // the same range: no difference
  EXPECT_NE(why.find("calibrated.yaml"), std::string::npos) << why;  // the run's file looked at
}

// The flat joint's broken-element friction (lump.joint_friction) moves the
// strength ratio (bench/README.md, "UCS/T of 10 at bond gap 1.4"): set, it is
// part of the scale; absent, the hash is the one of the calibrations made
// before the key; a section fitted without it is not taken with it, and says
// so both ways.
TEST(CalibrationHash, JointFrictionIsPartOfTheFlatJointsScale) {
  const mill::test::TempDir dir("mill_cal_jf_" + std::to_string(getpid()));
  const std::string fj = "{bond_model: flat_joint, bond_gap: 1.4, max_bonds: 48, n_elements: 2000";
  const auto none = with_card(dir / "none", 0.73e6, fj + "}"),
             one = with_card(dir / "one", 0.73e6, fj + ", joint_friction: 1.0}"),
             other = with_card(dir / "other", 0.73e6, fj + ", joint_friction: 0.8}");
  EXPECT_FALSE(mill::lump_scale(none).contains("joint_friction"));
  EXPECT_DOUBLE_EQ(mill::lump_scale(one)["joint_friction"].get<double>(), 1.0);
  EXPECT_NE(mill::calibration_hash(none), mill::calibration_hash(one));
  EXPECT_NE(mill::calibration_hash(one), mill::calibration_hash(other));
  EXPECT_DOUBLE_EQ(mill::estimate_bond_params(one.ore, one.doc).joint_friction, 1.0);
  EXPECT_LT(mill::estimate_bond_params(none.ore, none.doc).joint_friction, 0);

  // A run folder whose calibrated.yaml was fitted without the key.
  const auto section = [&](const mill::config::CaseConfig& c) {
    YAML::Emitter y;
    y << YAML::BeginMap;
    mill::emit_calibrated(y, mill::estimate_bond_params(c.ore, c.doc), mill::calibration_hash(c),
                          mill::lump_scale(c));
    y << YAML::EndMap;
    return std::string(y.c_str()) + "\n";
  };
  const fs::path run = dir / "run";
  fs::create_directories(run / "calibrate");
  std::ofstream(run / "calibrate" / "calibrated.yaml") << section(none);
  EXPECT_EQ(mill::uncalibrated_reason(none, run), "");
  const std::string why = mill::uncalibrated_reason(one, run);
  EXPECT_NE(why.find("joint_friction not set (this case: 1)"), std::string::npos) << why;
  std::ofstream(run / "calibrate" / "calibrated.yaml") << section(one);
  const std::string back = mill::uncalibrated_reason(none, run);
  EXPECT_NE(back.find("joint_friction 1 (this case: not set)"), std::string::npos) << back;
  EXPECT_NE(mill::uncalibrated_reason(other, run).find("joint_friction 1 (this case: 0.8)"),
            std::string::npos);
}

// calibrate.tensile_test direct aims at the card's direct tensile strength,
// else at its Brazilian one x f of its rock_class (Perras & Diederichs 2014:
// 0.7 sedimentary, 0.8 igneous, 0.9 metamorphic). The target is hashed where
// the fit aims at it, and rock_class and direct_tensile_strength change
// nothing where it does not (a Brazilian fit keeps its hash).
TEST(CalibrationHash, DirectTensionAimsAtTheConvertedStrengthAndHashesIt) {
  const mill::test::TempDir dir("mill_cal_direct_" + std::to_string(getpid()));
  const std::string lump = "{n_elements: 200}";
  const std::string direct = "calibrate: {tensile_test: direct}\n";
  // The card with its rock_class line replaced by `extra` (sandstone: 5 MPa Brazilian).
  auto card = [&](const std::string& name, const std::string& extra, const std::string& cal) {
    const auto c = with_card(dir / name, 0.73e6, lump, cal);
    std::ifstream in(dir / name / "card.yaml");
    std::stringstream text;
    text << in.rdbuf();
    std::ofstream(dir / name / "card.yaml")
        << std::regex_replace(text.str(), std::regex("\nrock_class: [a-z]+"), "\n" + extra);
    return mill::config::load_case(dir / name / "case.yaml", kProject);
  };
  const auto brazilian = card("b", "rock_class: sedimentary", "");
  EXPECT_FALSE(mill::fits_direct_tension(brazilian));
  EXPECT_EQ(mill::tensile_target(brazilian), 5e6);
  const auto sed = card("s", "rock_class: sedimentary", direct);
  const auto ign = card("i", "rock_class: igneous", direct);
  const auto met = card("m", "rock_class: metamorphic", direct);
  EXPECT_TRUE(mill::fits_direct_tension(sed));
  EXPECT_NEAR(mill::tensile_target(sed), 3.5e6, 1e-6);
  EXPECT_NEAR(mill::tensile_target(ign), 4.0e6, 1e-6);
  EXPECT_NEAR(mill::tensile_target(met), 4.5e6, 1e-6);
  // A measured direct strength wins over the conversion.
  const auto measured =
      card("d", "rock_class: sedimentary\ndirect_tensile_strength: 4.2e6", direct);
  EXPECT_EQ(mill::tensile_target(measured), 4.2e6);
  // Hashes: the direct target is part of the fit's inputs ...
  EXPECT_NE(mill::calibration_hash(sed), mill::calibration_hash(brazilian));
  EXPECT_NE(mill::calibration_hash(sed), mill::calibration_hash(ign));
  EXPECT_NE(mill::calibration_hash(sed), mill::calibration_hash(measured));
  // ... and nothing of a Brazilian fit (nor of any other stage: ore_hash).
  const auto other = card("o", "rock_class: igneous\ndirect_tensile_strength: 4.2e6", "");
  EXPECT_EQ(mill::calibration_hash(other), mill::calibration_hash(brazilian));
  EXPECT_EQ(mill::ore_hash(other.ore), mill::ore_hash(brazilian.ore));
}
