// Loading and validating a case file and its ore card against the schema.
// Every user-caused problem becomes a ConfigError whose text names the file,
// line, key, the value found and what is expected; main() exits with 2.
#pragma once

#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "config/feed.h"
#include "config/schema.h"

namespace mill::config {

struct ConfigError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A YAML file validated against a schema, with defaults filled in.
class Document {
 public:
  static Document load(const std::filesystem::path& file, const Schema& schema);
  static Document parse(const std::string& text, const std::string& file_label, const Schema& schema,
                        const std::vector<std::pair<std::string, std::string>>& overrides = {});

  bool has(const std::string& path) const;
  double real(const std::string& path) const;
  long integer(const std::string& path) const;
  bool boolean(const std::string& path) const;
  std::string str(const std::string& path) const;
  std::vector<double> reals(const std::string& path) const;
  // 1-based line of the key in the file; 0 when it took its default.
  int line(const std::string& path) const;
  // Canonical JSON (sorted keys, defaults included): the basis of job hashes.
  nlohmann::json to_json() const;
  // "file:line: key" prefix for messages about a key.
  std::string where(const std::string& path) const;

  const std::string& file() const { return file_; }
  // Values outside their plausible range that the file allows (allow_outside_range):
  // [{file, key, value, unit, plausible: [lo, hi]}].
  const nlohmann::json& outliers() const { return outliers_; }

 private:
  const KeyDef& def(const std::string& path) const;
  void check_plausible();
  nlohmann::json outliers_ = nlohmann::json::array();
  std::string file_;
  const Schema* schema_ = nullptr;
  std::map<std::string, YAML::Node> values_;
  std::map<std::string, int> lines_;
};

// A case ready to run: the case document, its ore card, and where things live.
struct CaseConfig {
  std::filesystem::path file;         // the case file (absolute)
  std::string name;                   // case name (for runs/<name>)
  Document doc;                       // validated case
  std::filesystem::path ore_file;     // resolved ore card (absolute)
  Document ore;                       // validated ore card
  std::optional<Feed> feed;           // the feed section (config/feed.h); none: one lump size
  std::filesystem::path project_dir;  // templates, foam_case, ... live here
};

// Load a case: schema validation, cross-key checks, ore card resolution.
// `overrides` (dotted key -> YAML value) replace keys of the file before
// validation, e.g. {"lump.n_elements", "400"} from a command-line option.
CaseConfig load_case(const std::filesystem::path& file, const std::filesystem::path& project_dir,
                     const std::vector<std::pair<std::string, std::string>>& overrides = {});

// resources.<stage>.np of a stage that runs MPI engines: on a cluster
// (`default_counts`: the Slurm scripts) also its schema default, on this
// machine only when the case file sets it (the flow keeps resources.np).
// None: the caller's ranks (--np, else resources.np).
std::optional<int> stage_np(const Document& d, const std::string& stage, bool default_counts);

// The values of the case and its ore card kept outside their plausible range
// (allow_outside_range), for resolved_case.json and the report.
nlohmann::json outliers(const CaseConfig& c);

// The text of a case file or ore card (`what` names it in messages): a
// ConfigError, never a hang, when the path is missing, a directory, a FIFO
// or another non-regular file, or unreadable.
std::string read_regular_file(const std::filesystem::path& file, const std::string& what);

// The ore card's macro properties (everything but name, source, calibrated.*,
// jk.*, allow_outside_range, the calibration's check keys kOreCheckKeys and
// rock_class and direct_tensile_strength, which act only through the target
// of a direct-tension fit, hashed where used: calibration_hash), as
// canonical JSON: what job ids hash and a calibration is fitted to.
nlohmann::json ore_keys(const Document& ore);

// Physical consistency of an ore card (UCS > tensile strength, ...).
void check_ore(const Document& ore);

// Levenshtein distance, for "did you mean".
size_t edit_distance(const std::string& a, const std::string& b);

}  // namespace mill::config
