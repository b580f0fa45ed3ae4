// The input_hash that ties a calibration to its ore card (lump/material.h,
// calibration_hash): the card's macro properties, and its K_IC when the flat
// joint's fit aims at it, so that a section fitted to another K_IC is stale.
#include <gtest/gtest.h>
#include <unistd.h>

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
  EXPECT_NE(mill::calibration_hash(a), mill::ore_hash(a.ore));
  // Where K_IC is no target (the parallel bond; the key off) the hash is the card's.
  const auto p = with_card(dir / "p", 0.73e6, "{n_elements: 200}"),
             q = with_card(dir / "q", 0.90e6, "{n_elements: 200}");
  EXPECT_FALSE(mill::fits_toughness(p));
  EXPECT_EQ(mill::calibration_hash(p), mill::ore_hash(p.ore));
  EXPECT_EQ(mill::calibration_hash(p), mill::calibration_hash(q));
  const auto off = with_card(dir / "off", 0.73e6, fj, "calibrate: {fit_toughness: false}\n");
  EXPECT_FALSE(mill::fits_toughness(off));
  EXPECT_EQ(mill::calibration_hash(off), mill::ore_hash(off.ore));
}
