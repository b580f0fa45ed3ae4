// The packing check: the result's spread over further specimen packings.
#include "stages/calibrate/packing_check.h"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

#include "stages/calibrate/energy_report.h"
#include "stages/calibrate/specimen.h"
#include "stages/stage_util.h"

namespace mill::calibrate {

namespace {

// Mean and spread of `v` (relative to the mean, or absolute).
PackingProperty property(std::vector<double> v, double limit, bool absolute) {
  PackingProperty p;
  p.values = std::move(v);
  p.limit = limit;
  double sum = 0;
  for (double x : p.values) sum += x;
  p.mean = sum / static_cast<double>(p.values.size());
  const auto [lo, hi] = std::minmax_element(p.values.begin(), p.values.end());
  const double range = *hi - *lo;
  p.spread = absolute ? range : (p.mean != 0 ? range / std::abs(p.mean) : 0.0);
  return p;
}

// The rows of the table and of the warning: name, unit scale, unit, property.
struct Row {
  const char* name;
  const char* json;  // its key in report.json
  double scale;
  const char* unit;
  const PackingProperty* p;
  bool absolute;
};

std::vector<Row> rows(const PackingSpread& s) {
  return {{"E", "youngs_modulus", 1e-9, "GPa", &s.E, false},
          {"nu", "poisson_ratio", 1.0, "", &s.nu, true},
          {"UCS", "ucs", 1e-6, "MPa", &s.ucs, false},
          {"tensile", "tensile_strength", 1e-6, "MPa", &s.tensile, false}};
}

std::string spread_text(const Row& r) {
  return r.absolute ? fmt::format("{:.3f}", r.p->spread) : fmt::format("{:.1f}%", 100 * r.p->spread);
}
std::string limit_text(const Row& r) {
  return r.absolute ? fmt::format("{:.2f}", r.p->limit) : fmt::format("{:.0f}%", 100 * r.p->limit);
}

}  // namespace

std::vector<PackingRun> run_packings(StageContext& ctx, const std::string& job_label,
                                     const std::filesystem::path& dir, long n, int first,
                                     int packings, const BondParams& p, const Targets& t,
                                     double rate, int lanes, double done, double step_share) {
  std::vector<PackingRun> runs;
  for (int k = 1; k <= packings; ++k) {
    PackingRun r;
    const Specimen sp = pack_specimen(ctx, job_label, dir, n, first + k - 1);
    r.seed = sp.seed;
    LabBench lab(ctx, job_label, dir, sp, t);
    lab.set_lanes(lanes);
    const double at = done + 2.0 * (k - 1) * step_share;
    const std::string of = fmt::format("packing check {}/{}", k, packings);
    // The fit's tests: UCS and its tensile test (calibrate.tensile_test).
    run_concurrently(
        {[&] {
           r.ucs = lab.ucs(p, rate,
                           {fmt::format("packing{}_ucs", k),
                            fmt::format("{}: UCS (seed {})", of, r.seed), at});
         },
         [&] {
           if (t.direct)
             r.tension = lab.tension(
                 p, rate,
                 {fmt::format("packing{}_tension", k),
                  fmt::format("{}: direct tension (seed {})", of, r.seed), at + step_share});
           else
             r.br = lab.brazilian(
                 p, rate,
                 {fmt::format("packing{}_brazilian", k),
                  fmt::format("{}: Brazilian (seed {})", of, r.seed), at + step_share});
         }},
        lab.lanes());
    runs.push_back(std::move(r));
  }
  return runs;
}

PackingSpread packing_spread(const Iteration& best, long seed, const std::vector<PackingRun>& runs,
                             double tol, double nu_tol) {
  if (runs.empty() && best.more.empty())
    throw std::invalid_argument("packing check: one packing only, nothing to compare");
  PackingSpread s;
  s.seeds.push_back(seed);
  s.fit_packings = 1 + best.more.size();
  // The tensile strength of the fit's test: the direct tension test's when
  // it ran (calibrate.tensile_test direct), else the Brazilian disc's.
  auto tensile = [](const BrazilianRun& br, const std::optional<UcsRun>& tension) {
    return tension ? tension->r.ucs : br.r.tensile_strength;
  };
  std::vector<double> e{best.ucs.r.youngs_modulus}, nu{best.ucs.r.poisson_ratio},
      ucs{best.ucs.r.ucs}, t{tensile(best.br, best.tension)};
  // The fit's further packings, then the check's (no copies of their curves).
  for (const std::vector<PackingRun>* group : {&best.more, &runs})
    for (const PackingRun& r : *group) {
      s.seeds.push_back(r.seed);
      e.push_back(r.ucs.r.youngs_modulus);
      nu.push_back(r.ucs.r.poisson_ratio);
      ucs.push_back(r.ucs.r.ucs);
      t.push_back(tensile(r.br, r.tension));
    }
  s.E = property(std::move(e), tol, false);
  s.nu = property(std::move(nu), nu_tol, true);
  s.ucs = property(std::move(ucs), tol, false);
  s.tensile = property(std::move(t), tol, false);
  return s;
}

nlohmann::json packing_run_json(long seed, const UcsRun& ucs, const BrazilianRun& br,
                                const std::optional<UcsRun>& tension) {
  nlohmann::json j = {
      {"seed", seed},
      {"youngs_modulus", ucs.r.youngs_modulus},
      {"poisson_ratio", ucs.r.poisson_ratio},
      {"ucs", ucs.r.ucs},
      {"tensile_strength", br.r.tensile_strength},
      {"ucs_run", ucs.tag},
      {"brazilian_run", br.tag},
      {"energy",
       {{"ucs", lab_energy_json(ucs.energy)}, {"brazilian", lab_energy_json(br.energy)}}}};
  if (tension) {  // calibrate.tensile_test direct: the fit's tensile strength
    j["direct_tensile_strength"] = tension->r.ucs;
    j["tension_run"] = tension->tag;
    j["energy"]["tension"] = lab_energy_json(tension->energy);
    if (br.tag.empty()) {  // the discs ran on the kept parameters only
      j["tensile_strength"] = nullptr;
      j["brazilian_run"] = nullptr;
      j["energy"].erase("brazilian");
    }
  }
  return j;
}

nlohmann::json packing_json(const PackingSpread& s, const std::vector<PackingRun>& runs) {
  nlohmann::json j = {
      {"seeds", s.seeds}, {"fit_packings", s.fit_packings}, {"within_tolerance", s.within()}};
  for (const Row& r : rows(s))
    j[r.json] = {{"values", r.p->values},       {"mean", r.p->mean},
                 {"spread", r.p->spread},       {"spread_is_absolute", r.absolute},
                 {"limit", r.p->limit},         {"within", r.p->within()}};
  double seconds = 0;
  nlohmann::json each = nlohmann::json::array();
  for (const PackingRun& r : runs) {
    seconds += r.ucs.seconds + r.br.seconds + (r.tension ? r.tension->seconds : 0.0);
    each.push_back(packing_run_json(r.seed, r.ucs, r.br, r.tension));
  }
  j["wall_seconds"] = seconds;
  j["runs"] = each;
  return j;
}

std::string packing_markdown(const PackingSpread& s) {
  std::string md = "\n## Packing check\n\n";
  const size_t further = s.seeds.size() - s.fit_packings;
  md += fmt::format(
      "The result's bond parameters on {} further specimen packings (calibrate.packing_check){}, "
      "each carved from its own ball and named by the first seed of its packing (the fit's "
      "first follows calibrate.seed): the spread is the range over the {} packings (relative to "
      "their mean; nu absolute), against the fit's tolerance.\n\n",
      further,
      s.fit_packings > 1 ? fmt::format(" and the fit's own {} (calibrate.fit_packings: it aims "
                                       "their means at the card)",
                                       s.fit_packings)
                         : std::string(),
      s.seeds.size());
  md += "| property | ";
  for (size_t k = 0; k < s.seeds.size(); ++k)
    md += fmt::format("seed {}{} | ", s.seeds[k], k < s.fit_packings ? " (fit)" : "");
  md += "mean | spread | tolerance | within |\n|---|";
  for (size_t k = 0; k < s.seeds.size() + 4; ++k) md += "---|";
  md += "\n";
  for (const Row& r : rows(s)) {
    md += fmt::format("| {}{} | ", r.name, *r.unit ? fmt::format(" ({})", r.unit) : "");
    for (double v : r.p->values) md += fmt::format("{:.3g} | ", v * r.scale);
    md += fmt::format("{:.3g} | {} | {} | {} |\n", r.p->mean * r.scale, spread_text(r),
                      limit_text(r), r.p->within() ? "yes" : "**no**");
  }
  md += fmt::format("\nUCS / tensile: ");
  for (size_t k = 0; k < s.seeds.size(); ++k)
    md += fmt::format("{}{:.2f}", k ? ", " : "", s.ucs.values[k] / s.tensile.values[k]);
  md += s.within() ? ".\n\nWithin the tolerance: the fit describes the bonds, not one packing.\n"
        : s.fit_packings > 1
            ? ".\n\n**Beyond the tolerance** from packing to packing: the fit aims the mean of "
              "its packings at the card, but one specimen of this size (and one lump) can be "
              "that far from it; raise calibrate.n_elements (larger specimens average more "
              "contacts) to narrow it.\n"
            : ".\n\n**Beyond the tolerance**: what the fit met on its packing, another "
              "packing of the same size does not; raise calibrate.n_elements (larger "
              "specimens average more contacts), or fit the mean of several packings "
              "(calibrate.fit_packings), before reading the result as the ore's.\n";
  return md;
}

std::string packing_warning(const PackingSpread& s, long n_elements) {
  if (s.within()) return "";
  std::string what;
  for (const Row& r : rows(s))
    if (!r.p->within())
      what += fmt::format("{}{} {} (tolerance {})", what.empty() ? "" : ", ", r.name,
                          spread_text(r), limit_text(r));
  return fmt::format(
      "packing check: over {} packings of {} elements the result spreads beyond the "
      "fit's tolerance in {}: the specimens are too small for it; raise calibrate.n_elements{} "
      "(report.md, \"Packing check\")",
      s.seeds.size(), n_elements, what,
      s.fit_packings > 1 ? "" : ", or fit the mean of several packings (calibrate.fit_packings)");
}

}  // namespace mill::calibrate
