// The headline of a run: the numbers a mill engineer looks at first, read
// from the declared outputs of each stage that ran (flow, transport,
// calibrate, breakage), as JSON for tools and as rows in words and units for
// the report and `orchestrate compare`.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

#include "report/html.h"

namespace mill::report {

// The headline numbers of the run folder `run` (report/summary.json's
// "headline"): flow and transport per rotor speed ("rpm2000"), calibration,
// breakage (critical speed, comminution efficiency at it, JK fit) and the
// mill product per rotor speed.
// A stage that has not run is absent.
// A JSON file that does not parse is left out and added to `problems`.
nlohmann::json headline_json(const std::filesystem::path& run, Problems* problems = nullptr);

// One line of the headline: the stage group it belongs to, what it is, and
// its value in words and units with its spread where there is one.
struct HeadlineRow {
  std::string group;  // e.g. "Breakage of one lump (stage 2)"
  std::string what;   // e.g. "critical impact speed (largest piece < 5%)"
  std::string value;  // e.g. "66 m/s (65-82 over repeats)"
  bool brief = true;  // in the page's short headline; else only in its stage's section (and in compare)
};

// The headline in words, grouped by stage in pipeline order.
std::vector<HeadlineRow> headline_rows(const nlohmann::json& headline);

// The group names, in pipeline order, and the stage folder each belongs to.
struct HeadlineGroup {
  const char* stage;
  const char* title;
};
const std::vector<HeadlineGroup>& headline_groups();

}  // namespace mill::report
