// The runs of a feed's size classes (config/feed_classes.h): which classes
// get a transport run and in-mill runs of their own, their lumps' diameter
// and element count, and why the others have none; on hand-made feeds.
#include <gtest/gtest.h>

#include <cmath>

#include "config/case_config.h"
#include "config/feed_classes.h"
#include "lump/packing.h"
#include "stages/breakage/circuit.h"

using mill::config::case_schema;
using mill::config::Document;
using mill::config::FeedClassRuns;
using mill::config::plan_feed_classes;
using mill::config::read_feed;

namespace {

Document parse(const std::string& text) { return Document::parse(text, "f.yaml", case_schema()); }

std::vector<FeedClassRuns> plan(const std::string& text) {
  const Document d = parse(text);
  return plan_feed_classes(d, read_feed(d).value());
}

// Six classes on the default mill (1 m flywheel, 0.3 m hub and inlet, 2000
// rpm, 5e-6 s transport step): 31.5-63, 16-31.5, 8-16, 4-8, 2-4 and the pan
// (below 2 mm); the 4-8 mm class has no feed.
const std::string kSixClasses =
    "name: t\n"
    "lump: {n_elements: 3344, diameter: 0.04}\n"
    "breakage: {conditions: transport, in_mill: {lumps: 4}}\n"
    "feed:\n"
    "  sizes_mm: [2, 4, 8, 16, 31.5, 63]\n"
    "  mass_fractions: [0.05, 0.05, 0, 0.3, 0.5, 0.1]\n"
    "  rate_tph: 20\n"
    "  cut_size_mm: 8\n";

TEST(FeedClasses, RunsForEveryFedClassThatTheTransportTakes) {
  const auto p = plan(kSixClasses);
  ASSERT_EQ(p.size(), 6u);
  const std::vector<double> upper = {63, 31.5, 16, 8, 4, 2};
  const std::vector<double> fraction = {0.1, 0.5, 0.3, 0, 0.05, 0.05};
  for (size_t i = 0; i < p.size(); ++i) {
    EXPECT_EQ(p[i].cls, i);
    EXPECT_NEAR(p[i].mass_fraction, fraction[i], 1e-15) << i;
    // The representative size: the geometric mean of the edges; the pan's
    // lower edge continues the series of the two finest sieves (1 mm).
    const double lower = i + 1 < p.size() ? upper[i + 1] : 1.0;
    EXPECT_NEAR(p[i].diameter_m, 1e-3 * std::sqrt(upper[i] * lower), 1e-15) << i;
  }
  // 31.5-63, 16-31.5 and 8-16 mm: transport and in-mill runs.
  for (size_t i : {0u, 1u, 2u}) {
    EXPECT_TRUE(p[i].transport) << i;
    EXPECT_TRUE(p[i].in_mill) << i;
    EXPECT_EQ(p[i].without_runs, "") << i;
  }
  // 4-8 mm: no feed.
  EXPECT_FALSE(p[3].transport);
  EXPECT_FALSE(p[3].in_mill);
  EXPECT_NE(p[3].without_runs.find("0% of the feed"), std::string::npos) << p[3].without_runs;
  // 2-4 mm (2.83 mm): at 105 m/s a step of 5e-6 s moves it more than a
  // quarter of its radius; the message names the key and the step that would do.
  EXPECT_FALSE(p[4].transport);
  EXPECT_NE(p[4].without_runs.find("injection.timestep"), std::string::npos) << p[4].without_runs;
  EXPECT_NE(p[4].without_runs.find("3.38e-06"), std::string::npos) << p[4].without_runs;
  // The pan (1.41 mm): below the smallest lump the transport takes.
  EXPECT_FALSE(p[5].transport);
  EXPECT_NE(p[5].without_runs.find("injection.lump_diameter in [0.002, 0.5] m"), std::string::npos)
      << p[5].without_runs;
}

TEST(FeedClasses, ElementCountKeepsTheCalibratedElementSize) {
  const auto p = plan(kSixClasses);
  // The count whose mean element radius is that of lump.diameter's lump
  // (3344 elements of 40 mm): within half a count's step of it, and more
  // than the cube rule 3344 (d / 40 mm)^3 gives for the coarser 44.5 mm
  // class (4619), fewer for the finer 22.3 mm one (579: the solid fraction
  // rises with the count).
  const double r_cal = mill::target_mean_radius(3344, 0.04, 0.25);
  for (size_t i : {0u, 1u}) {
    const double d = p[i].diameter_m;
    const long n = p[i].n_elements;
    const double r = mill::target_mean_radius(n, d, 0.25);
    EXPECT_NEAR(p[i].element_size, r / r_cal, 1e-15) << i;
    EXPECT_LE(std::abs(r - r_cal), std::abs(mill::target_mean_radius(n + 1, d, 0.25) - r_cal)) << i;
    EXPECT_LE(std::abs(r - r_cal), std::abs(mill::target_mean_radius(n - 1, d, 0.25) - r_cal)) << i;
    EXPECT_NEAR(p[i].element_size, 1.0, 2e-3) << i;  // rounding of the count only
  }
  EXPECT_GT(p[0].n_elements, 4619);
  EXPECT_LT(p[1].n_elements, 579);
  // The 11.3 mm class: the calibration's elements would fill it with fewer
  // than 15, where the packing rule's radius stops falling with the count;
  // it gets 15, a little finer than the calibration's.
  EXPECT_EQ(p[2].n_elements, 15);
  EXPECT_LT(p[2].element_size, 1.0);
  EXPECT_GT(p[2].element_size, 0.9);
}

TEST(FeedClasses, ElementCountIsCappedOnlyWhenTheCaseAsksAndFloored) {
  // A 10 mm, 100-element lump: the 44.5 mm class keeps the calibration's
  // element size with about 10 000 elements (no cap by default) ...
  auto text = kSixClasses;
  text.replace(text.find("{n_elements: 3344, diameter: 0.04}"), 34,
               "{n_elements: 100, diameter: 0.01}");
  auto p = plan(text);
  EXPECT_GT(p[0].n_elements, 9000);
  EXPECT_LT(p[0].n_elements, 20000);
  EXPECT_NEAR(p[0].element_size, 1.0, 1e-3);
  // ... and with feed.class_element_cap 8 it gets 8 x 100 and elements that
  // many times the calibration's: the ratio of the two lumps' mean radii.
  text += "  class_element_cap: 8\n";
  p = plan(text);
  EXPECT_EQ(p[0].n_elements, 800);
  EXPECT_NEAR(p[0].element_size,
              mill::target_mean_radius(800, p[0].diameter_m, 0.25) / mill::target_mean_radius(100, 0.01, 0.25),
              1e-12);
  EXPECT_GT(p[0].element_size, 2.0);
  // A 20-element lump of 40 mm: the 11.3 mm class gets the fewest the
  // packing rule gives (15), much finer elements than the calibration's.
  text = kSixClasses;
  text.replace(text.find("n_elements: 3344"), 16, "n_elements: 20");
  p = plan(text);
  EXPECT_EQ(p[2].n_elements, 15);
  EXPECT_LT(p[2].element_size, 0.5);
}

TEST(FeedClasses, WithoutInMillLumpsOnlyTheTransportRuns) {
  auto text = kSixClasses;
  text.replace(text.find("in_mill: {lumps: 4}"), 19, "in_mill: {lumps: 0}");
  const auto p = plan(text);
  for (size_t i : {0u, 1u, 2u}) {
    EXPECT_TRUE(p[i].transport) << i;
    EXPECT_FALSE(p[i].in_mill) << i;
    EXPECT_NE(p[i].without_runs.find("breakage.in_mill.lumps"), std::string::npos);
  }
}

TEST(FeedClasses, TheFinestClassIsTransportedButNotBroken) {
  // 0-8 mm (the pan, 5.66 mm) is fed and the transport takes it; no sieve
  // sees its breakage, so it has no in-mill runs.
  const auto p = plan(
      "name: t\nlump: {diameter: 0.02}\nbreakage: {conditions: transport, in_mill: {lumps: 2}}\n"
      "feed: {sizes_mm: [8, 16, 31.5], mass_fractions: [0.2, 0.3, 0.5], rate_tph: 5, "
      "cut_size_mm: 8}\n");
  ASSERT_EQ(p.size(), 3u);
  EXPECT_TRUE(p[2].transport);
  EXPECT_FALSE(p[2].in_mill);
  EXPECT_NE(p[2].without_runs.find("the finest class"), std::string::npos);
  EXPECT_TRUE(p[0].in_mill);
  EXPECT_TRUE(p[1].in_mill);
}

// The tiny mill of the e2e tests (0.5 m flywheel, 0.15 m hub: 0.175 m
// plates, 0.15 m inlet) refuses a class whose lumps would not pass its inlet.
TEST(FeedClasses, ALumpThatDoesNotPassTheInletHasNoRuns) {
  const auto p = plan(
      "name: t\n"
      "mill: {housing: {height: 1.2, width: 0.8, depth: 0.3}, flywheel: {diameter: 0.5, "
      "hub_diameter: 0.15, n_plates: 4, plate_width: 0.2, plate_thickness: 0.02, axis_height: "
      "0.45}, inlet: {center_x: -0.15, size: 0.15}, outlet: {center_x: 0.0, size: 0.3}}\n"
      "lump: {diameter: 0.02}\nbreakage: {conditions: transport, in_mill: {lumps: 1}}\n"
      "feed: {sizes_mm: [8, 16, 31.5, 125, 200], mass_fractions: [0, 0.5, 0.3, 0, 0.2], "
      "rate_tph: 5, cut_size_mm: 8}\n");
  ASSERT_EQ(p.size(), 5u);
  EXPECT_FALSE(p[0].transport);  // 125-200 mm: 158 mm, wider than the 0.15 m inlet
  EXPECT_NE(p[0].without_runs.find("mill.inlet.size"), std::string::npos) << p[0].without_runs;
  EXPECT_TRUE(p[2].in_mill);  // 16-31.5 mm
  EXPECT_TRUE(p[3].in_mill);  // 8-16 mm
}

}  // namespace

// The element pieces of a lump (stages/breakage/circuit.h): a piece of one
// element of mass share m/M takes lump_mm x (m/M)^(1/3); the radius classes
// r (1 + 0.25 {-1, ..., 1}) have mass shares (1 + s)^3 / (c n), c the mean
// of the cubes (1.09375 at spread 0.25, by hand: (0.421875 + 0.669921875 +
// 1 + 1.423828125 + 1.953125) / 5), and the mean-mass piece is lump_mm / n^(1/3).
TEST(ElementPieces, OneElementsPieceSizesByHand) {
  const double c = (0.421875 + 0.669921875 + 1 + 1.423828125 + 1.953125) / 5;
  EXPECT_DOUBLE_EQ(c, 1.09375);
  const auto e = mill::breakage::element_piece_mm(53.24, 5134, 0.25);
  EXPECT_NEAR(e.mean_mm, 53.24 / std::cbrt(5134.0), 1e-12);
  EXPECT_NEAR(e.smallest_mm, 53.24 * std::cbrt(0.421875 / (c * 5134)), 1e-12);
  EXPECT_NEAR(e.largest_mm, 53.24 * std::cbrt(1.953125 / (c * 5134)), 1e-12);
  // The bench's two lumps (bench/README.md, "A class lump at the element
  // cap"): the mean pieces 3.08 and 4.94 mm, 1.60 x apart for 4.1 x the
  // elements.
  EXPECT_NEAR(e.mean_mm, 3.08, 0.01);
  EXPECT_NEAR(mill::breakage::element_piece_mm(53.24, 1248, 0.25).mean_mm, 4.94, 0.01);
  // Without spread every piece is the mean one.
  const auto u = mill::breakage::element_piece_mm(40, 2000, 0);
  EXPECT_DOUBLE_EQ(u.smallest_mm, u.largest_mm);
  EXPECT_NEAR(u.mean_mm, 40 / std::cbrt(2000.0), 1e-12);
}
