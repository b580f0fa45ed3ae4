// The cuts of fix balance/weighted (balance_cuts.h) against hand counts.
#include <gtest/gtest.h>

#include <cmath>

#include "balance_cuts.h"

namespace mill::balance {
namespace {

std::vector<Point> unit_points(int n) {
  std::vector<Point> p;
  for (int i = 0; i < n; ++i) p.push_back({static_cast<double>(i), 1.0});
  return p;
}

// Equal weights: the cuts halve (thirds, quarters) the points, midway
// between neighbours.
TEST(BalanceCuts, EqualWeightsCutBetweenEqualCounts) {
  EXPECT_EQ(weighted_cuts(unit_points(10), 2), std::vector<double>({4.5}));
  EXPECT_EQ(weighted_cuts(unit_points(9), 3), std::vector<double>({2.5, 5.5}));
  EXPECT_EQ(weighted_cuts(unit_points(8), 4), std::vector<double>({1.5, 3.5, 5.5}));
}

// Weights 3, 1, 1, 1 at x = 0..3: half the weight (3) is the first point
// alone; unsorted input is sorted first.
TEST(BalanceCuts, WeightsMoveTheCut) {
  std::vector<Point> p = {{3, 1}, {0, 3}, {2, 1}, {1, 1}};
  EXPECT_EQ(weighted_cuts(p, 2), std::vector<double>({0.5}));
  // Weight 1, 1, 1, 5: the heavy point alone is more than half: the cut
  // leaves it alone on its side.
  p = {{0, 1}, {1, 1}, {2, 1}, {3, 5}};
  EXPECT_EQ(weighted_cuts(p, 2), std::vector<double>({2.5}));
  // The nearest prefix wins: weights 1, 2, 1 (total 4, half 2): after the
  // first point 1 short, after the second 1 over: the tie keeps the shorter.
  p = {{0, 1}, {1, 2}, {2, 1}};
  EXPECT_EQ(weighted_cuts(p, 2), std::vector<double>({0.5}));
}

// Every part keeps at least one point; fewer points than parts: no cuts.
TEST(BalanceCuts, EveryPartKeepsAPoint) {
  const std::vector<Point> p = {{0, 100}, {1, 1}, {2, 1}};
  EXPECT_EQ(weighted_cuts(p, 3), std::vector<double>({0.5, 1.5}));
  EXPECT_TRUE(weighted_cuts(unit_points(2), 3).empty());
  EXPECT_TRUE(weighted_cuts({}, 2).empty());
  EXPECT_TRUE(weighted_cuts(unit_points(5), 1).empty());
}

// A cut moves no closer than margin to its neighbours' old places; with two
// parts (one cut) it is free.
TEST(BalanceCuts, CutsMoveAtMostToTheirNeighboursOldPlaces) {
  const std::vector<double> old3 = {0, 1, 2, 3};
  EXPECT_DOUBLE_EQ(limited_cut(old3, 1, 5.0, 0.1), 1.9);
  EXPECT_DOUBLE_EQ(limited_cut(old3, 2, -5.0, 0.1), 1.1);
  EXPECT_DOUBLE_EQ(limited_cut(old3, 1, 1.5, 0.1), 1.5);
  EXPECT_DOUBLE_EQ(limited_cut(old3, 1, -7.0, 0.1), -7.0);  // the first cut: free below
  const std::vector<double> old2 = {0, 1, 2};
  EXPECT_DOUBLE_EQ(limited_cut(old2, 1, 40.0, 0.1), 40.0);
  // Neighbours closer than twice the margin: the cut stays.
  const std::vector<double> tight = {0, 1, 1.1, 1.15, 3};
  EXPECT_DOUBLE_EQ(limited_cut(tight, 2, 2.0, 0.1), 1.1);
}

}  // namespace
}  // namespace mill::balance
