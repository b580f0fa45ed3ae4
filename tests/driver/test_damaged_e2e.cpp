// A finished tiny run whose files are damaged: a deleted, truncated or
// corrupted declared output makes its job run again (the log names the
// file), a damaged input of the report is named in it, NaN reads "n/a", an
// identical `orchestrate impact` is not redone (nor replaced by another
// without --force), a deleted merged table is rebuilt from its jobs, and a
// run folder refuses another case. Real engine runs of a 50-element lump (about a second each).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "jobs/output_checks.h"
#include "postprocess/breakage_results.h"

#include "e2e_util.h"

namespace fs = std::filesystem;

namespace {

using namespace mill::e2e;

const std::string kCase = std::string(MILL_TEST_DATA) + "/tiny_damaged.yaml";

class DamagedRun : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new mill::test::TempDir(scratch("damaged"));
    status_ = run("breakage", "first.log");
    if (status_ == 0) status_ = run("report", "first_report.log");
  }
  static void TearDownTestSuite() { delete dir_; }  // removed if every test passed
  // orchestrate --stage <stage> on the run folder; the log is kept in `log`.
  static int run(const std::string& stage, const std::string& log) {
    return orchestrate("--case " + kCase + " --stage " + stage + " --output " + dir_->string(), *dir_ / log);
  }
  static fs::path job(const std::string& f) { return *dir_ / "breakage/jobs/v20_a90_r0" / f; }
  static std::string log(const std::string& name) { return slurp(*dir_ / name); }
  // Set one column of the first data row of a CSV file to `value`.
  static void set_csv_cell(const fs::path& f, const std::string& column, const std::string& value) {
    std::ifstream in(f);
    std::string header, row;
    std::getline(in, header);
    std::getline(in, row);
    std::vector<std::string> h, r;
    std::stringstream hs(header), rs(row);
    for (std::string c; std::getline(hs, c, ',');) h.push_back(c);
    for (std::string c; std::getline(rs, c, ',');) r.push_back(c);
    for (size_t i = 0; i < h.size(); ++i)
      if (h[i] == column) r.at(i) = value;
    std::string out = header + "\n";
    for (size_t i = 0; i < r.size(); ++i) out += (i ? "," : "") + r[i];
    spit(f, out + "\n");
  }
  // The page's text: every embedded picture's base64 data left out.
  static std::string without_images(std::string html) {
    const std::string key = "data:image/png;base64,";
    for (size_t at = html.find(key); at != std::string::npos; at = html.find(key, at + key.size()))
      html.erase(at + key.size(), html.find('"', at + key.size()) - at - key.size());
    return html;
  }
  static mill::test::TempDir* dir_;
  static int status_;
};
mill::test::TempDir* DamagedRun::dir_ = nullptr;
int DamagedRun::status_ = -1;

TEST_F(DamagedRun, FinishedRunIsSound) {
  ASSERT_EQ(status_, 0) << log("first.log") << log("first_report.log");
  EXPECT_EQ(mill::jobs::check_text_ends(*dir_ / "report/index.html", "</html>"), "");
  // An untouched rerun redoes nothing.
  ASSERT_EQ(run("breakage", "clean.log"), 0) << log("clean.log");
  EXPECT_NE(log("clean.log").find("1 already done"), std::string::npos) << log("clean.log");
}

TEST_F(DamagedRun, DeletedJobOutputIsRebuilt) {
  ASSERT_EQ(status_, 0);
  fs::remove(job("summary.csv"));
  ASSERT_EQ(run("breakage", "deleted.log"), 0) << log("deleted.log");
  EXPECT_NE(log("deleted.log").find("summary.csv: missing"), std::string::npos) << log("deleted.log");
  EXPECT_EQ(mill::post::ReadSummaryCsv(job("summary.csv").string()).size(), 1u);
}

TEST_F(DamagedRun, TruncatedHdf5IsRebuilt) {
  ASSERT_EQ(status_, 0);
  fs::resize_file(job("impact.h5"), fs::file_size(job("impact.h5")) / 2);
  ASSERT_NE(mill::jobs::check_hdf5(job("impact.h5")), "");
  ASSERT_EQ(run("breakage", "truncated.log"), 0) << log("truncated.log");
  EXPECT_NE(log("truncated.log").find("impact.h5: not a readable HDF5 file"), std::string::npos)
      << log("truncated.log");
  EXPECT_EQ(mill::jobs::check_hdf5(job("impact.h5")), "");
}

TEST_F(DamagedRun, CorruptedCountIsNamedAndRebuilt) {
  ASSERT_EQ(status_, 0);
  set_csv_cell(job("summary.csv"), "n_pieces", "nan");
  ASSERT_EQ(run("breakage", "corrupt.log"), 0) << log("corrupt.log");
  EXPECT_NE(log("corrupt.log").find("n_pieces: expected a whole number, got 'nan'"), std::string::npos)
      << log("corrupt.log");
  EXPECT_GE(mill::post::ReadSummaryCsv(job("summary.csv").string()).at(0).n_pieces, 1);
}

TEST_F(DamagedRun, DamagedStatusIsNotDone) {
  ASSERT_EQ(status_, 0);
  spit(job("STATUS"), "done\nid=whatever\npid=notanumber\n");
  ASSERT_EQ(run("breakage", "status.log"), 0) << log("status.log");
  EXPECT_EQ(job_state(*dir_ / "breakage", "v20_a90_r0"), mill::jobs::State::Done);
  EXPECT_NE(log("status.log").find("rerun v20_a90_r0"), std::string::npos) << log("status.log");
}

TEST_F(DamagedRun, DeletedOrTruncatedReportIsRebuilt) {
  ASSERT_EQ(status_, 0);
  // Up to date with the breakage files the tests above rewrote.
  ASSERT_EQ(run("report", "report_fresh.log"), 0) << log("report_fresh.log");
  fs::remove(*dir_ / "report/index.html");
  ASSERT_EQ(run("report", "report_deleted.log"), 0) << log("report_deleted.log");
  EXPECT_NE(log("report_deleted.log").find("index.html: missing"), std::string::npos) << log("report_deleted.log");
  EXPECT_EQ(mill::jobs::check_text_ends(*dir_ / "report/index.html", "</html>"), "");

  fs::resize_file(*dir_ / "report/index.html", fs::file_size(*dir_ / "report/index.html") / 2);
  ASSERT_EQ(run("report", "report_truncated.log"), 0) << log("report_truncated.log");
  EXPECT_NE(log("report_truncated.log").find("truncated"), std::string::npos) << log("report_truncated.log");
  EXPECT_EQ(mill::jobs::check_text_ends(*dir_ / "report/index.html", "</html>"), "");
}

TEST_F(DamagedRun, ReportNamesDamagedInputsAndPrintsNanAsNa) {
  ASSERT_EQ(status_, 0);
  // A real-valued NaN reads n/a; a NaN count is a damaged file, named.
  set_csv_cell(*dir_ / "breakage/summary.csv", "largest_mass_fraction", "nan");
  ASSERT_EQ(run("report", "nan_real.log"), 0) << log("nan_real.log");
  std::string html = slurp(*dir_ / "report/index.html");
  EXPECT_NE(html.find("<td>n/a</td>"), std::string::npos);
  EXPECT_EQ(without_images(html).find("nan"), std::string::npos);  // base64 of a figure may hold "nan"

  // A NaN count damages the merged table, which is rebuilt from the done
  // jobs before the report reads it; a merged output without jobs to
  // rebuild it from is named at the top of the page.
  set_csv_cell(*dir_ / "breakage/summary.csv", "n_pieces", "nan");
  fs::create_directories(*dir_ / "flow");
  spit(*dir_ / "flow/flow_summary.json", "garbage{");
  ASSERT_EQ(run("report", "nan_count.log"), 0) << log("nan_count.log");
  EXPECT_NE(log("nan_count.log").find("[breakage] rebuild the merged outputs from its 1 done job(s)"),
            std::string::npos)
      << log("nan_count.log");
  EXPECT_NE(log("nan_count.log").find("n_pieces: expected a whole number"), std::string::npos) << log("nan_count.log");
  html = slurp(*dir_ / "report/index.html");
  EXPECT_EQ(html.find("-9223372036854775808"), std::string::npos);
  EXPECT_NE(html.find("Damaged input files"), std::string::npos);
  EXPECT_NE(html.find("<h3>Every impact</h3>"), std::string::npos);
  EXPECT_NE(html.find("flow/flow_summary.json</code>: not valid JSON"), std::string::npos);
  EXPECT_NE(log("nan_count.log").find("flow_summary.json: not valid JSON"), std::string::npos) << log("nan_count.log");
  const auto summary = nlohmann::json::parse(slurp(*dir_ / "report/summary.json"));
  EXPECT_EQ(summary.at("damaged_inputs").size(), 1u) << summary.dump(2);

  // The breakage stage's merge rewrites its summary from the sound job files.
  fs::remove_all(*dir_ / "flow");
  ASSERT_EQ(run("breakage", "remerge.log"), 0) << log("remerge.log");
  EXPECT_EQ(mill::post::ReadSummaryCsv((*dir_ / "breakage/summary.csv").string()).size(), 1u);
}

// A deleted merged table is rebuilt from the done jobs before the report
// reads it: the report never leaves "Every impact" out without a word.
TEST_F(DamagedRun, DeletedMergedSummaryIsRebuiltForTheReport) {
  ASSERT_EQ(status_, 0);
  fs::remove(*dir_ / "breakage/summary.csv");
  ASSERT_EQ(run("report", "merged_deleted.log"), 0) << log("merged_deleted.log");
  EXPECT_NE(log("merged_deleted.log").find("rebuild the merged outputs from its 1 done job(s): " + dir_->string() +
                                           "/breakage/summary.csv: missing"),
            std::string::npos)
      << log("merged_deleted.log");
  EXPECT_EQ(mill::post::ReadSummaryCsv((*dir_ / "breakage/summary.csv").string()).size(), 1u);
  EXPECT_NE(slurp(*dir_ / "report/index.html").find("<h3>Every impact</h3>"), std::string::npos);
}

TEST_F(DamagedRun, RunFolderRefusesAnotherCase) {
  ASSERT_EQ(status_, 0);
  const std::string other = "--case " + std::string(MILL_TEST_DATA) + "/tiny_breakage.yaml --stage breakage --output " +
                            dir_->string();
  EXPECT_EQ(orchestrate(other + " --dry-run", *dir_ / "other.log"), 2) << log("other.log");
  EXPECT_NE(log("other.log").find("belongs to case 'tiny_damaged'"), std::string::npos) << log("other.log");
  EXPECT_NE(slurp(*dir_ / "case.yaml").find("name: tiny_damaged"), std::string::npos);
  EXPECT_EQ(orchestrate(other + " --dry-run --force", *dir_ / "other_forced.log"), 0) << log("other_forced.log");
}

TEST(ImpactRerun, IdenticalImpactIsNotRedone) {
  const auto dir = scratch("impact_rerun");
  const std::string args = "impact --velocity 20 --elements 50 --output " + (dir / "out").string();
  ASSERT_EQ(orchestrate(args, dir / "first.log"), 0) << slurp(dir / "first.log");
  // The job is begun and ended in the progress (its ETA counts from its start).
  EXPECT_NE(slurp(dir / "first.log").find("[impact] start impact_v20_a90_r0"), std::string::npos)
      << slurp(dir / "first.log");
  EXPECT_NE(slurp(dir / "first.log").find("[impact] done impact_v20_a90_r0 in "), std::string::npos)
      << slurp(dir / "first.log");
  const auto t0 = fs::last_write_time(dir / "out/result.json");
  ASSERT_EQ(orchestrate(args, dir / "second.log"), 0) << slurp(dir / "second.log");
  EXPECT_NE(slurp(dir / "second.log").find("already done with the same inputs"), std::string::npos)
      << slurp(dir / "second.log");
  EXPECT_NE(slurp(dir / "second.log").find("20 m/s at 90 deg"), std::string::npos) << slurp(dir / "second.log");
  EXPECT_EQ(fs::last_write_time(dir / "out/result.json"), t0);
  // A damaged output, or other inputs, run it again.
  fs::remove(dir / "out/fractions.csv");
  ASSERT_EQ(orchestrate(args, dir / "third.log"), 0) << slurp(dir / "third.log");
  EXPECT_NE(slurp(dir / "third.log").find("fractions.csv: missing"), std::string::npos) << slurp(dir / "third.log");
  EXPECT_TRUE(fs::exists(dir / "out/fractions.csv"));
  // Another impact into the folder would replace the finished one: only with --force.
  EXPECT_EQ(orchestrate(args + " --angle 60", dir / "fourth.log"), 2) << slurp(dir / "fourth.log");
  EXPECT_NE(slurp(dir / "fourth.log").find("holds a finished impact made with other inputs (impact_v20_a90_r0"),
            std::string::npos)
      << slurp(dir / "fourth.log");
  EXPECT_TRUE(fs::exists(dir / "out/result.json"));
  ASSERT_EQ(orchestrate(args + " --angle 60 --force", dir / "fifth.log"), 0) << slurp(dir / "fifth.log");
  EXPECT_NE(slurp(dir / "fifth.log").find("inputs changed"), std::string::npos) << slurp(dir / "fifth.log");
}

}  // namespace
