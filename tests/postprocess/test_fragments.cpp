// Fragments over hand-built bond graphs with known answers.
#include "postprocess/fragments.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "postprocess/breakage_results.h"

namespace mill::post {
namespace {

constexpr double kRho = 2580.0;

// Elements with ids first..first+n-1, radius 1 mm, mass from kRho, at rest.
std::vector<Element> MakeElements(int n, long long first = 1) {
  std::vector<Element> out;
  for (int k = 0; k < n; ++k) {
    Element e;
    e.id = first + k;
    e.radius = 1e-3;
    e.mass = SphereMass(1e-3, kRho);
    out.push_back(e);
  }
  return out;
}

// Sizes of the fragments, in the order returned (heaviest first).
std::vector<std::size_t> Sizes(const std::vector<Fragment>& f) {
  std::vector<std::size_t> s;
  for (const auto& x : f) s.push_back(x.n_elements());
  return s;
}

// A spec with D = 10 mm, V = 60 m/s and the given initial bond count.
ImpactSpec Spec(long long initial_bonds) {
  ImpactSpec s;
  s.conditions = {60.0, 90.0, 0};
  s.initial_bonds = initial_bonds;
  s.lump_diameter_m = 0.01;
  s.density_kg_m3 = kRho;
  return s;
}

TEST(Fragments, ChainIsOnePiece) {
  const auto f = FindFragments(MakeElements(5), {{1, 2}, {2, 3}, {3, 4}, {4, 5}}, kRho);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_EQ(f[0].ids, (std::vector<long long>{1, 2, 3, 4, 5}));
}

TEST(Fragments, RingIsOnePiece) {
  const auto f =
      FindFragments(MakeElements(6), {{1, 2}, {2, 3}, {3, 4}, {4, 5}, {5, 6}, {1, 6}}, kRho);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_EQ(f[0].n_elements(), 6u);
}

TEST(Fragments, IsolatedElementsAreSingles) {
  const auto f = FindFragments(MakeElements(3), {}, kRho);
  EXPECT_EQ(Sizes(f), (std::vector<std::size_t>{1, 1, 1}));
}

TEST(Fragments, TwoClustersAndASingle) {
  const auto f = FindFragments(MakeElements(6), {{1, 2}, {2, 3}, {4, 5}}, kRho);
  EXPECT_EQ(Sizes(f), (std::vector<std::size_t>{3, 2, 1}));
  EXPECT_EQ(f[0].ids, (std::vector<long long>{1, 2, 3}));
  EXPECT_EQ(f[1].ids, (std::vector<long long>{4, 5}));
  EXPECT_EQ(f[2].ids, (std::vector<long long>{6}));
}

TEST(Fragments, SingleElementDiameterIsTwiceItsRadius) {
  const auto f = FindFragments(MakeElements(1), {}, kRho);
  EXPECT_NEAR(f[0].diameter, 2e-3, 1e-15);
}

TEST(Fragments, CentreOfMassVelocity) {
  auto e = MakeElements(2);
  e[0].mass = 1.0;
  e[0].v = {4.0, 0.0, -1.0};
  e[1].mass = 3.0;
  e[1].v = {0.0, 2.0, 3.0};
  const auto f = FindFragments(e, {{1, 2}}, kRho);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_DOUBLE_EQ(f[0].velocity[0], 1.0);
  EXPECT_DOUBLE_EQ(f[0].velocity[1], 1.5);
  EXPECT_DOUBLE_EQ(f[0].velocity[2], 2.0);
  EXPECT_DOUBLE_EQ(f[0].mass, 4.0);
}

TEST(Fragments, MassIsConserved) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> radius(0.8e-3, 1.6e-3);
  std::uniform_int_distribution<int> pick(1, 400);
  auto e = MakeElements(400);
  double total = 0.0;
  for (auto& x : e) {
    x.radius = radius(rng);
    x.mass = SphereMass(x.radius, kRho);
    total += x.mass;
  }
  std::vector<Bond> bonds;
  for (int k = 0; k < 300; ++k) {
    const int a = pick(rng), b = pick(rng);
    if (a != b) bonds.push_back({std::min(a, b), std::max(a, b)});
  }
  const auto f = FindFragments(e, bonds, kRho);
  double sum = 0.0;
  std::size_t count = 0;
  for (const auto& x : f) {
    sum += x.mass;
    count += x.n_elements();
  }
  EXPECT_EQ(count, e.size());
  EXPECT_LE(std::abs(sum - total) / total, 1e-12);
}

TEST(Fragments, BondToMissingIdNamesItAndTheSource) {
  try {
    FindFragments(MakeElements(3), {{1, 2}, {2, 42}}, kRho, "run7/bonds.txt");
    FAIL() << "expected PostError";
  } catch (const PostError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("run7/bonds.txt"), std::string::npos) << msg;
    EXPECT_NE(msg.find("42"), std::string::npos) << msg;
  }
}

TEST(Fragments, DuplicateElementIdIsAnError) {
  auto e = MakeElements(3);
  e[2].id = 1;
  EXPECT_THROW(FindFragments(e, {}, kRho), PostError);
}

TEST(Impact, EmptyBondListGivesAllSingles) {
  const auto r = AnalyseImpact(MakeElements(8), {}, Spec(12));
  EXPECT_EQ(r.summary.n_pieces, 8);
  EXPECT_EQ(r.summary.n_single, 8);
  EXPECT_EQ(r.summary.n_multi, 0);
  EXPECT_DOUBLE_EQ(r.summary.single_mass_fraction, 1.0);
  EXPECT_DOUBLE_EQ(r.summary.largest_mass_fraction, 1.0 / 8.0);
  EXPECT_DOUBLE_EQ(r.summary.broken_bond_fraction, 1.0);
}

TEST(Impact, FullyBondedLumpIsOnePieceWithNoBrokenBonds) {
  std::vector<Bond> bonds;
  for (int i = 1; i <= 5; ++i) {
    for (int j = i + 1; j <= 5; ++j) bonds.push_back({i, j});
  }
  const auto r = AnalyseImpact(MakeElements(5), bonds, Spec(static_cast<long long>(bonds.size())));
  EXPECT_EQ(r.summary.n_pieces, 1);
  EXPECT_EQ(r.summary.n_single, 0);
  EXPECT_EQ(r.summary.n_multi, 1);
  EXPECT_DOUBLE_EQ(r.summary.largest_mass_fraction, 1.0);
  EXPECT_DOUBLE_EQ(r.summary.broken_bond_fraction, 0.0);
}

TEST(Impact, DuplicateBondsCountOnce) {
  const auto r = AnalyseImpact(MakeElements(3), {{1, 2}, {2, 1}, {2, 3}}, Spec(4));
  EXPECT_EQ(r.summary.intact_bonds, 2);
  EXPECT_DOUBLE_EQ(r.summary.broken_bond_fraction, 0.5);
}

TEST(Impact, MoreIntactThanInitialBondsIsAnError) {
  EXPECT_THROW(AnalyseImpact(MakeElements(3), {{1, 2}, {2, 3}}, Spec(1)), PostError);
}

}  // namespace
}  // namespace mill::post
