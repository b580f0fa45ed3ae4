// The calibrate stage's packing check (stages/calibrate/packing_check.h): the
// spread of the result over further specimen packings, by hand.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "stages/calibrate/fitting.h"
#include "stages/calibrate/packing_check.h"

namespace {

using mill::calibrate::Iteration;
using mill::calibrate::PackingRun;

// A result with E, nu, UCS and T on the fit's packing.
Iteration result(double E, double nu, double ucs, double t) {
  Iteration it;
  it.ucs.r.youngs_modulus = E;
  it.ucs.r.poisson_ratio = nu;
  it.ucs.r.ucs = ucs;
  it.br.r.tensile_strength = t;
  return it;
}

PackingRun run(long seed, double E, double nu, double ucs, double t) {
  PackingRun r;
  r.seed = seed;
  r.ucs.r.youngs_modulus = E;
  r.ucs.r.poisson_ratio = nu;
  r.ucs.r.ucs = ucs;
  r.br.r.tensile_strength = t;
  r.ucs.tag = "packing_ucs";
  r.br.tag = "packing_brazilian";
  return r;
}

}  // namespace

// The flat joint at bond gap 1.4 on three 400-element packings (bench/README.md,
// "UCS/T of 10 at bond gap 1.4"): the tensile strength 4.81, 9.28, 7.74 MPa,
// mean 7.277, range 4.47: spread 61.4 %, beyond 10 %; the UCS 49.3, 44.7,
// 65.1: mean 53.03, spread 38.5 %; E 19.0, 17.6, 19.5 GPa: 10.1 %, just
// beyond; nu 0.159, 0.122, 0.184: 0.062 > 0.05.
TEST(CalibratePacking, SpreadOfThreePackingsByHand) {
  const auto s = mill::calibrate::packing_spread(
      result(19.0e9, 0.159, 49.3e6, 4.81e6), 2002,
      {run(2003, 17.6e9, 0.122, 44.7e6, 9.28e6), run(2004, 19.5e9, 0.184, 65.1e6, 7.74e6)}, 0.1,
      0.05);
  EXPECT_EQ(s.seeds, (std::vector<long>{2002, 2003, 2004}));
  EXPECT_NEAR(s.tensile.mean, 7.2766667e6, 1);
  EXPECT_NEAR(s.tensile.spread, (9.28 - 4.81) / 7.2766667, 1e-6);
  EXPECT_NEAR(s.ucs.spread, (65.1 - 44.7) / 53.033333, 1e-6);
  EXPECT_NEAR(s.E.spread, (19.5 - 17.6) / 18.7, 1e-9);
  EXPECT_NEAR(s.nu.spread, 0.062, 1e-12);  // absolute
  EXPECT_FALSE(s.tensile.within());
  EXPECT_FALSE(s.E.within());
  EXPECT_FALSE(s.nu.within());
  EXPECT_FALSE(s.within());
  const std::string w = mill::calibrate::packing_warning(s, 400);
  EXPECT_NE(w.find("3 packings of 400 elements"), std::string::npos) << w;
  EXPECT_NE(w.find("tensile 61.4% (tolerance 10%)"), std::string::npos) << w;
  EXPECT_NE(w.find("nu 0.062 (tolerance 0.05)"), std::string::npos) << w;
  EXPECT_NE(w.find("raise calibrate.n_elements"), std::string::npos) << w;
  const std::string md = mill::calibrate::packing_markdown(s);
  EXPECT_NE(md.find("| tensile (MPa) | 4.81 | 9.28 | 7.74 | 7.28 | 61.4% | 10% | **no** |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("UCS / tensile: 10.25, 4.82, 8.41"), std::string::npos) << md;
  EXPECT_NE(md.find("Beyond the tolerance"), std::string::npos) << md;
  const auto j = mill::calibrate::packing_json(s, {});
  EXPECT_FALSE(j.at("within_tolerance").get<bool>());
  EXPECT_NEAR(j.at("tensile_strength").at("spread").get<double>(), s.tensile.spread, 1e-15);
  EXPECT_TRUE(j.at("poisson_ratio").at("spread_is_absolute").get<bool>());
}

// The parallel bond's three packings (same bench): UCS 21.1, 18.2, 17.8 MPa
// (17.9 %: beyond), T 5.16, 5.07, 4.28 (18.2 %); and a tight set within.
TEST(CalibratePacking, WithinWhenEveryPropertyIsWithinItsTolerance) {
  const auto tight = mill::calibrate::packing_spread(
      result(20e9, 0.18, 50e6, 5e6), 1,
      {run(2, 20.5e9, 0.19, 52e6, 5.2e6), run(3, 19.6e9, 0.17, 48e6, 4.9e6)}, 0.1, 0.05);
  EXPECT_TRUE(tight.within());
  EXPECT_EQ(mill::calibrate::packing_warning(tight, 400), "");
  EXPECT_NE(mill::calibrate::packing_markdown(tight).find("Within the tolerance"),
            std::string::npos);
  const auto pb = mill::calibrate::packing_spread(
      result(19.9e9, 0.181, 21.1e6, 5.16e6), 2002,
      {run(2003, 19.5e9, 0.225, 18.2e6, 5.07e6), run(2004, 19.9e9, 0.224, 17.8e6, 4.28e6)}, 0.1,
      0.05);
  EXPECT_NEAR(pb.ucs.spread, 3.3 / 19.033333, 1e-6);
  EXPECT_FALSE(pb.ucs.within());
  EXPECT_TRUE(pb.E.within());
  EXPECT_TRUE(pb.nu.within());  // 0.044
}

// No further packing: an error, not an empty table.
TEST(CalibratePacking, NoRunsIsAnError) {
  EXPECT_THROW(mill::calibrate::packing_spread(result(1, 0.2, 1, 1), 1, {}, 0.1, 0.05),
               std::invalid_argument);
}
