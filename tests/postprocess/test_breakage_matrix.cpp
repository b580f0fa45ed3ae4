// The breakage matrix from hand-made piece lists: binning conserves mass,
// columns are mass-weighted over lumps and sum to 1, a scaled column is the
// measured one shifted on a geometric series, the assembled matrix's origins.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <random>

#include "postprocess/breakage_matrix.h"
#include "postprocess/fragments.h"

namespace mill::post {
namespace {

double Sum(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); }

// The classes of the sieves 16, 22.4, 31.5, 45, 63 mm: 45-63, 31.5-45,
// 22.4-31.5, 16-22.4, below 16.
SizeClasses FiveClasses() { return SizeClassesFromSieves({16, 22.4, 31.5, 45, 63}); }

TEST(BinPieces, EachPieceInItsClassAndMassConserved) {
  const SizeClasses c = FiveClasses();
  // A lump of the 31.5-45 mm class: a piece of 40 mm stays in it, one of 50
  // mm (coarser than its class: an element-packing artefact) counts in it
  // too, 31.5 mm is on the sieve (the class below holds [22.4, 31.5)), 20 mm
  // and 5 mm go to their classes.
  const LumpPieces p{{40, 50, 31.5, 31.4999, 20, 5}, {0.3, 0.01, 0.2, 0.1, 0.25, 0.14}};
  const auto m = BinPieces(c, 1, p);
  ASSERT_EQ(m.size(), 5u);
  EXPECT_EQ(m[0], 0.0);
  EXPECT_NEAR(m[1], 0.3 + 0.01 + 0.2, 1e-15);
  EXPECT_NEAR(m[2], 0.1, 1e-15);
  EXPECT_NEAR(m[3], 0.25, 1e-15);
  EXPECT_NEAR(m[4], 0.14, 1e-15);
  EXPECT_NEAR(Sum(m), Sum(p.mass_kg), 1e-12 * Sum(p.mass_kg));
}

TEST(BinPieces, ManyRandomPiecesConserveMassTo1e12) {
  const SizeClasses c = GeometricSieveSeries(63, std::sqrt(2.0), 12);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> size(0.01, 63), mass(1e-6, 1e-3);
  LumpPieces p;
  for (int k = 0; k < 5000; ++k) {
    p.size_mm.push_back(size(rng));
    p.mass_kg.push_back(mass(rng));
  }
  for (std::size_t j : {0u, 3u, 11u}) {
    const auto m = BinPieces(c, j, p);
    EXPECT_NEAR(Sum(m), Sum(p.mass_kg), 1e-12 * Sum(p.mass_kg)) << "class " << j;
    for (std::size_t i = 0; i < j; ++i) EXPECT_EQ(m[i], 0.0) << "coarser than the lump";
  }
}

TEST(MeasuredBreakageColumn, MassWeightedOverLumpsAndSumsToOne) {
  const SizeClasses c = FiveClasses();
  // Lump A (2 kg) stays whole; lump B (1 kg) becomes fines. Weighted by
  // mass: 2/3 stays, 1/3 goes to the finest class (a plain mean of the two
  // lumps' fractions would say 1/2 each).
  const std::vector<LumpPieces> lumps = {{{38}, {2.0}}, {{1, 2, 3}, {0.5, 0.25, 0.25}}};
  const auto col = MeasuredBreakageColumn(c, 1, lumps);
  EXPECT_NEAR(col[1], 2.0 / 3.0, 1e-15);
  EXPECT_NEAR(col[4], 1.0 / 3.0, 1e-15);
  EXPECT_EQ(col[0] + col[2] + col[3], 0.0);
  EXPECT_NEAR(Sum(col), 1.0, 1e-12);
}

TEST(MeasuredBreakageColumn, NoLumpOrNoMassIsAnError) {
  const SizeClasses c = FiveClasses();
  EXPECT_THROW(MeasuredBreakageColumn(c, 1, {}), PostError);
  try {
    MeasuredBreakageColumn(c, 2, {{{30}, {0.0}}});
    ADD_FAILURE() << "expected a PostError";
  } catch (const PostError& e) {
    EXPECT_NE(std::string(e.what()).find("22.4-31.5 mm"), std::string::npos) << e.what();
  }
}

// A random column of class m: mass in classes m .. n-1, summing to 1.
std::vector<double> RandomColumn(std::size_t n, std::size_t m, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.05, 1.0);
  std::vector<double> col(n, 0.0);
  for (std::size_t i = m; i < n; ++i) col[i] = u(rng);
  const double s = Sum(col);
  for (double& v : col) v /= s;
  return col;
}

TEST(ScaledBreakageColumn, OnAGeometricSeriesItIsTheMeasuredColumnShifted) {
  const SizeClasses c = GeometricSieveSeries(64, std::sqrt(2.0), 6);
  const auto m = RandomColumn(6, 2, 3);
  // One class finer: shifted down by one, what passes beyond the finest
  // sieve in the pan.
  const auto finer = ScaledBreakageColumn(c, 2, m, 3);
  const std::vector<double> want_finer = {0, 0, 0, m[2], m[3], m[4] + m[5]};
  // One class coarser: shifted up by one; the measured pan's mass stays in
  // the pan (nothing is known of its spread below the finest sieve).
  const auto coarser = ScaledBreakageColumn(c, 2, m, 1);
  const std::vector<double> want_coarser = {0, m[2], m[3], m[4], 0, m[5]};
  // Its own class: the measured column itself.
  const auto same = ScaledBreakageColumn(c, 2, m, 2);
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_NEAR(finer[i], want_finer[i], 1e-12) << i;
    EXPECT_NEAR(coarser[i], want_coarser[i], 1e-12) << i;
    EXPECT_NEAR(same[i], m[i], 1e-12) << i;
  }
  EXPECT_NEAR(Sum(finer), 1.0, 1e-12);
  EXPECT_NEAR(Sum(coarser), 1.0, 1e-12);
}

TEST(ScaledBreakageColumn, OnUnevenSievesAColumnOfFractionsSummingToOne) {
  const SizeClasses c = SizeClassesFromSieves({1, 2, 4, 8, 11.2, 16, 22.4, 31.5, 45, 63});
  const auto m = RandomColumn(10, 2, 11);
  for (std::size_t j = 0; j + 1 < 10; ++j) {
    const auto col = ScaledBreakageColumn(c, 2, m, j);
    EXPECT_NEAR(Sum(col), 1.0, 1e-12) << j;
    for (std::size_t i = 0; i < 10; ++i) {
      EXPECT_GE(col[i], 0.0) << i << " " << j;
      if (i < j) {
        EXPECT_EQ(col[i], 0.0) << i << " " << j;
      }
    }
  }
}

TEST(AssembleBreakageMatrix, MeasuredScaledAndFinestColumns) {
  const SizeClasses c = GeometricSieveSeries(64, 2.0, 6);
  const auto m1 = RandomColumn(6, 1, 5), m3 = RandomColumn(6, 3, 6);
  const AssembledMatrix a = AssembleBreakageMatrix(c, {{1, m1}, {3, m3}});
  ASSERT_EQ(a.origin.size(), 6u);
  EXPECT_EQ(a.origin[1].kind, "measured");
  EXPECT_EQ(a.origin[3].kind, "measured");
  EXPECT_EQ(a.origin[5].kind, "finest");
  // Class 0 is nearest to class 1; class 2 equally near 1 and 3 (the
  // coarser wins); class 4 nearest to class 3.
  EXPECT_EQ(a.origin[0].kind, "scaled");
  EXPECT_EQ(a.origin[0].from, 1u);
  EXPECT_EQ(a.origin[2].from, 1u);
  EXPECT_EQ(a.origin[4].from, 3u);
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(a.b[i][1], m1[i]);
    EXPECT_EQ(a.b[i][5], i == 5 ? 1.0 : 0.0);
  }
  for (std::size_t j = 0; j < 6; ++j) {
    double s = 0;
    for (std::size_t i = 0; i < 6; ++i) s += a.b[i][j];
    EXPECT_NEAR(s, 1.0, 1e-12) << "column " << j;
  }
  // The matrix from pieces: a mass-conserving pass.
  std::vector<double> feed = {1, 2, 3, 4, 5, 6}, out(6, 0.0);
  for (std::size_t i = 0; i < 6; ++i)
    for (std::size_t j = 0; j < 6; ++j) out[i] += a.b[i][j] * feed[j];
  EXPECT_NEAR(Sum(out), Sum(feed), 1e-12 * Sum(feed));
}

TEST(AssembleBreakageMatrix, NothingMeasuredIsAnError) {
  const SizeClasses c = FiveClasses();
  EXPECT_THROW(AssembleBreakageMatrix(c, {}), PostError);
  EXPECT_THROW(AssembleBreakageMatrix(c, {{1, {0, 1, 0}}}), PostError);
}

TEST(ClassOfSize, UpperEdgeBelongsToTheCoarserClass) {
  const SizeClasses c = FiveClasses();
  EXPECT_EQ(ClassOfSize(c, 70), 5u);  // above the top sieve
  EXPECT_EQ(ClassOfSize(c, 63), 5u);
  EXPECT_EQ(ClassOfSize(c, 50), 0u);
  EXPECT_EQ(ClassOfSize(c, 45), 0u);
  EXPECT_EQ(ClassOfSize(c, 44.9), 1u);
  EXPECT_EQ(ClassOfSize(c, 16), 3u);
  EXPECT_EQ(ClassOfSize(c, 15.9), 4u);
  EXPECT_EQ(ClassOfSize(c, 0.1), 4u);
}

}  // namespace
}  // namespace mill::post
