// The bond parameters' table (driver/lump/bond_parameters.h): the names it
// gives each format stay what jobs, calibrations and decks already use, its
// readers invert its writers, and every row reaches the decks and the style.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>

#include "config/case_config.h"
#include "lump/bond_parameters.h"

namespace fs = std::filesystem;
using namespace mill;

namespace {

const fs::path kProject = MILL_PROJECT_DIR;

std::string slurp(const fs::path& f) {
  std::ifstream in(f);
  EXPECT_TRUE(in) << f;
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// One set of parameters, by name (a new member keeps its default).
BondParams sample() {
  BondParams b;
  b.modulus = 18.69e9;
  b.stiffness_ratio = 2.5;
  b.tensile = 1.0e7;
  b.cohesion = 2.0e7;
  b.friction_angle_deg = 30;
  b.moment_factor = 0.5;
  b.radius_multiplier = 0.8;
  b.origin = "test";
  return b;
}

}  // namespace

// The job JSON keys are hashed into every breakage job's id: each of today's
// parameters keeps its key (a new row adds one, and changes the ids).
TEST(BondParameters, JobJsonKeysAreTheJobIdKeys) {
  const auto j = bond_json(sample(), BondNames::job);
  // and the model; a parallel bond has no flat-joint rows
  size_t joint_rows = 0;
  for (const BondParameter& p : kBondParameters) joint_rows += p.joint_only;
  EXPECT_EQ(j.size(), std::size(kBondParameters) - joint_rows + 1);
  EXPECT_EQ(j.value("bond_model", ""), "parallel");
  const std::pair<const char*, double> pinned[] = {
      {"modulus", 18.69e9},      {"stiffness_ratio", 2.5},   {"tensile", 1.0e7},
      {"cohesion", 2.0e7},       {"friction_angle_deg", 30}, {"moment_factor", 0.5},
      {"radius_multiplier", 0.8}};
  for (const auto& [key, value] : pinned) EXPECT_EQ(j.value(key, -1.0), value) << key;
  const auto r = bond_json(sample(), BondNames::report);
  for (const char* key :
       {"bond_modulus", "stiffness_ratio", "bond_tensile_strength", "bond_cohesion",
        "bond_friction_angle", "bond_moment_factor", "radius_multiplier"})
    EXPECT_TRUE(r.contains(key)) << key;
  EXPECT_EQ(bond_json(sample(), BondNames::card).value("calibrated.bond_tensile_strength", -1.0),
            1.0e7);
}

// A flat joint's JSON has its model and layout, and none of the parallel
// bond's own rows (fix bond/flatjoint refuses their keywords).
TEST(BondParameters, FlatJointJsonHasItsLayoutAndNoParallelRows) {
  BondParams b = sample();
  b.model = BondModel::flat_joint;
  b.joint_rings = 2;
  b.joint_sectors = 4;
  const auto j = bond_json(b, BondNames::job);
  EXPECT_EQ(j.value("bond_model", ""), "flat_joint");
  EXPECT_EQ(j.value("joint_rings", 0), 2);
  EXPECT_EQ(j.value("joint_sectors", 0), 4);
  // (its own rows only off their start: below)
  for (const BondParameter& p : kBondParameters)
    EXPECT_EQ(j.contains(p.json), !p.parallel_only && !p.joint_only) << p.json;
  EXPECT_EQ(bond_json(b, BondNames::card).value("calibrated.joint_sectors", 0), 4);
  EXPECT_FALSE(same_model(b, sample()));
  BondParams c = b;
  c.joint_sectors = 3;
  EXPECT_FALSE(same_model(b, c));
  c.joint_sectors = 4;
  c.cohesion *= 2;
  EXPECT_TRUE(same_model(b, c));
}

// The decks' variables of a model: the style, the model's own keywords.
TEST(BondParameters, DeckVariablesOfEachModel) {
  auto value = [](const BondParams& b, const std::string& key) {
    for (const auto& [k, v] : bond_deck_vars(b))
      if (k == key) return v;
    return std::string("(absent)");
  };
  BondParams b = sample();
  EXPECT_EQ(value(b, "bond_style"), "breakable");
  EXPECT_EQ(value(b, "bond_model_keys"), "moment_factor 0.5");
  EXPECT_EQ(value(b, "moment_factor"), "(absent)");  // in bond_model_keys
  EXPECT_EQ(value(b, "bond_tensile"), "10000000");
  b.model = BondModel::flat_joint;
  b.joint_rings = 1;
  b.joint_sectors = 5;
  EXPECT_EQ(value(b, "bond_style"), "flatjoint");
  EXPECT_EQ(value(b, "bond_model_keys"), "elements 1 5");
  b.joint_friction = 0.75;  // lump.joint_friction: the broken elements' mu
  EXPECT_EQ(value(b, "bond_model_keys"), "elements 1 5 joint_friction 0.75");
  // The tension softening (calibrated.joint_softening): a keyword of the
  // flat joint's once off its start (1, brittle), and in its maps then only.
  EXPECT_EQ(value(b, "joint_softening"), "(absent)");
  EXPECT_FALSE(bond_json(b, BondNames::job).contains("softening"));
  b.softening = 40;
  EXPECT_EQ(value(b, "bond_model_keys"), "softening 40 elements 1 5 joint_friction 0.75");
  EXPECT_EQ(bond_json(b, BondNames::job).value("softening", 0.0), 40.0);
  EXPECT_EQ(bond_json(b, BondNames::card).value("calibrated.joint_softening", 0.0), 40.0);
  b.model = BondModel::parallel;  // no such keyword: never passed
  EXPECT_EQ(value(b, "bond_model_keys"), "moment_factor 0.5");
  EXPECT_FALSE(bond_json(b, BondNames::job).contains("softening"));
}

// A flat-joint calibration with its softening reads back; one without it
// (made before the row) reads the start, 1.
TEST(BondParameters, JointSofteningRoundTripsAndDefaultsToBrittle) {
  BondParams b = sample();
  b.model = BondModel::flat_joint;
  b.softening = 25;
  YAML::Emitter y;
  y << YAML::BeginMap;
  emit_calibrated(y, b, "abc");
  y << YAML::EndMap;
  const YAML::Node node = YAML::Load(y.c_str())["calibrated"];
  EXPECT_EQ(node["joint_softening"].as<double>(), 25.0);
  EXPECT_EQ(read_calibrated(node, BondParams{}).softening, 25.0);
  YAML::Node old = YAML::Clone(node);
  old.remove("joint_softening");
  EXPECT_EQ(read_calibrated(old, BondParams{}).softening, 1.0);
}

// calibrated.yaml's map: today's lines, byte for byte and in this order, then
// the input hash last; read back.
TEST(BondParameters, CalibratedMapRoundTrips) {
  YAML::Emitter y;
  y.SetDoublePrecision(8);
  y << YAML::BeginMap;
  emit_calibrated(y, sample(), "abc");
  y << YAML::EndMap;
  const std::string text = y.c_str();
  size_t at = 0;
  for (const char* line :
       {"calibrated:\n", "  bond_model: parallel\n", "  bond_modulus: 1.869e+10\n", "  stiffness_ratio: 2.5\n",
        "  bond_tensile_strength: 10000000\n", "  bond_cohesion: 20000000\n",
        "  bond_friction_angle: 30\n", "  bond_moment_factor: 0.5\n"}) {
    const size_t found = text.find(line, at);
    ASSERT_NE(found, std::string::npos) << line << " in\n" << text;
    at = found + std::string(line).size();
  }
  const std::string last = "\n  input_hash: abc";
  EXPECT_EQ(text.substr(text.size() - last.size()), last) << text;
  EXPECT_EQ(text.rfind("calibrated:\n  bond_model: parallel\n  bond_modulus:", 0), 0u) << text;
  BondParams base;
  base.radius_multiplier = 0.8;  // not fitted: kept from base
  const BondParams r = read_calibrated(YAML::Load(text)["calibrated"], base);
  EXPECT_EQ(bond_json(r, BondNames::job), bond_json(sample(), BondNames::job));
}

// A flat joint's calibration: its model and layout, no moment factor; read
// back. A map of a flat joint without its layout is an error naming the key.
TEST(BondParameters, FlatJointCalibratedMapRoundTrips) {
  BondParams b = sample();
  b.model = BondModel::flat_joint;
  b.joint_rings = 2;
  b.joint_sectors = 3;
  YAML::Emitter y;
  y.SetDoublePrecision(8);
  y << YAML::BeginMap;
  emit_calibrated(y, b, "abc");
  y << YAML::EndMap;
  const std::string text = y.c_str();
  EXPECT_EQ(text.rfind("calibrated:\n  bond_model: flat_joint\n  joint_rings: 2\n  joint_sectors: 3\n", 0), 0u)
      << text;
  EXPECT_EQ(text.find("moment_factor"), std::string::npos) << text;
  BondParams base;
  base.radius_multiplier = 0.8;
  const BondParams r = read_calibrated(YAML::Load(text)["calibrated"], base);
  EXPECT_EQ(bond_json(r, BondNames::job), bond_json(b, BondNames::job));
  try {
    read_calibrated(YAML::Load("{bond_model: flat_joint, joint_rings: 1, bond_modulus: 1}"), BondParams{});
    FAIL() << "no error for a missing layout";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("calibrated.joint_sectors"), std::string::npos) << e.what();
  }
  try {
    read_calibrated(YAML::Load("{bond_model: glue}"), BondParams{});
    FAIL() << "no error for an unknown model";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("calibrated.bond_model"), std::string::npos) << e.what();
  }
}

// An optional row absent from a calibration takes its start; a required one
// is an error naming the key.
TEST(BondParameters, AbsentKeysOfACalibration) {
  const YAML::Node old = YAML::Load(
      "{bond_modulus: 1, stiffness_ratio: 2, bond_tensile_strength: 3, bond_cohesion: 4, "
      "bond_friction_angle: 5}");
  EXPECT_EQ(read_calibrated(old, BondParams{}).moment_factor, 1.0);
  try {
    read_calibrated(YAML::Load("{bond_modulus: 1}"), BondParams{});
    FAIL() << "no error for a missing key";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("calibrated.stiffness_ratio"), std::string::npos)
        << e.what();
  }
}

// Every shared row's deck variable is declared by each deck that bonds (a
// default that -var overrides) and passed to the style's keyword; the
// parallel bond's own rows are in the decks' default bond_model_keys, which
// each deck passes with the style bond/${bond_style}; the style reads every
// keyword.
TEST(BondParameters, EveryRowReachesTheDecksAndTheStyle) {
  const fs::path decks = kProject / "liggghts_inputs";
  const fs::path style = kProject / "liggghts_styles" / "fix_bond_breakable.cpp";
  const char* declaring[] = {"impact.in.tmpl", "in_mill.in.tmpl", "ucs.in.tmpl",
                             "brazilian.in.tmpl", "triaxial.in.tmpl", "scb.in.tmpl"};
  const char* bonding[] = {"lump_bonds.in", "ucs.in.tmpl", "brazilian.in.tmpl",
                           "triaxial.in.tmpl", "scb.in.tmpl"};
  for (const char* deck : declaring)
    for (const char* v : {"bond_style", "bond_model_keys"})
      EXPECT_NE(slurp(decks / deck).find(std::string("variable ") + v + " "), std::string::npos)
          << deck << " does not declare " << v;
  for (const char* deck : bonding) {
    EXPECT_NE(slurp(decks / deck).find("fix bonds all bond/${bond_style} "), std::string::npos)
        << deck;
    EXPECT_NE(slurp(decks / deck).find(" ${bond_model_keys} "), std::string::npos) << deck;
  }
  for (const BondParameter& p : kBondParameters) {
    if (p.joint_only) {
      // Passed in bond_model_keys by the flat joint only (its start: not at all).
    } else if (p.parallel_only) {
      for (const char* deck : declaring)
        EXPECT_NE(slurp(decks / deck).find(std::string("bond_model_keys  index \"") + p.keyword),
                  std::string::npos)
            << deck << ": " << p.keyword << " not in the default bond_model_keys";
    } else {
      for (const char* deck : declaring)
        EXPECT_NE(slurp(decks / deck).find(std::string("variable ") + p.deck + " "),
                  std::string::npos)
            << deck << " does not declare " << p.deck;
      const std::string passed = std::string(p.keyword) + " ${" + p.deck + "}";
      for (const char* deck : bonding)
        EXPECT_NE(slurp(decks / deck).find(passed), std::string::npos) << deck << ": " << passed;
    }
    if (fs::exists(style)) {
      EXPECT_NE(slurp(style).find(std::string("key == \"") + p.keyword + "\""), std::string::npos)
          << p.keyword;
    }
  }
}
