// The ball packing's seed rule and size rules (driver/lump/packing.h): the
// one rule that gives the lump and the calibrate specimens their LIGGGHTS
// seeds keeps the seeds every lump and specimen has been packed with.
#include <gtest/gtest.h>

#include <cmath>

#include "lump/packing.h"

using namespace mill;

namespace {

bool is_prime(long n) {
  if (n < 2) return false;
  for (long i = 2; i * i <= n; ++i)
    if (n % i == 0) return false;
  return true;
}

long next_prime(long n) {
  while (!is_prime(n)) ++n;
  return n;
}

// The two recipes the one rule replaced, as they derived their seeds. The
// lump's packing k of lump.seed s: the bases 2 (s + k) and 2 (s + k) + 1.
PackingSeeds old_lump_seeds(long lump_seed, int packing) {
  const long base = 2 * (lump_seed + packing);
  PackingSeeds s{prime_seed(base), prime_seed(base + 1)};
  if (s.ins == s.dist) s.ins = next_prime(s.dist + 1);
  return s;
}
// The specimen of calibrate.seed s: the base s, then the slot after the prime's.
PackingSeeds old_specimen_seeds(long seed) {
  const long dist = prime_seed(seed);
  return {dist, prime_seed((dist - 20000) / 7 + 1)};
}

}  // namespace

// The default lump (lump.seed 1001, packing 0) and the default specimen
// (calibrate.seed 2002) keep their seeds; so does the tests' specimen (2003).
TEST(Packing, SeedsOfTheDefaultLumpAndSpecimens) {
  const PackingSeeds lump = packing_seeds(2 * (1001 + 0));
  EXPECT_EQ(lump.dist, 34019);
  EXPECT_EQ(lump.ins, 34031);
  const PackingSeeds specimen = packing_seeds(prime_stream(2002));
  EXPECT_EQ(specimen.dist, 34019);
  EXPECT_EQ(specimen.ins, 34031);
  const PackingSeeds tests = packing_seeds(prime_stream(2003));
  EXPECT_EQ(tests.dist, 34031);
  EXPECT_EQ(tests.ins, 34039);
}

// The one rule gives every lump packing and every specimen the seeds the two
// old recipes gave (seeds around the wrap of prime_seed's base included).
TEST(Packing, OneRuleReproducesBothOldRecipes) {
  for (long seed = 1; seed < 20000; ++seed) {
    const PackingSeeds l = packing_seeds(2 * (seed + 3)), lo = old_lump_seeds(seed, 3);
    ASSERT_EQ(l.dist, lo.dist) << "lump.seed " << seed;
    ASSERT_EQ(l.ins, lo.ins) << "lump.seed " << seed;
    const PackingSeeds c = packing_seeds(prime_stream(seed)), co = old_specimen_seeds(seed);
    ASSERT_EQ(c.dist, co.dist) << "calibrate.seed " << seed;
    ASSERT_EQ(c.ins, co.ins) << "calibrate.seed " << seed;
  }
  for (long seed = 999990; seed < 1000010; ++seed) {
    const PackingSeeds c = packing_seeds(prime_stream(seed)), co = old_specimen_seeds(seed);
    ASSERT_EQ(c.dist, co.dist) << "calibrate.seed " << seed;
    ASSERT_EQ(c.ins, co.ins) << "calibrate.seed " << seed;
  }
}

// When no prime lies in [20000 + 7 s, 20000 + 7 s + 7) the two fixes would
// share a seed (LIGGGHTS then aborts without a message): ins moves on to the
// next prime. Stream 2006 (lump.seed 1003) is such a stream.
TEST(Packing, TwoFixesNeverShareASeed) {
  const PackingSeeds s = packing_seeds(2006);
  EXPECT_EQ(s.dist, 34057);
  EXPECT_EQ(s.ins, 34061);
  for (long stream = 1; stream < 5000; ++stream) {
    const PackingSeeds p = packing_seeds(stream);
    ASSERT_TRUE(is_prime(p.dist) && is_prime(p.ins)) << "stream " << stream;
    ASSERT_GT(p.dist, 20000) << "stream " << stream;
    ASSERT_GT(p.ins, p.dist) << "stream " << stream;
  }
}

// The five radius classes r_mean (1 + spread {-1, -1/2, 0, 1/2, 1}) have the
// mean r_mean, and the mean radius fills the ball at the fitted solid fraction.
TEST(Packing, RadiusClassesAndMeanRadius) {
  double sum = 0;
  for (int k = 0; k < 5; ++k) sum += class_factor(k, 0.25);
  EXPECT_DOUBLE_EQ(sum / 5, 1.0);
  EXPECT_DOUBLE_EQ(class_factor(0, 0.25), 0.75);
  EXPECT_DOUBLE_EQ(class_factor(4, 0.25), 1.25);
  const long n = 3344;
  const double d = 0.04, rm = target_mean_radius(n, d, 0.25);
  const double solid = n * rm * rm * rm * mean_cube_factor(0.25) / std::pow(d / 2, 3);
  EXPECT_NEAR(solid, 0.62 * std::pow(1 - 1.23 * std::pow(n, -1.0 / 3), 3), 1e-12);
}

// elements_for_radius inverts target_mean_radius: the count it gives has
// the radius nearest the one asked for (its neighbours are no nearer), a
// count's own radius gives it back, and a lump of 8 x the elements in twice
// the diameter has larger elements (the solid fraction rises with the
// count), so the same element size takes more than 8 x (hand check: 2000
// elements of 40 mm have r = 20 mm x (0.62 (1 - 1.23 / 2000^(1/3))^3 /
// (2000 c))^(1/3); the 80 mm ball needs about 2000 x 8 x (0.9024/0.9512)^-3).
TEST(Packing, ElementsForRadiusInvertsTheMeanRadius) {
  for (long n : {15L, 16L, 100L, 250L, 1668L, 2000L, 3344L, 100000L})
    EXPECT_EQ(elements_for_radius(target_mean_radius(n, 0.04, 0.25), 0.04, 0.25), n) << n;
  const double r = target_mean_radius(2000, 0.04, 0.25);
  for (double d : {0.01, 0.0266, 0.0376, 0.0532, 0.08}) {
    const long n = elements_for_radius(r, d, 0.25);
    const double miss = std::abs(target_mean_radius(n, d, 0.25) - r);
    EXPECT_LE(miss, std::abs(target_mean_radius(n - 1, d, 0.25) - r)) << d;
    EXPECT_LE(miss, std::abs(target_mean_radius(n + 1, d, 0.25) - r)) << d;
  }
  const double x2000 = 1 - 1.23 * std::pow(2000.0, -1.0 / 3), x16000 = 1 - 1.23 * std::pow(16000.0, -1.0 / 3);
  EXPECT_GT(target_mean_radius(16000, 0.08, 0.25), r);
  EXPECT_NEAR(target_mean_radius(16000, 0.08, 0.25) / r, x16000 / x2000, 1e-12);
  const long n80 = elements_for_radius(r, 0.08, 0.25);
  EXPECT_GT(n80, 16000);
  EXPECT_NEAR(static_cast<double>(n80), 16000 * std::pow(x16000 / x2000, 3), 0.02 * 16000);
  // Below 15 elements the rule's radius no longer falls with the count:
  // a radius larger than 15 elements' gives 15.
  EXPECT_EQ(elements_for_radius(target_mean_radius(15, 0.04, 0.25) * 1.5, 0.04, 0.25), 15);
}
