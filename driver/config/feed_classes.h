// The runs of a feed's size classes (docs/population_balance.md, "Runs per
// size class"): which classes of feed.sizes_mm get a transport run (stage 1)
// of their own and in-mill breakage runs of their own, the diameter of their
// lumps (the class's representative size) and the element count of their
// bonded lump (the calibration's element size unless the case caps it). A class
// without runs says why; its breakage column is then scaled from a measured
// one. Planned from the case alone: the transport and breakage stages both
// call it and get the same classes.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "config/feed.h"

namespace mill::config {

class Document;

// A class with less than this share of the feed has no runs of its own
// (a table's zeros; a Rosin-Rammler feed's far tails).
inline constexpr double kFeedClassMinFraction = 1e-3;
// A class lump of more than this many times lump.n_elements (a class of
// about twice lump.diameter) names feed.class_element_cap in its plan line:
// its runs cost that many times lump.diameter's.
inline constexpr long kCostlyClassLumpFactor = 8;

struct FeedClassRuns {
  std::size_t cls = 0;       // class index, coarsest first (post::SizeClassesFromSieves)
  std::string name;          // "16-22.4 mm"
  double mass_fraction = 0;  // of the feed
  double diameter_m = 0;     // its lumps' diameter: post::RepresentativeSize, m
  bool transport = false;    // a stage-1 run of its own (transport/class_<k>/<rpm>/)
  bool in_mill = false;      // in-mill runs of its own (breakage.in_mill.lumps of them)
  long n_elements = 0;       // elements of its bonded lump (when in_mill)
  double element_size = 1;   // its mean element radius / the calibration's (1 to the count's rounding, unless capped)
  std::string without_runs;  // why it has no transport run, or no in-mill runs ("" if both)
};

// Every class of the feed, coarsest first, with its runs:
// - a transport run when its share of the feed is at least
//   kFeedClassMinFraction and its representative size is a lump the
//   transport accepts: in the plausible range of injection.lump_diameter,
//   smaller than the beater plates and the inlet, and large enough that
//   injection.timestep moves it at most kMaxLumpStepMove of its radius per
//   step at the fastest tip speed;
// - in-mill runs when it has a transport run, breakage.in_mill.lumps > 0 and
//   it is not the finest class (whose breakage no sieve sees);
// - the in-mill lump's elements: the count whose mean element radius
//   (target_mean_radius) is that of lump.diameter's lump, for which the
//   calibration was made (elements_for_radius), at least kMinLumpElements
//   and, when the case sets feed.class_element_cap, at most that many
//   times lump.n_elements (coarser elements than the calibration's, which
//   bias the class's breakage: bench/README.md, "A class lump at the
//   element cap"); no cap otherwise.
std::vector<FeedClassRuns> plan_feed_classes(const Document& d, const Feed& f);

}  // namespace mill::config
