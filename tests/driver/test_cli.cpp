// The orchestrate program as a user meets it: help, bad input, plans, tasks.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "jobs/job_store.h"
#include "temp_dir.h"

namespace fs = std::filesystem;

namespace {

struct Out {
  int status;
  std::string text;  // stdout and stderr
};

// Run orchestrate with arguments in a scratch folder; capture output and status.
// The folder is this process's, removed at its end when every test passed.
Out orchestrate(const std::string& args) {
  static const mill::test::TempDir cwd("mill_cli_" + std::to_string(getpid()));
  const std::string cmd = "cd '" + cwd.string() + "' && '" + std::string(ORCHESTRATE_EXE) + "' " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string text;
  std::array<char, 4096> buf{};
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) text.append(buf.data(), n);
  int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, text};
}

const std::string kProject = MILL_PROJECT_DIR;
const std::string kData = MILL_TEST_DATA;
const std::string kBadInput = MILL_BAD_INPUT_DIR;

TEST(Cli, HelpHasExamples) {
  auto o = orchestrate("--help");
  EXPECT_EQ(o.status, 0);
  EXPECT_NE(o.text.find("Examples:"), std::string::npos);
  EXPECT_NE(o.text.find("--list-tasks"), std::string::npos);
  EXPECT_NE(o.text.find("--task"), std::string::npos);
}

TEST(Cli, Version) {
  auto o = orchestrate("--version");
  EXPECT_EQ(o.status, 0);
  EXPECT_NE(o.text.find("orchestrate "), std::string::npos);
}

TEST(Cli, UnknownStageSuggests) {
  auto o = orchestrate("--stage breakge --dry-run");
  EXPECT_EQ(o.status, 2);
  EXPECT_NE(o.text.find("did you mean 'breakage'"), std::string::npos) << o.text;
}

TEST(Cli, BadCaseExitsTwoNamingKey) {
  auto o = orchestrate("--case " + kBadInput + "/bad_unknown_key.yaml --stage all --dry-run");
  EXPECT_EQ(o.status, 2);
  EXPECT_NE(o.text.find("rotor.rmp"), std::string::npos) << o.text;
  EXPECT_FALSE(fs::exists(fs::temp_directory_path() / ("mill_cli_" + std::to_string(getpid())) / "runs" / "bad"));
}

TEST(Cli, MissingCaseFile) {
  auto o = orchestrate("--case /nonexistent/case.yaml --stage all");
  EXPECT_EQ(o.status, 2);
  EXPECT_NE(o.text.find("/nonexistent/case.yaml"), std::string::npos);
}

TEST(Cli, UnknownOptionExitsTwo) {
  auto o = orchestrate("--stagez all");
  EXPECT_EQ(o.status, 2);
}

TEST(Cli, DryRunListsEveryStageOfBothCases) {
  for (const char* c : {"default", "reference"}) {
    auto o = orchestrate("--case " + kProject + "/cases/" + c + ".yaml --stage all --dry-run");
    EXPECT_EQ(o.status, 0) << o.text;
    for (const char* s : {"stage flow", "stage sample", "stage transport", "stage calibrate", "stage breakage",
                          "stage report"})
      EXPECT_NE(o.text.find(s), std::string::npos) << c << ": " << s << "\n" << o.text;
    EXPECT_NE(o.text.find("rpm2000"), std::string::npos);
  }
  // default: conditions from transport (two rotor speeds), so breakage waits for it;
  // reference: an explicit sweep up to 169 m/s.
  auto def = orchestrate("--case " + kProject + "/cases/default.yaml --stage all --dry-run");
  EXPECT_NE(def.text.find("rpm1500"), std::string::npos) << def.text;
  EXPECT_NE(def.text.find("waits for"), std::string::npos) << def.text;
  EXPECT_NE(def.text.find("transport/rpm2000/impacts.csv"), std::string::npos) << def.text;
  EXPECT_NE(orchestrate("--case " + kProject + "/cases/reference.yaml --stage all --dry-run").text.find("v169_a90_r0"),
            std::string::npos);
  auto ref = orchestrate("--case " + kProject + "/cases/reference.yaml --stage breakage --dry-run");
  // 14 speeds x 3 repeats, and 3 more at each of the 3 crossing speeds (30, 35, 40 m/s)
  EXPECT_NE(ref.text.find("51 jobs"), std::string::npos) << ref.text;
  EXPECT_NE(ref.text.find("v35_a90_r5"), std::string::npos) << ref.text;
  EXPECT_EQ(ref.text.find("v50_a90_r3"), std::string::npos) << ref.text;
}

// resources.<stage>.np set in the case file is that stage's ranks on this
// machine too (the reference case: np 2 for the flow, 1 for the calibration
// and the impacts); --np overrides it; a stage without it keeps resources.np.
TEST(Cli, StageRanksFromTheCaseUnlessNpIsGiven) {
  const std::string ref = "--case " + kProject + "/cases/reference.yaml --dry-run --stage ";
  const auto cal = orchestrate(ref + "calibrate");
  EXPECT_EQ(cal.status, 0) << cal.text;
  EXPECT_NE(cal.text.find("2 MPI rank(s) each"), std::string::npos) << cal.text;  // resources.np
  EXPECT_NE(cal.text.find("1 MPI rank(s) per engine run (resources.calibrate.np)"),
            std::string::npos)
      << cal.text;
  const auto brk = orchestrate(ref + "breakage");
  EXPECT_NE(brk.text.find("1 MPI rank(s) per engine run (resources.breakage.np)"),
            std::string::npos)
      << brk.text;
  for (const std::string& args :
       {ref + "flow", ref + "calibrate --np 2", ref + "breakage --np 3"}) {
    const auto o = orchestrate(args);
    EXPECT_EQ(o.status, 0) << o.text;
    EXPECT_EQ(o.text.find("per engine run (resources."), std::string::npos) << args << "\n"
                                                                            << o.text;
  }
}

TEST(Cli, ListTasksOneLinePerJob) {
  auto o = orchestrate("--case " + kData + "/good_small.yaml --stage breakage --list-tasks");
  EXPECT_EQ(o.status, 0);
  int lines = 0;
  for (char ch : o.text) lines += ch == '\n';
  EXPECT_EQ(lines, 4) << o.text;  // 2 speeds x 2 repeats
  EXPECT_EQ(o.text.rfind("0\tv5_a90_r0\t", 0), 0u) << o.text;
}

// breakage.crossing_velocities: those speeds of the sweep run
// breakage.crossing_repeats times, the others breakage.repeats times.
TEST(Cli, CrossingVelocitiesGetTheirOwnRepeats) {
  const mill::test::TempDir dir("mill_cli_crossing_" + std::to_string(getpid()));
  const fs::path yaml = dir.path() / "crossing.yaml";
  std::ofstream(yaml)
      << "name: crossing\nlump: {n_elements: 200}\n"
         "breakage:\n  velocities: [5, 20, 50]\n  repeats: 2\n"
         "  crossing_velocities: [20]\n  crossing_repeats: 5\nore: {card: sandstone}\n";
  auto o = orchestrate("--case " + yaml.string() + " --stage breakage --list-tasks");
  ASSERT_EQ(o.status, 0) << o.text;
  EXPECT_EQ(std::count(o.text.begin(), o.text.end(), '\n'), 2 + 5 + 2) << o.text;
  for (const char* label : {"v5_a90_r1\t", "v20_a90_r4\t", "v50_a90_r1\t"})
    EXPECT_NE(o.text.find(label), std::string::npos) << label << "\n" << o.text;
  EXPECT_EQ(o.text.find("v5_a90_r2"), std::string::npos) << o.text;
  EXPECT_EQ(o.text.find("v20_a90_r5"), std::string::npos) << o.text;
}

// --task narrows --list-tasks and --dry-run to its job.
TEST(Cli, TaskNarrowsListTasksAndDryRun) {
  const std::string args = "--case " + kData + "/good_small.yaml --stage breakage --task 2";
  auto o = orchestrate(args + " --list-tasks");
  EXPECT_EQ(o.status, 0) << o.text;
  EXPECT_EQ(o.text.rfind("2\tv50_a90_r0\t", 0), 0u) << o.text;
  EXPECT_EQ(std::count(o.text.begin(), o.text.end(), '\n'), 1) << o.text;
  o = orchestrate(args + " --dry-run");
  EXPECT_EQ(o.status, 0) << o.text;
  EXPECT_NE(o.text.find("   2 v50_a90_r0"), std::string::npos) << o.text;
  EXPECT_EQ(o.text.find("v5_a90_r0"), std::string::npos) << o.text;
}

TEST(Cli, TaskOutOfRange) {
  auto o = orchestrate("--case " + kData + "/good_small.yaml --stage breakage --task 99");
  EXPECT_EQ(o.status, 2);
  EXPECT_NE(o.text.find("--task"), std::string::npos);
}

TEST(Cli, TaskNeedsOneStage) {
  auto o = orchestrate("--stage all --task 0");
  EXPECT_EQ(o.status, 2);
}

TEST(Cli, PrintSchema) {
  auto o = orchestrate("--print-schema");
  EXPECT_EQ(o.status, 0);
  EXPECT_NE(o.text.find("breakage.velocities"), std::string::npos);
}

}  // namespace

namespace {

TEST(Cli, HpcWritesArrayAndMergeScripts) {
  const mill::test::TempPath out("mill_cli_hpc_" + std::to_string(getpid()));
  auto o = orchestrate("hpc --scheduler slurm --stage breakage --case " + kData + "/good_small.yaml --np 2 --output " +
                       out.string());
  ASSERT_EQ(o.status, 0) << o.text;
  std::ifstream a(out / "hpc" / "breakage.array.sh");
  const std::string array((std::istreambuf_iterator<char>(a)), std::istreambuf_iterator<char>());
  EXPECT_NE(array.find("#SBATCH --array=0-3"), std::string::npos) << array;  // 2 speeds x 2 repeats
  EXPECT_NE(array.find("--task \"$SLURM_ARRAY_TASK_ID\""), std::string::npos);
  EXPECT_NE(array.find("#SBATCH --ntasks=2"), std::string::npos);
  EXPECT_TRUE(fs::exists(out / "hpc" / "breakage.merge.sh"));
  std::ifstream s(out / "hpc" / "submit_breakage.sh");
  const std::string submit((std::istreambuf_iterator<char>(s)), std::istreambuf_iterator<char>());
  EXPECT_NE(submit.find("--dependency=afterok"), std::string::npos);
}

TEST(Cli, HpcStageAllWritesTheChainWithAPlannedBreakage) {
  const mill::test::TempPath out("mill_cli_hpc_all_" + std::to_string(getpid()));
  auto o = orchestrate("hpc --scheduler slurm --stage all --case " + kData + "/tiny_hpc.yaml --output " + out.string());
  ASSERT_EQ(o.status, 0) << o.text;
  EXPECT_NE(o.text.find("array sized by a planning job"), std::string::npos) << o.text;
  EXPECT_NE(o.text.find("submit with: sh " + (out / "hpc" / "submit_all.sh").string()), std::string::npos) << o.text;
  EXPECT_TRUE(fs::exists(out / "hpc" / "breakage.plan.sh"));
  // A range is named by what was given.
  o = orchestrate("hpc --stage flow-transport --case " + kData + "/tiny_hpc.yaml --output " + out.string());
  ASSERT_EQ(o.status, 0) << o.text;
  EXPECT_TRUE(fs::exists(out / "hpc" / "submit_flow-transport.sh"));
  o = orchestrate("hpc --stage report-flow --case " + kData + "/tiny_hpc.yaml --output " + out.string());
  EXPECT_EQ(o.status, 2) << o.text;
}

TEST(Cli, MergeOnlyNamesTheJobsNotDoneWithTheirSchedulerJob) {
  const mill::test::TempPath out("mill_cli_merge_" + std::to_string(getpid()));
  const std::string args = "--case " + kData + "/good_small.yaml --output " + out.string() + " --stage breakage";
  // Task 0 failed under a scheduler; the others never started.
  const std::string list = orchestrate(args + " --list-tasks").text;
  const std::string label = list.substr(2, list.find('\t', 2) - 2);
  const mill::jobs::JobStore store(out / "breakage");
  store.mark_running(label, {{"x", 1}}, "77_0", "/logs/mill-good_small-breakage_77_0.out");
  store.mark_failed(label, "liggghts-mill exited with status 1");
  auto o = orchestrate(args + " --merge-only");
  EXPECT_EQ(o.status, 1) << o.text;
  EXPECT_NE(o.text.find("breakage/" + label + " (task 0): failed: liggghts-mill exited with status 1; scheduler job "
                        "77_0, log /logs/mill-good_small-breakage_77_0.out"),
            std::string::npos)
      << o.text;
  EXPECT_NE(o.text.find("(task 1): not run"), std::string::npos) << o.text;
  EXPECT_NE(o.text.find("4 of 4 job(s) not done; nothing merged"), std::string::npos) << o.text;
  EXPECT_FALSE(fs::exists(out / "breakage" / "summary.csv"));
  EXPECT_EQ(orchestrate(args + " --merge-only --task 0").status, 2);
}

TEST(Cli, HpcRejectsUnknownScheduler) {
  auto o = orchestrate("hpc --scheduler pbs --stage breakage");
  EXPECT_EQ(o.status, 2);
  EXPECT_NE(o.text.find("--scheduler"), std::string::npos) << o.text;
}

// Valid Slurm values go into the #SBATCH lines as given; a run folder with
// blanks is quoted there (sbatch splits #SBATCH lines on blanks).
TEST(Cli, HpcWritesCheckedValuesAndQuotesPaths) {
  const mill::test::TempPath out("mill cli hpc spaces " + std::to_string(getpid()));
  auto o = orchestrate("hpc --stage breakage --case " + kData + "/good_small.yaml --time 1-12:30 --mem 4G --partition "
                       "gpu,short --account proj_1 --max-parallel 2 --output '" + out.string() + "'");
  ASSERT_EQ(o.status, 0) << o.text;
  std::ifstream a(out / "hpc" / "breakage.array.sh");
  const std::string array((std::istreambuf_iterator<char>(a)), std::istreambuf_iterator<char>());
  for (const std::string& line : std::vector<std::string>{"#SBATCH --time=1-12:30\n", "#SBATCH --mem=4G\n", "#SBATCH --partition=gpu,short\n",
                                 "#SBATCH --account=proj_1\n", "#SBATCH --array=0-3%2\n",
                                 "#SBATCH --output=\"" + (out / "hpc" / "logs").string() + "/%x_%A_%a.out\"\n"})
    EXPECT_NE(array.find(line), std::string::npos) << line << " not in:\n" << array;
}

}  // namespace
