// The feed of a case (section feed:, optional): its size distribution over
// the sieves of the population balance, its rate, the mill's cut and the P80
// wanted (docs/population_balance.md, "The feed in the case"). Read from a
// validated case document; the rules the schema cannot state key by key
// (one distribution, matching lengths, fractions summing to 1, the cut and
// the target against the sieves) are checked here, when the case is loaded.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

namespace mill::config {

class Document;

struct Feed {
  std::vector<double> sizes_mm;         // feed.sizes_mm: the sieves, ascending, as in the file
  std::vector<double> mass_fractions;   // per class of sizes_mm, same order, summing to 1
  bool rosin_rammler = false;           // fractions from feed.rosin_rammler, not a table
  double rate_tph = 0;                  // feed.rate_tph: fresh feed, t/h
  double cut_size_mm = 0;               // feed.cut_size_mm: outlet grate or classifier aperture
  std::optional<double> target_p80_mm;  // feed.target_p80_mm
};

// Fractions of a feed table may miss 1 by this much (typed decimals); they
// are then scaled to sum to 1.
inline constexpr double kFeedFractionTolerance = 1e-6;
// Rosin-Rammler: the tail above the top sieve that the top class may take.
inline constexpr double kFeedTopTail = 0.01;

// The case's feed; nullopt when the case has no feed.* key (one lump size,
// as without a feed). Throws ConfigError naming the file, line and key, the
// value found and what is expected.
std::optional<Feed> read_feed(const Document& d);

// The class of feed.sizes_mm (coarsest first, as the population balance
// numbers them) that the in-mill lumps (lump.diameter) belong to: their runs
// make its column of the breakage matrix. Throws ConfigError naming
// lump.diameter when the lump lies at or above the top sieve or in the
// finest class (no sieve would see its breakage). Checked by read_feed when
// breakage.in_mill.lumps > 0.
std::size_t lump_feed_class(const Document& d, const Feed& f);

}  // namespace mill::config
