// summary.csv, fractions.csv and breakage.h5: layout, round trips, atomic writes.
#include "postprocess/breakage_results.h"

#include <gtest/gtest.h>
#include <hdf5.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numeric>

#include "test_dir.h"

namespace mill::post {
namespace {

namespace fs = std::filesystem;
constexpr double kRho = 2580.0;

// First line of a text file.
std::string FirstLine(const fs::path& p) {
  std::ifstream in(p);
  std::string line;
  std::getline(in, line);
  return line;
}

// Number of lines of a text file.
int CountLines(const fs::path& p) {
  std::ifstream in(p);
  std::string line;
  int n = 0;
  while (std::getline(in, line)) ++n;
  return n;
}

// An impact of n elements (radius 1.2 mm) where elements 1..k are one bonded
// chain and the rest are singles; D = 20 mm.
ImpactResult MakeImpact(double v, int repeat, int n = 10, int k = 4) {
  std::vector<Element> e;
  for (int i = 1; i <= n; ++i) {
    Element x;
    x.id = i;
    x.radius = 1.2e-3;
    x.mass = SphereMass(x.radius, kRho);
    x.v = {0.0, 0.0, v * 0.1};
    e.push_back(x);
  }
  std::vector<Bond> b;
  for (int i = 1; i < k; ++i) b.push_back({i, i + 1});
  ImpactSpec spec;
  spec.conditions = {v, 90.0, repeat};
  spec.initial_bonds = 20;
  spec.lump_diameter_m = 0.02;
  spec.density_kg_m3 = kRho;
  spec.wall_seconds = 12.5;
  return AnalyseImpact(e, b, spec);
}

TEST(ImpactPieces, ReadBackFromAnImpactFileAsWritten) {
  const auto dir = TestDir();
  const std::string path = (dir / "impact.h5").string();
  const ImpactResult r = MakeImpact(40.0, 0, 10, 4);
  WriteBreakageH5(path, {r});
  const ImpactPieces p = ReadImpactPieces(path);
  ASSERT_EQ(p.mass_kg.size(), r.fragments.size());
  const double d_ref = EquivalentDiameter(r.summary.lump_mass_kg, kRho);
  for (std::size_t k = 0; k < r.fragments.size(); ++k) {
    EXPECT_DOUBLE_EQ(p.mass_kg[k], r.fragments[k].mass);
    EXPECT_DOUBLE_EQ(p.d_rel[k], r.fragments[k].diameter / d_ref);
  }
  // A file of two impacts is not one run's.
  const std::string two = (dir / "two.h5").string();
  WriteBreakageH5(two, {r, MakeImpact(20.0, 1)});
  try {
    ReadImpactPieces(two);
    ADD_FAILURE() << "expected a PostError";
  } catch (const PostError& e) {
    EXPECT_NE(std::string(e.what()).find("2 impacts"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(two), std::string::npos) << e.what();
  }
}

TEST(SummaryCsv, HeaderStartsWithTheRequiredColumnsInOrder) {
  const auto dir = TestDir();
  AppendSummaryCsv((dir / "summary.csv").string(), MakeImpact(150.0, 0).summary);
  const std::string required =
      "velocity_m_s,angle_deg,repeat,n_elements,n_pieces,n_single,n_multi,largest_mass_fraction,"
      "single_mass_fraction,broken_bond_fraction,specific_energy_J_kg,t10_percent,wall_seconds";
  const std::string header = FirstLine(dir / "summary.csv");
  EXPECT_EQ(header.substr(0, required.size()), required);
  EXPECT_EQ(header.substr(required.size(), 23), ",specific_energy_kWh_t,");
  // The energy ledger's columns come last.
  const std::string ledger =
      ",t10_resolved,comminution_efficiency,ledger_residual_fraction,max_element_speed_m_s";
  ASSERT_GT(header.size(), ledger.size());
  EXPECT_EQ(header.substr(header.size() - ledger.size()), ledger);
  EXPECT_EQ(SummaryCsvColumns().size(), 24u);
  EXPECT_EQ(SummaryCsvColumns().back(), "max_element_speed_m_s");
}

// The ledger's figures round-trip; without a ledger they are NaN ("nan"), and
// a file from before the columns existed reads with NaN.
TEST(SummaryCsv, LedgerColumnsRoundTripAndMayBeAbsent) {
  const auto dir = TestDir();
  const std::string path = (dir / "summary.csv").string();
  ImpactSummary with = MakeImpact(60.0, 0).summary;
  with.comminution_efficiency = 0.0123;
  with.ledger_residual_fraction = -2.5e-4;
  with.max_element_speed_m_s = 171.5;
  AppendSummaryCsv(path, with);
  AppendSummaryCsv(path, MakeImpact(90.0, 0).summary);
  auto rows = ReadSummaryCsv(path);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_DOUBLE_EQ(rows[0].comminution_efficiency, 0.0123);
  EXPECT_DOUBLE_EQ(rows[0].ledger_residual_fraction, -2.5e-4);
  EXPECT_DOUBLE_EQ(rows[0].max_element_speed_m_s, 171.5);
  EXPECT_TRUE(std::isnan(rows[1].comminution_efficiency));

  const std::string old = (dir / "old.csv").string();
  std::ifstream in(path);
  std::string header, row;
  std::getline(in, header);
  std::getline(in, row);
  const std::string tail = ",comminution_efficiency,ledger_residual_fraction,max_element_speed_m_s";
  ASSERT_EQ(header.substr(header.size() - tail.size()), tail);
  std::string short_row = row;  // without its last three values
  for (int k = 0; k < 3; ++k) short_row.erase(short_row.rfind(','));
  std::ofstream(old) << header.substr(0, header.size() - tail.size()) << "\n" << short_row << "\n";
  rows = ReadSummaryCsv(old);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_DOUBLE_EQ(rows[0].velocity_m_s, 60.0);
  EXPECT_TRUE(std::isnan(rows[0].comminution_efficiency));
  EXPECT_TRUE(std::isnan(rows[0].max_element_speed_m_s));
}

TEST(SummaryCsv, AppendsRowsUnderOneHeaderAndReadsBack) {
  const auto dir = TestDir();
  const std::string path = (dir / "summary.csv").string();
  const auto a = MakeImpact(60.0, 0);
  const auto b = MakeImpact(150.0, 1, 12, 2);
  AppendSummaryCsv(path, a.summary);
  AppendSummaryCsv(path, b.summary);
  EXPECT_EQ(CountLines(path), 3);
  EXPECT_FALSE(fs::exists(path + ".tmp"));
  const auto rows = ReadSummaryCsv(path);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_DOUBLE_EQ(rows[0].velocity_m_s, 60.0);
  EXPECT_DOUBLE_EQ(rows[0].specific_energy_J_kg, 1800.0);
  EXPECT_DOUBLE_EQ(rows[0].specific_energy_kWh_t, 0.5);
  EXPECT_EQ(rows[0].n_pieces, 7);
  EXPECT_EQ(rows[0].n_single, 6);
  EXPECT_EQ(rows[0].n_multi, 1);
  EXPECT_EQ(rows[1].repeat, 1);
  EXPECT_EQ(rows[1].n_elements, 12);
  EXPECT_DOUBLE_EQ(rows[1].largest_mass_fraction, b.summary.largest_mass_fraction);
  EXPECT_DOUBLE_EQ(rows[1].t10_percent, b.summary.t10_percent);
  EXPECT_DOUBLE_EQ(rows[1].wall_seconds, 12.5);
  EXPECT_EQ(rows[1].t10_resolved, b.summary.t10_resolved);
}

TEST(SummaryCsv, ForeignHeaderIsRefused) {
  const auto dir = TestDir();
  const std::string path = (dir / "summary.csv").string();
  std::ofstream(path) << "a,b,c\n1,2,3\n";
  EXPECT_THROW(AppendSummaryCsv(path, MakeImpact(60.0, 0).summary), PostError);
}

TEST(SummaryCsv, MissingRequiredColumnIsNamed) {
  const auto dir = TestDir();
  const std::string path = (dir / "summary.csv").string();
  std::ofstream(path) << "velocity_m_s,angle_deg\n1,2\n";
  try {
    ReadSummaryCsv(path);
    FAIL() << "expected PostError";
  } catch (const PostError& e) {
    EXPECT_NE(std::string(e.what()).find("'repeat'"), std::string::npos) << e.what();
  }
}

TEST(FractionsCsv, OneRowPerFractionSummingToOne) {
  const auto dir = TestDir();
  const std::string path = (dir / "fractions.csv").string();
  const auto r = MakeImpact(60.0, 0);
  AppendFractionsCsv(path, r);
  EXPECT_EQ(FirstLine(path),
            "velocity_m_s,angle_deg,repeat,fraction_index,d_low_rel,d_high_rel,mass_fraction");
  EXPECT_EQ(CountLines(path), 13);
  EXPECT_NEAR(std::accumulate(r.fraction_mass.begin(), r.fraction_mass.end(), 0.0), 1.0, 1e-14);
}

TEST(FractionsCsv, ReadsBackWhatWasWritten) {
  const auto dir = TestDir();
  const std::string path = (dir / "fractions.csv").string();
  const auto a = MakeImpact(60.0, 0), b = MakeImpact(150.0, 1, 12, 2);
  AppendFractionsCsv(path, a);
  AppendFractionsCsv(path, b);
  const auto rows = ReadFractionsCsv(path);
  ASSERT_EQ(rows.size(), 2 * a.fraction_mass.size());
  for (std::size_t k = 0; k < a.fraction_mass.size(); ++k) {
    const auto& r = rows[a.fraction_mass.size() + k];
    EXPECT_DOUBLE_EQ(r.conditions.velocity_m_s, 150.0);
    EXPECT_EQ(r.conditions.repeat, 1);
    EXPECT_EQ(r.index, static_cast<int>(k));
    EXPECT_DOUBLE_EQ(r.d_low_rel, b.fraction_edges[k]);
    EXPECT_DOUBLE_EQ(r.d_high_rel, b.fraction_edges[k + 1]);
    EXPECT_DOUBLE_EQ(r.mass_fraction, b.fraction_mass[k]);  // shortest round-trip format: exact
  }
  std::ifstream in(path);
  std::string header, line1;
  std::getline(in, header);
  std::getline(in, line1);
  EXPECT_EQ(FractionsCsvLine(rows[0]), line1);
}

TEST(FractionsCsv, BadFilesAreNamedWithLineAndColumn) {
  const auto dir = TestDir();
  const std::string path = (dir / "fractions.csv").string();
  auto message = [&](const std::string& text) {
    std::ofstream(path) << text;
    try {
      ReadFractionsCsv(path);
    } catch (const PostError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string header =
      "velocity_m_s,angle_deg,repeat,fraction_index,d_low_rel,d_high_rel,mass_fraction\n";
  EXPECT_NE(message("a,b\n").find("fractions.csv:1: header"), std::string::npos);
  EXPECT_NE(message(header + "1,90,0,0,0,0.05,x\n")
                .find("fractions.csv:2: mass_fraction: expected a number"),
            std::string::npos);
  EXPECT_NE(message(header + "1,90,0,1.5,0,0.05,0\n").find("fraction_index"), std::string::npos);
  EXPECT_NE(message(header + "1,90,0\n").find("fractions.csv:2: 3 values"), std::string::npos);
  EXPECT_NE(message("").find("empty"), std::string::npos);
}

TEST(Impact, T10FlagWhenElementsAreCoarserThanTenthOfD) {
  // Ten equal elements: the lump's solid is 10 element volumes, so one element
  // has d/D_solid = 10^(-1/3) = 0.464, coarser than D/10.
  const auto r = MakeImpact(60.0, 0);
  EXPECT_FALSE(r.summary.t10_resolved);
  EXPECT_NEAR(r.summary.element_d_rel_max, std::cbrt(0.1), 1e-12);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("t10"), std::string::npos);
}

// Ten elements of d = 2.4 mm: a chain of 4 and 6 singles out of one lump of
// 10 element volumes; new surface = pi d^2 (6 + 4^(2/3) - 10^(2/3)).
TEST(Impact, NewSurfaceOfThePieces) {
  const double d = 2.4e-3;
  const auto r = MakeImpact(60.0, 0);
  EXPECT_NEAR(r.new_surface_m2,
              kPi * d * d * (6.0 + std::pow(4.0, 2.0 / 3.0) - std::pow(10.0, 2.0 / 3.0)), 1e-15);
  EXPECT_EQ(MakeImpact(60.0, 0, 10, 10).new_surface_m2, 0.0);  // intact
}

TEST(Impact, GroupName) {
  EXPECT_EQ(ImpactGroupName({150.0, 90.0, 0}), "v150.0_a90_r0");
  EXPECT_EQ(ImpactGroupName({4.25, 45.0, 3}), "v4.25_a45_r3");
}

// Reads a string attribute of an object.
std::string ReadStringAttr(hid_t obj, const char* name) {
  const hid_t attr = H5Aopen(obj, name, H5P_DEFAULT);
  const hid_t type = H5Aget_type(attr);
  std::string s(H5Tget_size(type), '\0');
  H5Aread(attr, type, s.data());
  H5Tclose(type);
  H5Aclose(attr);
  return s.c_str();
}

TEST(BreakageH5, MassDatasetAndUnitRoundTrip) {
  const auto dir = TestDir();
  const std::string path = (dir / "breakage.h5").string();
  const auto r = MakeImpact(150.0, 0);
  WriteBreakageH5(path, {r, MakeImpact(20.0, 1)});
  EXPECT_FALSE(fs::exists(path + ".tmp"));

  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  const hid_t set = H5Dopen2(file, "/impacts/v150.0_a90_r0/mass", H5P_DEFAULT);
  ASSERT_GE(set, 0);
  std::vector<double> mass(r.fragments.size());
  ASSERT_GE(H5Dread(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, mass.data()), 0);
  for (std::size_t k = 0; k < mass.size(); ++k) EXPECT_DOUBLE_EQ(mass[k], r.fragments[k].mass);
  EXPECT_EQ(ReadStringAttr(set, "unit"), "kg");
  H5Dclose(set);

  const hid_t vel = H5Dopen2(file, "/impacts/v150.0_a90_r0/velocity", H5P_DEFAULT);
  const hid_t space = H5Dget_space(vel);
  hsize_t dims[2] = {0, 0};
  EXPECT_EQ(H5Sget_simple_extent_ndims(space), 2);
  H5Sget_simple_extent_dims(space, dims, nullptr);
  EXPECT_EQ(dims[0], r.fragments.size());
  EXPECT_EQ(dims[1], 3u);
  EXPECT_EQ(ReadStringAttr(vel, "unit"), "m/s");
  H5Sclose(space);
  H5Dclose(vel);

  const hid_t sv = H5Dopen2(file, "/summary/velocity_m_s", H5P_DEFAULT);
  double v[2] = {0, 0};
  H5Dread(sv, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v);
  EXPECT_DOUBLE_EQ(v[0], 150.0);
  EXPECT_DOUBLE_EQ(v[1], 20.0);
  EXPECT_EQ(ReadStringAttr(sv, "unit"), "m/s");
  H5Dclose(sv);
  H5Fclose(file);
}

TEST(BreakageH5, DuplicateImpactIsRefusedAndLeavesNoFile) {
  const auto dir = TestDir();
  const std::string path = (dir / "breakage.h5").string();
  EXPECT_THROW(WriteBreakageH5(path, {MakeImpact(150.0, 0), MakeImpact(150.0, 0)}), PostError);
  EXPECT_FALSE(fs::exists(path));
}

TEST(BreakageH5, MergeOfPerImpactFiles) {
  const auto dir = TestDir();
  const std::string a = (dir / "a.h5").string(), b = (dir / "b.h5").string();
  const std::string merged = (dir / "breakage.h5").string();
  WriteBreakageH5(a, {MakeImpact(150.0, 0)});
  WriteBreakageH5(b, {MakeImpact(20.0, 0, 10, 9)});
  MergeBreakageH5Files(merged, {a, b});

  const hid_t file = H5Fopen(merged.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  EXPECT_GT(H5Lexists(file, "/impacts/v150.0_a90_r0", H5P_DEFAULT), 0);
  EXPECT_GT(H5Lexists(file, "/impacts/v20.0_a90_r0", H5P_DEFAULT), 0);
  const hid_t set = H5Dopen2(file, "/summary/n_pieces", H5P_DEFAULT);
  long long n[2] = {0, 0};
  H5Dread(set, H5T_NATIVE_LLONG, H5S_ALL, H5S_ALL, H5P_DEFAULT, n);
  EXPECT_EQ(n[0], 7);
  EXPECT_EQ(n[1], 2);
  EXPECT_EQ(ReadStringAttr(set, "unit"), "1");
  H5Dclose(set);
  H5Fclose(file);

  EXPECT_THROW(MergeBreakageH5Files((dir / "twice.h5").string(), {a, a}), PostError);
  EXPECT_FALSE(fs::exists(dir / "twice.h5"));
}

// The JK fit goes into an existing breakage.h5 under /jk_fit/<name>, with
// units; written twice, the group is replaced, not duplicated.
TEST(BreakageH5, JkFitGroupWithUnits) {
  const auto dir = TestDir();
  const std::string path = (dir / "breakage.h5").string();
  WriteBreakageH5(path, {MakeImpact(150.0, 0)});
  JkFitRecord rec;
  rec.name = "a90";
  std::vector<JkPoint> pts;
  for (double v : {20.0, 50.0, 90.0, 150.0}) {
    const double e = SpecificEnergyKWhPerTonne(v);
    rec.ecs_kwh_t.push_back(e);
    rec.t10_percent.push_back(JkT10(45.0, 2.0, e));
    rec.repeat.push_back(0);
    rec.used.push_back(1);
    pts.push_back({e, rec.t10_percent.back(), 0});
  }
  rec.fit = FitJkSweep(pts);
  ASSERT_TRUE(rec.fit.pooled.ok);
  WriteJkFitH5(path, {rec});
  WriteJkFitH5(path, {rec});

  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  EXPECT_GT(H5Lexists(file, "/impacts/v150.0_a90_r0", H5P_DEFAULT), 0);  // the impacts stay
  const hid_t a = H5Dopen2(file, "/jk_fit/a90/A", H5P_DEFAULT);
  ASSERT_GE(a, 0);
  double value = 0;
  H5Dread(a, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, &value);
  EXPECT_NEAR(value, 45.0, 1e-6);
  EXPECT_EQ(ReadStringAttr(a, "unit"), "%");
  H5Dclose(a);
  const hid_t b = H5Dopen2(file, "/jk_fit/a90/b", H5P_DEFAULT);
  EXPECT_EQ(ReadStringAttr(b, "unit"), "t/kWh");
  H5Dclose(b);
  const hid_t e = H5Dopen2(file, "/jk_fit/a90/ecs", H5P_DEFAULT);
  EXPECT_EQ(ReadStringAttr(e, "unit"), "kWh/t");
  H5Dclose(e);
  const hid_t g = H5Gopen2(file, "/jk_fit/a90", H5P_DEFAULT);
  EXPECT_EQ(ReadStringAttr(g, "status"), "fitted");
  H5Gclose(g);
  H5Fclose(file);
}

// Reads a 1-D double dataset.
std::vector<double> ReadDoubles(hid_t file, const std::string& name) {
  const hid_t set = H5Dopen2(file, name.c_str(), H5P_DEFAULT);
  if (set < 0) return {};
  const hid_t space = H5Dget_space(set);
  std::vector<double> v(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space)));
  H5Dread(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  H5Sclose(space);
  H5Dclose(set);
  return v;
}

// The unit attribute of a dataset.
std::string UnitOf(hid_t file, const std::string& name) {
  const hid_t set = H5Dopen2(file, name.c_str(), H5P_DEFAULT);
  if (set < 0) return "(no dataset)";
  const std::string unit = ReadStringAttr(set, "unit");
  H5Dclose(set);
  return unit;
}

// impact.h5 /energy: one dataset per ledger column with its unit; the merge
// copies it into the impact's own group of breakage.h5.
TEST(BreakageH5, EnergyGroupWithUnitsAndItsMerge) {
  const auto dir = TestDir();
  const std::string a = (dir / "a.h5").string(), b = (dir / "b.h5").string();
  const EnergyLedger ledger =
      ReadEnergyLedger(std::string(MILL_POST_TEST_DATA) + "/ledger_small.csv");
  WriteBreakageH5(a, {MakeImpact(150.0, 0)});
  WriteEnergyLedgerH5(a, ledger);
  WriteEnergyLedgerH5(a, ledger);  // replaced, not duplicated
  WriteBreakageH5(b, {MakeImpact(20.0, 0)});

  hid_t file = H5Fopen(a.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  EXPECT_EQ(ReadDoubles(file, "/energy/bond_released_J"), (std::vector<double>{0, 2, 3}));
  EXPECT_EQ(UnitOf(file, "/energy/bond_released_J"), "J");
  EXPECT_EQ(UnitOf(file, "/energy/time_s"), "s");
  EXPECT_EQ(UnitOf(file, "/energy/max_speed_m_s"), "m/s");
  EXPECT_EQ(UnitOf(file, "/energy/wall_overlap"), "1");
  EXPECT_EQ(UnitOf(file, "/energy/step"), "1");
  const hid_t g = H5Gopen2(file, "/energy", H5P_DEFAULT);
  EXPECT_NE(ReadStringAttr(g, "balance").find("input + work_other = ke_trans"), std::string::npos);
  H5Gclose(g);
  H5Fclose(file);

  const std::string merged = (dir / "breakage.h5").string();
  MergeBreakageH5Files(merged, {a, b});
  file = H5Fopen(merged.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  EXPECT_EQ(ReadDoubles(file, "/impacts/v150.0_a90_r0/energy/time_s"),
            (std::vector<double>{0, 1e-5, 2e-5}));
  EXPECT_EQ(UnitOf(file, "/impacts/v150.0_a90_r0/energy/input_J"), "J");
  EXPECT_EQ(H5Lexists(file, "/impacts/v20.0_a90_r0/energy", H5P_DEFAULT), 0);  // b has no ledger
  EXPECT_EQ(H5Lexists(file, "/energy", H5P_DEFAULT), 0);
  H5Fclose(file);

  // A file of two impacts with an /energy: whose ledger is it?
  const std::string two = (dir / "two.h5").string();
  WriteBreakageH5(two, {MakeImpact(60.0, 0), MakeImpact(90.0, 0)});
  WriteEnergyLedgerH5(two, ledger);
  try {
    MergeBreakageH5Files((dir / "bad.h5").string(), {two});
    FAIL() << "expected PostError";
  } catch (const PostError& e) {
    EXPECT_NE(std::string(e.what()).find("two.h5: /energy beside 2 impacts"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "bad.h5"));
}

// An impact.h5 from before the ledger's summary columns merges; they read NaN.
TEST(BreakageH5, MergeOfAFileWithoutTheLedgerColumns) {
  const auto dir = TestDir();
  const std::string a = (dir / "a.h5").string();
  ImpactResult r = MakeImpact(150.0, 0);
  r.summary.comminution_efficiency = 0.5;
  WriteBreakageH5(a, {r});
  hid_t file = H5Fopen(a.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  const hid_t g = H5Gopen2(file, "/impacts/v150.0_a90_r0", H5P_DEFAULT);
  for (const char* name :
       {"comminution_efficiency", "ledger_residual_fraction", "max_element_speed_m_s"})
    ASSERT_GE(H5Adelete(g, name), 0) << name;
  H5Gclose(g);
  H5Fclose(file);
  const std::string merged = (dir / "breakage.h5").string();
  MergeBreakageH5Files(merged, {a});
  file = H5Fopen(merged.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  const auto eff = ReadDoubles(file, "/summary/comminution_efficiency");
  ASSERT_EQ(eff.size(), 1u);
  EXPECT_TRUE(std::isnan(eff[0]));
  EXPECT_EQ(UnitOf(file, "/summary/max_element_speed_m_s"), "m/s");
  H5Fclose(file);
}

}  // namespace
}  // namespace mill::post
