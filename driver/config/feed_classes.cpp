// The runs of a feed's size classes; see feed_classes.h and
// docs/population_balance.md, "Runs per size class".
#include "config/feed_classes.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "config/case_config.h"
#include "lump/packing.h"
#include "postprocess/population_balance.h"

namespace mill::config {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Why a lump of diameter dm (m) cannot go through the transport, or "".
std::string transport_refusal(const Document& d, double dm) {
  const KeyDef* k = case_schema().find("injection.lump_diameter");
  if (k->plausible && (dm < k->plausible->lo || dm > k->plausible->hi))
    return fmt::format(
        "its representative size, {:.4g} mm, lies outside the lumps the transport takes "
        "(injection.lump_diameter in [{:g}, {:g}] m)",
        1e3 * dm, k->plausible->lo, k->plausible->hi);
  const double D = d.real("mill.flywheel.diameter"), hub = d.real("mill.flywheel.hub_diameter");
  const double plate = (D - hub) / 2;
  if (dm >= plate)
    return fmt::format(
        "its representative size, {:.4g} mm, is not smaller than the beater plates ({:g} m "
        "from hub to tip)",
        1e3 * dm, plate);
  if (dm >= d.real("mill.inlet.size"))
    return fmt::format(
        "its representative size, {:.4g} mm, does not pass the inlet "
        "(mill.inlet.size {:g} m)",
        1e3 * dm, d.real("mill.inlet.size"));
  double tip_max = 0;
  for (double rpm : d.reals("rotor.rpm")) tip_max = std::max(tip_max, kPi * D * rpm / 60.0);
  const double dt = d.real("injection.timestep");
  if (tip_max * dt > kMaxLumpStepMove * dm / 2)
    return fmt::format(
        "at the tip speed {:.0f} m/s its {:.4g} mm lump moves more than {:g} of its radius per "
        "step of injection.timestep {:g} s: a step of at most {:.3g} s would run it",
        tip_max, 1e3 * dm, kMaxLumpStepMove, dt, kMaxLumpStepMove * dm / 2 / tip_max);
  return "";
}

}  // namespace

std::vector<FeedClassRuns> plan_feed_classes(const Document& d, const Feed& f) {
  const post::SizeClasses c = post::SizeClassesFromSieves(f.sizes_mm);
  const std::size_t n = c.size();
  const long k_lumps = d.integer("breakage.in_mill.lumps");
  const long n_ref = d.integer("lump.n_elements");
  const double spread = d.real("lump.radius_spread");
  // The calibration's element size: the mean element radius of lump.diameter's lump.
  const double r_cal = target_mean_radius(n_ref, d.real("lump.diameter"), spread);
  const long cap = d.has("feed.class_element_cap") ? d.integer("feed.class_element_cap") * n_ref
                                                   : std::numeric_limits<long>::max();
  std::vector<FeedClassRuns> out;
  for (std::size_t i = 0; i < n; ++i) {
    FeedClassRuns r;
    r.cls = i;
    r.name = c.name(i);
    r.mass_fraction = f.mass_fractions[n - 1 - i];  // the file lists the finest first
    r.diameter_m = 1e-3 * post::RepresentativeSize(c, i);
    if (r.mass_fraction < kFeedClassMinFraction) {
      r.without_runs = fmt::format("{:.3g}% of the feed, below the {:g}% that gets runs",
                                   100 * r.mass_fraction, 100 * kFeedClassMinFraction);
    } else if (std::string why = transport_refusal(d, r.diameter_m); !why.empty()) {
      r.without_runs = why;
    } else {
      r.transport = true;
      if (k_lumps <= 0)
        r.without_runs = "no in-mill runs (breakage.in_mill.lumps 0)";
      else if (i + 1 == n)
        r.without_runs = "the finest class: no sieve sees its breakage";
      else
        r.in_mill = true;
    }
    if (r.in_mill) {
      r.n_elements = std::clamp(elements_for_radius(r_cal, r.diameter_m, spread), kMinLumpElements, cap);
      r.element_size = target_mean_radius(r.n_elements, r.diameter_m, spread) / r_cal;
    }
    out.push_back(r);
  }
  return out;
}

}  // namespace mill::config
