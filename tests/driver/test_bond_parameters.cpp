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
  EXPECT_EQ(j.size(), std::size(kBondParameters));
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
       {"calibrated:\n", "  bond_modulus: 1.869e+10\n", "  stiffness_ratio: 2.5\n",
        "  bond_tensile_strength: 10000000\n", "  bond_cohesion: 20000000\n",
        "  bond_friction_angle: 30\n", "  bond_moment_factor: 0.5\n"}) {
    const size_t found = text.find(line, at);
    ASSERT_NE(found, std::string::npos) << line << " in\n" << text;
    at = found + std::string(line).size();
  }
  const std::string last = "\n  input_hash: abc";
  EXPECT_EQ(text.substr(text.size() - last.size()), last) << text;
  EXPECT_EQ(text.rfind("calibrated:\n  bond_modulus:", 0), 0u) << text;
  BondParams base;
  base.radius_multiplier = 0.8;  // not fitted: kept from base
  const BondParams r = read_calibrated(YAML::Load(text)["calibrated"], base);
  EXPECT_EQ(bond_json(r, BondNames::job), bond_json(sample(), BondNames::job));
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

// Every row's deck variable is declared by each deck that bonds (a default
// that -var overrides) and passed to the style's keyword; the style reads
// that keyword.
TEST(BondParameters, EveryRowReachesTheDecksAndTheStyle) {
  const fs::path decks = kProject / "liggghts_inputs";
  const fs::path style = kProject / "liggghts_styles" / "fix_bond_breakable.cpp";
  for (const BondParameter& p : kBondParameters) {
    for (const char* deck :
         {"impact.in.tmpl", "in_mill.in.tmpl", "ucs.in.tmpl", "brazilian.in.tmpl"}) {
      EXPECT_NE(slurp(decks / deck).find(std::string("variable ") + p.deck + " "),
                std::string::npos)
          << deck << " does not declare " << p.deck;
    }
    const std::string passed = std::string(p.keyword) + " ${" + p.deck + "}";
    for (const char* deck : {"lump_bonds.in", "ucs.in.tmpl", "brazilian.in.tmpl"}) {
      EXPECT_NE(slurp(decks / deck).find(passed), std::string::npos) << deck << ": " << passed;
    }
    if (fs::exists(style)) {
      EXPECT_NE(slurp(style).find(std::string("key == \"") + p.keyword + "\""), std::string::npos)
          << p.keyword;
    }
  }
}
