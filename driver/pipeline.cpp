// Stage execution: plan, decide per job, run with a small pool, finalize.
#include "pipeline.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <fstream>
#include <iostream>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include <yaml-cpp/yaml.h>

#include "engine/runner.h"
#include "jobs/job_store.h"
#include "progress.h"
#include "stages/breakage_stage.h"

namespace mill {
namespace fs = std::filesystem;

std::vector<std::string> resolve_stages(const std::string& stage) {
  const auto& names = stage_names();
  if (stage == "all") return names;
  if (std::find(names.begin(), names.end(), stage) != names.end()) return {stage};
  std::string list;
  for (const auto& n : names) list += n + ", ";
  std::string hint;
  size_t best = 99;
  for (const auto& n : names)
    if (config::edit_distance(stage, n) < best) best = config::edit_distance(stage, n), hint = n;
  throw config::ConfigError(fmt::format("--stage: expected one of {}all, got '{}'{}", list, stage,
                                        best <= 2 ? "; did you mean '" + hint + "'?" : ""));
}

namespace {

struct JobRow {
  JobSpec spec;
  jobs::Verdict verdict;
};

// Per job: run, skip or busy. A job marked done whose declared outputs are
// missing or damaged is run again, and the reason says which file.
std::vector<JobRow> decide_all(const Stage& stage, const StageContext& ctx, const jobs::JobStore& store,
                               const Plan& plan, bool force) {
  std::vector<JobRow> rows;
  for (const auto& j : plan.jobs) {
    jobs::Verdict v = store.decide(j.label, j.inputs, force);
    if (v.decision == jobs::Decision::Skip)
      if (const std::string why = stage.damaged_outputs(ctx, j); !why.empty())
        v = {jobs::Decision::Run, "done before, but an output is damaged: " + why};
    rows.push_back({j, v});
  }
  return rows;
}

// Two jobs of a stage with one label would share a folder and overwrite each
// other: the conditions are equal, or differ past the label's precision.
void check_unique_labels(const std::string& stage, const Plan& plan) {
  std::map<std::string, size_t> seen;
  for (size_t i = 0; i < plan.jobs.size(); ++i) {
    const auto [it, fresh] = seen.emplace(plan.jobs[i].label, i);
    if (!fresh)
      throw config::ConfigError(fmt::format(
          "stage {}: jobs {} ({}) and {} ({}) have the same label '{}': their conditions are equal or differ past the "
          "label's precision; give each condition once, with values that differ in the first 6 digits",
          stage, it->second, plan.jobs[it->second].summary, i, plan.jobs[i].summary, plan.jobs[i].label));
  }
}

std::string verdict_tag(const jobs::Verdict& v) {
  if (v.decision == jobs::Decision::Skip) return "done";
  if (v.decision == jobs::Decision::Busy) return "busy";
  return "todo";
}

// Keep a copy of what was run next to the results (provenance).
void write_provenance(const config::CaseConfig& cfg, const fs::path& run_dir) {
  fs::create_directories(run_dir);
  auto copy = [&](const fs::path& from, const fs::path& to) {
    std::ifstream in(from);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    jobs::atomic_write(to, text);
  };
  copy(cfg.file, run_dir / "case.yaml");
  copy(cfg.ore_file, run_dir / "ore.yaml");
  nlohmann::json j = {{"case_file", cfg.file.string()},   {"ore_card", cfg.ore_file.string()},
                      {"case", cfg.doc.to_json()},         {"ore", cfg.ore.to_json()},
                      {"orchestrate_version", MILL_VERSION}};
  j["case_name"] = cfg.name;
  jobs::atomic_write(run_dir / "resolved_case.json", j.dump(2) + "\n");
}

// Run one job with its STATUS bookkeeping. Returns "" on success, else the reason.
std::string run_one(Stage& stage, StageContext& ctx, const jobs::JobStore& store, const JobSpec& job) {
  store.mark_running(job.label, job.inputs);
  const auto t0 = std::chrono::steady_clock::now();
  ctx.progress.job_begin(job.label);
  std::string reason;
  try {
    stage.run_job(ctx, job, store.job_dir(job.label));
  } catch (const engine::Interrupted& e) {
    store.mark_failed(job.label, e.what());
    ctx.progress.job_end(job.label, false, 0);
    throw;
  } catch (const NotImplemented&) {
    store.mark_failed(job.label, "not implemented");
    throw;
  } catch (const std::exception& e) {
    reason = e.what();
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (reason.empty()) {
    store.mark_done(job.label);
  } else {
    store.mark_failed(job.label, reason.substr(0, reason.find('\n')));
  }
  ctx.progress.job_end(job.label, reason.empty(), secs);
  return reason;
}

}  // namespace

int run_pipeline(const config::CaseConfig& cfg, const Invocation& inv, std::ostream& out) {
  auto stages = make_stages();
  engine::Runner runner;
  Progress progress(out, isatty(STDOUT_FILENO) && &out == &std::cout);
  const fs::path run_dir = inv.opts.output;

  if (inv.task && inv.stages.size() != 1)
    throw config::ConfigError("--task: needs exactly one --stage (the stage whose job list --list-tasks shows), not 'all'");
  bool provenance_written = false;

  if (inv.dry_run)
    out << fmt::format("plan for case '{}' ({}), output {}\n", cfg.name, cfg.file.string(), run_dir.string());
  // Every stage's plan as far as it is known now, before any stage runs: a
  // label clash in a late stage must not surface after hours of earlier ones.
  for (const auto& name : inv.stages) {
    auto it = std::find_if(stages.begin(), stages.end(), [&](const auto& s) { return s->name() == name; });
    StageContext ctx{cfg, inv.opts, run_dir, run_dir / name, runner, progress};
    check_unique_labels(name, (*it)->plan(ctx));
  }

  for (const auto& name : inv.stages) {
    auto it = std::find_if(stages.begin(), stages.end(), [&](const auto& s) { return s->name() == name; });
    Stage& stage = **it;
    StageContext ctx{cfg, inv.opts, run_dir, run_dir / name, runner, progress};
    const jobs::JobStore store(ctx.stage_dir);
    const Plan plan = stage.plan(ctx);
    check_unique_labels(name, plan);
    if (inv.task && (*inv.task < 0 || *inv.task >= static_cast<int>(plan.jobs.size())))
      throw config::ConfigError(
          plan.jobs.empty()
              ? fmt::format("--task: stage '{}' has no jobs yet{}, got --task {}", name,
                            plan.note.empty() ? "" : " (" + plan.note + ")", *inv.task)
              : fmt::format("--task: expected an index in [0, {}] for stage '{}' ({} job{}), got {}",
                            plan.jobs.size() - 1, name, plan.jobs.size(), plan.jobs.size() == 1 ? "" : "s", *inv.task));
    const auto rows = decide_all(stage, ctx, store, plan, inv.opts.force);
    const int n_done = static_cast<int>(std::count_if(rows.begin(), rows.end(), [](const JobRow& r) {
      return r.verdict.decision == jobs::Decision::Skip;
    }));

    if (inv.list_tasks) {
      for (size_t i = 0; i < rows.size(); ++i)
        out << fmt::format("{}\t{}\t{}\t{}\n", i, rows[i].spec.label, verdict_tag(rows[i].verdict), rows[i].spec.summary);
      if (rows.empty() && !plan.note.empty()) out << "# " << name << ": no tasks yet: " << plan.note << "\n";
      continue;
    }
    if (inv.dry_run) {
      out << fmt::format("stage {} - {}{}\n  {} job{}, {} done, {} to run\n", name, stage.description(),
                         stage.implemented() ? "" : " [not implemented yet]", rows.size(), rows.size() == 1 ? "" : "s",
                         n_done, rows.size() - n_done);
      if (!plan.note.empty()) out << "  note: " << plan.note << "\n";
      for (size_t i = 0; i < rows.size(); ++i)
        out << fmt::format("  [{}] {:>3} {:<22} {} ({}, id {})\n", verdict_tag(rows[i].verdict), i, rows[i].spec.label,
                           rows[i].spec.summary, rows[i].verdict.why, jobs::job_id(rows[i].spec.inputs));
      continue;
    }

    std::vector<JobRow> todo;
    if (inv.task) {
      todo.push_back(rows[*inv.task]);
    } else {
      todo = rows;
    }
    if (!stage.implemented()) {
      out << fmt::format("stage '{}' ({}) is not implemented yet: nothing was run and no output was written.\n", name,
                         stage.description());
      return kExitNotImplemented;
    }

    if (!provenance_written) write_provenance(cfg, run_dir), provenance_written = true;
    progress.stage_begin(name, static_cast<int>(todo.size()),
                         static_cast<int>(std::count_if(todo.begin(), todo.end(), [](const JobRow& r) {
                           return r.verdict.decision == jobs::Decision::Skip;
                         })));
    std::vector<std::string> failures, busy;
    std::mutex mu;
    std::atomic<size_t> next{0};
    std::exception_ptr fatal;
    auto worker = [&]() {
      for (;;) {
        const size_t i = next.fetch_add(1);
        if (i >= todo.size()) return;
        const JobRow& r = todo[i];
        if (r.verdict.decision == jobs::Decision::Skip) continue;
        if (r.verdict.decision == jobs::Decision::Busy) {
          std::lock_guard<std::mutex> g(mu);
          busy.push_back(r.spec.label + ": " + r.verdict.why);
          continue;
        }
        {
          std::lock_guard<std::mutex> g(mu);
          if (fatal) return;
        }
        if (r.verdict.why != "new") progress.info(fmt::format("[{}] rerun {}: {}", name, r.spec.label, r.verdict.why));
        try {
          const std::string reason = run_one(stage, ctx, store, r.spec);
          if (!reason.empty()) {
            std::lock_guard<std::mutex> g(mu);
            failures.push_back(fmt::format("{}/{}: {}", name, r.spec.label, reason));
          }
        } catch (...) {
          std::lock_guard<std::mutex> g(mu);
          if (!fatal) fatal = std::current_exception();
          return;
        }
      }
    };
    const int n_threads = std::max(1, std::min<int>(inv.opts.jobs, static_cast<int>(todo.size())));
    // MPI ranks that wait for each other on shared cores burn CPU in the
    // wait: 2 jobs x 2 ranks on 2 cores cost ~3x the CPU of 1 rank per job.
    const unsigned cores = std::thread::hardware_concurrency();
    if (n_threads > 1 && cores > 0 && static_cast<unsigned>(n_threads * inv.opts.np) > cores)
      out << fmt::format("warning: {} jobs x {} MPI ranks = {} processes on {} cores: oversubscribed, every run slows "
                         "down; prefer --np 1 --jobs {} here (resources.np / resources.jobs)\n",
                         n_threads, inv.opts.np, n_threads * inv.opts.np, cores, cores);
    std::vector<std::thread> pool;
    for (int t = 0; t < n_threads; ++t) pool.emplace_back(worker);
    for (auto& t : pool) t.join();
    progress.stage_end();
    if (fatal) std::rethrow_exception(fatal);

    for (const auto& f : failures) out << "error: " << f << "\n";
    for (const auto& b : busy) out << "warning: not run, " << b << "\n";
    if (!failures.empty()) {
      out << fmt::format("stage '{}': {} job(s) failed; fix the cause and rerun the same command: done jobs are kept.\n",
                         name, failures.size());
      return kExitFailed;
    }
    if (!busy.empty()) return kExitFailed;
    // A single array task does not merge; the follow-up (whole stage) run does.
    if (!inv.task) stage.finalize(ctx, plan.jobs);
  }
  return kExitOk;
}

void check_run_folder(const config::CaseConfig& cfg, const fs::path& run_dir, bool force) {
  if (force) return;
  const fs::path resolved = run_dir / "resolved_case.json", copy = run_dir / "case.yaml";
  std::string owner, owner_file;
  std::error_code ec;
  if (fs::exists(resolved, ec)) {
    std::ifstream in(resolved);
    const auto j = nlohmann::json::parse(in, nullptr, false);
    if (!j.is_object())
      throw config::ConfigError(fmt::format("--output {}: {} is damaged (not a JSON object), so the folder's case is "
                                            "unknown; use another --output, or --force to take the folder over",
                                            run_dir.string(), resolved.string()));
    owner_file = j.value("case_file", std::string());
    if (j.contains("case_name") && j["case_name"].is_string()) owner = j["case_name"].get<std::string>();
    else if (j.contains("case") && j["case"].is_object() && j["case"].contains("name") && j["case"]["name"].is_string())
      owner = j["case"]["name"].get<std::string>();
    else if (!owner_file.empty()) owner = fs::path(owner_file).stem().string();
  } else if (fs::exists(copy, ec)) {
    try {
      const YAML::Node n = YAML::LoadFile(copy.string());
      if (n.IsMap() && n["name"] && n["name"].IsScalar()) owner = n["name"].Scalar();
    } catch (const YAML::Exception&) {
    }
  }
  if (owner.empty() || owner == cfg.name) return;
  throw config::ConfigError(fmt::format(
      "--output {}: the run folder belongs to case '{}'{}; this is case '{}' ({}): use another --output (the default "
      "is runs/{}), or --force to take the folder over (every job is then redone)",
      run_dir.string(), owner, owner_file.empty() ? "" : " (" + owner_file + ")", cfg.name, cfg.file.string(),
      cfg.name));
}

int count_tasks(const config::CaseConfig& cfg, const Invocation& inv) {
  auto stages = make_stages();
  engine::Runner runner;
  std::ostringstream sink;
  Progress progress(sink, false);
  for (auto& s : stages)
    if (s->name() == inv.stages.at(0)) {
      StageContext ctx{cfg, inv.opts, inv.opts.output, inv.opts.output / s->name(), runner, progress};
      return static_cast<int>(s->plan(ctx).jobs.size());
    }
  return 0;
}

int run_single_impact(const config::CaseConfig& cfg, const RunOptions& opts, double velocity, double angle,
                      int repeat, std::ostream& out) {
  engine::Runner runner;
  Progress progress(out, isatty(STDOUT_FILENO) && &out == &std::cout);
  StageContext ctx{cfg, opts, opts.output, opts.output / "breakage", runner, progress};
  const std::string label = fmt::format("impact_v{:g}_a{:g}_r{}", velocity, angle, repeat);
  // The output folder is the job's folder: an identical rerun is skipped.
  const jobs::JobStore store = jobs::JobStore::single(opts.output);
  const nlohmann::json inputs = impact_inputs(ctx, velocity, angle, repeat);
  jobs::Verdict v = store.decide(label, inputs, opts.force);
  if (v.decision == jobs::Decision::Skip)
    if (const std::string why = damaged_impact_outputs(opts.output); !why.empty())
      v = {jobs::Decision::Run, "done before, but an output is damaged: " + why};
  if (v.decision == jobs::Decision::Busy)
    throw std::runtime_error(fmt::format("impact into {}: {}", opts.output.string(), v.why));
  if (v.decision == jobs::Decision::Skip) {
    std::ifstream in(opts.output / "result.json");
    out << impact_line(nlohmann::json::parse(in, nullptr, false)) << "\n"
        << "already done with the same inputs (job " << jobs::job_id(inputs) << "): " << opts.output.string()
        << "; --force redoes it\n";
    return kExitOk;
  }
  write_provenance(cfg, opts.output);
  if (v.why != "new") progress.info(fmt::format("impact: rerun: {}", v.why));
  progress.info(fmt::format("impact: {}-element lump of {} at {:g} m/s, {:g} deg, into {}", cfg.doc.integer("lump.n_elements"),
                            cfg.ore.str("name"), velocity, angle, opts.output.string()));
  progress.stage_begin("impact", 1, 0);
  store.mark_running(label, inputs);
  std::string line;
  try {
    line = run_impact(ctx, velocity, angle, repeat, opts.output, label);
  } catch (const std::exception& e) {
    const std::string why = e.what();
    store.mark_failed(label, why.substr(0, why.find('\n')));
    throw;
  }
  store.mark_done(label);
  progress.stage_end();
  out << line << "\n"
      << "written: " << (opts.output / "summary.csv").string() << ", fractions.csv, impact.h5, fragments.vtp, result.json\n";
  return kExitOk;
}

}  // namespace mill
