// orchestrate's command line.
#include "cli.h"

#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <regex>

#include "compare.h"
#include "config/case_config.h"
#include "config/schema.h"
#include "engine/runner.h"
#include "hpc.h"
#include "jobs/run_lock.h"
#include "lump/material.h"
#include "pipeline.h"
#include "run_folder.h"
#include "stages/stage.h"

namespace mill {
namespace fs = std::filesystem;

std::string project_dir() {
  if (const char* env = std::getenv("MILL_PROJECT_DIR")) return env;
  return MILL_PROJECT_DIR;
}

namespace {

const char* kExamples = R"(
Stages, in order: flow, sample, transport, calibrate, breakage, report (or all,
or a range such as transport-breakage).

Examples:
  orchestrate --stage all                        run everything on the default case
  orchestrate --case cases/reference.yaml --stage all --dry-run
                                                 show the plan: stages, jobs, what is done
  orchestrate --stage breakage --jobs 2          two impact runs at once on this machine
  orchestrate --stage flow --np 4                the CFD on 4 MPI ranks
  orchestrate --stage breakage --list-tasks      one job per line (HPC array units)
  orchestrate --stage breakage --task 7          run job 7 only (e.g. $SLURM_ARRAY_TASK_ID)
  orchestrate hpc --scheduler slurm --stage all  Slurm scripts chaining every stage (docs/hpc.md)
  orchestrate --print-schema > docs/config.md    every case-file and ore-card key
  orchestrate compare runs/default runs/granite  headline numbers and product curves side by side

A rerun of the same command resumes: done jobs whose inputs did not change are
skipped; failed, interrupted and changed ones are rerun (--force redoes all).
A run folder holds one case with one set of values, written by one command at
a time: another case, or this case with other values, is refused (--force
takes the folder over).
Exit status: 0 ok, 1 a job failed (or the run folder is in use), 2 bad input,
3 stage not implemented yet, 128+N interrupted by signal N.
)";

// A CLI11 check: a plain decimal number (no hex, inf or nan) in [lo, hi],
// a whole number when `integer`. The message reads "expected ..., got '...'".
CLI::Validator decimal(double lo, double hi, bool integer, const std::string& what,
                       bool lo_open = false) {
  const std::string range =
      integer ? fmt::format("a whole number in [{}, {}]", static_cast<long long>(lo),
                            static_cast<long long>(hi))
              : fmt::format("{} in {}{:g}, {:g}]", what, lo_open ? "(" : "[", lo, hi);
  return CLI::Validator(
      [=](std::string& in) -> std::string {
        static const std::regex real(R"([+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?)");
        static const std::regex whole(R"([+-]?[0-9]+)");
        const bool form = std::regex_match(in, integer ? whole : real);
        double v = 0;
        if (form) {
          errno = 0;
          v = std::strtod(in.c_str(), nullptr);
        }
        if (form && errno == 0 && (lo_open ? v > lo : v >= lo) && v <= hi) return "";
        return fmt::format("expected {}{}, got '{}'", range, integer ? "" : " (decimal)", in);
      },
      integer ? "INT" : "NUMBER");
}

// The run folder must be a folder, or a path that can become one: no part of
// it may be an existing regular file.
void check_output_path(const fs::path& out) {
  std::error_code ec;
  for (fs::path p = out; !p.empty(); p = p.parent_path()) {
    const bool exists = fs::exists(p, ec);
    if (ec && ec != std::errc::no_such_file_or_directory)
      throw config::ConfigError(fmt::format("--output {}: {}: {}; expected a run folder (a directory, or a path that "
                                            "does not exist yet)",
                                            out.string(), p.string(),
                                            ec == std::errc::too_many_symbolic_link_levels
                                                ? "a loop of symbolic links"
                                                : ec.message()));
    if (exists) {
      if (fs::is_directory(p, ec)) return;
      throw config::ConfigError(p == out
                                    ? fmt::format("--output {}: is a file; expected a run folder "
                                                  "(a directory, or a path that does not "
                                                  "exist yet)",
                                                  out.string())
                                    : fmt::format("--output {}: {} is a file, so the run folder "
                                                  "cannot be made below it; expected a "
                                                  "path under a directory",
                                                  out.string(), p.string()));
    }
    if (p == p.parent_path()) return;
  }
}

// The commands of orchestrate, for the table of which option each takes.
enum Command { kStages, kImpact, kCompare, kHpc, kCommands };
const char* const kCommandName[kCommands] = {"a stage run", "orchestrate impact",
                                             "orchestrate compare", "orchestrate hpc"};

// Which command takes which option of the main command (which subcommands
// reach through CLI11's fallthrough), and what the option is for. An option
// given to a command that does not take it is refused, never ignored.
struct OptionUse {
  const char* name;
  bool takes[kCommands];  // stages, impact, compare, hpc
  const char* what;
};
const OptionUse kOptionUse[] = {
    {"--case", {true, true, false, true}, "names the case file"},
    {"--stage", {true, false, false, true}, "chooses the stages"},
    {"--output", {true, true, true, true}, "names the output folder"},
    {"--np", {true, true, false, true}, "sets the MPI ranks of an engine run"},
    {"--jobs", {true, false, false, false}, "sets how many engine runs go at once"},
    {"--dry-run", {true, true, true, false}, "shows what would be done"},
    {"--list-tasks", {true, false, false, false}, "lists a stage's jobs"},
    {"--task", {true, false, false, false}, "runs one job of a stage"},
    {"--merge-only", {true, false, false, false}, "merges a stage whose jobs are done"},
    {"--force", {true, true, false, true}, "redoes done work or takes a run folder over"},
    {"--check", {true, true, false, false}, "validates the case"},
    {"--print-schema", {true, false, false, false}, "prints the case keys"},
};

// The options given on the command line (by their long name).
std::vector<std::string> given_options(const CLI::App& app) {
  std::vector<std::string> given;
  for (const auto& u : kOptionUse)
    if (app.get_option(u.name)->count() > 0) given.push_back(u.name);
  return given;
}

// Refuses an option that `cmd` does not take, and options that contradict
// each other (each would ignore the other): ConfigError naming both.
void check_option_use(const CLI::App& app, Command cmd) {
  const auto given = given_options(app);
  for (const auto& u : kOptionUse)
    if (!u.takes[cmd] && app.get_option(u.name)->count() > 0)
      throw config::ConfigError(
          fmt::format("{}: not an option of {} (in a stage run it {}); drop it", u.name,
                      kCommandName[cmd], u.what));
  auto has = [&](const char* o) { return std::find(given.begin(), given.end(), o) != given.end(); };
  // At most one of the modes that replace running.
  const char* modes[] = {"--print-schema", "--check", "--dry-run", "--list-tasks", "--merge-only"};
  std::vector<std::string> on;
  for (const char* m : modes)
    if (has(m)) on.push_back(m);
  if (on.size() > 1)
    throw config::ConfigError(
        fmt::format("{}: cannot go with {}: each does something else instead of running; "
                    "give one of them",
                    on[1], on[0]));
  // The modes that stop before any stage take only what they use.
  if (cmd == kStages && (has("--print-schema") || has("--check")))
    for (const auto& g : given) {
      const bool used = g == on[0] || (on[0] == std::string("--check") && g == "--case");
      if (!used)
        throw config::ConfigError(fmt::format(
            "{}: {} {} and runs nothing, so {} would be ignored; drop it", g, on[0],
            on[0] == std::string("--check") ? "validates the case file" : "prints the case keys",
            g));
    }
}

// Everything the command line sets, with its defaults.
struct CliArgs {
  std::string case_file = (fs::path(project_dir()) / "cases" / "default.yaml").string();
  std::string stage, output;
  int np = 0, jobs = 0, task = -1;
  bool dry_run = false, list_tasks = false, force = false, print_schema = false, check = false,
       merge_only = false;
  // orchestrate impact
  double imp_velocity = 0, imp_angle = 90;
  std::string imp_ore;
  long imp_elements = 0;
  int imp_repeat = 0;
  // orchestrate hpc
  HpcOptions hpc_opt;
  // orchestrate compare
  std::vector<std::string> compare_runs;
};

// The options of a stage run (the main command).
void add_stage_options(CLI::App& app, CliArgs& a) {
  app.add_option("-c,--case", a.case_file, "Case file (YAML)")->capture_default_str();
  app.add_option("-s,--stage", a.stage,
                 "Stage to run: flow, sample, transport, calibrate, breakage, report, all, or a "
                 "range FIRST-LAST");
  app.add_option("-o,--output", a.output, "Run folder (default: runs/<case name>)");
  app.add_option("--np", a.np, "MPI ranks per engine run (default: resources.np of the case)")
      ->check(decimal(1, 100000, true, "ranks"));
  app.add_option("-j,--jobs", a.jobs,
                 "Engine runs at once on this machine (default: resources.jobs)")
      ->check(decimal(1, 1024, true, "jobs"));
  app.add_flag("-n,--dry-run", a.dry_run,
               "Print the plan (stages, jobs, which are done); run nothing");
  app.add_flag("--list-tasks", a.list_tasks,
               "List the jobs of the stage, one per line: index, label, state, summary");
  app.add_option("--task", a.task, "Run only job I (0-based) of the stage: one HPC array task")
      ->check(decimal(0, 10000000, true, "task"));
  app.add_flag("--merge-only", a.merge_only,
               "Run no job: merge the stage if every job is done, else name the jobs that are "
               "not and exit 1 (the "
               "merge job of `orchestrate hpc`)");
  app.add_flag("-f,--force", a.force, "Redo jobs that are already done");
  app.add_flag("--print-schema", a.print_schema,
               "Print every case-file and ore-card key as Markdown");
  app.add_flag("--check", a.check, "Validate the case file and its ore card, then exit");
}

// orchestrate impact: one impact, for trying things.
CLI::App* add_impact_command(CLI::App& app, CliArgs& a) {
  CLI::App* impact = app.add_subcommand(
      "impact", "One lump impact (deck + fragment analysis) into --output; prints its figures");
  // The same bounds as breakage.velocities and breakage.angles in the case schema.
  const config::KeyDef& vel_key = *config::case_schema().find("breakage.velocities");
  impact->add_option("-v,--velocity", a.imp_velocity, "Impact speed, m/s")
      ->required()
      ->check(decimal(0, *vel_key.max, false, "a speed in m/s", true));
  impact->add_option("-a,--angle", a.imp_angle, "Angle to the surface, deg (90 = normal)")
      ->check(decimal(0, 90, false, "an angle in deg", true))
      ->capture_default_str();
  impact->add_option("--ore", a.imp_ore,
                     "Ore card (file or bundled name, e.g. granite); default: the case's");
  impact
      ->add_option("--elements", a.imp_elements,
                   "Elements in the lump; default: the case's lump.n_elements")
      ->check(decimal(config::kMinLumpElements, 10000000, true, "elements"));
  impact->add_option("--repeat", a.imp_repeat, "Repeat index (random orientation)")
      ->check(decimal(0, 1000000, true, "repeat"));
  impact->footer(
      "\nExample:\n  orchestrate impact --velocity 100 --angle 60 --ore granite --elements 400 "
      "--output try1\n");
  impact->fallthrough();
  return impact;
}

// orchestrate hpc: scheduler scripts for a stage or a chain of stages.
CLI::App* add_hpc_command(CLI::App& app, CliArgs& a) {
  HpcOptions& o = a.hpc_opt;
  CLI::App* hpc = app.add_subcommand(
      "hpc",
      "Write Slurm scripts for a stage or a range of stages (arrays of one task per job, chained "
      "with "
      "--dependency=afterok) and the script that submits them");
  hpc->add_option("--scheduler", o.scheduler, "Scheduler (slurm)")->capture_default_str();
  hpc->add_option("--partition", o.partition,
                  "Slurm partition of every job (default: resources.<stage>.partition)");
  hpc->add_option("--account", o.account, "Slurm account");
  hpc->add_option("--time", o.time,
                  "Wall-time limit of every job (HH:MM:SS; default: resources.<stage>.time)");
  hpc->add_option("--mem", o.mem, "Memory of every job, e.g. 4G (default: resources.<stage>.mem)");
  hpc->add_option("--max-parallel", o.max_parallel, "At most this many tasks at once (0: no limit)")
      ->check(decimal(0, 100000, true, "tasks"));
  hpc->footer(
      "\nExamples:\n  orchestrate hpc --scheduler slurm --stage all --case cases/reference.yaml "
      "--np 16\n"
      "  sh runs/reference/hpc/submit_all.sh\n"
      "  orchestrate hpc --scheduler slurm --stage breakage --case cases/reference.yaml\n"
      "  sh runs/reference/hpc/submit_breakage.sh\n");
  hpc->fallthrough();
  return hpc;
}

// orchestrate compare: several finished runs side by side.
CLI::App* add_compare_command(CLI::App& app, CliArgs& a) {
  CLI::App* compare = app.add_subcommand(
      "compare",
      "One page (HTML) with the headline numbers and product curves of several finished runs "
      "side by side");
  compare
      ->add_option("runs", a.compare_runs,
                   "Run folders (runs/<case>), at least two, each finished (report done)")
      ->required();
  compare->footer(
      "\nExample:\n  orchestrate compare runs/default runs/granite --output runs/compare\n"
      "  (writes runs/compare/index.html; default --output: runs/compare)\n");
  compare->fallthrough();
  return compare;
}

// The command line as one string, for the run-folder lock's record.
std::string command_text(int argc, char** argv) {
  std::string s;
  for (int i = 0; i < argc && s.size() < 200; ++i) s += (i ? " " : "") + std::string(argv[i]);
  for (auto& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  return s.substr(0, 200);
}

// orchestrate impact: the case with --ore and --elements applied, one impact
// into --output (--check: validate only; --dry-run: say what would be done).
int impact_command(const CliArgs& a, const std::string& command, std::ostream& out,
                   std::ostream& err) {
  std::vector<std::pair<std::string, std::string>> ov;
  if (!a.imp_ore.empty()) ov.push_back({"ore.card", "'" + a.imp_ore + "'"});
  if (a.imp_elements > 0) ov.push_back({"lump.n_elements", std::to_string(a.imp_elements)});
  const auto cfg = config::load_case(a.case_file, project_dir(), ov);
  const fs::path out_dir =
      a.output.empty()
          ? fs::path("runs") / fmt::format("impact_v{:g}_a{:g}", a.imp_velocity, a.imp_angle)
          : fs::path(a.output);
  RunOptions opts;
  opts.output = fs::absolute(out_dir);
  check_output_path(opts.output);
  check_run_folder(cfg, opts.output, a.force, FolderKind::Impact);
  opts.force = a.force;
  opts.np = a.np > 0 ? a.np : static_cast<int>(cfg.doc.integer("resources.np"));
  if (a.check) {
    out << fmt::format(
        "{}: case '{}' is valid for an impact at {:g} m/s, {:g} deg into {}; ore card {} ({})\n",
        cfg.file.string(), cfg.name, a.imp_velocity, a.imp_angle, opts.output.string(),
        cfg.ore_file.string(), cfg.ore.str("name"));
    return 0;
  }
  std::optional<jobs::RunLock> lock;
  if (!a.dry_run) lock.emplace(opts.output, jobs::RunLock::Mode::Exclusive, command);
  if (lock && !lock->warning().empty()) err << "warning: " << lock->warning() << "\n";
  return run_single_impact(cfg, opts, a.imp_velocity, a.imp_angle, a.imp_repeat, a.dry_run, out);
}

// orchestrate compare: the page of the runs given, into a folder of its own
// (never inside a run folder: the page would take the place of its report).
int compare_command(const CliArgs& a, std::ostream& out) {
  CompareOptions co;
  for (const auto& r : a.compare_runs) co.runs.emplace_back(r);
  co.output = fs::absolute(a.output.empty() ? fs::path("runs") / "compare" : fs::path(a.output));
  co.project_dir = project_dir();
  check_output_path(co.output);
  if (const fs::path owner = owning_run_folder(co.output); !owner.empty())
    throw config::ConfigError(fmt::format(
        "compare: --output {}: inside the run folder {} (it holds resolved_case.json), which "
        "belongs to "
        "its case and stages; give compare a folder of its own, e.g. --output runs/compare",
        co.output.string(), owner.string()));
  if (a.dry_run) {
    check_compare_runs(co.runs);
    out << fmt::format(
        "compare: {} finished runs; would write {} and {} (dry run: nothing written)\n",
        co.runs.size(), (co.output / "index.html").string(),
        (co.output / "figures" / "compare_passing.png").string());
    return 0;
  }
  out << write_compare(co);
  return 0;
}

// orchestrate hpc: the Slurm scripts of the stages given.
int hpc_command(const config::CaseConfig& cfg, CliArgs& a, std::ostream& out) {
  HpcOptions& o = a.hpc_opt;
  if (a.stage.empty())
    throw config::ConfigError(
        "--stage: hpc needs the stages to script: one stage, a range FIRST-LAST or all");
  o.stages = resolve_stages(a.stage);
  o.stage = a.stage;
  o.output = fs::absolute(a.output.empty() ? fs::path("runs") / cfg.name : fs::path(a.output));
  check_output_path(o.output);
  check_run_folder(cfg, o.output, a.force);
  o.np = a.np;  // 0: not given; the stages' resources decide
  const auto n_tasks = [&](const std::string& s) {
    Invocation inv;
    inv.stages = {s};
    inv.opts.output = o.output;
    return count_tasks(cfg, inv);
  };
  out << write_hpc_scripts(cfg, o, n_tasks, fs::canonical("/proc/self/exe").string());
  return 0;
}

// The main command: run (or plan, list, merge) the stages given.
int stage_command(const config::CaseConfig& cfg, const CliArgs& a, const std::string& command,
                  std::ostream& out, std::ostream& err) {
  if (a.stage.empty()) {
    err << "error: --stage: which stage? expected one of flow, sample, transport, calibrate, "
           "breakage, report, all\n"
        << "Run 'orchestrate --help' for examples.\n";
    return kExitBadInput;
  }
  Invocation inv;
  inv.stages = resolve_stages(a.stage);
  // Absolute: engines and helper scripts run in other working directories.
  inv.opts.output =
      fs::absolute(a.output.empty() ? fs::path("runs") / cfg.name : fs::path(a.output));
  check_output_path(inv.opts.output);
  if (const std::string warning = check_run_folder(cfg, inv.opts.output, a.force,
                                                   FolderKind::Stages, a.dry_run || a.list_tasks);
      !warning.empty())
    err << "warning: " << warning << "\n";
  inv.opts.np = a.np > 0 ? a.np : static_cast<int>(cfg.doc.integer("resources.np"));
  inv.np_given = a.np > 0;
  inv.opts.jobs = a.jobs > 0 ? a.jobs : static_cast<int>(cfg.doc.integer("resources.jobs"));
  inv.opts.force = a.force;
  if (const char* job = std::getenv("MILL_SCHEDULER_JOB")) inv.opts.scheduler_job = job;
  if (const char* log = std::getenv("MILL_SCHEDULER_LOG")) inv.opts.scheduler_log = log;
  inv.dry_run = a.dry_run;
  inv.list_tasks = a.list_tasks;
  inv.merge_only = a.merge_only;
  if (a.task >= 0) inv.task = a.task;
  // One writer per stage at a time; the tasks of a scheduler array share
  // their stage.
  std::vector<std::unique_ptr<jobs::RunLock>> locks;
  if (!a.dry_run && !a.list_tasks)
    for (const std::string& stage : inv.stages) {
      locks.push_back(std::make_unique<jobs::RunLock>(
          inv.opts.output,
          a.task >= 0 ? jobs::RunLock::Mode::Shared : jobs::RunLock::Mode::Exclusive, command,
          stage));
      if (!locks.back()->warning().empty()) {
        err << "warning: " << locks.back()->warning() << "\n";
        break;  // the same file system for every stage's lock
      }
    }
  return run_pipeline(cfg, inv, out);
}

// The exit status of an error thrown by a command, its message written to `err`.
int error_status(std::ostream& err) {
  try {
    throw;
  } catch (const config::ConfigError& e) {
    err << "error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const NotImplemented& e) {
    err << "error: " << e.what() << "\n";
    return kExitNotImplemented;
  } catch (const jobs::RunFolderBusy& e) {
    err << "error: " << e.what() << "\n";
    return kExitFailed;
  } catch (const MissingInput& e) {
    err << "error: " << e.what() << "\n";
    return kExitFailed;
  } catch (const fs::filesystem_error& e) {
    // A file operation the user's paths or disk made fail: name the path.
    err << "error: " << (e.path1().empty() ? std::string("a file operation") : e.path1().string())
        << ": " << e.code().message()
        << (e.path2().empty() ? "" : " (with " + e.path2().string() + ")")
        << "\nCheck that the run folder (--output) is a writable directory with free space.\n";
    return kExitFailed;
  } catch (const engine::Interrupted& e) {
    err << "orchestrate: " << e.what()
        << "; finished jobs are kept, rerun the same command to resume\n";
    return 128 + e.signal;
  } catch (const std::exception& e) {
    err << "error: " << e.what() << "\n";
    return kExitFailed;
  }
}

}  // namespace

int cli_main(int argc, char** argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orchestrate: beater-mill comminution workflow (OpenFOAM flow, LIGGGHTS transport and "
      "breakage)"};
  app.footer(kExamples);
  app.set_version_flag("--version", std::string("orchestrate ") + MILL_VERSION);
  CliArgs a;
  add_stage_options(app, a);
  const CLI::App* impact = add_impact_command(app, a);
  const CLI::App* hpc = add_hpc_command(app, a);
  const CLI::App* compare = add_compare_command(app, a);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    out << app.help();
    return 0;
  } catch (const CLI::CallForVersion& e) {
    out << e.what() << "\n";
    return 0;
  } catch (const CLI::ParseError& e) {
    err << "error: " << e.what() << "\nRun 'orchestrate --help' for the options.\n";
    return kExitBadInput;
  }

  const std::string command = command_text(argc, argv);
  try {
    check_option_use(app, *impact ? kImpact : *compare ? kCompare : *hpc ? kHpc : kStages);
    if (a.print_schema) {
      out << config::schema_markdown();
      return 0;
    }
    if (*impact) return impact_command(a, command, out, err);
    if (*compare) return compare_command(a, out);
    const auto cfg = config::load_case(a.case_file, project_dir());
    if (*hpc) return hpc_command(cfg, a, out);
    if (a.check) {
      out << fmt::format("{}: case '{}' is valid; ore card {} ({})\n", cfg.file.string(), cfg.name,
                         cfg.ore_file.string(), cfg.ore.str("name"));
      // What a calibrated: section must carry to be taken for this case's
      // lump (docs/calibration.md): for calibrations written by hand or
      // carried over from another run.
      const nlohmann::json fitted_for = lump_scale(cfg);
      std::string scale;
      for (const auto& [k, v] : fitted_for.items())
        scale += fmt::format("{}{} {}", scale.empty() ? "" : ", ", k,
                             v.is_boolean() ? (v.get<bool>() ? "true" : "false")
                                            : fmt::format("{:.6g}", v.get<double>()));
      out << fmt::format(
          "calibration key of this ore card and lump: input_hash {} (fitted_for: {})\n",
          calibration_hash(cfg), scale);
      // The tensile strength the calibration aims at (calibrate.tensile_test).
      if (fits_direct_tension(cfg))
        out << fmt::format(
            "tensile target: direct tension, {:g} MPa ({})\n", tensile_target(cfg) / 1e6,
            cfg.ore.has("direct_tensile_strength")
                ? std::string("the card's direct_tensile_strength")
                : fmt::format("{:g} x the card's Brazilian {:g} MPa, rock_class {}",
                              direct_over_brazilian(cfg.ore),
                              cfg.ore.real("tensile_strength") / 1e6, cfg.ore.str("rock_class")));
      return 0;
    }
    return stage_command(cfg, a, command, out, err);
  } catch (...) {
    return error_status(err);
  }
}

}  // namespace mill
