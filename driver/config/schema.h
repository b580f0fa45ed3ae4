// The declared keys of a case file and of an ore card: every key once, with
// its type, unit, default, bounds and a one-line doc. Validation, defaults,
// `orchestrate --print-schema` and docs/config.md all read this table.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace mill::config {

// KeyList: names of other keys of the same file (allow_outside_range).
enum class KeyType { Int, Real, Bool, String, Choice, Path, RealList, IntList, KeyList };

// A unit a value is often typed in by mistake: value x factor + offset is the
// value in the key's own unit (MPa for Pa: factor 1e6; degC for K: offset 273.15).
struct UnitSlip {
  std::string unit;
  double factor = 1;
  double offset = 0;
};

// The values a real rock, gas or mill takes. A value outside them is an error
// that names the likely unit slip, unless the file lists the key in its
// allow_outside_range (a deliberate outlier).
struct Plausible {
  double lo = 0, hi = 0;
  std::string what;    // what the bounds describe: "a rock's uniaxial compressive strength"
  std::string source;  // the handbook or paper the bounds come from
  std::vector<UnitSlip> slips;
};

// A default that depends on another key's value: `yaml` when the key `when`
// has the value `is` (after its own default), else the key's default_yaml.
struct DefaultIf {
  std::string when;
  std::string is;
  std::string yaml;
};

// One declared key. `path` is dotted ("rotor.rpm"); `default_yaml` is the
// default written as YAML ("" = required key, no default).
struct KeyDef {
  std::string path;
  KeyType type;
  std::string unit;
  std::string default_yaml;
  std::string doc;
  std::optional<double> min;  // numeric lower bound (applies to list items too)
  bool min_exclusive = false;
  std::optional<double> max;
  bool max_exclusive = false;
  std::vector<std::string> choices;  // for KeyType::Choice
  bool optional = false;             // may be absent with no default
  std::string pattern;               // String: ECMAScript regex the whole value must match
  std::string pattern_text;          // String: what the pattern admits, for messages and docs
  std::optional<Plausible> plausible;  // numbers: the range a real rock, gas or mill takes
  std::optional<DefaultIf> default_if;  // a default that follows another key's value
};

// What a table describes: used in messages ("case file", "ore card").
struct Schema {
  std::string what;
  std::vector<KeyDef> keys;
  const KeyDef* find(const std::string& path) const;
  // True when `path` is a section: some key lies below it.
  bool is_section(const std::string& path) const;
};

const Schema& case_schema();
const Schema& ore_schema();

std::string type_name(KeyType t);
// Human text for the admissible range of a key: "> 0", "in [0, 0.5)", "one of a, b".
std::string expected_text(const KeyDef& k);
// Fewest elements of a lump: below ten, LIGGGHTS' insert/pack in the packing
// deck (liggghts_inputs/lump_build.in.tmpl) places only one element in its
// sphere, whatever the seed.
inline constexpr long kMinLumpElements = 10;
// Most a transported lump may move in one step at the fastest tip speed, as
// a share of its radius, or it passes through a beater plate between two
// contact checks (injection.timestep).
inline constexpr double kMaxLumpStepMove = 0.25;
// Most elements of one flat-joint interface (rings x sectors): the slots of
// fix bond/flatjoint (liggghts_styles/flat_joint.h, kMaxElements).
inline constexpr int kMaxJointElements = 32;
// The key that lists a file's deliberate outliers of their plausible range.
inline constexpr const char* kAllowOutsideRange = "allow_outside_range";
// The ore card keys that the calibration checks after its fit and that no
// simulation reads (docs/calibration.md, "Checks after the fit"): they are
// not part of the card's hash (config::ore_keys), so adding one reruns only
// the calibration.
inline constexpr const char* kOreCheckKeys[] = {"friction_angle", "hoek_brown_mi",
                                                "fracture_toughness"};
// Text for a number in messages and docs: 50, 5e7, 1.869e10 (no "e+07").
std::string num(double v);
// The units a value outside its plausible range was likely typed in, as
// "50 MPa (5e7 Pa)" pieces joined by " or "; "" when no slip fits.
std::string slip_hint(const KeyDef& k, double v);

// The schema as a Markdown document (for --print-schema and docs/config.md).
std::string schema_markdown();

}  // namespace mill::config
