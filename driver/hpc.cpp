// Slurm scripts for a stage or a chain of stages (docs/hpc.md).
#include "hpc.h"

#include <fmt/format.h>
#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <regex>
#include <set>

#include "config/schema.h"
#include "jobs/job_store.h"
#include "stages/stage.h"

namespace mill {
namespace fs = std::filesystem;

namespace {

// Stages whose jobs run as an array (one task per job) and a merge job; the
// others are small and run as one job each.
const std::set<std::string> kArrayStages = {"flow", "transport", "breakage"};

// A word for the shell, in single quotes.
std::string quote(const std::string& s) {
  std::string o = "'";
  for (char c : s) o += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return o + "'";
}

// Text for inside a double-quoted shell word: $ ` " \ escaped.
std::string in_dq(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '$' || c == '`' || c == '"' || c == '\\') o += '\\';
    o += c;
  }
  return o;
}

// A value in a message: quoted, control characters as \xNN (one line).
std::string shown(const std::string& v) {
  std::string o = "'";
  for (unsigned char c : v)
    o += std::iscntrl(c) ? fmt::format("\\x{:02x}", c) : std::string(1, static_cast<char>(c));
  return o + "'";
}

// What one stage of the chain submits.
struct StageJob {
  std::string stage;
  bool array = false;
  int tasks = 0;             // array size known now; -1: counted by the planning job
  std::string planned_from;  // tasks < 0: the stage of the range whose output decides the count
  std::vector<std::string> after;  // stages of the range whose outputs it reads
  StageResources res;
};

// The one template: the #SBATCH header of every script.
// log_pattern: Slurm's file-name pattern, %x_%A_%a (array) or %x_%j (single job).
std::string header(const HpcOptions& o, const std::string& name, int ntasks,
                   const std::string& time, const std::string& time_from, const StageResources& r,
                   bool with_mem, const fs::path& logs, const char* log_pattern) {
  std::string h = "#!/bin/bash\n";
  h += sbatch_directive("--job-name", name, "name (the case name)");
  h += sbatch_directive("--ntasks", std::to_string(ntasks), "ranks");
  h += sbatch_directive("--time", time, time_from);
  if (!r.partition.empty()) h += sbatch_directive("--partition", r.partition, r.partition_from);
  if (!o.account.empty()) h += sbatch_directive("--account", o.account, "--account");
  if (with_mem && !r.mem.empty()) h += sbatch_directive("--mem", r.mem, r.mem_from);
  h += sbatch_directive("--output", fmt::format("{}/{}.out", logs.string(), log_pattern),
                        "--output (the run folder)");
  return h;
}

std::string throttle(const HpcOptions& o) {
  return o.max_parallel > 0 ? fmt::format("%{}", o.max_parallel) : "";
}

}  // namespace

void check_hpc_options(const HpcOptions& o) {
  auto bad = [](const std::string& opt, const std::string& value, const std::string& expected) {
    std::string shown;
    for (char c : value)
      shown += std::iscntrl(static_cast<unsigned char>(c))
                   ? fmt::format("\\x{:02x}", static_cast<unsigned char>(c))
                   : std::string(1, c);
    throw config::ConfigError(fmt::format("{}: expected {}, got '{}'", opt, expected, shown));
  };
  // Slurm's --time forms: M, M:S, H:M:S, D-H, D-H:M, D-H:M:S.
  static const std::regex time_re(
      R"((\d+)|(\d+):(\d{1,2})|(\d+):(\d{1,2}):(\d{1,2})|(\d+)-(\d{1,2})(:(\d{1,2})(:(\d{1,2}))?)?)");
  std::smatch m;
  bool time_ok =
      o.time.empty() || std::regex_match(o.time, m, time_re);  // empty: resources.<stage>.time
  if (time_ok && !o.time.empty()) {
    // Minutes and seconds after a larger unit below 60, hours after days below 24; not all zero.
    const auto num = [&](int i) { return m[i].matched ? std::stol(m[i].str()) : 0L; };
    if (m[2].matched) time_ok = num(3) < 60;
    if (m[4].matched) time_ok = num(5) < 60 && num(6) < 60;
    if (m[7].matched) time_ok = num(8) < 24 && num(10) < 60 && num(12) < 60;
    time_ok = time_ok && o.time.find_first_not_of("0:-") != std::string::npos;
  }
  if (!time_ok)
    bad("--time", o.time,
        "a Slurm wall time above zero: MINUTES, MM:SS, HH:MM:SS, DAYS-HH, DAYS-HH:MM or "
        "DAYS-HH:MM:SS (e.g. 02:00:00)");
  static const std::regex mem_re(R"([1-9][0-9]{0,8}[KMGT]?)");
  if (!o.mem.empty() && !std::regex_match(o.mem, mem_re))
    bad("--mem", o.mem,
        "a memory size: a whole number above 0 with an optional unit K, M, G or T (e.g. 4G; no "
        "unit: MB)");
  static const std::regex name_re(R"([A-Za-z0-9_.-]+(,[A-Za-z0-9_.-]+)*)");
  if (!o.partition.empty() && !std::regex_match(o.partition, name_re))
    bad("--partition", o.partition,
        "a Slurm partition name (letters, digits, '_', '.', '-'; a comma between several)");
  static const std::regex account_re(R"([A-Za-z0-9_.-]+)");
  if (!o.account.empty() && !std::regex_match(o.account, account_re))
    bad("--account", o.account, "a Slurm account name (letters, digits, '_', '.', '-')");
  if (o.max_parallel < 0)
    bad("--max-parallel", std::to_string(o.max_parallel), "a whole number >= 0 (0: no limit)");
  if (o.np < 0)
    bad("--np", std::to_string(o.np), "a whole number >= 1 (or none: resources.<stage>.np)");
  // The run folder appears in #SBATCH --output="..." and in the scripts:
  // one line, no quote or '%' (Slurm's file-name pattern character).
  const std::string out = fs::absolute(o.output).string();
  for (char c : out)
    if (std::iscntrl(static_cast<unsigned char>(c)) || c == '"' || c == '%' || c == '\\')
      bad("--output", out,
          "a run folder path without control characters, '\"', '%' or '\\' (it is written into "
          "#SBATCH lines)");
}

std::string sbatch_directive(const std::string& option, const std::string& value,
                             const std::string& source) {
  if (value.empty())
    throw config::ConfigError(
        fmt::format("{}: expected a value for #SBATCH {}, got nothing", source, option));
  for (char c : value)
    if (std::iscntrl(static_cast<unsigned char>(c)) || c == '"' || c == '\\')
      throw config::ConfigError(
          fmt::format("{}: expected a value for #SBATCH {} on one line without control "
                      "characters, '\"' or '\\', got {}",
                      source, option, shown(value)));
  // sbatch splits a directive at blanks and ends it at '#' outside double quotes.
  const bool plain = value.find_first_of(" #") == std::string::npos;
  return fmt::format("#SBATCH {}={}\n", option, plain ? value : "\"" + value + "\"");
}

StageResources stage_resources(const config::CaseConfig& cfg, const HpcOptions& o,
                               const std::string& stage) {
  const auto& d = cfg.doc;
  const std::string p = "resources." + stage + ".";
  StageResources r;
  if (config::case_schema().find(p + "np")) {  // a stage that runs MPI engines
    if (o.np > 0 && (stage == "flow" || o.stages.size() == 1))
      r.np = o.np;
    else
      r.np = config::stage_np(d, stage, /*default_counts=*/true)
                 .value_or(static_cast<int>(d.integer("resources.np")));
  }
  // An option given on the command line, else the case's key (or none).
  auto pick = [&](const std::string& opt_value, const char* opt_name, const std::string& key,
                  std::string& value, std::string& from) {
    if (!opt_value.empty()) {
      value = opt_value, from = opt_name;
    } else if (d.has(key)) {
      value = d.str(key), from = d.where(key);
    }
  };
  pick(o.time, "--time", p + "time", r.time, r.time_from);
  pick(o.mem, "--mem", p + "mem", r.mem, r.mem_from);
  pick(o.partition, "--partition", p + "partition", r.partition, r.partition_from);
  pick(o.time, "--time", "resources.merge.time", r.merge_time, r.merge_time_from);
  return r;
}

namespace {

// The checks of an hpc request before anything is planned: the scheduler,
// the stages, the options, and a run folder `out` that Slurm can take.
void check_hpc_request(const HpcOptions& o, const fs::path& out) {
  if (o.scheduler != "slurm")
    throw config::ConfigError(fmt::format(
        "--scheduler: expected 'slurm' (the only scheduler supported), got '{}'", o.scheduler));
  if (o.stages.empty()) throw config::ConfigError("--stage: hpc needs the stages to script");
  check_hpc_options(o);
  // '%' starts a Slurm file-name pattern in #SBATCH --output.
  if (out.string().find('%') != std::string::npos)
    throw config::ConfigError(
        fmt::format("--output: expected a run folder without '%' (Slurm reads it as a "
                    "file-name pattern in #SBATCH --output), got {}",
                    shown(out.string())));
}

// What each stage of the range submits: its kind, size and the stages it
// waits for. Throws when an array stage has no jobs yet and the stage its
// jobs come from is outside the range.
std::vector<StageJob> stage_chain(const config::CaseConfig& cfg, const HpcOptions& o,
                                  const std::function<int(const std::string&)>& n_tasks) {
  const auto stage_list = make_stages();
  const auto in_range = [&](const std::string& s) {
    return std::find(o.stages.begin(), o.stages.end(), s) != o.stages.end();
  };
  std::vector<StageJob> chain;
  for (const auto& name : o.stages) {
    const auto it = std::find_if(stage_list.begin(), stage_list.end(),
                                 [&](const auto& s) { return s->name() == name; });
    const Stage& st = **it;
    StageJob j;
    j.stage = name;
    j.array = kArrayStages.count(name) > 0;
    j.res = stage_resources(cfg, o, name);
    for (const auto& r : st.reads(cfg))
      if (in_range(r)) j.after.push_back(r);
    if (j.array) {
      for (const auto& r : st.jobs_from(cfg))
        if (in_range(r)) j.planned_from = r;
      if (!j.planned_from.empty()) {
        j.tasks = -1;
      } else if ((j.tasks = n_tasks(name)) <= 0) {
        const auto from = st.jobs_from(cfg);
        throw config::ConfigError(fmt::format(
            "--stage {}: stage '{}' has no jobs yet (its jobs come from an earlier stage that has "
            "not run){}",
            o.stage, name,
            from.empty() ? "" : fmt::format("; script both: --stage {}-{}", from.front(), name)));
      }
    }
    chain.push_back(j);
  }
  return chain;
}

// What every script of one chain shares.
struct ChainScripts {
  const config::CaseConfig& cfg;
  const HpcOptions& o;
  fs::path dir;             // <run>/hpc
  fs::path logs;            // <run>/hpc/logs
  std::string common;       // orchestrate --case ... --output ...
  std::string submit_name;  // submit_<stage>.sh
  fs::path submit_path;     // dir / submit_name
  std::string resubmit;     // the line telling how to submit again
  std::string job_name(const StageJob& j) const {
    return fmt::format("mill-{}-{}", cfg.name, j.stage);
  }
  std::string run(const StageJob& j) const { return fmt::format("{} --stage {}", common, j.stage); }
};

// <stage>.sh of a small stage: one job runs it whole (its done jobs are
// skipped) and merges it.
std::string single_script(const ChainScripts& c, const StageJob& j) {
  const std::string name = c.job_name(j);
  std::string s =
      header(c.o, name, j.res.np, j.res.time, j.res.time_from, j.res, true, c.logs, "%x_%j");
  s += fmt::format(
      "# Stage {} of case '{}': every job of `orchestrate --stage {}` in this one Slurm job,\n"
      "# then its merge. Jobs done with the same inputs are skipped: resubmitting is safe.\n",
      j.stage, c.cfg.name, j.stage);
  s += "set -uo pipefail\n";
  s += "export MILL_SCHEDULER_JOB=\"$SLURM_JOB_ID\"\n";
  s += fmt::format("export MILL_SCHEDULER_LOG={}/\"{}_$SLURM_JOB_ID.out\"\n",
                   quote(c.logs.string()), name);
  s += fmt::format("if {} --np {} --jobs 1; then exit 0; fi\n", c.run(j), j.res.np);
  s += fmt::format(
      "echo \"error: stage {} failed in Slurm job $SLURM_JOB_ID (log: $MILL_SCHEDULER_LOG); "
      "the "
      "chain stops here.\" >&2\n",
      j.stage);
  return s + c.resubmit + "exit 1\n";
}

// <stage>.array.sh: task I runs job I of the stage.
std::string array_script(const ChainScripts& c, const StageJob& j) {
  const std::string name = c.job_name(j);
  std::string a =
      header(c.o, name, j.res.np, j.res.time, j.res.time_from, j.res, true, c.logs, "%x_%A_%a");
  if (j.tasks > 0)
    a += sbatch_directive("--array", fmt::format("0-{}{}", j.tasks - 1, throttle(c.o)),
                          "the stage's job count");
  a += fmt::format(
      "# Stage {} of case '{}': array task I runs job I of `orchestrate --stage {} "
      "--list-tasks`\n"
      "# on --ntasks MPI ranks. A task whose job is done with the same inputs returns at once:\n"
      "# resubmitting is safe.\n",
      j.stage, c.cfg.name, j.stage);
  if (j.tasks < 0)
    a += fmt::format(
        "# The task count comes from the stage's plan once {} has run: {}.plan.sh passes "
        "--array.\n",
        j.planned_from, j.stage);
  a += "set -euo pipefail\n";
  a += "export MILL_SCHEDULER_JOB=\"${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID}\"\n";
  a += fmt::format(
      "export "
      "MILL_SCHEDULER_LOG={}/\"{}_${{SLURM_ARRAY_JOB_ID}}_${{SLURM_ARRAY_TASK_ID}}.out\"\n",
      quote(c.logs.string()), name);
  a +=
      fmt::format("exec {} --task \"$SLURM_ARRAY_TASK_ID\" --np {} --jobs 1\n", c.run(j), j.res.np);
  return a;
}

// <stage>.merge.sh: after the array, merge the stage or name the failed tasks.
std::string merge_script(const ChainScripts& c, const StageJob& j) {
  std::string m = header(c.o, c.job_name(j) + "-merge", 1, j.res.merge_time, j.res.merge_time_from,
                         j.res, false, c.logs, "%x_%j");
  m += fmt::format(
      "# After the {} array (its job id is $1) ended, whatever the outcome: merge the stage "
      "when\n"
      "# every task succeeded; else name each failed task with its Slurm job and log, and fail,\n"
      "# which stops the chain (the next stages wait with afterok).\n",
      j.stage);
  m += "set -uo pipefail\n";
  m += fmt::format("if {} --merge-only --np 1 --jobs 1; then exit 0; fi\n", c.run(j));
  m += fmt::format(
      "echo \"error: stage {} did not complete (array job ${{1:-?}}; logs in {}); the chain "
      "stops "
      "here.\" >&2\n",
      j.stage, in_dq(c.logs.string()));
  return m + c.resubmit + "exit 1\n";
}

// <stage>.plan.sh of a stage whose job count comes from an earlier stage of
// the range: counts the jobs, then submits the array and what follows.
std::string plan_script(const ChainScripts& c, const StageJob& j) {
  std::string p = header(c.o, c.job_name(j) + "-plan", 1, j.res.merge_time, j.res.merge_time_from,
                         j.res, false, c.logs, "%x_%j");
  p += fmt::format(
      "# After {}: count the jobs of stage {} (they come from the outputs\n"
      "# of {}) and submit the {} array of that size and the stages after it.\n",
      fmt::join(j.after, " and "), j.stage, j.planned_from, j.stage);
  p += "set -euo pipefail\n";
  p += fmt::format("list=$({} --list-tasks)\n", c.run(j));
  p += "printf '%s\\n' \"$list\"\n";
  p += "n=$(printf '%s\\n' \"$list\" | grep -c '^[0-9]' || true)\n";
  p += fmt::format(
      "if [ \"$n\" -eq 0 ]; then\n"
      "  echo \"error: stage {} has no jobs (see the note above); the chain stops here.\" >&2\n"
      "  exit 1\n"
      "fi\n",
      j.stage);
  p += fmt::format(
      "echo \"stage {}: $n jobs, planned from the outputs of {}: submitting an array of $n "
      "tasks "
      "and the stages after it\"\n",
      j.stage, j.planned_from);
  p += fmt::format("exec sh {} --from {} --tasks \"$n\"\n", quote(c.submit_path.string()), j.stage);
  return p;
}

// The submit script's head: what it submits, its options (--from, --tasks)
// checked, and its two shell helpers.
std::string submit_head(const ChainScripts& c, const std::vector<StageJob>& chain) {
  std::vector<std::string> names, planned;
  for (const auto& j : chain) {
    names.push_back(j.stage);
    if (j.tasks < 0) planned.push_back(j.stage);
  }
  std::string s = "#!/bin/sh\n";
  s += fmt::format(
      "# Submits to Slurm the stage{} of case '{}': {},\n"
      "# chained with --dependency=afterok (written by `orchestrate hpc --stage {}`;\n"
      "# docs/hpc.md). Submitting it again resumes: jobs that are done are skipped.\n"
      "#   sh {}                            the whole chain\n"
      "#   sh {} --from STAGE [--tasks N]   from STAGE on (a planning job passes N,\n"
      "#                                      the size of the array it planned)\n",
      names.size() == 1 ? "" : "s", c.cfg.name, fmt::join(names, ", "), c.o.stage, c.submit_name,
      c.submit_name);
  s += "set -eu\n";
  s += fmt::format("hpc={}\n", quote(c.dir.string()));
  s += fmt::format("from={}\ntasks=\n", names.front());
  s += "while [ $# -gt 0 ]; do\n"
       "  case \"$1\" in\n"
       "    --from) from=${2:?--from needs a stage}; shift 2 ;;\n"
       "    --tasks) tasks=${2:?--tasks needs a count}; shift 2 ;;\n"
       "    *) echo \"usage: $0 [--from STAGE [--tasks N]]\" >&2; exit 2 ;;\n"
       "  esac\n"
       "done\n";
  s += fmt::format(
      "case \"$from\" in\n  {}) ;;\n  *) echo \"$0: --from: expected one of {}, got '$from'\" >&2; "
      "exit 2 ;;\n"
      "esac\n",
      fmt::join(names, "|"), fmt::join(names, ", "));
  s += "case \"$tasks\" in\n"
       "  '') ;;\n"
       "  *[!0-9]* | 0 | 0*) echo \"$0: --tasks: expected a whole number > 0, got '$tasks'\" >&2; "
       "exit 2 ;;\n";
  if (!planned.empty())
    s += fmt::format(
        "  *) case \"$from\" in {}) ;; *) echo \"$0: --tasks: only with --from {}\" >&2; exit 2 ;; "
        "esac ;;\n",
        fmt::join(planned, "|"), fmt::join(planned, " or --from "));
  else
    s +=
        "  *) echo \"$0: --tasks: no stage of this chain is planned at run time\" >&2; exit 2 ;;\n";
  s += "esac\n";
  s += "# Submit a script with sbatch; print its job id. A job whose dependency can never\n"
       "# be met (an earlier stage failed) is cancelled rather than left pending.\n"
       "submit() { id=$(sbatch --parsable --kill-on-invalid-dep=yes \"$@\") || exit 1; echo "
       "\"${id%%;*}\"; }\n"
       "# The non-empty job ids given, joined with ':' (a stage not submitted by this run is "
       "done).\n"
       "ids() { r=; for i in \"$@\"; do if [ -n \"$i\" ]; then r=\"$r${r:+:}$i\"; fi; done; echo "
       "\"$r\"; }\n"
       "on=\n";
  return s;
}

// The submit script's lines for an array stage: (its planning job, or) its
// array and merge jobs.
std::string submit_array_stage(const ChainScripts& c, const StageJob& j) {
  std::string s, size;
  if (j.tasks < 0) {
    s += fmt::format("  if [ \"$from\" != {} ] || [ -z \"$tasks\" ]; then\n", j.stage);
    s += fmt::format("    plan=$(submit ${{up:+--dependency=afterok:$up}} \"$hpc/{}.plan.sh\")\n",
                     j.stage);
    s += fmt::format(
        "    echo \"{}: planning job $plan (sizes the {} array from the outputs of {}, then "
        "submits "
        "it and the stages after it)\"\n",
        j.stage, j.stage, j.planned_from);
    s += fmt::format("    echo \"logs: {}\"\n", in_dq(c.logs.string()));
    s += "    exit 0\n  fi\n";
    size = fmt::format(" --array=0-$((tasks - 1)){}", throttle(c.o));
  }
  s +=
      fmt::format("  {}_array=$(submit ${{up:+--dependency=afterok:$up}}{} \"$hpc/{}.array.sh\")\n",
                  j.stage, size, j.stage);
  s += fmt::format(
      "  {0}_done=$(submit --dependency=afterany:${0}_array${{up:+,afterok:$up}} "
      "\"$hpc/{0}.merge.sh\" "
      "\"${0}_array\")\n",
      j.stage);
  s += fmt::format("  echo \"{0}: array job ${0}_array ({1} task{2}), merge job ${0}_done\"\n",
                   j.stage, j.tasks > 0 ? std::to_string(j.tasks) : std::string("$tasks"),
                   j.tasks == 1 ? "" : "s");
  return s;
}

// The submit script's block of one stage: what it is, and its submission
// once the chain has reached --from.
std::string submit_stage(const ChainScripts& c, const StageJob& j) {
  std::vector<std::string> ups;
  for (const auto& a : j.after) ups.push_back(fmt::format("\"${}_done\"", a));
  std::string s = "\n";
  if (!j.array)
    s += fmt::format("# {}: one job, after {}.\n", j.stage,
                     j.after.empty() ? "nothing" : fmt::format("{}", fmt::join(j.after, ", ")));
  else if (j.tasks > 0)
    s += fmt::format("# {}: an array of {} task{} (one per job), then its merge; after {}.\n",
                     j.stage, j.tasks, j.tasks == 1 ? "" : "s",
                     j.after.empty() ? "nothing" : fmt::format("{}", fmt::join(j.after, ", ")));
  else
    s += fmt::format(
        "# {}: its job count comes from the outputs of {}. A planning job after {}\n"
        "# submits the array, its merge and the stages after it (this script with\n"
        "# --from {} --tasks N).\n",
        j.stage, j.planned_from, fmt::join(j.after, " and "), j.stage);
  s += fmt::format("if [ \"$from\" = {} ]; then on=1; fi\n", j.stage);
  s += "if [ -n \"$on\" ]; then\n";
  s += ups.empty() ? std::string("  up=\n") : fmt::format("  up=$(ids {})\n", fmt::join(ups, " "));
  if (!j.array) {
    s += fmt::format("  {}_done=$(submit ${{up:+--dependency=afterok:$up}} \"$hpc/{}.sh\")\n",
                     j.stage, j.stage);
    s += fmt::format("  echo \"{}: job ${}_done\"\n", j.stage, j.stage);
  } else {
    s += submit_array_stage(c, j);
  }
  return s + "fi\n";
}

// The submit script: every stage in order, each waiting (afterok) for the
// stages of the range whose outputs it reads; re-entered by planning jobs.
std::string submit_script(const ChainScripts& c, const std::vector<StageJob>& chain) {
  std::string s = submit_head(c, chain);
  for (const auto& j : chain) s += fmt::format("{}_done=\n", j.stage);
  for (const auto& j : chain) s += submit_stage(c, j);
  s += fmt::format("echo \"logs: {}\"\n", in_dq(c.logs.string()));
  return s;
}

// One line per stage of the chain: its size, ranks, time, memory, partition.
std::string chain_table(const std::vector<StageJob>& chain) {
  std::string text;
  for (const auto& j : chain) {
    const StageResources& r = j.res;
    const std::string size = !j.array      ? "one job"
                             : j.tasks > 0 ? fmt::format("array of {}", j.tasks)
                                           : "array sized by a planning job";
    text += fmt::format("  {:<10} {:<30} {} rank{}, time {}{}{}\n", j.stage, size, r.np,
                        r.np == 1 ? "" : "s", r.time, r.mem.empty() ? "" : ", mem " + r.mem,
                        r.partition.empty() ? "" : ", partition " + r.partition);
  }
  return text;
}

}  // namespace

std::string write_hpc_scripts(const config::CaseConfig& cfg, const HpcOptions& o,
                              const std::function<int(const std::string&)>& n_tasks,
                              const std::string& exe) {
  const fs::path out = fs::absolute(o.output);
  check_hpc_request(o, out);
  const std::vector<StageJob> chain = stage_chain(cfg, o, n_tasks);
  ChainScripts c{cfg, o, out / "hpc", out / "hpc" / "logs", "", "", {}, ""};
  c.common = fmt::format("{} --case {} --output {}", quote(exe), quote(cfg.file.string()),
                         quote(out.string()));
  c.submit_name = fmt::format("submit_{}.sh", o.stage);
  c.submit_path = c.dir / c.submit_name;
  c.resubmit =
      fmt::format("echo \"Fix the cause, then submit again: sh {}  (done jobs are skipped)\" >&2\n",
                  in_dq(quote(c.submit_path.string())));
  // Every script is made (and every value checked) before any is written.
  std::vector<std::pair<fs::path, std::string>> scripts;
  for (const auto& j : chain) {
    if (!j.array) {
      scripts.emplace_back(c.dir / (j.stage + ".sh"), single_script(c, j));
      continue;
    }
    scripts.emplace_back(c.dir / (j.stage + ".array.sh"), array_script(c, j));
    scripts.emplace_back(c.dir / (j.stage + ".merge.sh"), merge_script(c, j));
    if (j.tasks < 0) scripts.emplace_back(c.dir / (j.stage + ".plan.sh"), plan_script(c, j));
  }
  scripts.emplace_back(c.submit_path, submit_script(c, chain));
  fs::create_directories(c.logs);
  for (const auto& [file, text] : scripts) {
    jobs::atomic_write(file, text);
    chmod(file.c_str(), 0755);
  }
  return fmt::format("wrote {} scripts in {}:\n{}submit with: sh {}\n", scripts.size(),
                     c.dir.string(), chain_table(chain), c.submit_path.string());
}

}  // namespace mill
