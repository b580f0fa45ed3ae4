// Stage execution: plan, decide per job, run with a small pool, finalize.
#include "pipeline.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include "config/schema.h"
#include "engine/runner.h"
#include "jobs/job_store.h"
#include "progress.h"
#include "run_folder.h"
#include "stages/breakage/impact_runs.h"

namespace mill {
namespace fs = std::filesystem;

namespace {
// One stage name, or a ConfigError naming --stage (with a "did you mean").
size_t stage_index(const std::string& stage, const std::string& given) {
  const auto& names = stage_names();
  const auto it = std::find(names.begin(), names.end(), stage);
  if (it != names.end()) return static_cast<size_t>(it - names.begin());
  std::string list;
  for (const auto& n : names) list += n + ", ";
  std::string hint;
  size_t best = 99;
  for (const auto& n : names)
    if (config::edit_distance(stage, n) < best) best = config::edit_distance(stage, n), hint = n;
  throw config::ConfigError(
      fmt::format("--stage: expected one of {}all or a range FIRST-LAST (e.g. transport-breakage), "
                  "got '{}'{}",
                  list, given, best <= 2 ? "; did you mean '" + hint + "'?" : ""));
}
}  // namespace

std::vector<std::string> resolve_stages(const std::string& stage) {
  const auto& names = stage_names();
  if (stage == "all") return names;
  const size_t dash = stage.find('-');
  if (dash == std::string::npos) return {names[stage_index(stage, stage)]};
  // A range FIRST-LAST: every stage from FIRST to LAST in pipeline order.
  const size_t first = stage_index(stage.substr(0, dash), stage),
               last = stage_index(stage.substr(dash + 1), stage);
  if (first > last)
    throw config::ConfigError(
        fmt::format("--stage {}: '{}' comes after '{}' in the pipeline; expected FIRST-LAST in "
                    "pipeline order, e.g. {}-{}",
                    stage, names[first], names[last], names[last], names[first]));
  return {names.begin() + static_cast<long>(first), names.begin() + static_cast<long>(last) + 1};
}

namespace {

struct JobRow {
  JobSpec spec;
  jobs::Verdict verdict;
};

// Per job: run, skip or busy. A job marked done whose declared outputs are
// missing or damaged is run again, and the reason says which file.
std::vector<JobRow> decide_all(const Stage& stage, const StageContext& ctx,
                               const jobs::JobStore& store, const Plan& plan, bool force) {
  std::vector<JobRow> rows;
  for (const auto& j : plan.jobs) {
    engine::throw_if_interrupted();
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
    engine::throw_if_interrupted();
    const auto [it, fresh] = seen.emplace(plan.jobs[i].label, i);
    if (!fresh)
      throw config::ConfigError(
          fmt::format("stage {}: jobs {} ({}) and {} ({}) have the same label '{}': their "
                      "conditions are equal or differ past the "
                      "label's precision; give each condition once, with values that differ in the "
                      "first 6 digits",
                      stage, it->second, plan.jobs[it->second].summary, i, plan.jobs[i].summary,
                      plan.jobs[i].label));
  }
}

std::string verdict_tag(const jobs::Verdict& v) {
  if (v.decision == jobs::Decision::Skip) return "done";
  if (v.decision == jobs::Decision::Busy) return "busy";
  return "todo";
}

// Run one job with its STATUS bookkeeping. Returns "" on success, else the reason.
std::string run_one(Stage& stage, StageContext& ctx, const jobs::JobStore& store,
                    const JobSpec& job) {
  store.mark_running(job.label, job.inputs, ctx.opts.scheduler_job, ctx.opts.scheduler_log);
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

// Why a job that is not done is not: its STATUS, with the scheduler job and
// log that last ran it (for the merge job of a scheduler chain).
std::string not_done_text(const jobs::JobStore& store, const JobRow& r) {
  const jobs::Status s = store.read_status(r.spec.label);
  std::string why;
  switch (s.state) {
    case jobs::State::None:
      why = "not run: no STATUS (its task did not start, or failed before the job did)";
      break;
    case jobs::State::Running:
      why = s.host == jobs::JobStore::hostname() &&
                    !jobs::JobStore::process_alive(s.pid, s.start_ticks)
                ? fmt::format(
                      "did not finish: STATUS says running as pid {} on {}, which is gone (stale: "
                      "killed, e.g. at the time limit?)",
                      s.pid, s.host)
                : fmt::format(
                      "did not finish: STATUS still says running as pid {} on {} (killed, e.g. at "
                      "the time "
                      "limit?)",
                      s.pid, s.host);
      break;
    case jobs::State::Failed:
      why = "failed: " + s.reason;
      break;
    default:
      why = r.verdict.why;
      break;
  }
  if (!s.scheduler_job.empty()) why += fmt::format("; scheduler job {}", s.scheduler_job);
  if (!s.log.empty()) why += fmt::format(", log {}", s.log);
  return why;
}

// The stage called `name` (one of make_stages()).
Stage& find_stage(const std::vector<std::unique_ptr<Stage>>& stages, const std::string& name) {
  const auto it =
      std::find_if(stages.begin(), stages.end(), [&](const auto& s) { return s->name() == name; });
  return **it;
}

// The options that exclude each other: --task with --merge-only or several stages.
void check_invocation(const Invocation& inv) {
  if (inv.task && inv.merge_only)
    throw config::ConfigError("--merge-only: runs no job, so it takes no --task");
  if (inv.task && inv.stages.size() != 1)
    throw config::ConfigError(
        "--task: needs exactly one --stage (the stage whose job list --list-tasks shows), not "
        "'all'");
}

// --task names a job of the stage's plan.
void check_task_index(const Invocation& inv, const std::string& name, const Plan& plan) {
  if (inv.task && (*inv.task < 0 || *inv.task >= static_cast<int>(plan.jobs.size())))
    throw config::ConfigError(
        plan.jobs.empty()
            ? fmt::format("--task: stage '{}' has no jobs yet{}, got --task {}", name,
                          plan.note.empty() ? "" : " (" + plan.note + ")", *inv.task)
            : fmt::format("--task: expected an index in [0, {}] for stage '{}' ({} job{}), got {}",
                          plan.jobs.size() - 1, name, plan.jobs.size(),
                          plan.jobs.size() == 1 ? "" : "s", *inv.task));
}

// The indices of the jobs an invocation covers: all, or job --task.
std::vector<size_t> covered(const Invocation& inv, size_t n) {
  if (inv.task) return {static_cast<size_t>(*inv.task)};
  std::vector<size_t> all(n);
  for (size_t i = 0; i < n; ++i) all[i] = i;
  return all;
}

// --list-tasks: one job per line (index, label, state, summary); only job
// --task with --task.
void print_tasks(std::ostream& out, const Invocation& inv, const std::string& name,
                 const Plan& plan, const std::vector<JobRow>& rows) {
  for (const size_t i : covered(inv, rows.size()))
    out << fmt::format("{}\t{}\t{}\t{}\n", i, rows[i].spec.label, verdict_tag(rows[i].verdict),
                       rows[i].spec.summary);
  if (rows.empty() && !plan.note.empty())
    out << "# " << name << ": no tasks yet: " << plan.note << "\n";
}

// --dry-run: the stage, its jobs, which are done and their ids (only job
// --task with --task, which runs no merge).
void print_plan(std::ostream& out, const Invocation& inv, const StageContext& ctx,
                const Stage& stage, const Plan& plan, const std::vector<JobRow>& rows) {
  const int n_done = static_cast<int>(std::count_if(rows.begin(), rows.end(), [](const JobRow& r) {
    return r.verdict.decision == jobs::Decision::Skip;
  }));
  out << fmt::format("stage {} - {}{}\n  {} job{}, {} done, {} to run\n", stage.name(),
                     stage.description(), stage.implemented() ? "" : " [not implemented yet]",
                     rows.size(), rows.size() == 1 ? "" : "s", n_done, rows.size() - n_done);
  if (ctx.opts.np != inv.opts.np)
    out << fmt::format("  {} MPI rank(s) per engine run (resources.{}.np)\n", ctx.opts.np,
                       stage.name());
  if (!plan.note.empty()) out << "  note: " << plan.note << "\n";
  if (inv.task)
    out << fmt::format("  --task {}: only this job would run, and the stage would not be merged\n",
                       *inv.task);
  for (const size_t i : covered(inv, rows.size()))
    out << fmt::format("  [{}] {:>3} {:<22} {} ({}, id {})\n", verdict_tag(rows[i].verdict), i,
                       rows[i].spec.label, rows[i].spec.summary, rows[i].verdict.why,
                       jobs::job_id(rows[i].spec.inputs));
}

// What one pass over a stage shares: the stage, its context and job store,
// its plan and the verdict per job.
struct StagePass {
  Stage& stage;
  StageContext& ctx;
  const jobs::JobStore& store;
  const Plan& plan;
  const std::vector<JobRow>& rows;
};

// --merge-only, after a scheduler ran the jobs: merge only when every job is
// done (calling `before_merge` first); else name each job that is not and
// return kExitFailed.
int merge_stage(const StagePass& p, std::ostream& out, const std::function<void()>& before_merge) {
  const std::string name = p.stage.name();
  std::vector<std::string> missing;
  for (size_t i = 0; i < p.rows.size(); ++i)
    if (p.rows[i].verdict.decision != jobs::Decision::Skip)
      missing.push_back(fmt::format("{}/{} (task {}): {}", name, p.rows[i].spec.label, i,
                                    not_done_text(p.store, p.rows[i])));
  if (p.rows.empty() && !p.plan.note.empty())
    missing.push_back(fmt::format("{}: no jobs: {}", name, p.plan.note));
  for (const auto& m : missing) out << "error: " << m << "\n";
  if (!missing.empty()) {
    out << fmt::format("stage '{}': {} of {} job(s) not done; nothing merged.\n", name,
                       missing.size(), p.rows.size());
    return kExitFailed;
  }
  before_merge();
  p.stage.finalize(p.ctx, p.plan.jobs);
  if (!p.plan.jobs.empty()) write_stage_stamp(p.ctx.stage_dir, p.plan);
  out << fmt::format("stage '{}': all {} job(s) done; merged.\n", name, p.rows.size());
  return kExitOk;
}

// MPI ranks that wait for each other on shared cores burn CPU in the
// wait: 2 jobs x 2 ranks on 2 cores cost ~3x the CPU of 1 rank per job.
void warn_oversubscribed(std::ostream& out, int n_threads, int np) {
  const unsigned cores = std::thread::hardware_concurrency();
  if (n_threads > 1 && cores > 0 && static_cast<unsigned>(n_threads * np) > cores)
    out << fmt::format(
        "warning: {} jobs x {} MPI ranks = {} processes on {} cores: oversubscribed, every run "
        "slows "
        "down; prefer --np 1 --jobs {} here (resources.np / resources.jobs)\n",
        n_threads, np, n_threads * np, cores, cores);
}

// The jobs of a pass that failed (with the reason) or were busy elsewhere.
struct PoolOutcome {
  std::vector<std::string> failures, busy;
};

// Runs the jobs of `todo` that are to run, on n_threads threads; the first
// fatal error (interrupt, not implemented) stops the pool and is rethrown.
PoolOutcome run_pool(const StagePass& p, const std::vector<JobRow>& todo, int n_threads) {
  const std::string name = p.stage.name();
  PoolOutcome res;
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
        res.busy.push_back(r.spec.label + ": " + r.verdict.why);
        continue;
      }
      {
        std::lock_guard<std::mutex> g(mu);
        if (fatal) return;
      }
      if (r.verdict.why != "new")
        p.ctx.progress.info(fmt::format("[{}] rerun {}: {}", name, r.spec.label, r.verdict.why));
      try {
        const std::string reason = run_one(p.stage, p.ctx, p.store, r.spec);
        if (!reason.empty()) {
          std::lock_guard<std::mutex> g(mu);
          res.failures.push_back(fmt::format("{}/{}: {}", name, r.spec.label, reason));
        }
      } catch (...) {
        std::lock_guard<std::mutex> g(mu);
        if (!fatal) fatal = std::current_exception();
        return;
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 0; t < n_threads; ++t) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
  p.ctx.progress.stage_end();
  if (fatal) std::rethrow_exception(fatal);
  return res;
}

// Runs the stage's jobs (only job --task with --task), reports failed and
// busy jobs, and merges the stage when all are done (not after one --task).
int run_stage(const StagePass& p, const Invocation& inv, std::ostream& out) {
  const std::string name = p.stage.name();
  std::vector<JobRow> todo;
  if (inv.task) {
    todo.push_back(p.rows[*inv.task]);
  } else {
    todo = p.rows;
  }
  for (const auto& w : p.plan.warnings) p.ctx.progress.warn(w);
  p.ctx.progress.stage_begin(
      name, static_cast<int>(todo.size()),
      static_cast<int>(std::count_if(todo.begin(), todo.end(), [](const JobRow& r) {
        return r.verdict.decision == jobs::Decision::Skip;
      })));
  // A stage whose jobs start engine runs of their own (the calibrate
  // stage's fits): every job at once, the engine runs limited instead.
  const bool shared = p.stage.jobs_share_engine_runs();
  const int n_threads =
      std::max(1, shared ? static_cast<int>(todo.size())
                         : std::min<int>(inv.opts.jobs, static_cast<int>(todo.size())));
  warn_oversubscribed(out, shared ? inv.opts.jobs : n_threads, p.ctx.opts.np);
  if (shared) p.ctx.runner.limit_runs(inv.opts.jobs);
  struct Unlimit {
    engine::Runner& r;
    bool on;
    ~Unlimit() {
      if (on) r.limit_runs(0);
    }
  } unlimit{p.ctx.runner, shared};
  const PoolOutcome res = run_pool(p, todo, n_threads);
  for (const auto& f : res.failures) out << "error: " << f << "\n";
  for (const auto& b : res.busy) out << "warning: not run, " << b << "\n";
  if (!res.failures.empty()) {
    out << fmt::format(
        "stage '{}': {} job(s) failed; fix the cause and rerun the same command: done jobs are "
        "kept.\n",
        name, res.failures.size());
    return kExitFailed;
  }
  if (!res.busy.empty()) return kExitFailed;
  // A single array task does not merge; the follow-up (whole stage) run does.
  if (!inv.task) {
    p.stage.finalize(p.ctx, p.plan.jobs);
    if (!p.plan.jobs.empty()) write_stage_stamp(p.ctx.stage_dir, p.plan);
  }
  return kExitOk;
}

// The earlier stages whose merged outputs `stage` reads: the report reads
// every earlier stage; the others name theirs.
std::vector<std::string> read_stages(const Stage& stage, const config::CaseConfig& cfg) {
  if (stage.name() != "report") return stage.reads(cfg);
  std::vector<std::string> earlier;
  for (const auto& n : stage_names())
    if (n != "report") earlier.push_back(n);
  return earlier;
}

// What stage `name` finds in an earlier stage `stage` that it reads and that
// ran in this folder: merged outputs made from jobs this case no longer plans
// (`stale`, a sentence), or a damaged merged output while every job of it is
// done (`damaged`: finalize rebuilds it).
struct EarlierStage {
  std::string stage;
  Plan plan;
  std::string stale, damaged;
};

// Every earlier stage that stage `name` reads (see EarlierStage) with a
// problem, in pipeline order.
std::vector<EarlierStage> earlier_stage_problems(const std::vector<std::unique_ptr<Stage>>& stages,
                                                 const std::string& name,
                                                 const config::CaseConfig& cfg,
                                                 const Invocation& inv, engine::Runner& runner,
                                                 Progress& progress) {
  const fs::path run_dir = inv.opts.output;
  std::vector<EarlierStage> found;
  for (const auto& e : read_stages(find_stage(stages, name), cfg)) {
    engine::throw_if_interrupted();
    const Stage& earlier = find_stage(stages, e);
    const StageContext ctx{cfg, inv.opts, run_dir, run_dir / e, runner, progress};
    if (!fs::is_directory(ctx.stage_dir)) continue;
    EarlierStage p{e, earlier.plan(ctx), "", ""};
    if (const std::string why = stage_stamp_mismatch(ctx.stage_dir, p.plan); !why.empty()) {
      p.stale = fmt::format(
          "stage {} reads the results of stage {}, but {}: {}. Rerun it first: orchestrate --case "
          "{} --stage {}-{} --output {} (with --force if the folder is said to hold other values)",
          name, e, ctx.stage_dir.string(), why, cfg.file.string(), e, name, run_dir.string());
    } else if (const std::string damaged = earlier.damaged_merged_outputs(ctx, p.plan.jobs);
               !damaged.empty() && !p.plan.jobs.empty()) {
      const auto rows = decide_all(earlier, ctx, jobs::JobStore(ctx.stage_dir), p.plan, false);
      // Not all done: not merged yet, and the stage that reads it names what it misses.
      if (std::all_of(rows.begin(), rows.end(),
                      [](const JobRow& r) { return r.verdict.decision == jobs::Decision::Skip; }))
        p.damaged = fmt::format("from its {} done job(s): {}", rows.size(), damaged);
    }
    if (!p.stale.empty() || !p.damaged.empty()) found.push_back(std::move(p));
  }
  return found;
}

// Before stage `name` runs: an earlier stage it reads whose merged outputs
// come from other jobs stops the command (a report never mixes two runs); a
// damaged merged output is rebuilt from the stage's done jobs (not from an
// array task: its siblings would race).
void check_read_stages(const std::vector<std::unique_ptr<Stage>>& stages, const std::string& name,
                       const config::CaseConfig& cfg, const Invocation& inv, engine::Runner& runner,
                       Progress& progress) {
  for (const auto& p : earlier_stage_problems(stages, name, cfg, inv, runner, progress)) {
    if (!p.stale.empty()) throw config::ConfigError(p.stale);
    if (inv.task) continue;
    Stage& earlier = find_stage(stages, p.stage);
    StageContext ctx{cfg, inv.opts, inv.opts.output, inv.opts.output / p.stage, runner, progress};
    progress.info(fmt::format("[{}] rebuild the merged outputs {}", p.stage, p.damaged));
    earlier.finalize(ctx, p.plan.jobs);
    write_stage_stamp(ctx.stage_dir, p.plan);
    if (const std::string still = earlier.damaged_merged_outputs(ctx, p.plan.jobs); !still.empty())
      throw std::runtime_error(
          fmt::format("stage {}: its merged outputs, rebuilt from its jobs, are still damaged: {}",
                      p.stage, still));
  }
}

// --dry-run: what check_read_stages would do before stage `name`.
void print_read_stages(std::ostream& out, const std::vector<std::unique_ptr<Stage>>& stages,
                       const std::string& name, const config::CaseConfig& cfg,
                       const Invocation& inv, engine::Runner& runner, Progress& progress) {
  for (const auto& p : earlier_stage_problems(stages, name, cfg, inv, runner, progress))
    out << (p.stale.empty() ? fmt::format("  note: would first rebuild the merged outputs of stage "
                                          "{} {}\n",
                                          p.stage, p.damaged)
                            : "  note: a run would stop here: " + p.stale + "\n");
}

}  // namespace

// The run options of one stage: its MPI ranks per engine run are --np when
// given, else resources.<stage>.np when the case file sets it (as the Slurm
// scripts read it: 400-element lab specimens and single impacts gain nothing
// from two ranks that the flow wants), else resources.np.
RunOptions stage_options(const config::CaseConfig& cfg, const Invocation& inv,
                         const std::string& stage) {
  RunOptions o = inv.opts;
  if (inv.np_given) return o;
  if (const auto np = config::stage_np(cfg.doc, stage, /*default_counts=*/false)) o.np = *np;
  return o;
}

int run_pipeline(const config::CaseConfig& cfg, const Invocation& inv, std::ostream& out) {
  auto stages = make_stages();
  engine::Runner runner;
  Progress progress(out, isatty(STDOUT_FILENO) && &out == &std::cout);
  const fs::path run_dir = inv.opts.output;
  check_invocation(inv);
  bool provenance_written = false;
  // A copy of what was run, written once before the first job or merge.
  const std::function<void()> provenance = [&]() {
    if (!provenance_written)
      write_provenance(cfg, run_dir, FolderKind::Stages), provenance_written = true;
  };

  if (inv.dry_run)
    out << fmt::format(
        "plan for case '{}' ({}), output {}; {} engine run(s) at once, {} MPI rank(s) each\n",
        cfg.name, cfg.file.string(), run_dir.string(), inv.opts.jobs, inv.opts.np);
  // Every stage's plan as far as it is known now, before any stage runs: a
  // label clash in a late stage must not surface after hours of earlier ones.
  for (const auto& name : inv.stages) {
    engine::throw_if_interrupted();
    StageContext ctx{cfg, inv.opts, run_dir, run_dir / name, runner, progress};
    check_unique_labels(name, find_stage(stages, name).plan(ctx));
  }

  for (const auto& name : inv.stages) {
    engine::throw_if_interrupted();
    if (!inv.dry_run && !inv.list_tasks)
      check_read_stages(stages, name, cfg, inv, runner, progress);
    Stage& stage = find_stage(stages, name);
    const RunOptions opts = stage_options(cfg, inv, name);
    StageContext ctx{cfg, opts, run_dir, run_dir / name, runner, progress};
    const jobs::JobStore store(ctx.stage_dir);
    const Plan plan = stage.plan(ctx);
    check_unique_labels(name, plan);
    check_task_index(inv, name, plan);
    const auto rows = decide_all(stage, ctx, store, plan, inv.opts.force);
    const StagePass pass{stage, ctx, store, plan, rows};
    if (inv.list_tasks) {
      print_tasks(out, inv, name, plan, rows);
      continue;
    }
    if (inv.dry_run) {
      print_plan(out, inv, ctx, stage, plan, rows);
      print_read_stages(out, stages, name, cfg, inv, runner, progress);
      continue;
    }
    if (inv.merge_only) {
      if (merge_stage(pass, out, provenance) != kExitOk) return kExitFailed;
      continue;
    }
    if (!stage.implemented()) {
      out << fmt::format(
          "stage '{}' ({}) is not implemented yet: nothing was run and no output was written.\n",
          name, stage.description());
      return kExitNotImplemented;
    }
    provenance();
    if (const int status = run_stage(pass, inv, out); status != kExitOk) return status;
  }
  return kExitOk;
}

int count_tasks(const config::CaseConfig& cfg, const Invocation& inv) {
  auto stages = make_stages();
  engine::Runner runner;
  std::ostringstream sink;
  Progress progress(sink, false);
  for (auto& s : stages)
    if (s->name() == inv.stages.at(0)) {
      StageContext ctx{cfg,    inv.opts, inv.opts.output, inv.opts.output / s->name(),
                       runner, progress};
      return static_cast<int>(s->plan(ctx).jobs.size());
    }
  return 0;
}

namespace {

// A finished impact in the folder that was made with other inputs is
// replaced only with --force: its result would be lost.
void refuse_replacing(const jobs::JobStore& store, const fs::path& dir, const std::string& id,
                      bool force) {
  const jobs::Status s = store.read_status("");
  if (force || s.state != jobs::State::Done || s.id == id) return;
  std::ifstream in(dir / "job.json");
  const auto job = nlohmann::json::parse(in, nullptr, false);
  const std::string was = job.is_object() && job.contains("label") && job["label"].is_string()
                              ? job["label"].get<std::string>()
                              : std::string("unnamed");
  throw config::ConfigError(
      fmt::format("impact into {}: the folder holds a finished impact made with other inputs ({}, "
                  "job {}); this impact would "
                  "replace it. Use another --output, or --force to replace it",
                  dir.string(), was, s.id));
}

// Run, skip or busy for the impact, with a damaged output counted as not done.
jobs::Verdict impact_verdict(const jobs::JobStore& store, const RunOptions& opts,
                             const std::string& label, const nlohmann::json& inputs) {
  jobs::Verdict v = store.decide(label, inputs, opts.force);
  if (v.decision == jobs::Decision::Skip)
    if (const std::string why = breakage::damaged_impact_outputs(opts.output); !why.empty())
      v = {jobs::Decision::Run, "done before, but an output is damaged: " + why};
  if (v.decision == jobs::Decision::Busy)
    throw std::runtime_error(fmt::format("impact into {}: {}", opts.output.string(), v.why));
  return v;
}

}  // namespace

int run_single_impact(const config::CaseConfig& cfg, const RunOptions& opts, double velocity,
                      double angle, int repeat, bool dry_run, std::ostream& out) {
  engine::Runner runner;
  Progress progress(out, isatty(STDOUT_FILENO) && &out == &std::cout);
  StageContext ctx{cfg, opts, opts.output, opts.output / "breakage", runner, progress};
  const std::string label = fmt::format("impact_v{:g}_a{:g}_r{}", velocity, angle, repeat);
  // The output folder is the job's folder: an identical rerun is skipped.
  const jobs::JobStore store = jobs::JobStore::single(opts.output);
  const nlohmann::json inputs = breakage::impact_inputs(ctx, velocity, angle, repeat);
  refuse_replacing(store, opts.output, jobs::job_id(inputs), opts.force);
  const jobs::Verdict v = impact_verdict(store, opts, label, inputs);
  if (v.decision == jobs::Decision::Skip) {
    std::ifstream in(opts.output / "result.json");
    out << breakage::impact_line(nlohmann::json::parse(in, nullptr, false)) << "\n"
        << "already done with the same inputs (job " << jobs::job_id(inputs)
        << "): " << opts.output.string() << "; --force redoes it\n";
    return kExitOk;
  }
  if (dry_run) {
    out << fmt::format(
        "impact {} ({}): would run a {}-element lump of {} at {:g} m/s, {:g} deg into {} (job {}); "
        "dry run: nothing run or written\n",
        label, v.why, cfg.doc.integer("lump.n_elements"), cfg.ore.str("name"), velocity, angle,
        opts.output.string(), jobs::job_id(inputs));
    return kExitOk;
  }
  write_provenance(cfg, opts.output, FolderKind::Impact);
  if (v.why != "new") progress.info(fmt::format("impact: rerun: {}", v.why));
  progress.info(fmt::format("impact: {}-element lump of {} at {:g} m/s, {:g} deg, into {}",
                            cfg.doc.integer("lump.n_elements"), cfg.ore.str("name"), velocity,
                            angle, opts.output.string()));
  progress.stage_begin("impact", 1, 0);
  store.mark_running(label, inputs);
  progress.job_begin(label);  // the job's clock: its ETA
  const auto t0 = std::chrono::steady_clock::now();
  std::string line;
  try {
    line = breakage::run_impact(ctx, velocity, angle, repeat, opts.output, label);
  } catch (const std::exception& e) {
    const std::string why = e.what();
    progress.job_end(label, false, 0);
    store.mark_failed(label, why.substr(0, why.find('\n')));
    throw;
  }
  progress.job_end(label, true,
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  store.mark_done(label);
  progress.stage_end();
  out << line << "\n"
      << "written: " << (opts.output / "summary.csv").string()
      << ", fractions.csv, impact.h5, fragments.vtp, result.json\n";
  return kExitOk;
}

}  // namespace mill
