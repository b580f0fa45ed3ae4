// The energy ledger of a lump run: reading ledger.csv, bad files named by
// file and line, the summary figures of a hand-written ledger, new surface.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "postprocess/energy_ledger.h"
#include "postprocess/fragments.h"
#include "test_dir.h"

namespace mill::post {
namespace {

namespace fs = std::filesystem;
const std::string kData = MILL_POST_TEST_DATA;
const std::string kSmall = kData + "/ledger_small.csv";

const std::string kComment =
    "# fix energy/ledger: energy of the run [J] (docs/styles/fix_energy_ledger.md)\n";
const std::string kHeader =
    "step,time_s,ke_trans_J,ke_rot_J,numerical_J,bond_elastic_J,bond_released_J,bond_damping_J,"
    "bond_friction_J,wall_elastic_J,wall_damping_J,wall_friction_J,contact_elastic_J,"
    "contact_damping_J,contact_friction_J,work_other_J,input_J,residual_J,max_speed_m_s,wall_"
    "overlap\n";
const std::string kRow0 = "0,0,12.5,0,0,0,0,0,0,0,0,0,0,0,0,0,12.5,0,150,0\n";

// The message ReadEnergyLedger (and SummariseLedger) gives for a file of
// `text`, or "no error".
std::string Message(const fs::path& file, const std::string& text) {
  std::ofstream(file) << text;
  try {
    SummariseLedger(ReadEnergyLedger(file.string()));
  } catch (const PostError& e) {
    return e.what();
  }
  return "no error";
}

TEST(EnergyLedger, ReadsTheColumnsOfTheFix) {
  const EnergyLedger l = ReadEnergyLedger(kSmall);
  EXPECT_EQ(l.path, kSmall);
  ASSERT_EQ(l.columns.size(), LedgerColumns().size());
  for (std::size_t c = 0; c < l.columns.size(); ++c)
    EXPECT_EQ(l.columns[c], LedgerColumns()[c].name);
  ASSERT_EQ(l.rows(), 3u);
  EXPECT_EQ(l.lines, (std::vector<long>{3, 4, 5}));  // after the comment and the header
  EXPECT_DOUBLE_EQ(l.column("time_s")[1], 1e-5);
  EXPECT_DOUBLE_EQ(l.last("bond_released_J"), 3.0);
  EXPECT_THROW(l.column("no_such_J"), PostError);
}

// input + work_other = the held terms + residual, in every row of the file.
TEST(EnergyLedger, TheBalanceColumnsAddUp) {
  const EnergyLedger l = ReadEnergyLedger(kSmall);
  for (std::size_t k = 0; k < l.rows(); ++k) {
    double held = 0.0, given = 0.0;
    for (const LedgerColumn& c : LedgerColumns()) {
      const double v = l.column(c.name)[k];
      if (c.role == LedgerRole::kHeld) held += v;
      if (c.role == LedgerRole::kInput || c.role == LedgerRole::kWorkOther) given += v;
    }
    EXPECT_NEAR(given, held + l.column("residual_J")[k], 1e-12) << "row " << k;
  }
  int held = 0;
  for (const LedgerColumn& c : LedgerColumns()) held += c.role == LedgerRole::kHeld;
  EXPECT_EQ(held, 13);  // ke_trans .. contact_friction
}

// The figures worked out by hand from ledger_small.csv.
TEST(EnergyLedger, SummaryByHand) {
  const LedgerSummary s = SummariseLedger(ReadEnergyLedger(kSmall));
  EXPECT_DOUBLE_EQ(s.end_time_s, 2e-5);
  EXPECT_DOUBLE_EQ(s.input_J, 12.0);
  EXPECT_DOUBLE_EQ(s.work_other_J, 1.0);
  EXPECT_DOUBLE_EQ(s.residual_J, -0.02);
  EXPECT_DOUBLE_EQ(s.bond_released_J, 3.0);
  EXPECT_DOUBLE_EQ(s.residual_fraction, -0.02 / 13.0);     // residual / (12 + |1|)
  EXPECT_DOUBLE_EQ(s.residual_fraction_max, 0.02 / 13.0);  // row 2: 0.02/13 > row 1: 0.01/12.5
  EXPECT_DOUBLE_EQ(s.max_speed_m_s, 180.0);                // row 1, not the last row
  EXPECT_DOUBLE_EQ(s.max_speed_time_s, 1e-5);
  EXPECT_DOUBLE_EQ(s.wall_overlap_max, 0.02);
  EXPECT_DOUBLE_EQ(s.comminution_efficiency, 3.0 / 13.0);  // released / (input + work_other)
  // Every column in J of the last row, in file order: the 13 held terms,
  // work_other, input and residual.
  ASSERT_EQ(s.final_energy.size(), 16u);
  EXPECT_EQ(s.final_energy.front().first, "ke_trans_J");
  EXPECT_DOUBLE_EQ(s.final_energy.front().second, 3.0);
  EXPECT_EQ(s.final_energy[11].first, "contact_damping_J");
  EXPECT_DOUBLE_EQ(s.final_energy[11].second, 2.5);
  EXPECT_EQ(s.final_energy[12].first, "contact_friction_J");
  EXPECT_DOUBLE_EQ(s.final_energy[12].second, 0.4);
  EXPECT_EQ(s.final_energy.back().first, "residual_J");
}

// Energy taken out by the other forces (work_other < 0) gives the lump
// nothing: the efficiency is over the input alone.
TEST(EnergyLedger, NegativeOtherWorkIsNotCountedAsGiven) {
  EnergyLedger l = ReadEnergyLedger(kSmall);
  auto set = [&](const std::string& name, double v) {
    const auto it = std::find(l.columns.begin(), l.columns.end(), name);
    l.values[static_cast<std::size_t>(it - l.columns.begin())].back() = v;
  };
  set("work_other_J", -1.0);
  set("residual_J", -2.02);  // keeps the row's balance: 12 - 1 = 13.02 - 2.02
  const LedgerSummary s = SummariseLedger(l);
  EXPECT_DOUBLE_EQ(s.comminution_efficiency, 3.0 / 12.0);
  EXPECT_DOUBLE_EQ(s.residual_fraction, -2.02 / 13.0);
}

TEST(EnergyLedger, BadFilesNameTheFileAndLine) {
  const auto dir = TestDir();
  const fs::path f = dir / "ledger.csv";
  const std::string name = f.string();
  auto has = [](const std::string& message, const std::string& part) {
    return message.find(part) != std::string::npos;
  };
  std::string m = Message(f, kComment + "step,time_s,ke_trans_J\n" + kRow0);
  EXPECT_TRUE(has(m, name + ":2: header lacks column 'ke_rot_J'")) << m;
  m = Message(f, kComment + kHeader + kRow0 + "1,1e-6,12.5,0,0,0,0,0,0,0,0,0,0,0,0,0,12.5,0,150\n");
  EXPECT_TRUE(has(m, name + ":4: 19 values, the header has 20")) << m;
  m = Message(f, kComment + kHeader + "0,0,12.5,abc,0,0,0,0,0,0,0,0,0,0,0,0,12.5,0,150,0\n");
  EXPECT_TRUE(has(m, name + ":3: ke_rot_J: expected a finite number, got 'abc'")) << m;
  m = Message(f, kComment + kHeader + "0,0,12.5,nan,0,0,0,0,0,0,0,0,0,0,0,0,12.5,0,150,0\n");
  EXPECT_TRUE(has(m, name + ":3: ke_rot_J: expected a finite number, got 'nan'")) << m;
  m = Message(f, kComment + kHeader);
  EXPECT_TRUE(has(m, name + ": no rows after the header")) << m;
  m = Message(f, kComment);
  EXPECT_TRUE(has(m, name + ": no header line")) << m;
  m = Message(f, kComment + "step,step," + kHeader.substr(5) + kRow0);
  EXPECT_TRUE(has(m, name + ":2: header names column 'step' twice")) << m;
  // A row whose terms do not add up to input + work_other.
  m = Message(f, kComment + kHeader + kRow0 + "1,1e-6,11,0,0,0,0,0,0,0,0,0,0,0,0,0,12.5,0,150,0\n");
  EXPECT_TRUE(has(m, name + ":4: the balance does not close")) << m;
  // Nothing put in: the efficiency is undefined.
  m = Message(f, kComment + kHeader + "0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n");
  EXPECT_TRUE(has(m, name + ":3: input_J + max(work_other_J, 0) is 0 J")) << m;
  try {
    ReadEnergyLedger((f.parent_path() / "absent.csv").string());
    FAIL() << "expected PostError";
  } catch (const PostError& e) {
    EXPECT_TRUE(has(e.what(), "absent.csv: cannot open the energy ledger")) << e.what();
  }
}

// Columns beyond the fix's are kept, with a unit from their name; comments
// and blank lines anywhere are skipped; CRLF line ends are read.
TEST(EnergyLedger, ExtraColumnsAndCommentsAreKept) {
  const auto dir = TestDir();
  const fs::path f = dir / "ledger.csv";
  std::string header = kHeader;
  header.insert(header.size() - 1, ",residual_bonds_J");
  std::string row = kRow0;
  row.insert(row.size() - 1, ",0.5");
  std::ofstream(f) << kComment << header << "\n# a comment\n"
                   << row.substr(0, row.size() - 1) << "\r\n";
  const EnergyLedger l = ReadEnergyLedger(f.string());
  ASSERT_EQ(l.columns.size(), 21u);
  EXPECT_EQ(l.columns.back(), "residual_bonds_J");
  EXPECT_DOUBLE_EQ(l.last("residual_bonds_J"), 0.5);
  EXPECT_EQ(l.lines, std::vector<long>{5});
  EXPECT_EQ(LedgerUnit("residual_bonds_J"), "J");
  EXPECT_EQ(LedgerUnit("max_speed_m_s"), "m/s");
  EXPECT_EQ(LedgerUnit("time_s"), "s");
  EXPECT_EQ(LedgerUnit("wall_overlap"), "1");
  EXPECT_EQ(LedgerUnit("step"), "1");
  const LedgerSummary s = SummariseLedger(l);
  EXPECT_EQ(s.final_energy.back().first, "residual_bonds_J");
  EXPECT_DOUBLE_EQ(s.comminution_efficiency, 0.0);
}

TEST(EnergyLedger, CsvMirrorReadsBackTheSame) {
  const auto dir = TestDir();
  const fs::path f = dir / "energy_ledger.csv";
  const EnergyLedger a = ReadEnergyLedger(kSmall);
  WriteEnergyLedgerCsv(f.string(), a);
  EXPECT_FALSE(fs::exists(f.string() + ".tmp"));
  const EnergyLedger b = ReadEnergyLedger(f.string());
  EXPECT_EQ(b.columns, a.columns);
  EXPECT_EQ(b.values, a.values);  // shortest round-trip format: exact
  std::ifstream in(f);
  std::string first;
  std::getline(in, first);
  EXPECT_EQ(first + "\n", kComment);
}

// Two equal halves of a lump of diameter D: each d = D / 2^(1/3), so the new
// surface is 2 pi d^2 - pi D^2 = pi D^2 (2^(1/3) - 1).
TEST(NewSurface, TwoHalvesAndAnIntactLump) {
  const double big = 0.02, half = big / std::cbrt(2.0);
  EXPECT_NEAR(NewSurfaceArea({half, half}, big), kPi * big * big * (std::cbrt(2.0) - 1.0), 1e-15);
  EXPECT_EQ(NewSurfaceArea({big}, big), 0.0);
  EXPECT_FALSE(EnergyPerNewSurface(1.0, 0.0));
  EXPECT_FALSE(EnergyPerNewSurface(1.0, -1e-12));
  EXPECT_DOUBLE_EQ(*EnergyPerNewSurface(3.0, 1.5e-3), 2000.0);
}

}  // namespace
}  // namespace mill::post
