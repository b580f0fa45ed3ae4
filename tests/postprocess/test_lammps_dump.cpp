// Reading dumps (columns by name, last snapshot) and intact-bond files.
#include "postprocess/lammps_dump.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "postprocess/breakage_results.h"

namespace mill::post {
namespace {

const std::string kData = MILL_POST_TEST_DATA;

// Expects `fn` to throw PostError whose text contains every one of `parts`.
template <typename Fn>
void ExpectErrorNaming(Fn fn, std::initializer_list<std::string> parts) {
  try {
    fn();
    ADD_FAILURE() << "expected PostError";
  } catch (const PostError& e) {
    for (const auto& p : parts)
      EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what();
  }
}

TEST(Dump, ShuffledColumnsAndTwoSnapshotsGiveTheLast) {
  const auto s = ReadDumpLastSnapshot(kData + "/two_snapshots_shuffled.dump", 2580.0);
  EXPECT_EQ(s.timestep, 30000);
  EXPECT_EQ(s.n_snapshots, 2);
  EXPECT_FALSE(s.mass_from_density);
  EXPECT_DOUBLE_EQ(s.box[3], 0.3);
  ASSERT_EQ(s.elements.size(), 3u);
  const Element& e = s.elements[0];
  EXPECT_EQ(e.id, 12);
  EXPECT_EQ(e.type, 1);
  EXPECT_DOUBLE_EQ(e.radius, 0.002);
  EXPECT_DOUBLE_EQ(e.mass, 3e-5);
  EXPECT_DOUBLE_EQ(e.x[0], 0.01);
  EXPECT_DOUBLE_EQ(e.x[1], 0.02);
  EXPECT_DOUBLE_EQ(e.x[2], 0.03);
  EXPECT_DOUBLE_EQ(e.v[0], 2.0);
  EXPECT_DOUBLE_EQ(e.v[1], 0.5);
  EXPECT_DOUBLE_EQ(e.v[2], -1.5);
  EXPECT_EQ(s.elements[1].type, 2);
}

TEST(Dump, MassFromDensityWhenNoMassColumn) {
  std::istringstream in(
      "ITEM: TIMESTEP\n5\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS ff ff ff\n0 1\n0 1\n0 1\n"
      "ITEM: ATOMS id radius vx vy vz\n3 0.002 0 0 0\n");
  const auto s = ParseDumpLastSnapshot(in, "mem", 2580.0);
  EXPECT_TRUE(s.mass_from_density);
  EXPECT_NEAR(s.elements[0].mass, 2580.0 * 4.0 / 3.0 * kPi * 8e-9, 1e-20);
}

TEST(Dump, MissingColumnIsNamed) {
  std::istringstream in(
      "ITEM: TIMESTEP\n5\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS ff ff ff\n0 1\n0 1\n0 1\n"
      "ITEM: ATOMS id vx vy vz\n3 0 0 0\n");
  ExpectErrorNaming([&] { ParseDumpLastSnapshot(in, "mem.dump", 2580.0); },
                    {"mem.dump:9", "'radius'"});
}

TEST(Dump, TruncatedSnapshotIsAnError) {
  std::istringstream in(
      "ITEM: TIMESTEP\n5\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS ff ff ff\n0 1\n0 1\n0 1\n"
      "ITEM: ATOMS id radius vx vy vz\n3 0.002 0 0 0\n");
  ExpectErrorNaming([&] { ParseDumpLastSnapshot(in, "cut.dump", 2580.0); },
                    {"cut.dump", "truncated"});
}

TEST(Dump, BadNumberNamesFileAndLine) {
  std::istringstream in(
      "ITEM: TIMESTEP\n5\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS ff ff ff\n0 1\n0 1\n0 1\n"
      "ITEM: ATOMS id radius vx vy vz\n3 0.002 0 abc 0\n");
  ExpectErrorNaming([&] { ParseDumpLastSnapshot(in, "x.dump", 2580.0); }, {"x.dump:10", "abc"});
}

TEST(Bonds, CommentsAndBlankLinesAreSkipped) {
  const auto b = ReadIntactBonds(kData + "/bonds_ok.txt");
  ASSERT_EQ(b.size(), 1u);
  EXPECT_EQ(b[0].i, 10);
  EXPECT_EQ(b[0].j, 11);
}

TEST(Bonds, MalformedLineNamesFileAndLine) {
  std::istringstream in("# c\n1 2\n3\n");
  ExpectErrorNaming([&] { ParseIntactBonds(in, "b.txt"); }, {"b.txt:3"});
}

TEST(Bonds, BondToMissingIdNamesFileAndId) {
  ImpactSpec spec;
  spec.conditions = {20.0, 90.0, 0};
  spec.initial_bonds = 3;
  spec.lump_diameter_m = 0.01;
  spec.density_kg_m3 = 2580.0;
  ExpectErrorNaming(
      [&] {
        AnalyseImpactFiles(kData + "/two_snapshots_shuffled.dump",
                           kData + "/bad_bond_missing_id.txt", spec);
      },
      {"bad_bond_missing_id.txt", "atom id 99"});
}

TEST(Bonds, FilesTogetherGiveFragments) {
  ImpactSpec spec;
  spec.conditions = {20.0, 90.0, 0};
  spec.initial_bonds = 3;
  spec.lump_diameter_m = 0.01;
  spec.density_kg_m3 = 2580.0;
  const auto r =
      AnalyseImpactFiles(kData + "/two_snapshots_shuffled.dump", kData + "/bonds_ok.txt", spec);
  EXPECT_EQ(r.summary.n_pieces, 2);
  EXPECT_EQ(r.summary.n_single, 1);
  EXPECT_NEAR(r.summary.lump_mass_kg, 6e-5, 1e-18);
  EXPECT_NEAR(r.summary.largest_mass_fraction, 0.5, 1e-12);
  EXPECT_NEAR(r.summary.broken_bond_fraction, 2.0 / 3.0, 1e-12);
}

}  // namespace
}  // namespace mill::post
