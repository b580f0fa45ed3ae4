// Who a run folder belongs to. A run folder (runs/<case>, or the output of
// `orchestrate impact`) records its owner in resolved_case.json: what wrote
// it (the stages of a case, or one impact), the case's name and the values of
// the case and ore card that decide its results. Other writers, another case,
// and the same case with other values are refused (--force takes it over).
// Each stage also stamps its merged outputs with the jobs they were merged
// from, so that a later stage never reads results of other inputs.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "config/case_config.h"
#include "stages/stage.h"

namespace mill {

// What writes a run folder: the stages of a case, or `orchestrate impact`.
enum class FolderKind { Stages, Impact };

// The case's and ore card's values that decide results (flat keys; the
// case's resources.* and description, which do not, left out).
nlohmann::json resolved_inputs(const config::CaseConfig& cfg);

// case.yaml and ore.yaml (copies) and resolved_case.json (the owner record).
void write_provenance(const config::CaseConfig& cfg, const std::filesystem::path& dir,
                      FolderKind kind);

// Throws a ConfigError naming the owner when `run_dir` lies inside another
// run folder, belongs to another case or to another kind of writer, and (unless `force`) when it
// holds this case's results made with other values (the keys that differ named). A command that
// only reads (`read_only`: --dry-run, --list-tasks) gets that last one back as a warning instead,
// to print; else "".
std::string check_run_folder(const config::CaseConfig& cfg, const std::filesystem::path& run_dir,
                             bool force, FolderKind kind = FolderKind::Stages,
                             bool read_only = false);

// The run folder at or above `path` (one that holds resolved_case.json), or
// an empty path.
std::filesystem::path owning_run_folder(const std::filesystem::path& path);

// <stage_dir>/stage.json: the jobs (labels and ids) the stage's merged
// outputs were made from; written after a successful finalize.
void write_stage_stamp(const std::filesystem::path& stage_dir, const Plan& plan);
// "" when the stage's stamp matches `plan` (or there is no stamp), else why
// not, in words.
std::string stage_stamp_mismatch(const std::filesystem::path& stage_dir, const Plan& plan);

}  // namespace mill
