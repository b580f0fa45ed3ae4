// Run-folder ownership and stage stamps; see run_folder.h.
#include "run_folder.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <fstream>
#include <iterator>
#include <set>

#include "jobs/job_store.h"

namespace mill {
namespace fs = std::filesystem;

namespace {

const char* kind_name(FolderKind k) { return k == FolderKind::Impact ? "impact" : "stages"; }

// The case keys that do not change a result: how it runs, and its prose.
bool decides_results(const std::string& key) {
  return key.rfind("resources.", 0) != 0 && key != "description";
}

nlohmann::json case_part(const nlohmann::json& doc) {
  nlohmann::json out = nlohmann::json::object();
  if (!doc.is_object()) return out;
  for (auto it = doc.begin(); it != doc.end(); ++it)
    if (decides_results(it.key())) out[it.key()] = it.value();
  return out;
}

// What resolved_case.json says about the folder's owner.
struct Owner {
  std::string name, file;
  std::string kind;       // "stages", "impact", or "" when unknown
  nlohmann::json inputs;  // {"case": {...}, "ore": {...}} when recorded
};

std::string slurp(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

Owner owner_from_json(const fs::path& run_dir, const fs::path& resolved) {
  const auto j = nlohmann::json::parse(slurp(resolved), nullptr, false);
  if (!j.is_object())
    throw config::ConfigError(
        fmt::format("--output {}: {} is damaged (not a JSON object), so the folder's case is "
                    "unknown; use another --output, or --force to take the folder over",
                    run_dir.string(), resolved.string()));
  Owner o;
  o.file = j.value("case_file", std::string());
  if (j.contains("case_name") && j["case_name"].is_string())
    o.name = j["case_name"].get<std::string>();
  else if (j.contains("case") && j["case"].is_object() && j["case"].contains("name") &&
           j["case"]["name"].is_string())
    o.name = j["case"]["name"].get<std::string>();
  else if (!o.file.empty())
    o.name = fs::path(o.file).stem().string();
  if (j.contains("kind") && j["kind"].is_string()) o.kind = j["kind"].get<std::string>();
  if (j.contains("case") && j["case"].is_object() && j.contains("ore") && j["ore"].is_object())
    o.inputs = {{"case", case_part(j["case"])}, {"ore", j["ore"]}};
  return o;
}

Owner read_owner(const fs::path& run_dir) {
  const fs::path resolved = run_dir / "resolved_case.json", copy = run_dir / "case.yaml";
  std::error_code ec;
  Owner o;
  if (fs::exists(resolved, ec)) {
    o = owner_from_json(run_dir, resolved);
  } else if (fs::exists(copy, ec)) {
    try {
      const YAML::Node n = YAML::LoadFile(copy.string());
      if (n.IsMap() && n["name"] && n["name"].IsScalar()) o.name = n["name"].Scalar();
    } catch (const YAML::Exception&) {
    }
  }
  // Folders written before the record named its writer: an impact folder
  // holds the job's own job.json.
  if (o.kind.empty() && (!o.name.empty() || fs::exists(run_dir / "job.json", ec)))
    o.kind = fs::exists(run_dir / "job.json", ec) ? "impact" : "stages";
  return o;
}

// The values that differ between the recorded inputs and now, as
// "ore card ucs: 5e+07 -> 1e+08", a changed name first (keys present in both
// only: a key that a newer orchestrate added is not a change of the case).
std::vector<std::string> differences(const nlohmann::json& was, const nlohmann::json& now) {
  std::vector<std::string> out;
  for (const char* part : {"ore", "case"}) {
    if (!was.contains(part) || !now.contains(part)) continue;
    const auto &a = was[part], &b = now[part];
    for (auto it = b.begin(); it != b.end(); ++it)
      if (a.contains(it.key()) && a[it.key()] != it.value())
        out.insert(it.key() == "name" || it.key() == "ore.card" ? out.begin() : out.end(),
                   fmt::format("{} {}: {} -> {}", part == std::string("ore") ? "ore card" : "case",
                               it.key(), a[it.key()].dump(), it.value().dump()));
  }
  return out;
}

void refuse_other_kind(const config::CaseConfig& cfg, const fs::path& run_dir, const Owner& o,
                       FolderKind kind) {
  const std::string holds =
      o.kind == "impact"
          ? "one impact of `orchestrate impact` (job.json and STATUS beside its results)"
          : fmt::format("the stages of case '{}'", o.name);
  const std::string writes =
      kind == FolderKind::Impact
          ? "`orchestrate impact` writes one impact into a folder of its own"
          : fmt::format("this command writes the stages of case '{}'", cfg.name);
  throw config::ConfigError(
      fmt::format("--output {}: the folder holds {}; {}: use another --output", run_dir.string(),
                  holds, writes));
}

}  // namespace

nlohmann::json resolved_inputs(const config::CaseConfig& cfg) {
  return {{"case", case_part(cfg.doc.to_json())}, {"ore", cfg.ore.to_json()}};
}

void write_provenance(const config::CaseConfig& cfg, const fs::path& dir, FolderKind kind) {
  fs::create_directories(dir);
  jobs::atomic_write(dir / "case.yaml", slurp(cfg.file));
  jobs::atomic_write(dir / "ore.yaml", slurp(cfg.ore_file));
  nlohmann::json j = {{"case_file", cfg.file.string()},
                      {"ore_card", cfg.ore_file.string()},
                      {"case", cfg.doc.to_json()},
                      {"ore", cfg.ore.to_json()},
                      {"orchestrate_version", MILL_VERSION}};
  j["case_name"] = cfg.name;
  j["kind"] = kind_name(kind);
  j["inputs_id"] = jobs::job_id(resolved_inputs(cfg));
  j["outside_plausible_range"] = config::outliers(cfg);
  jobs::atomic_write(dir / "resolved_case.json", j.dump(2) + "\n");
}

std::string check_run_folder(const config::CaseConfig& cfg, const fs::path& run_dir, bool force,
                             FolderKind kind, bool read_only) {
  // A folder inside another run folder would mix into that run's stages.
  fs::path self = fs::absolute(run_dir).lexically_normal();
  if (!self.has_filename()) self = self.parent_path();  // "runs/x/"
  if (const fs::path above = owning_run_folder(self.parent_path()); !above.empty())
    throw config::ConfigError(fmt::format(
        "--output {}: inside the run folder {} (it holds resolved_case.json), which belongs to its "
        "case and stages; use a folder outside it, e.g. --output runs/{}",
        run_dir.string(), above.string(), cfg.name));
  const Owner o = read_owner(run_dir);
  if (!o.kind.empty() && o.kind != kind_name(kind)) refuse_other_kind(cfg, run_dir, o, kind);
  if (force || o.name.empty()) return "";
  if (o.name != cfg.name)
    throw config::ConfigError(fmt::format(
        "--output {}: the run folder belongs to case '{}'{}; this is case '{}' ({}): use "
        "another --output (the default is runs/{}), or --force to take the folder over (every job "
        "is then redone)",
        run_dir.string(), o.name, o.file.empty() ? "" : " (" + o.file + ")", cfg.name,
        cfg.file.string(), cfg.name));
  if (kind != FolderKind::Stages || o.inputs.is_null()) return "";
  const auto diff = differences(o.inputs, resolved_inputs(cfg));
  if (diff.empty()) return "";
  std::string list;
  for (size_t i = 0; i < diff.size() && i < 4; ++i) list += (i ? "; " : "") + diff[i];
  if (diff.size() > 4) list += fmt::format("; and {} more", diff.size() - 4);
  const std::string why = fmt::format(
      "--output {}: the run folder holds results of case '{}' made with other values ({}); its "
      "results and "
      "this case's would mix in one report. Give this case another name (or --output), or add "
      "--force to "
      "redo the stages given with these values",
      run_dir.string(), cfg.name, list);
  if (read_only) return why + " (a run stops here)";
  throw config::ConfigError(why);
}

fs::path owning_run_folder(const fs::path& path) {
  std::error_code ec;
  for (fs::path p = fs::absolute(path).lexically_normal(); !p.empty(); p = p.parent_path()) {
    if (fs::exists(p / "resolved_case.json", ec)) return p;
    if (p == p.parent_path()) break;
  }
  return {};
}

namespace {
nlohmann::json plan_record(const Plan& plan) {
  nlohmann::json jobs = nlohmann::json::object();
  for (const auto& j : plan.jobs) jobs[j.label] = jobs::job_id(j.inputs);
  return jobs;
}
}  // namespace

void write_stage_stamp(const fs::path& stage_dir, const Plan& plan) {
  const auto rec = plan_record(plan);
  jobs::atomic_write(
      stage_dir / "stage.json",
      nlohmann::json({{"plan_id", jobs::job_id(rec)}, {"jobs", rec}}).dump(2) + "\n");
}

std::string stage_stamp_mismatch(const fs::path& stage_dir, const Plan& plan) {
  const fs::path f = stage_dir / "stage.json";
  std::error_code ec;
  if (!fs::exists(f, ec)) return "";
  const auto j = nlohmann::json::parse(slurp(f), nullptr, false);
  if (!j.is_object() || !j.contains("jobs") || !j["jobs"].is_object()) return "";
  const auto now = plan_record(plan);
  if (j["jobs"] == now) return "";
  int changed = 0, gone = 0, added = 0;
  std::string example;
  for (auto it = j["jobs"].begin(); it != j["jobs"].end(); ++it) {
    if (!now.contains(it.key())) {
      ++gone;
    } else if (now[it.key()] != it.value()) {
      ++changed;
      if (example.empty()) example = it.key();
    }
  }
  for (auto it = now.begin(); it != now.end(); ++it) added += j["jobs"].contains(it.key()) ? 0 : 1;
  return fmt::format(
      "its merged results come from {} job(s); with this case's values {} of them have other "
      "inputs{}, {} are no longer planned and {} are new",
      j["jobs"].size(), changed, example.empty() ? "" : " (e.g. " + example + ")", gone, added);
}

}  // namespace mill
