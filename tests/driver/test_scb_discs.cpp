// The semi-circular bend test over several half discs (LabBench::scb,
// calibrate.scb_orientations): the mean K_IC, its standard error and the
// summary line, on hand-made discs (no engine).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "stages/calibrate/lab_runs.h"

using namespace mill::calibrate;

namespace {

ScbDisc disc(double kic, double force, double seconds, bool peaked) {
  ScbDisc d;
  d.r.toughness = kic;
  d.r.peak_force = force;
  d.seconds = seconds;
  d.peaked = peaked;
  return d;
}

}  // namespace

// Three discs 0.3, 0.4, 0.5 MPa m^0.5: mean 0.4, sample standard deviation
// 0.1, standard error 0.1 / sqrt(3) (to 1e-12 relative).
TEST(ScbDiscs, MeanAndStandardErrorOfThreeDiscs) {
  const ScbRun s =
      ScbRun::of({disc(0.3e6, 100, 2, true), disc(0.4e6, 130, 3, true), disc(0.5e6, 160, 1, true)});
  EXPECT_NEAR(s.toughness, 0.4e6, 1e-12 * 0.4e6);
  EXPECT_NEAR(s.toughness_sem, 0.1e6 / std::sqrt(3.0), 1e-12 * 0.1e6);
  EXPECT_NEAR(s.peak_force, 130, 1e-12 * 130);
  EXPECT_DOUBLE_EQ(s.seconds, 6);
  EXPECT_TRUE(s.peaked);
  EXPECT_EQ(s.summary(), "0.400 MPa m^0.5 +- 0.058 (0.300-0.500 over 3 half discs)");
}

// One disc: its own K_IC, no standard error; one disc at its cap marks the test.
TEST(ScbDiscs, OneDiscHasNoErrorAndACappedDiscMarksTheTest) {
  const ScbRun one = ScbRun::of({disc(0.7e6, 90, 2, true)});
  EXPECT_DOUBLE_EQ(one.toughness, 0.7e6);
  EXPECT_DOUBLE_EQ(one.toughness_sem, 0.0);
  EXPECT_EQ(one.summary(), "0.700 MPa m^0.5 (one half disc)");
  EXPECT_FALSE(ScbRun::of({disc(0.7e6, 90, 2, true), disc(0.6e6, 80, 2, false)}).peaked);
  EXPECT_THROW(ScbRun::of({}), std::logic_error);
}

// A half disc with no element under its load point (or over a support) is
// named, with the file, the layer and calibrate.n_elements; one with both is
// accepted.
TEST(ScbDiscs, TooCoarseHalfDiscIsNamed) {
  const std::map<std::string, double> ok = {
      {"atoms", 120}, {"load_layer", 1}, {"support_layer", 3}};
  EXPECT_NO_THROW(check_scb_layers(ok, "runs/scb/scb_info.txt"));
  for (const char* layer : {"load_layer", "support_layer"}) {
    auto bad = ok;
    bad[layer] = 0;
    try {
      check_scb_layers(bad, "runs/scb_o3/scb_info.txt");
      FAIL() << layer << ": accepted";
    } catch (const ScbTooCoarse& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("runs/scb_o3/scb_info.txt"), std::string::npos) << m;
      EXPECT_NE(m.find(std::string("no element in its ") + layer), std::string::npos) << m;
      EXPECT_NE(m.find("calibrate.n_elements"), std::string::npos) << m;
    }
  }
}
