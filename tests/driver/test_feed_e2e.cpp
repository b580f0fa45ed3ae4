// A case with a feed end to end on the tiny mill: one 40-element lump per
// rotor speed struck in the turning mill (stage 1's strike written by hand),
// then the feed's population balance: the breakage matrix of the lump's
// class measured from the run's pieces, the coarser feed class scaled.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "e2e_util.h"
#include "postprocess/breakage_results.h"

namespace fs = std::filesystem;

namespace {

using namespace mill::e2e;
using nlohmann::json;

const std::string kData = MILL_TEST_DATA;
const std::vector<double> kRpm = {2000, 2500};

// Per rotor speed, one lump falling at 5 m/s onto plate 0's leading face,
// which points up at t = (pi/2) / omega (as in test_in_mill_e2e.cpp).
void write_transport_impacts(const fs::path& run) {
  for (double rpm : kRpm) {
    const fs::path d = run / fmt::format("transport/rpm{:g}", rpm);
    fs::create_directories(d);
    const double t = 0.5 * M_PI / (rpm * 2 * M_PI / 60);
    spit(d / "impacts.csv",
         std::string(kImpactsCsvHeader) + tiny_strike_row(rpm, 1, t, {-0.021, 0.62, 0}, {0, -5, 0},
                                                          {-0.01, 0.62, 0}, {-1, 0, 0}));
  }
}

class Feed : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(scratch("feed"));
    write_transport_impacts(*dir_);
    status_ = orchestrate(
        "--case " + kData + "/tiny_feed.yaml --stage breakage --output " + dir_->string(),
        *dir_ / "breakage.log");
  }
  static void TearDownTestSuite() { delete dir_; }
  static fs::path* dir_;
  static int status_;
  fs::path stage() const { return *dir_ / "breakage"; }
  json read(const std::string& f) const { return json::parse(slurp(stage() / f)); }
};
fs::path* Feed::dir_ = nullptr;
int Feed::status_ = -1;

TEST_F(Feed, BreakageMatrixPerRotorSpeedFromTheInMillPieces) {
  ASSERT_EQ(status_, 0) << slurp(*dir_ / "breakage.log");
  const json m = read("breakage_matrix.json");
  // Sieves 2 .. 31.5 mm: 8 classes, coarsest first; the 20 mm lump is in
  // class 1 (16-22.4 mm).
  ASSERT_EQ(m.at("classes").size(), 8u);
  ASSERT_EQ(m.at("rotor_speeds").size(), kRpm.size());
  for (const auto& s : m.at("rotor_speeds")) {
    const auto b = s.at("matrix").get<std::vector<std::vector<double>>>();
    const auto& cols = s.at("columns");
    EXPECT_EQ(cols[1].at("origin"), "measured") << s.dump();
    EXPECT_EQ(cols[1].at("lumps").get<int>(), 1);
    EXPECT_EQ(cols[0].at("origin"), "scaled");
    EXPECT_EQ(cols[0].at("scaled_from_class").get<int>(), 1);
    EXPECT_EQ(cols[7].at("origin"), "finest");
    for (size_t j = 0; j < 8; ++j) {
      double sum = 0;
      for (size_t i = 0; i < 8; ++i) {
        if (i < j) {
          EXPECT_EQ(b[i][j], 0.0);
        }
        EXPECT_GE(b[i][j], 0.0);
        sum += b[i][j];
      }
      EXPECT_NEAR(sum, 1.0, 1e-12) << "column " << j;
    }
    // The measured column is the run's pieces binned by size: recomputed
    // here from its impact.h5 (d/D x 20 mm) on the sieves.
    const fs::path job = stage() / fmt::format("jobs/rpm{:g}_mill_p1", s.at("rpm").get<double>());
    const auto p = mill::post::ReadImpactPieces((job / "impact.h5").string());
    const std::vector<double> upper = {31.5, 22.4, 16, 11.2, 8, 5.6, 4, 2};
    std::vector<double> want(8, 0.0);
    double total = 0;
    for (size_t k = 0; k < p.mass_kg.size(); ++k) {
      const double x = 20 * p.d_rel[k];
      size_t i = 1;  // nothing coarser than the lump's class
      while (i + 1 < 8 && x < upper[i + 1]) ++i;
      want[i] += p.mass_kg[k];
      total += p.mass_kg[k];
    }
    for (size_t i = 0; i < 8; ++i) EXPECT_NEAR(b[i][1], want[i] / total, 1e-12) << i;
    // The struck lump broke: not all of it stayed in its class.
    EXPECT_LT(b[1][1], 1.0) << s.dump();
  }
  EXPECT_NE(slurp(stage() / "breakage_matrix.csv").find("rpm,from_class,from_upper_mm"),
            std::string::npos);
}

}  // namespace
