// Slurm job-array scripts for any stage.
#include "hpc.h"

#include <fmt/format.h>
#include <sys/stat.h>

#include <cctype>
#include <regex>

#include "jobs/job_store.h"

namespace mill {
namespace fs = std::filesystem;

namespace {
std::string quote(const std::string& s) {
  std::string o = "'";
  for (char c : s) o += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return o + "'";
}

// log_pattern: Slurm's file-name pattern, %x_%A_%a (array) or %x_%j (single job).
std::string header(const HpcOptions& o, const std::string& name, const fs::path& logs, int ntasks,
                   const char* log_pattern) {
  std::string h = "#!/bin/bash\n";
  h += fmt::format("#SBATCH --job-name={}\n", name);
  h += fmt::format("#SBATCH --ntasks={}\n", ntasks);
  h += fmt::format("#SBATCH --time={}\n", o.time);
  if (!o.partition.empty()) h += fmt::format("#SBATCH --partition={}\n", o.partition);
  if (!o.account.empty()) h += fmt::format("#SBATCH --account={}\n", o.account);
  if (!o.mem.empty()) h += fmt::format("#SBATCH --mem={}\n", o.mem);
  // Quoted: sbatch splits #SBATCH lines on blanks outside quotes.
  h += fmt::format("#SBATCH --output=\"{}/{}.out\"\n", logs.string(), log_pattern);
  return h;
}
}  // namespace

void check_hpc_options(const HpcOptions& o) {
  auto bad = [](const std::string& opt, const std::string& value, const std::string& expected) {
    std::string shown;
    for (char c : value)
      shown += std::iscntrl(static_cast<unsigned char>(c)) ? fmt::format("\\x{:02x}", static_cast<unsigned char>(c))
                                                            : std::string(1, c);
    throw config::ConfigError(fmt::format("{}: expected {}, got '{}'", opt, expected, shown));
  };
  // Slurm's --time forms: M, M:S, H:M:S, D-H, D-H:M, D-H:M:S.
  static const std::regex time_re(R"((\d+)|(\d+):(\d{1,2})|(\d+):(\d{1,2}):(\d{1,2})|(\d+)-(\d{1,2})(:(\d{1,2})(:(\d{1,2}))?)?)");
  std::smatch m;
  bool time_ok = std::regex_match(o.time, m, time_re);
  if (time_ok) {
    // Minutes and seconds after a larger unit below 60, hours after days below 24; not all zero.
    const auto num = [&](int i) { return m[i].matched ? std::stol(m[i].str()) : 0L; };
    if (m[2].matched) time_ok = num(3) < 60;
    if (m[4].matched) time_ok = num(5) < 60 && num(6) < 60;
    if (m[7].matched) time_ok = num(8) < 24 && num(10) < 60 && num(12) < 60;
    time_ok = time_ok && o.time.find_first_not_of("0:-") != std::string::npos;
  }
  if (!time_ok)
    bad("--time", o.time,
        "a Slurm wall time above zero: MINUTES, MM:SS, HH:MM:SS, DAYS-HH, DAYS-HH:MM or DAYS-HH:MM:SS (e.g. 02:00:00)");
  static const std::regex mem_re(R"([1-9][0-9]{0,8}[KMGT]?)");
  if (!o.mem.empty() && !std::regex_match(o.mem, mem_re))
    bad("--mem", o.mem, "a memory size: a whole number above 0 with an optional unit K, M, G or T (e.g. 4G; no unit: MB)");
  static const std::regex name_re(R"([A-Za-z0-9_.-]+(,[A-Za-z0-9_.-]+)*)");
  if (!o.partition.empty() && !std::regex_match(o.partition, name_re))
    bad("--partition", o.partition, "a Slurm partition name (letters, digits, '_', '.', '-'; a comma between several)");
  static const std::regex account_re(R"([A-Za-z0-9_.-]+)");
  if (!o.account.empty() && !std::regex_match(o.account, account_re))
    bad("--account", o.account, "a Slurm account name (letters, digits, '_', '.', '-')");
  if (o.max_parallel < 0) bad("--max-parallel", std::to_string(o.max_parallel), "a whole number >= 0 (0: no limit)");
  if (o.np < 1) bad("--np", std::to_string(o.np), "a whole number >= 1");
  // The run folder appears in #SBATCH --output="..." and in the scripts:
  // one line, no quote or '%' (Slurm's file-name pattern character).
  const std::string out = fs::absolute(o.output).string();
  for (char c : out)
    if (std::iscntrl(static_cast<unsigned char>(c)) || c == '"' || c == '%' || c == '\\')
      bad("--output", out, "a run folder path without control characters, '\"', '%' or '\\' (it is written into "
                           "#SBATCH lines)");
}

std::string write_hpc_scripts(const config::CaseConfig& cfg, const HpcOptions& o, int n_tasks,
                              const std::string& exe) {
  if (o.scheduler != "slurm")
    throw config::ConfigError(fmt::format("--scheduler: expected 'slurm' (the only scheduler supported), got '{}'",
                                          o.scheduler));
  if (o.stage == "all")
    throw config::ConfigError("--stage: expected one stage (an array runs the jobs of one stage), got 'all'");
  check_hpc_options(o);
  if (n_tasks <= 0)
    throw config::ConfigError(fmt::format("--stage {}: the stage has no jobs yet (its inputs come from an earlier "
                                          "stage that has not run)", o.stage));
  const fs::path out = fs::absolute(o.output), dir = out / "hpc", logs = dir / "logs";
  fs::create_directories(logs);
  const std::string common = fmt::format("{} --case {} --output {} --stage {}", quote(exe), quote(cfg.file.string()),
                                         quote(out.string()), o.stage);
  const std::string array_name = fmt::format("mill-{}-{}", cfg.name, o.stage);
  std::string array = header(o, array_name, logs, o.np, "%x_%A_%a");
  array += fmt::format("#SBATCH --array=0-{}{}\n", n_tasks - 1, o.max_parallel > 0 ? fmt::format("%{}", o.max_parallel) : "");
  array += "# One array task per job of `orchestrate --stage " + o.stage + " --list-tasks`.\n";
  array += "# A task that finds its job done (same inputs) returns at once: resubmitting is safe.\n";
  array += "set -euo pipefail\n";
  array += fmt::format("exec {} --task \"$SLURM_ARRAY_TASK_ID\" --np {} --jobs 1\n", common, o.np);

  std::string merge = header(o, array_name + "-merge", logs, 1, "%x_%j");
  merge += "# After every array task succeeded: merge the stage's results and write the report.\n";
  merge += "set -euo pipefail\n";
  merge += fmt::format("{} --jobs 1\n", common);
  merge += fmt::format("{} --case {} --output {} --stage report\n", quote(exe), quote(cfg.file.string()),
                       quote(out.string()));

  std::string submit = "#!/bin/sh\n# Submit the array, then the merge job once every task succeeded.\nset -eu\n";
  submit += fmt::format("array=$(sbatch --parsable {})\n", quote((dir / (o.stage + ".array.sh")).string()));
  submit += fmt::format("merge=$(sbatch --parsable --dependency=afterok:\"${{array%%;*}}\" {})\n",
                        quote((dir / (o.stage + ".merge.sh")).string()));
  submit += "echo \"submitted array job $array and merge job $merge\"\n";

  const fs::path a = dir / (o.stage + ".array.sh"), m = dir / (o.stage + ".merge.sh"), s = dir / ("submit_" + o.stage + ".sh");
  jobs::atomic_write(a, array);
  jobs::atomic_write(m, merge);
  jobs::atomic_write(s, submit);
  for (const auto& f : {a, m, s}) chmod(f.c_str(), 0755);
  return fmt::format("wrote {} ({} array tasks, {} MPI rank{} each), {} and {}\nsubmit with: sh {}\n", a.string(),
                     n_tasks, o.np, o.np == 1 ? "" : "s", m.string(), s.string(), s.string());
}

}  // namespace mill
