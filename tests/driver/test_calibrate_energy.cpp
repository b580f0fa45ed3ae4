// The calibration's energy-ledger reports on hand-made lab runs (no engine):
// each run's `energy` object, the worst residual over the runs and report.md's
// section (docs/calibration.md, "Energy ledger"), and the error for a run
// folder whose ledger is missing or bad.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "stages/calibrate/energy_report.h"
#include "stages/stage_util.h"
#include "temp_dir.h"

using namespace mill;
using namespace mill::calibrate;

namespace {

// A ledger summary with the given input, platen work, released energy and residuals.
post::LedgerSummary ledger(double input, double work, double released, double residual_max) {
  post::LedgerSummary e;
  e.input_J = input;
  e.work_other_J = work;
  e.bond_released_J = released;
  e.residual_J = 0.5 * residual_max * (input + work);
  e.residual_fraction = 0.5 * residual_max;
  e.residual_fraction_max = residual_max;
  e.max_speed_m_s = 0.25;
  e.end_time_s = 2e-3;
  e.comminution_efficiency = released / (input + work);
  // Columns the summary carries but the report must not depend on.
  e.final_energy = {{"contact_damping_J", 1.0}, {"work_platen_top_J", 2.0}};
  return e;
}

// An iteration whose UCS and Brazilian runs are tagged itK_ucs, itK_brazilian.
Iteration iteration(int k, double residual_ucs, double residual_br) {
  Iteration it;
  it.ucs.tag = "it" + std::to_string(k) + "_ucs";
  it.ucs.energy = ledger(0.0, 4e-3, 1e-3, residual_ucs);
  it.br.tag = "it" + std::to_string(k) + "_brazilian";
  it.br.energy = ledger(1e-6, 2e-3, 5e-4, residual_br);
  return it;
}

}  // namespace

// Every figure of the summary under its report.json key; no column names.
TEST(CalibrateEnergy, RunJsonHoldsTheSummaryFigures) {
  const post::LedgerSummary e = ledger(1e-6, 4e-3, 1e-3, 2e-4);
  const nlohmann::json j = lab_energy_json(e);
  EXPECT_DOUBLE_EQ(j.at("input_J").get<double>(), 1e-6);
  EXPECT_DOUBLE_EQ(j.at("work_other_J").get<double>(), 4e-3);
  EXPECT_DOUBLE_EQ(j.at("bond_released_J").get<double>(), 1e-3);
  EXPECT_DOUBLE_EQ(j.at("residual_J").get<double>(), e.residual_J);
  EXPECT_DOUBLE_EQ(j.at("residual_fraction").get<double>(), 1e-4);
  EXPECT_DOUBLE_EQ(j.at("residual_fraction_max").get<double>(), 2e-4);
  EXPECT_DOUBLE_EQ(j.at("max_element_speed_m_s").get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(j.at("comminution_efficiency").get<double>(), e.comminution_efficiency);
  EXPECT_FALSE(j.contains("contact_damping_J")) << j.dump();
  EXPECT_FALSE(j.contains("work_platen_top_J")) << j.dump();
}

// The runs in the order they ran, rate check last; the worst residual named by its run.
TEST(CalibrateEnergy, WorstResidualIsNamedByItsRun) {
  Outcome o;
  o.hist = {iteration(1, 1e-5, 3e-4), iteration(2, 2e-5, 4e-5)};
  o.best = 1;
  o.half = UcsRun{};
  o.half->tag = "rate_check_ucs";
  o.half->energy = ledger(0.0, 3e-3, 1e-3, 1e-4);
  const auto runs = lab_runs(o);
  ASSERT_EQ(runs.size(), 5u);
  EXPECT_EQ(runs.front()->tag, "it1_ucs");
  EXPECT_EQ(runs[3]->tag, "it2_brazilian");
  EXPECT_EQ(runs.back()->tag, "rate_check_ucs");

  const nlohmann::json s = energy_summary_json(o);
  EXPECT_EQ(s.at("lab_runs").get<int>(), 5);
  EXPECT_EQ(s.at("worst_run").get<std::string>(), "it1_brazilian");
  EXPECT_DOUBLE_EQ(s.at("worst_residual_fraction_max").get<double>(), 3e-4);

  o.half->energy.residual_fraction_max = 5e-3;
  EXPECT_EQ(energy_summary_json(o).at("worst_run").get<std::string>(), "rate_check_ucs");
}

// The checks' runs follow the rate check, triaxial tests first, and count
// towards the worst residual like the others.
TEST(CalibrateEnergy, CheckRunsComeLastAndCount) {
  Outcome o;
  o.hist = {iteration(1, 1e-5, 3e-4)};
  o.half = UcsRun{};
  o.half->tag = "rate_check_ucs";
  for (const char* tag : {"triaxial_1", "triaxial_2"}) {
    o.checks.triaxial.emplace_back();
    o.checks.triaxial.back().tag = tag;
  }
  o.checks.scb = ScbRun{};
  for (const char* tag : {"scb", "scb_o1"}) {
    o.checks.scb->discs.emplace_back();
    o.checks.scb->discs.back().tag = tag;
    o.checks.scb->discs.back().energy = ledger(0.0, 3e-3, 1e-3, 1e-4);
  }
  o.checks.scb->discs.back().energy.residual_fraction_max = 6e-3;
  const auto runs = lab_runs(o);
  ASSERT_EQ(runs.size(), 7u);
  EXPECT_EQ(runs[3]->tag, "triaxial_1");
  EXPECT_EQ(runs[4]->tag, "triaxial_2");
  EXPECT_EQ(runs[5]->tag, "scb");
  EXPECT_EQ(runs[6]->tag, "scb_o1");
  EXPECT_EQ(energy_summary_json(o).at("worst_run").get<std::string>(), "scb_o1");
  const std::string md = energy_markdown(o);
  for (const char* row : {"| triaxial_1 |", "| triaxial_2 |", "| scb |", "| scb_o1 |"})
    EXPECT_NE(md.find(row), std::string::npos) << row << " in\n" << md;
}

// With K_IC fitted the checks' bend test is the kept iteration's own: its
// half discs are listed once, with the iteration, marked as the result's.
TEST(CalibrateEnergy, FittedBendTestIsListedOnceWithItsIteration) {
  Outcome o;
  o.hist = {iteration(1, 1e-5, 3e-4)};
  o.hist[0].scb.emplace();
  for (const char* tag : {"it1_scb", "it1_scb_o1", "it1_scb_o2"}) {
    o.hist[0].scb->discs.emplace_back();
    o.hist[0].scb->discs.back().tag = tag;
    o.hist[0].scb->discs.back().energy = ledger(0.0, 3e-3, 1e-3, 1e-4);
  }
  o.checks.scb = o.hist[0].scb;
  o.checks.toughness_fitted = true;
  const auto runs = lab_runs(o);
  ASSERT_EQ(runs.size(), 5u);
  EXPECT_EQ(runs[2]->tag, "it1_scb");
  EXPECT_EQ(runs[4]->tag, "it1_scb_o2");
  const std::string md = energy_markdown(o);
  for (const char* row : {"| it1_scb * |", "| it1_scb_o1 * |", "| it1_scb_o2 * |"})
    EXPECT_NE(md.find(row), std::string::npos) << row << " in\n" << md;
}

// One row per run, the result's runs marked, and the worst residual line.
TEST(CalibrateEnergy, MarkdownSectionHasEveryRunAndTheWorst) {
  Outcome o;
  o.hist = {iteration(1, 1e-5, 3e-4), iteration(2, 2e-5, 4e-5)};
  o.best = 1;
  const std::string md = energy_markdown(o);
  EXPECT_NE(md.find("## Energy ledger"), std::string::npos) << md;
  EXPECT_NE(md.find("| it1_ucs |"), std::string::npos) << md;
  EXPECT_NE(md.find("| it1_brazilian |"), std::string::npos) << md;
  EXPECT_NE(md.find("| it2_ucs * |"), std::string::npos) << md;
  EXPECT_NE(md.find("| it2_brazilian * |"), std::string::npos) << md;
  EXPECT_EQ(md.find("rate_check"), std::string::npos) << md;
  EXPECT_NE(md.find("Largest residual of any lab run: 0.03% of the energy given (it1_brazilian)"),
            std::string::npos)
      << md;
}

// A run folder without ledger.csv, or with one that does not parse: the error
// names the file.
TEST(CalibrateEnergy, MissingOrBadLedgerNamesTheFile) {
  const mill::test::TempDir dir("mill_calibrate_energy_" + std::to_string(::getpid()));
  const std::string file = (dir / "ledger.csv").string();
  try {
    read_run_ledger(dir);
    ADD_FAILURE() << "no error for a missing ledger";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(file + ": missing"), std::string::npos) << e.what();
  }
  std::ofstream(file) << "step,time_s,input_J\n0,0,1\n";
  try {
    read_run_ledger(dir);
    ADD_FAILURE() << "no error for a ledger without the fix's columns";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(file + ":1: header lacks column"), std::string::npos)
        << e.what();
  }
}
