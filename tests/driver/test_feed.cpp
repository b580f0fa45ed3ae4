// The feed section of a case (config/feed.h): optional, read into a typed
// struct, a table scaled to sum to 1, Rosin-Rammler put on the sieves.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "config/case_config.h"
#include "config/feed.h"
#include "postprocess/population_balance.h"

namespace fs = std::filesystem;
using mill::config::case_schema;
using mill::config::Document;
using mill::config::read_feed;

namespace {

const fs::path kProject = MILL_PROJECT_DIR;

Document parse(const std::string& text) { return Document::parse(text, "f.yaml", case_schema()); }

// A case without feed.* keys has no feed, and its canonical inputs (job ids,
// the run folder's inputs id) hold no feed key: existing runs keep their ids.
TEST(Feed, IsOptionalAndAbsentFromTheInputsWithoutOne) {
  for (const char* f : {"cases/reference.yaml"}) {
    const auto c = mill::config::load_case(kProject / f, kProject);
    EXPECT_FALSE(c.feed.has_value()) << f;
    const nlohmann::json inputs = c.doc.to_json();
    for (auto it = inputs.begin(); it != inputs.end(); ++it)
      EXPECT_NE(it.key().rfind("feed.", 0), 0u) << f << ": " << it.key();
  }
}

// The default case carries a feed: three classes around its 40 mm lump, a
// 10 mm grate and a 6 mm P80 target, and its keys are in the inputs.
TEST(Feed, TheDefaultCaseCarriesAFeed) {
  const auto c = mill::config::load_case(kProject / "cases/default.yaml", kProject);
  ASSERT_TRUE(c.feed.has_value());
  EXPECT_EQ(c.feed->sizes_mm.back(), 45.0);
  EXPECT_NEAR(c.feed->mass_fractions.back(), 0.5, 1e-12);
  EXPECT_EQ(c.feed->cut_size_mm, 10.0);
  ASSERT_TRUE(c.feed->target_p80_mm.has_value());
  EXPECT_EQ(*c.feed->target_p80_mm, 6.0);
  EXPECT_TRUE(c.doc.to_json().contains("feed.rate_tph"));
}

// A table whose fractions miss 1 by less than 1e-6 is scaled to sum to 1.
TEST(Feed, TableIsReadAndScaledToSumToOne) {
  const auto f =
      read_feed(parse("name: t\nfeed:\n  sizes_mm: [2, 4, 8, 16, 31.5, 40, 50]\n"
                      "  mass_fractions: [0, 0, 0, 0, 0.3, 0.4, 0.3000005]\n"
                      "  rate_tph: 12.5\n  cut_size_mm: 8\n  target_p80_mm: 4\n"));
  ASSERT_TRUE(f.has_value());
  EXPECT_FALSE(f->rosin_rammler);
  EXPECT_EQ(f->sizes_mm, (std::vector<double>{2, 4, 8, 16, 31.5, 40, 50}));
  ASSERT_EQ(f->mass_fractions.size(), 7u);
  EXPECT_NEAR(std::accumulate(f->mass_fractions.begin(), f->mass_fractions.end(), 0.0), 1.0, 1e-15);
  EXPECT_NEAR(f->mass_fractions[5], 0.4 / 1.0000005, 1e-15);
  EXPECT_EQ(f->rate_tph, 12.5);
  EXPECT_EQ(f->cut_size_mm, 8.0);
  ASSERT_TRUE(f->target_p80_mm.has_value());
  EXPECT_EQ(*f->target_p80_mm, 4.0);
}

// Rosin-Rammler on the sieves: the population balance's discretisation, and
// no target unless given.
TEST(Feed, RosinRammlerIsPutOnTheSieves) {
  const auto f =
      read_feed(parse("name: t\nfeed:\n  sizes_mm: [2, 4, 8, 16, 31.5, 63, 125]\n"
                      "  rosin_rammler: {d63_mm: 30, n: 1.2}\n  rate_tph: 20\n  cut_size_mm: 8\n"));
  ASSERT_TRUE(f.has_value());
  EXPECT_TRUE(f->rosin_rammler);
  EXPECT_EQ(f->mass_fractions, mill::post::RosinRammlerFractions(f->sizes_mm, 30, 1.2));
  EXPECT_NEAR(std::accumulate(f->mass_fractions.begin(), f->mass_fractions.end(), 0.0), 1.0, 1e-15);
  EXPECT_FALSE(f->target_p80_mm.has_value());
}

// A cut at or above the top sieve is an open circuit: allowed (one pass).
TEST(Feed, CutAboveTheTopSieveIsAllowed) {
  const auto f =
      read_feed(parse("name: t\nfeed:\n  sizes_mm: [10, 20, 40]\n  mass_fractions: [0, 0.5, 0.5]\n"
                      "  rate_tph: 20\n  cut_size_mm: 60\n"));
  ASSERT_TRUE(f.has_value());
  EXPECT_EQ(f->cut_size_mm, 60.0);
}

}  // namespace
