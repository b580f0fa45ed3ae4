// The feed section of a case; see feed.h and docs/population_balance.md.
#include "config/feed.h"

#include <fmt/format.h>

#include <cmath>

#include "config/case_config.h"
#include "config/feed_classes.h"
#include "postprocess/breakage_matrix.h"
#include "postprocess/population_balance.h"

namespace mill::config {
namespace {

constexpr const char* kSizes = "feed.sizes_mm";
constexpr const char* kFractions = "feed.mass_fractions";
constexpr const char* kD63 = "feed.rosin_rammler.d63_mm";
constexpr const char* kN = "feed.rosin_rammler.n";
constexpr const char* kRate = "feed.rate_tph";
constexpr const char* kCut = "feed.cut_size_mm";
constexpr const char* kTarget = "feed.target_p80_mm";
constexpr const char* kCap = "feed.class_element_cap";
constexpr const char* kFeedKeys[] = {kSizes, kFractions, kD63, kN, kRate, kCut, kTarget};

[[noreturn]] void fail(const Document& d, const std::string& key, const std::string& msg) {
  throw ConfigError(fmt::format("{}: {}", d.where(key), msg));
}

// The feed key given first in the file: where a message about a missing key
// says the feed is.
std::string first_given(const Document& d) {
  std::string first;
  for (const char* k : kFeedKeys)
    if (d.has(k) && (first.empty() || (d.line(k) > 0 && d.line(k) < d.line(first)))) first = k;
  return first;
}

// A key the feed needs and the file lacks.
void require(const Document& d, const std::string& key, const std::string& anchor) {
  if (d.has(key)) return;
  const int l = d.line(anchor);
  throw ConfigError(
      fmt::format("{}: {}: required with a feed (the case has {}{}); expected {} ({})", d.file(),
                  key, anchor, l > 0 ? fmt::format(" at line {}", l) : "",
                  expected_text(*case_schema().find(key)), case_schema().find(key)->doc));
}

// The fractions of a feed table: one per sieve, summing to 1 within the
// tolerance, then scaled to sum to 1.
std::vector<double> table_fractions(const Document& d, size_t n_sizes) {
  std::vector<double> f = d.reals(kFractions);
  if (f.size() != n_sizes)
    fail(d, kFractions,
         fmt::format("expected {} fractions, one per size of feed.sizes_mm, got {}", n_sizes,
                     f.size()));
  double sum = 0;
  for (double x : f) sum += x;
  if (!(std::abs(sum - 1.0) <= kFeedFractionTolerance))
    fail(d, kFractions,
         fmt::format("expected fractions summing to 1, got {} (within {} of 1 they are "
                     "scaled to sum to 1)",
                     num(sum), num(kFeedFractionTolerance)));
  for (double& x : f) x /= sum;
  return f;
}

// The Rosin-Rammler fractions on the sieves; the top sieve must pass all
// but kFeedTopTail of the feed.
std::vector<double> rosin_rammler_fractions(const Document& d, const std::vector<double>& sizes) {
  const double d63 = d.real(kD63), n = d.real(kN);
  const double tail = post::RosinRammlerRetained(sizes.back(), d63, n);
  if (tail > kFeedTopTail)
    fail(
        d, kSizes,
        fmt::format("the top sieve, {} mm, passes {:.3g}% of the Rosin-Rammler feed "
                    "(d63 {} mm, n {}); expected a top sieve that passes at least {}%: "
                    "add sizes up to {:.3g} mm",
                    num(sizes.back()), 100 * (1 - tail), num(d63), num(n),
                    num(100 * (1 - kFeedTopTail)), d63 * std::pow(-std::log(kFeedTopTail), 1 / n)));
  return post::RosinRammlerFractions(sizes, d63, n);
}

// The feed's one distribution: a table or Rosin-Rammler on the sieves.
std::vector<double> fractions(const Document& d, const std::vector<double>& sizes,
                              const std::string& anchor) {
  const bool table = d.has(kFractions), rr = d.has(kD63) || d.has(kN);
  if (table && rr)
    fail(d, d.has(kD63) ? kD63 : kN,
         fmt::format("the feed's distribution is given twice, also as feed.mass_fractions "
                     "(line {}); expected one of feed.mass_fractions or feed.rosin_rammler: "
                     "remove the other",
                     d.line(kFractions)));
  if (!table && !rr)
    throw ConfigError(
        fmt::format("{}: {}: required with a feed (the case has {}{}), or feed.rosin_rammler: "
                    "{{d63_mm, n}} instead; expected one mass fraction per size of feed.sizes_mm, "
                    "summing to 1",
                    d.file(), kFractions, anchor,
                    d.line(anchor) > 0 ? fmt::format(" at line {}", d.line(anchor)) : ""));
  if (table) return table_fractions(d, sizes.size());
  require(d, kD63, d.has(kD63) ? kD63 : kN);
  require(d, kN, kD63);
  return rosin_rammler_fractions(d, sizes);
}

// The cut and the target against the sieves: something must lie wholly
// below the cut, and the target must be below the cut and readable.
void check_cut_and_target(const Document& d, const Feed& f) {
  const double finest = f.sizes_mm.front();
  if (f.cut_size_mm < finest)
    fail(d, kCut,
         fmt::format("expected a cut at or above the finest sieve, feed.sizes_mm[0] = {} mm "
                     "(below it no size class lies wholly under the cut and nothing could "
                     "leave the mill), got {} mm: add finer sieves to feed.sizes_mm",
                     num(finest), num(f.cut_size_mm)));
  if (!f.target_p80_mm) return;
  const double t = *f.target_p80_mm;
  if (!(t < f.cut_size_mm))
    fail(d, kTarget,
         fmt::format("expected a P80 below feed.cut_size_mm ({} mm): all the product passes "
                     "the cut, so a target at or above it is met at any rotor speed; got {} mm",
                     num(f.cut_size_mm), num(t)));
  if (t < finest)
    fail(d, kTarget,
         fmt::format("expected a P80 at or above the finest sieve, feed.sizes_mm[0] = {} mm "
                     "(a finer P80 cannot be read off the sieves), got {} mm: add finer "
                     "sieves to feed.sizes_mm",
                     num(finest), num(t)));
}

// The fed classes' lumps go through the transport in the run of
// injection.lump_diameter's lumps, the sizes taking turns at the inlet: each
// size enters over m x injection.duration (m sizes), which the run must outlast.
void check_shared_injection(const Document& d, const Feed& f) {
  std::size_t m = 1;
  for (const auto& c : plan_feed_classes(d, f)) m += c.transport ? 1 : 0;
  const double duration = d.real("injection.duration"), t_limit = d.real("injection.time_limit");
  if (m > 1 && !(t_limit > static_cast<double>(m) * duration))
    fail(d, "injection.time_limit",
         fmt::format("expected longer than {} x injection.duration = {} s: with the feed, {} lump "
                     "sizes (injection.lump_diameter and {} fed classes) take turns at the inlet, "
                     "each over {} x {} s; got {} s: raise injection.time_limit or shorten "
                     "injection.duration",
                     m, num(static_cast<double>(m) * duration), m, m - 1, m, num(duration),
                     num(t_limit)));
}

}  // namespace

std::optional<Feed> read_feed(const Document& d) {
  const std::string anchor = first_given(d);
  if (anchor.empty()) {
    if (d.line(kCap) > 0)
      fail(d, kCap,
           "sets the size of a feed class's in-mill lump, and the case has no feed: add "
           "feed.sizes_mm, feed.mass_fractions (or feed.rosin_rammler), feed.rate_tph and "
           "feed.cut_size_mm, or remove feed.class_element_cap");
    return std::nullopt;
  }
  require(d, kSizes, anchor);
  require(d, kRate, anchor);
  require(d, kCut, anchor);

  Feed f;
  f.sizes_mm = d.reals(kSizes);
  for (size_t i = 1; i < f.sizes_mm.size(); ++i)
    if (!(f.sizes_mm[i] > f.sizes_mm[i - 1]))
      throw ConfigError(
          fmt::format("{}[{}]: expected sizes strictly increasing (the sieves, "
                      "finest first), got {} mm after {} mm",
                      d.where(kSizes), i, num(f.sizes_mm[i]), num(f.sizes_mm[i - 1])));
  f.rosin_rammler = !d.has(kFractions);
  f.mass_fractions = fractions(d, f.sizes_mm, anchor);
  f.rate_tph = d.real(kRate);
  f.cut_size_mm = d.real(kCut);
  if (d.has(kTarget)) f.target_p80_mm = d.real(kTarget);
  check_cut_and_target(d, f);
  if (d.integer("breakage.in_mill.lumps") > 0) lump_feed_class(d, f);
  check_shared_injection(d, f);
  return f;
}

std::size_t lump_feed_class(const Document& d, const Feed& f) {
  const post::SizeClasses c = post::SizeClassesFromSieves(f.sizes_mm);
  const double lump_mm = 1000 * d.real("lump.diameter");
  const std::size_t j = post::ClassOfSize(c, lump_mm);
  if (j == c.size())
    fail(d, "lump.diameter",
         fmt::format("{:g} mm is at or above the top sieve of feed.sizes_mm ({:g} mm); the in-mill "
                     "lumps (breakage.in_mill.lumps) measure the breakage of their feed class: add "
                     "a coarser sieve to feed.sizes_mm, or make the lump smaller",
                     lump_mm, c.upper_mm.front()));
  if (j + 1 == c.size())
    fail(d, "lump.diameter",
         fmt::format("{:g} mm lies in the finest class of feed.sizes_mm (below {:g} mm), whose "
                     "breakage no sieve sees; expected a lump of a coarser feed class: make the "
                     "lump larger, or add finer sieves to feed.sizes_mm",
                     lump_mm, c.upper_mm.back()));
  return j;
}

}  // namespace mill::config
