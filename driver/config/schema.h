// The declared keys of a case file and of an ore card: every key once, with
// its type, unit, default, bounds and a one-line doc. Validation, defaults,
// `orchestrate --print-schema` and docs/config.md all read this table.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace mill::config {

enum class KeyType { Int, Real, Bool, String, Choice, Path, RealList, IntList };

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
// The schema as a Markdown document (for --print-schema and docs/config.md).
std::string schema_markdown();

}  // namespace mill::config
