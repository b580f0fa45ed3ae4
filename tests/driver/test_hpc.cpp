// The Slurm scripts of `orchestrate hpc`: which scripts a range of stages
// gets, their #SBATCH lines (array sizes, ranks, resources), the dependency
// chain the submit script builds (run against a stand-in sbatch that records
// its arguments), the planning job that sizes the breakage array, and the
// checks on values that go into #SBATCH lines.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include "config/case_config.h"
#include "hpc.h"
#include "pipeline.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using mill::HpcOptions;
using mill::config::ConfigError;

namespace {

const fs::path kData = MILL_TEST_DATA;
const fs::path kProject = MILL_PROJECT_DIR;

// An empty folder, removed when the test passes.
mill::test::TempDir fresh_dir(const std::string& name) {
  return mill::test::TempDir("mill_hpc_" + name + "_" + std::to_string(getpid()));
}

std::string slurp(const fs::path& f) {
  std::ifstream in(f);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void write_exe(const fs::path& f, const std::string& text) {
  std::ofstream(f) << text;
  fs::permissions(f, fs::perms::owner_all);
}

// Run a shell command; return its exit status and output.
std::pair<int, std::string> sh(const std::string& cmd) {
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  std::string text;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) text.append(buf, n);
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, text};
}

// The #SBATCH lines of a script, one string.
std::string directives(const fs::path& f) {
  std::istringstream in(slurp(f));
  std::string line, out;
  while (std::getline(in, line))
    if (line.rfind("#SBATCH", 0) == 0) out += line + "\n";
  return out;
}

HpcOptions options(const std::string& stage, const fs::path& out) {
  HpcOptions o;
  o.stage = stage;
  o.stages = mill::resolve_stages(stage);
  o.output = out;
  return o;
}

// tiny_hpc: breakage at the transport's conditions; per-stage resources set.
const mill::config::CaseConfig& tiny() {
  static const auto c = mill::config::load_case(kData / "tiny_hpc.yaml", kProject);
  return c;
}

TEST(HpcStages, RangesExpandInPipelineOrder) {
  EXPECT_EQ(mill::resolve_stages("transport-breakage"),
            (std::vector<std::string>{"transport", "calibrate", "breakage"}));
  EXPECT_EQ(mill::resolve_stages("breakage-breakage"), (std::vector<std::string>{"breakage"}));
  EXPECT_EQ(mill::resolve_stages("all").size(), 6u);
  try {
    mill::resolve_stages("breakage-flow");
    FAIL() << "a backward range was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("flow-breakage"), std::string::npos) << e.what();
  }
  try {
    mill::resolve_stages("transprt-breakage");
    FAIL() << "a misspelt range was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("did you mean 'transport'"), std::string::npos)
        << e.what();
  }
}

TEST(HpcScripts, WholeChainHasOneScriptPerStageAndAPlannedBreakageArray) {
  const auto out = fresh_dir("all");
  std::set<std::string> asked;
  const auto count = [&](const std::string& s) {
    asked.insert(s);
    return 1;  // one rotor speed
  };
  HpcOptions o = options("all", out);
  o.np = 2;
  const std::string text = mill::write_hpc_scripts(tiny(), o, count, "/opt/mill/orchestrate");
  const fs::path h = out / "hpc";
  for (const char* f : {"flow.array.sh", "flow.merge.sh", "sample.sh", "transport.array.sh",
                        "transport.merge.sh", "calibrate.sh", "breakage.plan.sh",
                        "breakage.array.sh", "breakage.merge.sh", "report.sh", "submit_all.sh"})
    EXPECT_TRUE(fs::exists(h / f)) << f << "\n" << text;
  EXPECT_FALSE(fs::exists(h / "sample.array.sh"));
  // The breakage count is never taken before the transport has run.
  EXPECT_EQ(asked, (std::set<std::string>{"flow", "transport"}));

  // Flow: --np ranks per task, an array over the rotor speeds, its own time.
  const std::string flow = directives(h / "flow.array.sh");
  EXPECT_NE(flow.find("#SBATCH --ntasks=2\n"), std::string::npos) << flow;
  EXPECT_NE(flow.find("#SBATCH --array=0-0\n"), std::string::npos) << flow;
  EXPECT_NE(flow.find("#SBATCH --time=00:15:00\n"), std::string::npos) << flow;
  EXPECT_NE(flow.find("#SBATCH --job-name=mill-tiny_hpc-flow\n"), std::string::npos) << flow;
  EXPECT_NE(slurp(h / "flow.array.sh")
                .find("--stage flow --task \"$SLURM_ARRAY_TASK_ID\" --np 2 --jobs 1"),
            std::string::npos);
  // Breakage: one rank per task, the case's memory, and no --array: the
  // planning job passes it.
  const std::string brk = directives(h / "breakage.array.sh");
  EXPECT_NE(brk.find("#SBATCH --ntasks=1\n"), std::string::npos) << brk;
  EXPECT_NE(brk.find("#SBATCH --mem=1G\n"), std::string::npos) << brk;
  EXPECT_NE(brk.find("#SBATCH --time=00:10:00\n"), std::string::npos) << brk;
  EXPECT_EQ(brk.find("--array"), std::string::npos) << brk;
  const std::string plan = slurp(h / "breakage.plan.sh");
  EXPECT_NE(plan.find("--stage breakage --list-tasks"), std::string::npos) << plan;
  EXPECT_NE(plan.find("--from breakage --tasks \"$n\""), std::string::npos) << plan;
  EXPECT_NE(directives(h / "breakage.plan.sh").find("#SBATCH --time=00:05:00\n"),
            std::string::npos);
  // Merges run no job themselves.
  EXPECT_NE(slurp(h / "transport.merge.sh").find("--stage transport --merge-only"),
            std::string::npos);
  EXPECT_NE(directives(h / "transport.merge.sh").find("#SBATCH --ntasks=1\n"), std::string::npos);
  // Logs: per array task and per job, in hpc/logs.
  EXPECT_NE(flow.find("#SBATCH --output=" + (h / "logs").string() + "/%x_%A_%a.out\n"),
            std::string::npos)
      << flow;
  EXPECT_NE(directives(h / "sample.sh").find("/%x_%j.out\n"), std::string::npos);
}

// A stand-in sbatch on PATH: logs "<id> <args>" per call, prints "<id>;cluster".
struct FakeSlurm {
  fs::path dir, log;
  explicit FakeSlurm(const fs::path& d) : dir(d / "bin"), log(d / "sbatch.log") {
    fs::create_directories(dir);
    write_exe(dir / "sbatch",
              "#!/bin/sh\n"
              "n=$(( $(cat '" +
                  (dir / "n").string() +
                  "' 2>/dev/null || echo 100) + 1 ))\n"
                  "echo $n > '" +
                  (dir / "n").string() +
                  "'\n"
                  "echo \"$n $*\" >> '" +
                  log.string() +
                  "'\n"
                  "echo \"$n;milltest\"\n");
  }
  std::string env() const { return "PATH='" + dir.string() + "':\"$PATH\" "; }
  // The logged call of a script: "<id> <options> <script path> <args>".
  std::string call_of(const std::string& script) const {
    std::istringstream in(slurp(log));
    std::string line;
    while (std::getline(in, line))
      if (line.find("/" + script) != std::string::npos) return line;
    return "";
  }
};

TEST(HpcScripts, SubmitChainsStagesWithAfterokAndThePlanningJobSubmitsTheRest) {
  const auto out = fresh_dir("chain");
  // A stand-in orchestrate whose breakage plan has three jobs.
  write_exe(out / "orchestrate",
            "#!/bin/sh\n"
            "case \"$*\" in *'--stage breakage --list-tasks'*)\n"
            "  printf '0\\tb0\\ttodo\\tx\\n1\\tb1\\ttodo\\tx\\n2\\tb2\\ttodo\\tx\\n' ;;\n"
            "*) exit 9 ;; esac\n");
  HpcOptions o = options("all", out / "run");
  o.max_parallel = 2;
  mill::write_hpc_scripts(
      tiny(), o, [](const std::string&) { return 1; }, (out / "orchestrate").string());
  const fs::path h = out / "run" / "hpc";
  FakeSlurm slurm(out);

  auto [st, text] = sh(slurm.env() + "sh '" + (h / "submit_all.sh").string() + "'");
  ASSERT_EQ(st, 0) << text;
  // Ids from 101 on, in submission order.
  EXPECT_EQ(slurm.call_of("flow.array.sh"),
            "101 --parsable --kill-on-invalid-dep=yes " + (h / "flow.array.sh").string());
  EXPECT_EQ(slurm.call_of("flow.merge.sh"),
            "102 --parsable --kill-on-invalid-dep=yes --dependency=afterany:101 " +
                (h / "flow.merge.sh").string() + " 101");
  EXPECT_EQ(slurm.call_of("sample.sh"),
            "103 --parsable --kill-on-invalid-dep=yes --dependency=afterok:102 " +
                (h / "sample.sh").string());
  EXPECT_EQ(slurm.call_of("transport.array.sh"),
            "104 --parsable --kill-on-invalid-dep=yes --dependency=afterok:103 " +
                (h / "transport.array.sh").string());
  EXPECT_EQ(slurm.call_of("transport.merge.sh"),
            "105 --parsable --kill-on-invalid-dep=yes --dependency=afterany:104,afterok:103 " +
                (h / "transport.merge.sh").string() + " 104");
  // The calibration reads no earlier stage: it runs beside the flow chain.
  EXPECT_EQ(slurm.call_of("calibrate.sh"),
            "106 --parsable --kill-on-invalid-dep=yes " + (h / "calibrate.sh").string());
  EXPECT_EQ(slurm.call_of("breakage.plan.sh"),
            "107 --parsable --kill-on-invalid-dep=yes --dependency=afterok:105:106 " +
                (h / "breakage.plan.sh").string());
  EXPECT_EQ(slurm.call_of("breakage.array.sh"), "")
      << "the breakage array is the planning job's to submit";
  EXPECT_NE(text.find("breakage: planning job 107"), std::string::npos) << text;

  // The planning job, run by hand: three jobs -> an array of three (throttled), then the rest.
  auto [pst, ptext] = sh(slurm.env() + "bash '" + (h / "breakage.plan.sh").string() + "'");
  ASSERT_EQ(pst, 0) << ptext;
  EXPECT_NE(ptext.find("stage breakage: 3 jobs"), std::string::npos) << ptext;
  EXPECT_EQ(slurm.call_of("breakage.array.sh"),
            "108 --parsable --kill-on-invalid-dep=yes --array=0-2%2 " +
                (h / "breakage.array.sh").string());
  EXPECT_EQ(slurm.call_of("breakage.merge.sh"),
            "109 --parsable --kill-on-invalid-dep=yes --dependency=afterany:108 " +
                (h / "breakage.merge.sh").string() + " 108");
  EXPECT_EQ(slurm.call_of("report.sh"),
            "110 --parsable --kill-on-invalid-dep=yes --dependency=afterok:109 " +
                (h / "report.sh").string());

  // A plan with no jobs fails the planning job and submits nothing.
  write_exe(out / "orchestrate",
            "#!/bin/sh\necho '# breakage: no tasks yet: waits for transport'\n");
  const std::string before = slurp(slurm.log);
  auto [est, etext] = sh(slurm.env() + "bash '" + (h / "breakage.plan.sh").string() + "'");
  EXPECT_EQ(est, 1) << etext;
  EXPECT_NE(etext.find("no jobs"), std::string::npos) << etext;
  EXPECT_EQ(slurp(slurm.log), before);

  // Bad arguments to the submit script.
  EXPECT_EQ(sh(slurm.env() + "sh '" + (h / "submit_all.sh").string() + "' --from breakge").first,
            2);
  EXPECT_EQ(
      sh(slurm.env() + "sh '" + (h / "submit_all.sh").string() + "' --from report --tasks 3").first,
      2);
  EXPECT_EQ(
      sh(slurm.env() + "sh '" + (h / "submit_all.sh").string() + "' --from breakage --tasks x")
          .first,
      2);
}

TEST(HpcScripts, SubmitStopsWhenSbatchFails) {
  const auto out = fresh_dir("sbatch_fails");
  mill::write_hpc_scripts(
      tiny(), options("all", out / "run"), [](const std::string&) { return 1; }, "/bin/false");
  fs::create_directories(out / "bin");
  write_exe(out / "bin" / "sbatch",
            "#!/bin/sh\necho 'sbatch: error: invalid partition' >&2\nexit 1\n");
  auto [st, text] = sh("PATH='" + (out / "bin").string() + "':\"$PATH\" sh '" +
                       (out / "run/hpc/submit_all.sh").string() + "'");
  EXPECT_NE(st, 0) << text;
  EXPECT_NE(text.find("invalid partition"), std::string::npos) << text;
  EXPECT_EQ(text.find("flow: array job"), std::string::npos) << text;
}

TEST(HpcScripts, BreakageAfterADoneTransportHasItsArraySizeNow) {
  const auto out = fresh_dir("known");
  const std::string text = mill::write_hpc_scripts(
      tiny(), options("breakage-report", out), [](const std::string&) { return 5; }, "/bin/true");
  const fs::path h = out / "hpc";
  EXPECT_NE(directives(h / "breakage.array.sh").find("#SBATCH --array=0-4\n"), std::string::npos);
  EXPECT_FALSE(fs::exists(h / "breakage.plan.sh"));
  const std::string submit = slurp(h / "submit_breakage-report.sh");
  EXPECT_NE(submit.find("report_done=$(submit ${up:+--dependency=afterok:$up}"), std::string::npos)
      << submit;
  EXPECT_NE(submit.find("up=$(ids \"$breakage_done\")"), std::string::npos) << submit;
  // Transport not run yet and not in the range: say which range to script.
  try {
    mill::write_hpc_scripts(
        tiny(), options("breakage", out), [](const std::string&) { return 0; }, "/bin/true");
    FAIL() << "a breakage array of no tasks was written";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("--stage transport-breakage"), std::string::npos)
        << e.what();
  }
}

TEST(HpcResources, CaseKeysThenOptionsThenStageDefaults) {
  const auto& cfg = tiny();
  HpcOptions o = options("all", "/tmp/x");
  auto r = mill::stage_resources(cfg, o, "flow");
  EXPECT_EQ(r.np, 2);  // resources.flow.np
  EXPECT_EQ(r.time, "00:15:00");
  EXPECT_NE(r.time_from.find("resources.flow.time"), std::string::npos) << r.time_from;
  EXPECT_EQ(r.merge_time, "00:05:00");
  r = mill::stage_resources(cfg, o, "breakage");
  EXPECT_EQ(r.np, 1);
  EXPECT_EQ(r.mem, "1G");
  EXPECT_TRUE(r.partition.empty());
  r = mill::stage_resources(cfg, o, "sample");
  EXPECT_EQ(r.np, 1);
  EXPECT_TRUE(r.mem.empty());
  // Options: --np is the flow's ranks; --time, --mem, --partition every job's.
  o.np = 8;
  o.time = "03:00:00";
  o.partition = "big";
  EXPECT_EQ(mill::stage_resources(cfg, o, "flow").np, 8);
  EXPECT_EQ(mill::stage_resources(cfg, o, "breakage").np, 1);
  EXPECT_EQ(mill::stage_resources(cfg, o, "breakage").time, "03:00:00");
  EXPECT_EQ(mill::stage_resources(cfg, o, "breakage").time_from, "--time");
  EXPECT_EQ(mill::stage_resources(cfg, o, "report").partition, "big");
  // A stage scripted alone takes --np.
  HpcOptions alone = options("breakage", "/tmp/x");
  alone.np = 4;
  EXPECT_EQ(mill::stage_resources(cfg, alone, "breakage").np, 4);
  // Defaults of a case without resources.<stage>: the flow takes resources.np.
  const auto plain = mill::config::load_case(kData / "good_small.yaml", kProject);
  const auto f = mill::stage_resources(plain, options("all", "/tmp/x"), "flow");
  EXPECT_EQ(f.np, static_cast<int>(plain.doc.integer("resources.np")));
  EXPECT_EQ(f.time, "04:00:00");
  EXPECT_EQ(mill::stage_resources(plain, options("all", "/tmp/x"), "breakage").time, "01:00:00");
}

TEST(HpcDirective, QuotesBlanksAndRejectsLineBreaks) {
  EXPECT_EQ(mill::sbatch_directive("--time", "01:00:00", "--time"), "#SBATCH --time=01:00:00\n");
  EXPECT_EQ(mill::sbatch_directive("--output", "/runs/my case/%x_%j.out", "--output"),
            "#SBATCH --output=\"/runs/my case/%x_%j.out\"\n");
  EXPECT_EQ(mill::sbatch_directive("--output", "/runs/#1/%x_%j.out", "--output"),
            "#SBATCH --output=\"/runs/#1/%x_%j.out\"\n");
  for (const std::string& bad : {std::string("big\n#SBATCH --exclusive"), std::string("a\"b"),
                                 std::string("a\\b"), std::string("a\tb"), std::string("")}) {
    try {
      mill::sbatch_directive("--partition", bad, "resources.flow.partition");
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("resources.flow.partition"), std::string::npos)
          << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos)
          << "message not on one line: " << e.what();
    }
  }
}

TEST(HpcScripts, OptionValuesAreCheckedBeforeAnyScriptIsWritten) {
  const auto out = fresh_dir("bad_option");
  HpcOptions o = options("all", out);
  o.account = "proj\nx";
  try {
    mill::write_hpc_scripts(
        tiny(), o, [](const std::string&) { return 1; }, "/bin/true");
    FAIL() << "an account with a newline was written";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("--account"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("\\x0a"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(out / "hpc" / "submit_all.sh"));
  HpcOptions pct = options("all", out / "100%");
  EXPECT_THROW(mill::write_hpc_scripts(
                   tiny(), pct, [](const std::string&) { return 1; }, "/bin/true"),
               ConfigError);
}

TEST(HpcScripts, RunFolderWithBlanksIsQuoted) {
  const auto dir = fresh_dir("blank");
  const fs::path out = dir / "my run";
  mill::write_hpc_scripts(
      tiny(), options("flow", out), [](const std::string&) { return 1; },
      "/opt/my mill/orchestrate");
  const std::string a = slurp(out / "hpc" / "flow.array.sh");
  EXPECT_NE(a.find("#SBATCH --output=\"" + (out / "hpc/logs").string() + "/%x_%A_%a.out\"\n"),
            std::string::npos)
      << a;
  EXPECT_NE(a.find("exec '/opt/my mill/orchestrate' --case "), std::string::npos) << a;
  EXPECT_NE(a.find("--output '" + out.string() + "'"), std::string::npos) << a;
}

}  // namespace
