// `orchestrate compare RUN_DIR RUN_DIR ...`: one page, in the report's style,
// that puts the headline numbers and the product size curves of several
// finished runs side by side (two ores, two mills, two rotor speeds).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace mill {

struct CompareOptions {
  std::vector<std::filesystem::path> runs;  // run folders, each with report/summary.json
  std::filesystem::path output;             // folder for index.html and the figure
  std::filesystem::path project_dir;        // for postprocess/plot_compare.py
};

// Checks that every run folder is a finished run (a folder holding
// report/summary.json, written by `--stage report`); throws config::ConfigError
// naming the folder and the command that finishes it otherwise, or when fewer
// than two runs are given or one is given twice.
void check_compare_runs(const std::vector<std::filesystem::path>& runs);

// Writes <output>/index.html and <output>/figures/compare_passing.png;
// returns a one-line message for the user.
std::string write_compare(const CompareOptions& opt);

}  // namespace mill
