// The packing check of the calibrate stage (docs/calibration.md, "Packing
// check"): the result's UCS and Brazilian tests repeated on further specimen
// packings (the next seed streams after calibrate.seed's), and how far E, nu, UCS and the
// tensile strength spread between the packings. A fit meets the card on one
// packing; when the packings spread by more than the fit's tolerance, that
// is the packing's doing as much as the bonds', and the specimens are too
// small for the tolerance (bench/README.md, "UCS/T of 10 at bond gap 1.4":
// flat joints at bond gap 1.4 on 400-element specimens gave tensile
// strengths of 4.8, 9.3 and 7.7 MPa on three packings with the same bonds).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "stages/calibrate/fitting.h"
#include "stages/calibrate/lab_runs.h"
#include "stages/stage.h"

namespace mill::calibrate {

// The result's parameters p on `packings` further packings of n-element
// specimens (pack_specimen's packings first, first + 1, ...: after the
// fit's own), each its own ball, with targets t at strain rate `rate`: a UCS
// and a Brazilian test each, side by side on `lanes` lanes; progress from
// `done`, `step_share` per test.
std::vector<PackingRun> run_packings(StageContext& ctx, const std::string& job_label,
                                     const std::filesystem::path& dir, long n, int first,
                                     int packings, const BondParams& p, const Targets& t,
                                     double rate, int lanes, double done, double step_share);

// One property over the packings, the fit's own first.
struct PackingProperty {
  std::vector<double> values;  // the fit's packing, then each further one
  double mean = 0;
  // (max - min) / mean; for nu, max - min (absolute, as its tolerance)
  double spread = 0;
  double limit = 0;  // the fit's tolerance for this property (relative; nu absolute)
  bool within() const { return spread <= limit; }
};

struct PackingSpread {
  std::vector<long> seeds;  // the fit's seeds first
  size_t fit_packings = 1;  // how many of them the fit averaged (calibrate.fit_packings)
  PackingProperty E, nu, ucs, tensile;
  // Every property within the fit's tolerance from packing to packing.
  bool within() const { return E.within() && nu.within() && ucs.within() && tensile.within(); }
};

// The spread of the result `best` over its own packings (the first of
// `seed`, then best.more) and its runs on further packings; `tol` the fit's
// relative tolerance, `nu_tol` its absolute one for nu. Throws
// std::invalid_argument with one packing in all.
PackingSpread packing_spread(const Iteration& best, long seed, const std::vector<PackingRun>& runs,
                             double tol, double nu_tol);

// One packing's runs in report.json: its seed, E, nu, UCS and tensile
// strength, the runs' folders and energy ledgers; with the direct tension
// test (calibrate.tensile_test direct) its strength and run too.
nlohmann::json packing_run_json(long seed, const UcsRun& ucs, const BrazilianRun& br,
                                const std::optional<UcsRun>& tension = std::nullopt);

// report.json's "packing_check": the spread, and each further packing's runs
// with their energy ledgers.
nlohmann::json packing_json(const PackingSpread& s, const std::vector<PackingRun>& runs);

// report.md's section "Packing check" (a heading, the table, the verdict).
std::string packing_markdown(const PackingSpread& s);

// The warning (and the report's note) when the packings spread beyond the
// tolerance: names the properties, their spread and the key that enlarges
// the specimens; "" when within.
std::string packing_warning(const PackingSpread& s, long n_elements);

}  // namespace mill::calibrate
