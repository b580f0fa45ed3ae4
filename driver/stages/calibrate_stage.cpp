// Stage 'calibrate': bond parameters from the ore card's macro properties.
// The job packs and carves the specimens (calibrate/specimen), runs the lab
// tests (calibrate/lab_runs), fits (calibrate/fitting) and writes the
// outputs (calibrate/outputs); this file plans, orchestrates and publishes.
#include "stages/calibrate_stage.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <utility>
#include <vector>

#include "jobs/job_store.h"
#include "jobs/output_checks.h"
#include "lump/bond_parameters.h"
#include "lump/material.h"
#include "progress.h"
#include "stages/calibrate/checks.h"
#include "stages/calibrate/fitting.h"
#include "stages/calibrate/lab_runs.h"
#include "stages/calibrate/outputs.h"
#include "stages/calibrate/packing_check.h"
#include "stages/calibrate/sensitivity.h"
#include "stages/calibrate/specimen.h"
#include "stages/calibrate/starts.h"
#include "stages/stage_util.h"

namespace mill {
namespace fs = std::filesystem;

namespace {
using namespace calibrate;

// Bumped when a deck or the fitting scheme changes what a calibration gives
// (git log of this line: what each version changed). 5: the job runs a UCS +
// Brazilian pair per lever after the rate check (calibrate.sensitivity) and
// its reports carry the levers' sensitivities: a calibration made before has
// neither. 6: the fit steps all four continuous parameters together on a
// local linear model (calibrate/local_model.h) instead of one secant each.
// 7: calibrated.yaml's input_hash covers the lump's scale (lump_scale: element
// radius, bonding range) and its fitted_for names it: a section written
// before would no longer be read. 8: the lab decks' step is also at most
// the bonds' critical step with their dashpots (fix bond/breakable f_ID[8]):
// smaller at high coordination, where the old one created energy. 9: the
// UCS is the peak before the specimen fails (post::kUcsFailureFraction), not
// a later one of its debris compacted between the platens. 10: the
// Brazilian strength is the load at the split (post::kBrazilianSplitFraction)
// and a disc that does not split gives none. 11: the triaxial deck presses
// only the shell elements held by a bond or a contact (a loose one was
// pushed across the open end face until the energy ledger stopped the run).
constexpr int kDeckVersion = 11;

// The fit's targets: the card's four macro properties, and its K_IC when
// the fit aims at it.
Targets targets_of(const config::CaseConfig& cfg) {
  const config::Document& o = cfg.ore;
  Targets t{o.real("youngs_modulus"), o.real("poisson_ratio"), o.real("ucs"), tensile_target(cfg)};
  t.direct = fits_direct_tension(cfg);
  t.brazilian = o.real("tensile_strength");
  if (fits_toughness(cfg)) t.toughness = o.real("fracture_toughness");
  return t;
}

// True when the ore card carries a complete calibrated.* section made with
// the case's bond model and layout (lump.bond_model, lump.joint_*): another
// model's parameters mean nothing to this one, not even as a start.
bool card_calibration_fits_model(const config::CaseConfig& cfg) {
  return card_has_calibration(cfg.ore) &&
         same_model(read_calibrated(cfg.ore, BondParams{}), estimate_bond_params(cfg.ore, cfg.doc));
}

// True when the ore card carries such a section fitted to its own macro
// properties (same input_hash).
bool card_is_calibrated(const config::CaseConfig& cfg) {
  return card_calibration_fits_model(cfg) && cfg.ore.str(std::string(kCalibratedSection) + "." +
                                                         kInputHashKey) == calibration_hash(cfg);
}

// True when the card carries such a section fitted to other properties (a
// stale calibration): the fit then starts from it.
bool card_has_stale_calibration(const config::CaseConfig& cfg) {
  return card_calibration_fits_model(cfg) && !card_is_calibrated(cfg);
}

// Everything one calibration run needs, gathered from the case.
class Calibration {
 public:
  // Targets and settings from the case and its ore card.
  Calibration(StageContext& ctx, const JobSpec& job, const fs::path& dir)
      : start_(start_of(job)),
        ctx_(ctx),
        job_(job),
        dir_(dir),
        d_(ctx.cfg.doc),
        ore_(ctx.cfg.ore),
        fit_(targets_of(ctx.cfg), d_.real("calibrate.tolerance")) {
    n_ = d_.integer("calibrate.n_elements");
    rate_ = d_.real("calibrate.strain_rate");
    max_it_ = static_cast<int>(d_.integer("calibrate.max_iterations"));
    scb_orientations_ = static_cast<int>(d_.integer("calibrate.scb_orientations"));
    fit_packings_ = static_cast<int>(d_.integer("calibrate.fit_packings"));
  }

  // The whole calibration: specimen, iterations, rate check, outputs.
  void run();

 private:
  int start_ = 1;  // calibrate.starts: 1 the primary fit, k >= 2 a fit from start k
  StageContext& ctx_;
  const JobSpec& job_;
  fs::path dir_;
  const config::Document& d_;
  const config::Document& ore_;
  Fitting fit_;
  double rate_ = 0.5;
  long n_ = 0;
  int max_it_ = 1;
  int scb_orientations_ = 1;  // half discs of each bend test
  int fit_packings_ = 1;      // specimen packings each iteration tests (the fit reads their means)
};

// The calibration: pack, iterate the two tests, check the rate, step each
// lever alone (sensitivities), run the checks (triaxial, semi-circular
// bend), write.
void Calibration::run() {
  const auto t0 = std::chrono::steady_clock::now();
  fs::create_directories(dir_ / "runs");
  Outcome o;
  o.specimen = pack_specimen(ctx_, job_.label, dir_, n_);
  const Specimen& sp = o.specimen;
  ctx_.progress.info(
      fmt::format("[calibrate] specimens of {} elements carved from the ball: cylinder {:.1f} mm x "
                  "{:.1f} mm (centres), disc "
                  "{:.1f} mm x {:.1f} mm",
                  n_, 2e3 * sp.cyl_r, 4e3 * sp.cyl_r, 2e3 * sp.disc_r, 1e3 * sp.disc_r));
  const Targets& t = fit_.targets();
  LabBench lab(ctx_, job_.label, dir_, sp, t);
  // Up to resources.jobs of this fit's independent tests at once; the
  // calibrate.starts fits run side by side and the pipeline's runner hands
  // out resources.jobs engine runs among them in the order they ask
  // (CalibrateStage::jobs_share_engine_runs; docs/calibration.md, "Runs at
  // once").
  lab.set_lanes(ctx_.opts.jobs);
  // The fit's further packings (calibrate.fit_packings): each its own ball,
  // the same tests in every iteration; the fit reads the means.
  std::vector<LabBench> more;
  std::vector<long> more_seeds;
  for (int k = 1; k < fit_packings_; ++k) {
    const Specimen spk = pack_specimen(ctx_, job_.label, dir_, n_, k);
    more.emplace_back(ctx_, job_.label, dir_, spk, t);
    more_seeds.push_back(spk.seed);
  }
  std::vector<Iteration>& hist = o.hist;
  std::vector<std::string>& notes = o.notes;
  BondParams p = estimate_bond_params(ore_, d_);
  if (start_ > 1) {
    // A further start: the estimate scaled (calibrate/starts.h); the fit
    // alone, the checks and sensitivities are the primary set's.
    p = start_params(p, start_);
    notes.push_back(p.origin);
    ctx_.progress.info("[calibrate] " + job_.label + ": " + p.origin);
  } else if (card_has_stale_calibration(ctx_.cfg)) {
    // A changed card: start from its previous calibration, not from scratch.
    p = read_calibrated(ore_, p);
    notes.push_back(
        "started from the ore card's calibrated.* section, fitted to other properties (stale "
        "input_hash)");
    ctx_.progress.info(
        "[calibrate] the ore card's calibrated.* was fitted to other properties (stale "
        "input_hash): "
        "starting the fit from it");
  }
  // Steps of the job: 2 tests per iteration (3 with the bend test of the
  // toughness fit), the half-rate UCS (twice as long), 2 tests per lever of
  // the sensitivities (the model's levers: the fit keeps the model), then
  // the checks.
  const bool primary = start_ == 1;
  const CheckTargets check_for = primary ? check_targets(ore_) : CheckTargets{};
  const double n_checks =
      primary ? static_cast<double>(d_.reals("calibrate.confining_pressures").size()) +
                    (check_for.fracture_toughness ? 1.0 : 0.0)
              : 0.0;
  const bool sensitivity = primary && d_.boolean("calibrate.sensitivity");
  const bool rate_check = primary && d_.boolean("calibrate.rate_check");
  const int n_packings = primary ? static_cast<int>(d_.integer("calibrate.packing_check")) : 0;
  const double n_sensitivity =
      sensitivity ? 2.0 * static_cast<double>(sensitivity_levers(p).size()) : 0.0;
  // Tests per packing: UCS and Brazilian, or with the direct tension test as
  // the fit's tensile test UCS and direct tension (the Brazilian discs then
  // run once, on the kept parameters: a check).
  const double per_packing = 2.0;
  const double per_it = per_packing * fit_packings_ + (fit_.fits_toughness() ? 1.0 : 0.0);
  const double disc_check = t.direct ? static_cast<double>(fit_packings_) : 0.0;
  const double steps_total = per_it * max_it_ + disc_check + (rate_check ? 2.0 : 0.0) +
                             2.0 * n_packings + n_sensitivity + n_checks;
  for (int k = 1; k <= max_it_; ++k) {
    Iteration it;
    it.p = p;
    it.more.resize(more.size());
    // The UCS and the tensile test (Brazilian, or direct tension) of every
    // packing, side by side as the job's lanes allow.
    const double at = per_it * (k - 1);
    std::vector<std::function<void()>> tests = {[&] {
      it.ucs = lab.ucs(p, rate_,
                       {fmt::format("it{}_ucs", k), fmt::format("iteration {}/{}: UCS", k, max_it_),
                        at / steps_total});
    }};
    if (t.direct)
      tests.push_back([&] {
        it.tension = lab.tension(
            p, rate_,
            {fmt::format("it{}_tension", k),
             fmt::format("iteration {}/{}: direct tension", k, max_it_), (at + 1) / steps_total});
      });
    else
      tests.push_back([&] {
        it.br = lab.brazilian(
            p, rate_,
            {fmt::format("it{}_brazilian", k),
             fmt::format("iteration {}/{}: Brazilian", k, max_it_), (at + 1) / steps_total});
      });
    for (size_t j = 0; j < more.size(); ++j) {
      const std::string of =
          fmt::format("iteration {}/{}, packing {}/{}", k, max_it_, j + 2, fit_packings_);
      const double at_j = at + per_packing * static_cast<double>(j + 1);
      it.more[j].seed = more_seeds[j];
      tests.push_back([&, j, of, at_j] {
        it.more[j].ucs = more[j].ucs(
            p, rate_, {fmt::format("it{}_p{}_ucs", k, j + 2), of + ": UCS", at_j / steps_total});
      });
      if (t.direct)
        tests.push_back([&, j, of, at_j] {
          it.more[j].tension = more[j].tension(p, rate_,
                                               {fmt::format("it{}_p{}_tension", k, j + 2),
                                                of + ": direct tension", (at_j + 1) / steps_total});
        });
      else
        tests.push_back([&, j, of, at_j] {
          it.more[j].br = more[j].brazilian(p, rate_,
                                            {fmt::format("it{}_p{}_brazilian", k, j + 2),
                                             of + ": Brazilian", (at_j + 1) / steps_total});
        });
    }
    // The bend test's half discs beside them: the same parameters.
    std::vector<ScbDisc> discs;
    if (fit_.fits_toughness())
      for (auto& task :
           lab.scb_tasks(p, rate_, scb_orientations_,
                         {fmt::format("it{}_scb", k),
                          fmt::format("iteration {}/{}: semi-circular bend", k, max_it_),
                          (at + per_packing * fit_packings_) / steps_total},
                         discs))
        tests.push_back(std::move(task));
    run_concurrently(tests, lab.lanes());
    if (fit_.fits_toughness()) it.scb = ScbRun::of(std::move(discs));
    fit_.score(it);
    hist.push_back(it);
    const Measured m = it.measured();
    ctx_.progress.info(fmt::format(
        "[calibrate] iteration {}/{}: E {:.2f} GPa (target {:.2f}), nu {:.3f} ({:.2f}), UCS {:.1f} "
        "MPa ({:.1f}), {}tensile "
        "{:.2f} MPa ({:.2f}){}{}{} [{:.0f} s + {:.0f} s{}{}{}]",
        k, max_it_, m.E / 1e9, t.E / 1e9, m.nu, t.nu, m.ucs / 1e6, t.ucs / 1e6,
        t.direct ? "direct " : "", m.tensile / 1e6, t.tensile / 1e6,
        more.empty() ? "" : fmt::format(" (means over {} packings)", fit_packings_),
        it.scb ? fmt::format(", K_IC {} ({:.3f})", it.scb->summary(), t.toughness / 1e6) : "",
        it.converged ? ": all within tolerance" : "", it.ucs.seconds,
        it.tension ? it.tension->seconds : it.br.seconds, it.tension ? " (direct tension)" : "",
        it.scb ? fmt::format(" + {:.0f} s", it.scb->seconds) : "",
        more.empty() ? "" : fmt::format(" + {:.0f} s on the other packings", it.more_seconds())));
    if (it.scb && !it.scb->peaked)
      notes.push_back(fmt::format(
          "iteration {}: the semi-circular bend test reached its cap still loading", k));
    if (!it.ucs.peaked)
      notes.push_back(
          fmt::format("iteration {}: the UCS test reached its strain cap still loading", k));
    if (!it.br.peaked)
      notes.push_back(
          fmt::format("iteration {}: the Brazilian test reached its cap still loading", k));
    if (it.tension && !it.tension->peaked)
      notes.push_back(fmt::format(
          "iteration {}: the direct tension test reached its strain cap still loading", k));
    for (const PackingRun& r : it.more)
      for (const auto& [done, test] : {std::pair{r.ucs.peaked, "UCS"},
                                       {r.br.peaked, "Brazilian"},
                                       {!r.tension || r.tension->peaked, "direct tension"}})
        if (!done)
          notes.push_back(fmt::format(
              "iteration {}: the {} test on packing seed {} reached its cap still loading", k, test,
              r.seed));
    // A disc that did not split has no tensile strength (post::kBrazilianSplitFraction).
    auto unsplit = [&](const BrazilianRun& b, const std::string& where) {
      if (!b.r.no_split) return;
      const std::string text = fmt::format(
          "iteration {}: the Brazilian disc{} did not split: it lost {:.0f}% of its bonds and "
          "its load, {:.2f} MPa as tensile strength at most, never fell below {:g} x its "
          "highest (a crushed disc compacting under the jaws): no tensile strength, the "
          "iteration is not used",
          k, where, 100 * b.r.bonds_lost, b.r.tensile_strength / 1e6,
          post::kBrazilianSplitFraction);
      notes.push_back(text);
      ctx_.progress.warn("[calibrate] " + text);
    };
    unsplit(it.br, "");
    for (const PackingRun& r : it.more) unsplit(r.br, fmt::format(" of packing seed {}", r.seed));
    if (it.converged || k == max_it_) break;
    p = fit_.update(hist, notes);
  }
  o.best = fit_.best(hist);
  // With the direct tension test as the tensile target: the Brazilian discs
  // of the kept parameters on every fit packing, a check against the card's
  // Brazilian strength (docs/calibration.md, "The direct tension test").
  if (t.direct) {
    Iteration& b = hist[o.best];
    std::vector<std::function<void()>> discs = {[&] {
      b.br = lab.brazilian(b.p, rate_,
                           {"check_brazilian", "check: Brazilian disc of the kept parameters",
                            per_it * max_it_ / steps_total});
    }};
    for (size_t j = 0; j < more.size(); ++j)
      discs.push_back([&, j] {
        b.more[j].br = more[j].brazilian(
            b.p, rate_,
            {fmt::format("check_p{}_brazilian", j + 2),
             fmt::format("check: Brazilian disc of the kept parameters, packing {}/{}", j + 2,
                         fit_packings_),
             (per_it * max_it_ + static_cast<double>(j + 1)) / steps_total});
      });
    run_concurrently(discs, lab.lanes());
    // Each disc's strength, "no split" for a crushed one (its largest load
    // then is no tensile strength: post::kBrazilianSplitFraction).
    auto disc = [](const BrazilianRun& r) {
      return r.r.no_split ? fmt::format("no split ({:.0f}% of the bonds lost, {:.2f} MPa at most)",
                                        100 * r.r.bonds_lost, r.r.tensile_strength / 1e6)
                          : fmt::format("{:.2f}", r.r.tensile_strength / 1e6);
    };
    std::string each = disc(b.br);
    for (const PackingRun& r : b.more) each += ", " + disc(r.br);
    const double mean = brazilian_mean(b);
    const std::string text = fmt::format(
        "check: the kept parameters' Brazilian discs {} MPa{} (the card's {:.2f} MPa; not "
        "fitted: the direct tension test is the tensile target)",
        each,
        std::isfinite(mean) ? fmt::format(", mean {:.2f}", mean / 1e6)
                            : std::string(", no mean: a disc did not split"),
        t.disc_tensile() / 1e6);
    notes.push_back(text);
    ctx_.progress.info("[calibrate] " + text);
  }
  // Rate check: the best parameters at half the strain rate.
  if (rate_check)
    o.half = lab.ucs(hist[o.best].p, 0.5 * rate_,
                     {"rate_check_ucs", "rate check: UCS at half the strain rate",
                      (per_it * max_it_ + disc_check) / steps_total});
  // Packing check: the best parameters on further packings, each its own ball.
  const double after_rate = per_it * max_it_ + disc_check + (rate_check ? 2.0 : 0.0);
  o.packings = run_packings(ctx_, job_.label, dir_, n_, fit_packings_, n_packings, hist[o.best].p,
                            t, rate_, lab.lanes(), after_rate / steps_total, 1.0 / steps_total);
  // The spread over the fit's packings and the check's (with one in all: none).
  if (primary && (!o.packings.empty() || fit_packings_ > 1)) {
    o.packing =
        packing_spread(hist[o.best], o.specimen.seed, o.packings, fit_.tolerance(), kNuTolerance);
    ctx_.progress.info(fmt::format(
        "[calibrate] packing check over {} packings: spread E {:.1f}%, nu {:.3f}, UCS {:.1f}%, "
        "tensile {:.1f}%",
        o.packing->seeds.size(), 100 * o.packing->E.spread, o.packing->nu.spread,
        100 * o.packing->ucs.spread, 100 * o.packing->tensile.spread));
    const std::string w = packing_warning(*o.packing, n_);
    if (!w.empty()) {
      ctx_.progress.warn("[calibrate] " + w);
      notes.push_back(w);
    }
  }
  // Sensitivities: each lever stepped alone from the best parameters.
  if (sensitivity) {
    o.sensitivity = run_sensitivity(lab, hist[o.best].p, rate_,
                                    (after_rate + 2.0 * n_packings) / steps_total,
                                    1.0 / steps_total);
    const Noise noise = sensitivity_noise(hist[o.best].ucs, o.half ? &*o.half : nullptr);
    for (const LeverRun& run : o.sensitivity) {
      const LeverSensitivity s = lever_sensitivity(hist[o.best], run);
      ctx_.progress.info(fmt::format(
          "[calibrate] sensitivity of {}: E {:+.1f}%, nu {:+.3f}, UCS {:+.1f}%, tensile "
          "{:+.1f}% for {}{}",
          run.lever.row->calibrated, 100 * s.E.change, s.nu.change, 100 * s.ucs.change,
          100 * s.tensile.change, step_text(run.lever),
          lever_verdict(s, fit_.tolerance(), noise).free() ? "" : " (moves no target: not free)"));
    }
  }
  if (primary)
    o.checks = run_checks(lab, hist[o.best].p, hist[o.best].ucs, rate_,
                          confining_pressures(d_, hist[o.best].ucs.r.ucs), check_for,
                          (after_rate + 2.0 * n_packings + n_sensitivity) / steps_total,
                          1.0 / steps_total,
                          scb_orientations_, hist[o.best].scb ? &*hist[o.best].scb : nullptr);
  for (const std::string& f : o.checks.failed) ctx_.progress.warn("[calibrate] check " + f);
  o.checks.toughness_fitted = fit_.fits_toughness();
  o.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_outputs(ctx_, dir_, fit_, o);
}

// The whole of a text file ("" when it cannot be read).
std::string read_text(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// With calibrate.starts > 1: each further start's calibrated.yaml and
// report.json under calibrate/sets/start<k>/ (where the breakage stage reads
// them: lump/material.h), calibrate/sets.json and its table appended to
// report.md. With one start: no sets/ folder, no sets.json.
template <class Copy>
void publish_sets(StageContext& ctx, const std::vector<JobSpec>& jobs, Copy copy) {
  const fs::path dst = ctx.stage_dir;
  fs::remove_all(dst / "sets");
  fs::remove(dst / "sets.json");
  if (jobs.size() < 2) return;
  const jobs::JobStore store(ctx.stage_dir);
  std::vector<StartResult> starts;
  for (const auto& j : jobs) {
    const fs::path dir = store.job_dir(j.label);
    const nlohmann::json report = nlohmann::json::parse(read_text(dir / "report.json"));
    const int k = start_of(j);
    starts.push_back({k, dir, report});
    if (k == 1) continue;
    const fs::path to = set_calibration_file(ctx.run_dir, k);
    fs::create_directories(to.parent_path());
    copy(dir / "report.json", to.parent_path() / "report.json");
    copy(dir / "calibrated.yaml", to);
  }
  std::sort(starts.begin(), starts.end(),
            [](const StartResult& a, const StartResult& b) { return a.start < b.start; });
  const nlohmann::json sets = sets_json(starts);
  jobs::atomic_write(dst / "sets.json", sets.dump(2) + "\n");
  if (fs::exists(dst / "report.md"))
    jobs::atomic_write(dst / "report.md", read_text(dst / "report.md") + sets_markdown(sets));
  ctx.progress.info(fmt::format(
      "[calibrate] {} parameter sets from different starts, {} meeting every target of the ore "
      "card: {}/sets.json",
      starts.size(), sets["meeting_card"].get<int>(), dst.string()));
}

}  // namespace

// One job, "calibration"; its summary says whether it fits or copies the card's section.
Plan CalibrateStage::plan(const StageContext& ctx) const {
  Plan p;
  nlohmann::json in = case_keys(ctx.cfg.doc, {"calibrate.", "lump."});
  // The number of starts is not an input of any one fit (the primary fit
  // keeps its job id whatever calibrate.starts is).
  in.erase("calibrate.starts");
  // One packing per iteration, as before the key: the job id a calibration
  // made then keeps.
  if (ctx.cfg.doc.integer("calibrate.fit_packings") == 1) in.erase("calibrate.fit_packings");
  // The toughness fit is an input only where it acts (flat joints, a card
  // with K_IC): a parallel-bond calibration keeps its job id.
  if (!fits_toughness(ctx.cfg)) in.erase("calibrate.fit_toughness");
  // The bend test's half discs are an input only where it runs (a card with
  // K_IC); with it, the half disc's radius factor (it moved from 1.0 to 1.2).
  if (ctx.cfg.ore.has("fracture_toughness"))
    in["scb_radius_factor"] = kScbRadiusFactor;
  else
    in.erase("calibrate.scb_orientations");
  in["ore"] = config::ore_keys(ctx.cfg.ore);
  for (const char* k : config::kOreCheckKeys)
    if (ctx.cfg.ore.has(k)) in["ore_checks"][k] = ctx.cfg.ore.real(k);
  in["deck_version"] = kDeckVersion;
  // The direct tension test and its target, where they act (a calibration
  // aimed at the Brazilian strength keeps its job id).
  if (!fits_direct_tension(ctx.cfg))
    in.erase("calibrate.tensile_test");
  else
    in["direct_tensile_strength"] = tensile_target(ctx.cfg);
  const bool from_card = card_is_calibrated(ctx.cfg);
  if (card_has_stale_calibration(ctx.cfg)) {
    // The fit starts from the card's stale calibration (read as the fit
    // reads it, optional moment factor included): part of the inputs.
    in["start"] = bond_json(read_calibrated(ctx.cfg.ore, BondParams{}), BondNames::card);
  }
  if (from_card) {
    in["from_card"] = true;
    p.note =
        "the ore card carries calibrated.* fitted to its properties: the job copies them, no lab "
        "tests";
  }
  // The tests of each iteration (the toughness fit adds the bend test).
  const long fit_packings = ctx.cfg.doc.integer("calibrate.fit_packings");
  const std::string tests =
      std::string(fits_direct_tension(ctx.cfg) ? "UCS + Brazilian + direct tension (the tensile "
                                                 "target)"
                                               : "UCS + Brazilian") +
      (fits_toughness(ctx.cfg) ? " + semi-circular bend tests (K_IC a target)" : " tests");
  // "400 elements" or "400 elements x 3 packings (their means fitted)".
  const std::string specimens = fmt::format(
      "{} elements{}", ctx.cfg.doc.integer("calibrate.n_elements"),
      fit_packings > 1 ? fmt::format(" x {} packings (their means fitted)", fit_packings)
                       : std::string());
  p.jobs.push_back(
      {"calibration", in,
       from_card
           ? fmt::format("copy calibrated.* from the ore card of {}", ctx.cfg.ore.str("name"))
           : fmt::format(
                 "{} on {}, fit to {}; then {}{} triaxial{} "
                 "check(s)",
                 tests, specimens, ctx.cfg.ore.str("name"),
                 ctx.cfg.doc.boolean("calibrate.sensitivity") ? "the levers' sensitivities, " : "",
                 ctx.cfg.doc.reals("calibrate.confining_pressures").size(),
                 ctx.cfg.ore.has("fracture_toughness") ? " + semi-circular bend" : "")});
  // Further starts: the fit alone from the estimate scaled (calibrate/starts.h).
  const int starts = static_cast<int>(ctx.cfg.doc.integer("calibrate.starts"));
  const BondParams estimate = estimate_bond_params(ctx.cfg.ore, ctx.cfg.doc);
  for (int k = 2; k <= starts; ++k) {
    nlohmann::json ink = in;
    ink.erase("from_card");
    ink.erase("start");
    ink["start_index"] = k;
    ink["start"] = bond_json(start_params(estimate, k), BondNames::card);
    const auto f = start_factors(k);
    p.jobs.push_back(
        {start_label(k), ink,
         fmt::format("{} on {}, fit to {} from start {} (the estimate "
                     "x {:.3g}, {:.3g}, {:.3g}, {:.3g})",
                     tests, specimens, ctx.cfg.ore.str("name"), k, f[0], f[1], f[2], f[3])});
  }
  return p;
}

// Fit (or copy the card's calibration) into the job folder.
void CalibrateStage::run_job(StageContext& ctx, const JobSpec& job, const fs::path& job_dir) {
  fs::create_directories(job_dir);
  for (const char* f : {"calibrated.yaml", "report.json", "report.md", "curves.csv"})
    fs::remove(job_dir / f);
  if (job.inputs.contains("from_card")) {
    ctx.progress.info(
        fmt::format("[calibrate] the ore card {} carries calibrated.* fitted to its properties "
                    "(input_hash matches): copied, no fitting",
                    ctx.cfg.ore_file.string()));
    calibrate::copy_from_card(ctx, job_dir);
    return;
  }
  Calibration(ctx, job, job_dir).run();
}

// The job's calibrated.yaml (and, after a fit, report.json) exist and parse.
std::string CalibrateStage::damaged_outputs(const StageContext& ctx, const JobSpec& job) const {
  const fs::path dir = jobs::JobStore(ctx.stage_dir).job_dir(job.label);
  return jobs::first_problem(
      {jobs::check_yaml_map(dir / "calibrated.yaml"),
       job.inputs.contains("from_card") ? "" : jobs::check_json(dir / "report.json")});
}

// calibrate/calibrated.yaml, which the breakage stage reads.
std::string CalibrateStage::damaged_merged_outputs(const StageContext& ctx,
                                                   const std::vector<JobSpec>& jobs) const {
  return jobs.empty() ? "" : jobs::check_yaml_map(ctx.stage_dir / "calibrated.yaml");
}

// Publish the job's outputs as the stage's: calibrate/calibrated.yaml, reports, plots.
void CalibrateStage::finalize(StageContext& ctx, const std::vector<JobSpec>& jobs) {
  if (jobs.empty()) return;
  const jobs::JobStore store(ctx.stage_dir);
  const fs::path src = store.job_dir(start_label(1)), dst = ctx.stage_dir;
  auto copy = [&](const fs::path& from, const fs::path& to) {
    std::ifstream in(from, std::ios::binary);
    if (!in) return;
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    jobs::atomic_write(to, text);
  };
  // Plots and tables first; calibrated.yaml (the declared output) last.
  fs::remove_all(dst / "plots");
  if (fs::exists(src / "plots")) {
    fs::create_directories(dst / "plots");
    for (const auto& e : fs::directory_iterator(src / "plots"))
      copy(e.path(), dst / "plots" / e.path().filename());
  }
  for (const char* f : {"curves.csv", "report.json", "report.md"})
    if (fs::exists(src / f))
      copy(src / f, dst / f);
    else
      fs::remove(dst / f);
  publish_sets(ctx, jobs, copy);
  copy(src / "calibrated.yaml", dst / "calibrated.yaml");
  ctx.progress.info(fmt::format("[calibrate] results: {}/calibrated.yaml, report.md, report.json{}",
                                dst.string(), fs::exists(src / "plots") ? ", plots/*.png" : ""));
}

}  // namespace mill
