// Case-file and ore-card validation: every bad file names its key and line.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>

#include "config/case_config.h"
#include "config/schema.h"
#include "stages/breakage/lump_run.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using mill::config::ConfigError;
using mill::config::load_case;

namespace {

const fs::path kData = MILL_TEST_DATA;
const fs::path kBadInput = MILL_BAD_INPUT_DIR;
const fs::path kProject = MILL_PROJECT_DIR;

// Load a bad case from tests/bad_input/ and return the error text (fails the test if none).
std::string error_of(const std::string& file) {
  try {
    load_case(kBadInput / file, kProject);
  } catch (const ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << file << " was accepted";
  return "";
}

struct BadCase {
  const char* file;
  std::vector<std::string> must_contain;  // key, line, value, expectation
};

// Short test names in CTest output.
void PrintTo(const BadCase& c, std::ostream* os) { *os << c.file; }

class BadCaseTest : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadCaseTest, MessageNamesKeyAndLine) {
  const BadCase& c = GetParam();
  const std::string msg = error_of(c.file);
  for (const auto& s : c.must_contain) EXPECT_NE(msg.find(s), std::string::npos) << "missing '" << s << "' in: " << msg;
}

INSTANTIATE_TEST_SUITE_P(
    Files, BadCaseTest,
    ::testing::Values(
        BadCase{
            "bad_unknown_key.yaml",
            {"bad_unknown_key.yaml:3:", "rotor.rmp", "unknown key", "did you mean 'rotor.rpm'"}},
        BadCase{"bad_unknown_section.yaml", {":2:", "breakge", "did you mean 'breakage'"}},
        BadCase{"bad_wrong_type.yaml",
                {":3:", "lump.n_elements", "'many'", "integer in [10, 10000000]"}},
        BadCase{"bad_negative_velocity.yaml",
                {":3:", "breakage.velocities[2]", "-3", "(0, 500] m/s"}},
        BadCase{"bad_choice.yaml",
                {":3:", "gas.model", "'supersonic'", "one of incompressible, compressible"}},
        BadCase{"bad_angle_range.yaml", {":3:", "breakage.angles[1]", "120", "(0, 90] deg"}},
        BadCase{"bad_missing_ore.yaml",
                {":3:", "ore.card", "unobtainium.yaml", "not found", "sandstone"}},
        BadCase{"bad_hub_too_big.yaml",
                {":5:", "mill.flywheel.hub_diameter", "1.2", "less than mill.flywheel.diameter"}},
        BadCase{"bad_section_is_scalar.yaml", {":2:", "mill", "expected a section"}},
        BadCase{"bad_not_yaml.yaml", {"bad_not_yaml.yaml:", "not valid YAML"}},
        BadCase{"bad_edges_order.yaml",
                {":3:", "breakage.size_fraction_edges", "ascending", "0.1 after 0.2"}},
        BadCase{"bad_bool.yaml", {":3:", "sample.turbulence", "'maybe'", "true or false"}},
        BadCase{"bad_sliding_threshold.yaml",
                {":3:", "transport.sliding_threshold", "0", "> 0 m/s"}},
        BadCase{"bad_int_float.yaml", {":3:", "injection.n_lumps", "'36.5'", "integer"}},
        BadCase{"bad_flywheel_too_tall.yaml",
                {":4:", "mill.flywheel.axis_height", "0.3", "must fit"}},
        BadCase{"bad_ore_ucs.yaml", {"bad_ore_ucs_card.yaml:5:", "ucs", "tensile_strength"}},
        BadCase{"bad_ore_nu.yaml", {"bad_ore_nu_card.yaml:4:", "poisson_ratio", "0.5", "[0, 0.5)"}},
        BadCase{"bad_ore_negative_E.yaml",
                {"bad_ore_negative_E_card.yaml:3:", "youngs_modulus", "-10.0e9", "> 0 Pa"}},
        BadCase{"bad_ore_missing_key.yaml",
                {"bad_ore_missing_key_card.yaml", "ucs", "required key is missing"}},
        BadCase{"bad_ore_moment_factor.yaml",
                {"bad_ore_moment_factor_card.yaml:8:", "calibrated.bond_moment_factor", "1.5",
                 "[0, 1]"}},
        BadCase{"bad_resources_time.yaml",
                {":3:", "resources.breakage.time", "'2 hours'", "Slurm wall time"}},
        BadCase{"bad_resources_partition.yaml",
                {":4:", "resources.flow.partition", "'big\\x0anodes'", "partition name"}},
        BadCase{"bad_resources_np.yaml", {":3:", "resources.breakage.np", "integer >= 1", "got 0"}},
        BadCase{"bad_ore_jk_A.yaml", {"bad_ore_jk_A_card.yaml:8:", "jk.A", "120", "(0, 100] %"}},
        BadCase{"bad_ore_jk_pair.yaml", {"bad_ore_jk_pair_card.yaml:8:", "jk.b", "without jk.A"}},
        BadCase{"calibrate_direct_without_class.yaml",
                {":5:", "calibrate.tensile_test", "calibrate_direct_without_class_card.yaml",
                 "direct_tensile_strength", "rock_class", "sedimentary, igneous or metamorphic"}},
        BadCase{"ore_friction_angle.yaml",
                {"ore_friction_angle_card.yaml:7:", "friction_angle", "120", "(0, 90) deg"}},
        BadCase{"bad_confining_pressure.yaml",
                {":3:", "calibrate.confining_pressures[1]", "0.5", "(0, 0.25] x ucs"}},
        BadCase{"slip_ucs_mpa.yaml",
                {"slip_ucs_mpa_card.yaml:5:", "ucs: 50 Pa", "did you mean 50 MPa",
                 "Hoek & Brown 1997", "allow_outside_range"}},
        BadCase{"slip_mill_mm.yaml",
                {":4:", "mill.flywheel.diameter: 1000 m", "did you mean 1000 mm (1 m)?"}},
        BadCase{"slip_rpm_rad_s.yaml", {":4:", "rotor.rpm[0]", "157.1 rad/s"}},
        BadCase{"slip_gas_celsius.yaml", {":4:", "gas.temperature", "20 degC (293.15 K)"}},
        BadCase{"slip_allow_unknown_key.yaml",
                {"_card.yaml:7:", "allow_outside_range[0]", "'ucss'", "did you mean 'ucs'"}},
        BadCase{"two_documents.yaml", {"two_documents.yaml:4:", "second YAML document"}},
        BadCase{"only_comments.yaml", {"holds no keys", "name"}},
        BadCase{"case_without_name.yaml", {"name: required key is missing"}},
        BadCase{"runaway_repeats.yaml", {":3:", "breakage.repeats", "1e7 jobs", "at most 100000"}},
        BadCase{"runaway_sample_spacing.yaml",
                {":3:", "sample.spacing", "grid points", "at most 2e7"}},
        BadCase{"runaway_dumps.yaml", {":4:", "breakage.dump_interval", "VTK dumps per run"}},
        BadCase{"engine_max_bonds.yaml", {":2:", "lump.max_bonds", "[1, 64]", "65"}},
        BadCase{"engine_long_name.yaml", {":1:", "name", "300 characters", "at most 100"}}),
    [](const auto& info) {
      std::string n = info.param.file;
      n = n.substr(0, n.find('.'));
      for (auto& ch : n)
        if (!isalnum(static_cast<unsigned char>(ch))) ch = '_';
      return n;
    });

// The *_card.yaml files are ore cards: load them through a case that points at them.
TEST(OreCard, BadCardsAreRejectedThroughTheCase) {
  for (const char* f : {"bad_ore_ucs.yaml", "bad_ore_nu.yaml", "bad_ore_negative_E.yaml", "bad_ore_missing_key.yaml"}) {
    const std::string msg = error_of(f);
    EXPECT_NE(msg.find("_card.yaml"), std::string::npos) << f << ": " << msg;
  }
}

TEST(CaseFile, BundledCasesAreValid) {
  for (const char* f : {"cases/default.yaml", "cases/reference.yaml"}) {
    const auto c = load_case(kProject / f, kProject);
    EXPECT_FALSE(c.name.empty());
    EXPECT_EQ(c.ore.str("name"), "sandstone");
  }
  const auto ref = load_case(kProject / "cases/reference.yaml", kProject);
  EXPECT_EQ(ref.doc.integer("lump.n_elements"), 3344);
  EXPECT_EQ(ref.doc.integer("injection.n_lumps"), 360);
  EXPECT_DOUBLE_EQ(ref.doc.reals("breakage.velocities").front(), 4.0);
  EXPECT_DOUBLE_EQ(ref.doc.reals("breakage.velocities").back(), 169.0);
}

// A calibration pasted into the card keeps a moment factor of 0 (what the
// UCS/tensile lever sets): the card must accept it, as calibrated.yaml does.
TEST(OreCard, CalibratedMomentFactorZeroIsValid) {
  const mill::test::TempDir dir("mill_card_beta0_" + std::to_string(getpid()));
  std::ofstream(dir / "card.yaml") << "name: r\ndensity: 2580\nyoungs_modulus: 18.69e9\n"
                                      "poisson_ratio: 0.18\nucs: 50.0e6\ntensile_strength: 5.0e6\n"
                                      "calibrated:\n  bond_moment_factor: 0\n";
  const auto ore = mill::config::Document::load(dir / "card.yaml", mill::config::ore_schema());
  EXPECT_EQ(ore.real("calibrated.bond_moment_factor"), 0.0);
}

// A deliberate outlier: the card lists the keys in allow_outside_range; the
// values are kept in outliers() (resolved_case.json and the report), and the
// key list changes no job id (ore_keys leaves it out).
TEST(OreCard, AllowedOutlierIsRecorded) {
  const auto c = load_case(kBadInput / "outlier_allowed.yaml", kProject);
  const auto all = mill::config::outliers(c);
  ASSERT_EQ(all.size(), 2u) << all.dump();
  EXPECT_EQ(all[0]["key"], "ucs");
  EXPECT_DOUBLE_EQ(all[0]["value"].get<double>(), 0.5e6);
  EXPECT_EQ(all[1]["key"], "tensile_strength");
  EXPECT_FALSE(mill::config::ore_keys(c.ore).contains("allow_outside_range"));
}

// The calibration's check keys (friction angle, m_i, K_IC) are read from the
// card but change no job id and no calibration hash (ore_keys leaves them out).
TEST(OreCard, CheckKeysAreReadButNotHashed) {
  const auto ore = mill::config::Document::load(kProject / "liggghts_inputs/materials/sandstone.yaml",
                                                mill::config::ore_schema());
  EXPECT_DOUBLE_EQ(ore.real("hoek_brown_mi"), 17.0);
  EXPECT_DOUBLE_EQ(ore.real("friction_angle"), 47.0);
  EXPECT_DOUBLE_EQ(ore.real("fracture_toughness"), 0.73e6);
  const auto keys = mill::config::ore_keys(ore);
  for (const char* k : mill::config::kOreCheckKeys) EXPECT_FALSE(keys.contains(k)) << k;
  EXPECT_TRUE(keys.contains("ucs"));
}

// A K_IC typed in MPa m^0.5 is named as such.
TEST(OreCard, ToughnessInMegapascalsIsNamed) {
  try {
    mill::config::Document::parse("name: r\ndensity: 2580\nyoungs_modulus: 18.69e9\npoisson_ratio: 0.18\n"
                                  "ucs: 50.0e6\ntensile_strength: 5.0e6\nfracture_toughness: 0.73\n",
                                  "card.yaml", mill::config::ore_schema());
    FAIL() << "accepted K_IC 0.73 Pa m^0.5";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("card.yaml:7: fracture_toughness"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("0.73 MPa m^0.5"), std::string::npos) << e.what();
  }
}

// Every bundled ore card and case lies inside the plausible ranges.
TEST(CaseFile, BundledFilesArePlausible) {
  for (const char* f : {"cases/default.yaml", "cases/reference.yaml",
                        "tests/data/tiny_all.yaml",
                        "tests/data/tiny_in_mill.yaml", "tests/data/tiny_hpc.yaml"})
    EXPECT_TRUE(mill::config::outliers(load_case(kProject / f, kProject)).empty()) << f;
  for (const char* card : {"granite", "sandstone"}) {
    const auto ore = mill::config::Document::load(kProject / "liggghts_inputs/materials" / (std::string(card) + ".yaml"),
                                                  mill::config::ore_schema());
    EXPECT_TRUE(ore.outliers().empty()) << card;
  }
}

// Text a YAML reader would half-read: an error, never a file of defaults.
TEST(CaseFile, HalfReadYamlIsRefused) {
  const auto schema = mill::config::case_schema();
  auto error = [&](const std::string& text) {
    try {
      mill::config::Document::parse(text, "t.yaml", schema);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(error("").find("holds no keys"), std::string::npos);
  EXPECT_NE(error("# only a comment\n").find("holds no keys"), std::string::npos);
  EXPECT_NE(error("name: a\rrotor: {rpm: [2000]}\r").find("line endings are CR only"), std::string::npos);
  EXPECT_NE(error("name: a\n---\nname: b\n").find("t.yaml:2: a second YAML document"), std::string::npos);
  EXPECT_NE(error("---\nname: a\n---\n").find("t.yaml:3: a second YAML document"), std::string::npos);
  EXPECT_EQ(error("---\nname: a\r\nrotor: {rpm: [2000]}\r\n"), "accepted");
}

TEST(Schema, NumbersReadAsTyped) {
  EXPECT_EQ(mill::config::num(50), "50");
  EXPECT_EQ(mill::config::num(5e7), "5e7");
  EXPECT_EQ(mill::config::num(1.869e10), "1.869e10");
  EXPECT_EQ(mill::config::num(1e-6), "1e-6");
  EXPECT_EQ(mill::config::num(0.018), "0.018");
}

TEST(CaseFile, GraniteCardIsValid) {
  const auto ore = mill::config::Document::load(kProject / "liggghts_inputs/materials/granite.yaml",
                                                mill::config::ore_schema());
  mill::config::check_ore(ore);
  EXPECT_GT(ore.real("ucs") / ore.real("tensile_strength"), 10.0);
}

TEST(CaseFile, DefaultsFillAbsentKeysAndLinesAreKept) {
  const auto c = load_case(kData / "good_small.yaml", kProject);
  EXPECT_EQ(c.doc.integer("lump.n_elements"), 200);
  EXPECT_EQ(c.doc.line("lump.n_elements"), 3);
  EXPECT_EQ(c.doc.line("mill.housing.height"), 0);  // default
  EXPECT_DOUBLE_EQ(c.doc.real("mill.housing.height"), 4.0);
  EXPECT_EQ(c.doc.reals("rotor.rpm").size(), 2u);
}

TEST(CaseFile, CanonicalJsonIsStable) {
  const auto a = load_case(kData / "good_small.yaml", kProject);
  const auto b = load_case(kData / "good_small.yaml", kProject);
  EXPECT_EQ(a.doc.to_json().dump(), b.doc.to_json().dump());
}

TEST(Schema, MarkdownListsEveryKeyWithUnit) {
  const std::string md = mill::config::schema_markdown();
  for (const auto& k : mill::config::case_schema().keys) EXPECT_NE(md.find("`" + k.path + "`"), std::string::npos) << k.path;
  EXPECT_NE(md.find("| `rotor.rpm` | list of numbers | rpm |"), std::string::npos);
}

TEST(Schema, DocsConfigIsUpToDate) {
  std::ifstream in(kProject / "docs" / "config.md");
  ASSERT_TRUE(in) << "docs/config.md is missing: regenerate with orchestrate --print-schema > docs/config.md";
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, mill::config::schema_markdown())
      << "docs/config.md is stale: regenerate with orchestrate --print-schema > docs/config.md";
}

TEST(EditDistance, Basics) {
  EXPECT_EQ(mill::config::edit_distance("rpm", "rmp"), 2u);
  EXPECT_EQ(mill::config::edit_distance("", "abc"), 3u);
  EXPECT_EQ(mill::config::edit_distance("same", "same"), 0u);
}

}  // namespace

// The adaptive step is on by default and acts on the automatic step only: a
// case that gives breakage.timestep keeps one step (and is valid), one that
// asks for both is refused (tests/bad_input/adaptive_step_with_timestep.yaml),
// and `false` turns it off.
TEST(CaseFile, AdaptiveStepIsTheDefaultWithTheAutomaticStep) {
  const mill::test::TempDir dir("mill_adaptive_default_" + std::to_string(getpid()));
  struct {
    const char *text;
    bool on;
  } cases[] = {{"name: a\n", true},
               {"name: b\nbreakage:\n  timestep: 1.0e-7\n", false},
               {"name: c\nbreakage:\n  adaptive_step: false\n", false},
               {"name: d\nbreakage:\n  adaptive_step: true\n", true}};
  for (const auto &c : cases) {
    const fs::path f = dir / "case.yaml";
    std::ofstream(f) << c.text;
    const auto cfg = load_case(f, kProject);
    EXPECT_EQ(mill::breakage::adaptive_step_on(cfg.doc), c.on) << c.text;
  }
  // Asked for as an override (not in the file) with a given step: refused too.
  const fs::path f = dir / "case.yaml";
  std::ofstream(f) << "name: e\nbreakage:\n  timestep: 1.0e-7\n";
  EXPECT_THROW(load_case(f, kProject, {{"breakage.adaptive_step", "true"}}),
               mill::config::ConfigError);
  EXPECT_NO_THROW(load_case(f, kProject, {{"breakage.adaptive_step", "false"}}));
}

// breakage.in_mill.lumps follows breakage.conditions when absent: 4 with
// transport (a band for the product and the decision), 0 with a sweep (in-mill
// lumps need stage 1's strikes); a given value stands either way, and the
// default taken is a default (line 0). The table names both.
TEST(CaseFile, InMillLumpsDefaultFollowsTheConditions) {
  const mill::test::TempDir dir("mill_in_mill_default_" + std::to_string(getpid()));
  struct {
    const char *text;
    long lumps;
    int line;
  } cases[] = {{"name: a\n", 0, 0},
               {"name: b\nbreakage:\n  conditions: sweep\n", 0, 0},
               {"name: c\nbreakage:\n  conditions: transport\n", 4, 0},
               {"name: d\nbreakage:\n  conditions: transport\n  in_mill: {lumps: 0}\n", 0, 4},
               {"name: e\nbreakage:\n  conditions: transport\n  in_mill: {lumps: 7}\n", 7, 4}};
  for (const auto &c : cases) {
    const fs::path f = dir / "case.yaml";
    std::ofstream(f) << c.text;
    const auto cfg = load_case(f, kProject);
    EXPECT_EQ(cfg.doc.integer("breakage.in_mill.lumps"), c.lumps) << c.text;
    EXPECT_EQ(cfg.doc.line("breakage.in_mill.lumps"), c.line) << c.text;
  }
  // Set by an override of the conditions, the default follows it too.
  const fs::path f = dir / "case.yaml";
  std::ofstream(f) << "name: f\n";
  EXPECT_EQ(load_case(f, kProject, {{"breakage.conditions", "transport"}}).doc.integer("breakage.in_mill.lumps"), 4);
  const std::string md = mill::config::schema_markdown();
  EXPECT_NE(md.find("| `4` with `breakage.conditions: transport`, else `0` |"), std::string::npos);
}
