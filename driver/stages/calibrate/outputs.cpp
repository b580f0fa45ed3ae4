// Outputs of the calibration job: calibrated.yaml, reports, curves, plots.
#include "stages/calibrate/outputs.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "engine/runner.h"
#include "jobs/job_store.h"
#include "lump/bond_parameters.h"
#include "progress.h"
#include "stages/calibrate/energy_report.h"

namespace mill::calibrate {
namespace fs = std::filesystem;

namespace {

// The macro properties an iteration achieved, with the ore card's key names:
// the means over the fit's packings (K_IC when the iteration ran the bend
// test of the toughness fit).
nlohmann::json macro(const Iteration& it) {
  const Measured a = it.measured();
  nlohmann::json m{{"youngs_modulus", a.E},
                   {"poisson_ratio", a.nu},
                   {"ucs", a.ucs},
                   {"tensile_strength", a.tensile}};
  if (it.scb) m["fracture_toughness"] = it.scb->toughness;
  // With the direct tension test as the tensile target: the model's
  // Brazilian strength beside it (a check against the card's).
  if (it.tension && !it.br.tag.empty()) m["brazilian_tensile_strength"] = brazilian_mean(it);
  return m;
}

// Wall seconds of an iteration's tests, every packing's and the bend test's.
double iteration_seconds(const Iteration& it) {
  return it.ucs.seconds + it.br.seconds + (it.tension ? it.tension->seconds : 0.0) +
         (it.scb ? it.scb->seconds : 0.0) + it.more_seconds();
}

// A value of a run's info line, 0 when the deck did not write it.
double info_or_zero(const std::map<std::string, double>& m, const char* k) {
  auto it = m.find(k);
  return it == m.end() ? 0.0 : it->second;
}

// One row per sample of every test run, for the plots and spreadsheets.
void append_curves(std::ostream& o, const std::string& run, int iteration, const std::string& test,
                   double rate, const post::LoadCurve& c, const std::vector<double>& strain,
                   const std::vector<double>& stress) {
  for (size_t i = 0; i < c.size(); ++i)
    o << fmt::format("{},{},{},{:.6g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n", run, iteration, test,
                     rate, c.displacement[i], c.force(i), strain[i], stress[i],
                     c.lateral_strain[i]);
}

// The outputs of one finished fit, each built from the same facts.
class Report {
 public:
  // What the outputs say about fit `o` to the case's ore card.
  Report(const config::CaseConfig& cfg, const Fitting& fit, const Outcome& o)
      : d_(cfg.doc),
        ore_(cfg.ore),
        t_(fit.targets()),
        tol_(fit.tolerance()),
        rate_(cfg.doc.real("calibrate.strain_rate")),
        n_(cfg.doc.integer("calibrate.n_elements")),
        o_(o),
        sp_(o.specimen),
        hist_(o.hist),
        best_(o.best),
        b_(o.hist[o.best]),
        bm_(b_.measured()),
        half_(o.half),
        wall_(o.wall),
        notes_(o.notes),
        hash_(calibration_hash(cfg)),
        scale_(lump_scale(cfg)),
        rate_change_(o.half ? post::RelativeError(o.half->r.ucs, b_.ucs.r.ucs) : 0.0),
        rate_ok_(rate_change_ < 0.05),
        noise_(sensitivity_noise(b_.ucs, o.half ? &*o.half : nullptr)),
        ui_(b_.ucs.info),
        bi_(b_.br.info),
        missed_(explain_missed()) {}

  // Why each target that was not reached was not, in words.
  const std::vector<std::string>& missed() const { return missed_; }
  nlohmann::json json() const;
  std::string yaml() const;
  std::string markdown() const;
  std::string curves() const;
  std::string summary() const;

 private:
  std::vector<std::string> explain_missed() const;

  const config::Document& d_;
  const config::Document& ore_;
  const Targets t_;
  const double tol_, rate_;
  const long n_;
  const Outcome& o_;
  const Specimen& sp_;
  const std::vector<Iteration>& hist_;
  const size_t best_;
  const Iteration& b_;
  const Measured bm_;  // what the fit read of the result (means over its packings)
  const std::optional<UcsRun>& half_;
  const double wall_;
  const std::vector<std::string>& notes_;
  const std::string hash_;
  const nlohmann::json scale_;  // the lump scale fitted for (calibrated.fitted_for)
  const double rate_change_;
  const bool rate_ok_;
  const Noise noise_;  // run-to-run noise of the sensitivities
  const std::map<std::string, double>& ui_;  // info line of the result's UCS run
  const std::map<std::string, double>& bi_;  // and of its Brazilian run
  const std::vector<std::string> missed_;
};

// Why a target was missed, in words (docs/calibration.md explains).
std::vector<std::string> Report::explain_missed() const {
  std::vector<std::string> missed;
  if (b_.err_E > tol_)
    missed.push_back(fmt::format("E {:.2f} GPa is {:.0f}% off the target after {} iterations",
                                 bm_.E / 1e9, 100 * b_.err_E, hist_.size()));
  if (b_.err_nu > kNuTolerance)
    missed.push_back(
        fmt::format("nu {:.3f} is {:.3f} off the target: kn/ks {:.2f} (kept in [0.5, 20])", bm_.nu,
                    b_.err_nu, b_.p.stiffness_ratio));
  if (b_.err_t > tol_)
    missed.push_back(fmt::format("tensile strength {:.2f} MPa is {:.0f}% off the target",
                                 bm_.tensile / 1e6, 100 * b_.err_t));
  if (t_.toughness > 0 && b_.err_kic > tol_) {
    // K_IC follows the bond tensile strength (the notch opens in tension);
    // the Brazilian strength follows it and the cohesion together, so K_IC
    // and T pull sigma_b apart at a given element size.
    missed.push_back(fmt::format(
        "K_IC {:.3f} MPa m^0.5 is {:.0f}% off the target {:.3f}: it follows the bond tensile "
        "strength (now {:.2f} MPa, cohesion {:.2f} MPa), which the tensile strength and the UCS "
        "pull too; at this element size (mean radius {:.2f} mm) the card's K_IC/tensile ratio of "
        "{:.3f} m^0.5 needs another sigma_b than its tensile strength does (docs/calibration.md, "
        "\"The toughness as a target\")",
        b_.scb ? b_.scb->toughness / 1e6 : 0.0, 100 * b_.err_kic, t_.toughness / 1e6,
        b_.p.tensile / 1e6, b_.p.cohesion / 1e6, sp_.mean_radius * 1e3, t_.toughness / t_.tensile));
  }
  if (b_.err_ucs > tol_) {
    const double ratio = bm_.ucs / bm_.tensile, want = t_.ucs / t_.tensile;
    // Measured sensitivity of the UCS to the cohesion ratio (last two iterations that moved it).
    std::string lever;
    for (size_t i = hist_.size(); i-- > 1;) {
      const double r1 = hist_[i - 1].p.cohesion / hist_[i - 1].p.tensile,
                   r2 = hist_[i].p.cohesion / hist_[i].p.tensile;
      if (std::abs(std::log(r2 / r1)) < 1e-3) continue;
      lever = fmt::format(
          "; raising cohesion/tensile from {:.2f} to {:.2f} changed the UCS by {:+.1f}%{}", r1, r2,
          100 * (hist_[i].measured().ucs / hist_[i - 1].measured().ucs - 1),
          std::abs(hist_[i].measured().ucs / hist_[i - 1].measured().ucs - 1) < 0.05
              ? ": the bonds fail in tension (bending included), so the shear strength cannot "
                "raise the UCS"
              : "");
      break;
    }
    double best_ratio = 0.0;
    for (const auto& it : hist_)
      best_ratio = std::max(best_ratio, it.measured().ucs / it.measured().tensile);
    // Where the UCS/tensile levers stand, by model; the same head and tail.
    const double c_ratio = b_.p.cohesion / b_.p.tensile;
    const char* cap = c_ratio >= kMaxCohesionRatio * 0.999 ? ", at its cap" : "";
    const std::string levers =
        b_.p.model == BondModel::flat_joint
            ? fmt::format(
                  "With flat joints ({}) the fit moves one lever for the ratio, the cohesion ratio "
                  "(now {:.2f}{}); it rises with the coordination (interfaces per element, set by "
                  "lump.bond_gap), so a wider bond gap or more iterations "
                  "(calibrate.max_iterations) may reach it (bench/README.md, \"Strength ratio: "
                  "coordination and cohesion with the flat joint\")",
                  bond_model_text(b_.p), c_ratio, cap)
            : fmt::format(
                  "Bonded sphere packings fail by bond tension under compression too; the levers "
                  "the fit moves, moment factor (now {:g}), bond friction angle (now {:g} deg) and "
                  "cohesion ratio (now {:.2f}{}), raise the ratio by tens of percent, not by the "
                  "factor needed (bench/README.md, \"Rock strength levers\")",
                  b_.p.moment_factor, b_.p.friction_angle_deg, c_ratio, cap);
    missed.push_back(
        post::RelativeError(ratio, want) > tol_
            ? fmt::format("UCS {:.1f} MPa is {:.0f}% off the target: UCS/tensile reached {:.1f} "
                          "against {:.1f} on the card (at most {:.1f} over the {} iterations). "
                          "{}{}",
                          bm_.ucs / 1e6, 100 * b_.err_ucs, ratio, want, best_ratio, hist_.size(),
                          levers, lever)
            : fmt::format("UCS {:.1f} MPa is {:.0f}% off the target (UCS/tensile "
                          "{:.1f} is right: the strength level needs more iterations)",
                          bm_.ucs / 1e6, 100 * b_.err_ucs, ratio));
  }
  return missed;
}

// report.json: targets, achieved values, every iteration, specimen, rate
// check, the lab runs' energy ledgers.
nlohmann::json Report::json() const {
  nlohmann::json iters = nlohmann::json::array();
  for (size_t i = 0; i < hist_.size(); ++i) {
    const auto& it = hist_[i];
    iters.push_back(
        {{"iteration", i + 1},
         {"bond", bond_json(it.p, BondNames::report)},
         {"achieved", macro(it)},
         {"errors",
          {{"youngs_modulus", it.err_E},
           {"poisson_ratio", it.err_nu},
           {"ucs", it.err_ucs},
           {"tensile_strength", it.err_t}}},
         {"within_tolerance", it.converged},
         {"ucs_fit_window_Pa", {it.ucs.r.fit_stress_lo, it.ucs.r.fit_stress_hi}},
         {"ucs_fit_r2", it.ucs.r.fit.r2},
         {"strain_at_peak", it.ucs.r.strain_at_peak},
         {"brazilian_peak_force_N", it.br.r.peak_force},
         {"ucs_peaked", it.ucs.peaked},
         {"brazilian_peaked", it.br.peaked},
         {"brazilian_split", !it.br.r.no_split},
         {"energy",
          {{"ucs", lab_energy_json(it.ucs.energy)}, {"brazilian", lab_energy_json(it.br.energy)}}},
         {"wall_seconds", iteration_seconds(it)}});
    if (t_.toughness > 0) iters.back()["errors"]["fracture_toughness"] = it.err_kic;
    if (it.tension) {  // the direct tension test, the fit's tensile target
      nlohmann::json& j = iters.back();
      j["tension_peaked"] = it.tension->peaked;
      j["energy"]["tension"] = lab_energy_json(it.tension->energy);
      if (it.br.tag.empty()) {  // the discs ran on the kept parameters only
        for (const char* k : {"brazilian_peak_force_N", "brazilian_peaked", "brazilian_split"})
          j[k] = nullptr;
        j["energy"].erase("brazilian");
      }
    }
    if (!it.more.empty()) {  // the fit's packings, each (calibrate.fit_packings)
      nlohmann::json each =
          nlohmann::json::array({packing_run_json(sp_.seed, it.ucs, it.br, it.tension)});
      for (const PackingRun& r : it.more)
        each.push_back(packing_run_json(r.seed, r.ucs, r.br, r.tension));
      iters.back()["packings"] = each;
    }
    if (it.scb) {  // the bend test of the toughness fit
      nlohmann::json& j = iters.back();
      j["scb_peak_force_N"] = it.scb->peak_force;
      j["fracture_toughness_sem_Pa_m0.5"] = it.scb->toughness_sem;
      nlohmann::json discs = nlohmann::json::array();
      for (const ScbDisc& d : it.scb->discs)
        discs.push_back({{"run", d.tag},
                         {"angle_deg", d.angle_deg},
                         {"fracture_toughness_Pa_m0.5", d.r.toughness},
                         {"peaked", d.peaked}});
      j["scb_discs"] = discs;
      j["energy"]["scb"] = nlohmann::json::array();
      for (const ScbDisc& d : it.scb->discs)
        j["energy"]["scb"].push_back(lab_energy_json(d.energy));
      j["wall_seconds"] = j["wall_seconds"].get<double>() + it.scb->seconds;
    }
  }
  nlohmann::json specimen = {{"seed", d_.integer("calibrate.seed")},
                             {"ball_elements", sp_.ball_elements},
                             {"ball_outer_radius_m", sp_.ball_outer_radius},
                             {"mean_element_radius_m", sp_.mean_radius},
                             {"ucs_cylinder",
                              {{"elements", info_or_zero(ui_, "atoms")},
                               {"diameter_m", info_or_zero(ui_, "diameter")},
                               {"height_m", info_or_zero(ui_, "height")},
                               {"gauge_length_m", info_or_zero(ui_, "gauge_length")},
                               {"bonds", info_or_zero(ui_, "bonds")},
                               {"platen_layer_elements", info_or_zero(ui_, "top_layer")}}},
                             {"brazilian_disc",
                              {{"elements", info_or_zero(bi_, "atoms")},
                               {"diameter_m", info_or_zero(bi_, "diameter")},
                               {"thickness_m", info_or_zero(bi_, "thickness")},
                               {"bonds", info_or_zero(bi_, "bonds")},
                               {"jaw_elements", info_or_zero(bi_, "top_layer")}}}};
  nlohmann::json targets = {{"youngs_modulus", t_.E},
                            {"poisson_ratio", t_.nu},
                            {"ucs", t_.ucs},
                            {"tensile_strength", t_.tensile}};
  nlohmann::json within = {{"youngs_modulus", b_.err_E <= tol_},
                           {"poisson_ratio", b_.err_nu <= kNuTolerance},
                           {"ucs", b_.err_ucs <= tol_},
                           {"tensile_strength", b_.err_t <= tol_}};
  // Which test the tensile strength is (calibrate.tensile_test) and, with
  // the direct one, the card's Brazilian strength it was converted from.
  targets["tensile_test"] = t_.direct ? "direct" : "brazilian";
  if (t_.direct) targets["brazilian_tensile_strength"] = t_.disc_tensile();
  if (t_.toughness > 0) {
    targets["fracture_toughness"] = t_.toughness;
    within["fracture_toughness"] = b_.err_kic <= tol_;
  }
  nlohmann::json report = {
      {"ore", ore_.str("name")},
      {"input_hash", hash_},
      {"fitted_for", scale_},
      {"source", "fitted"},
      {"targets", targets},
      {"achieved", macro(b_)},
      {"within_tolerance", within},
      {"tolerance", {{"relative", tol_}, {"poisson_ratio_absolute", kNuTolerance}}},
      {"converged", b_.converged},
      {"best_iteration", best_ + 1},
      {"iterations", iters},
      {"calibrated", bond_json(b_.p, BondNames::report)},
      {"specimen", specimen},
      {"strain_rate_1_s", rate_},
      {"rate_check", half_ ? nlohmann::json{{"strain_rate_1_s", 0.5 * rate_},
                                            {"ucs", half_->r.ucs},
                                            {"youngs_modulus", half_->r.youngs_modulus},
                                            {"ucs_change", rate_change_},
                                            {"youngs_modulus_change",
                                             post::RelativeError(half_->r.youngs_modulus,
                                                                 b_.ucs.r.youngs_modulus)},
                                            {"below_5_percent", rate_ok_},
                                            {"energy", lab_energy_json(half_->energy)},
                                            {"wall_seconds", half_->seconds}}
                           : nlohmann::json(nullptr)},
      {"packing_check",
       o_.packing ? packing_json(*o_.packing, o_.packings) : nlohmann::json(nullptr)},
      {"sensitivity", o_.sensitivity.empty() ? nlohmann::json(nullptr)
                                             : sensitivity_json(b_, o_.sensitivity, tol_, noise_)},
      {"checks", checks_json(o_.checks, b_.ucs.r.ucs)},
      {"energy", energy_summary_json(o_)},
      {"not_reached", missed_},
      {"notes", notes_},
      {"wall_seconds", wall_}};
  return report;
}

// calibrated.yaml: the calibrated: map is what material.cpp reads (and
// what may be pasted into the ore card); the rest documents the fit.
std::string Report::yaml() const {
  YAML::Emitter y;
  y.SetDoublePrecision(8);
  y << YAML::BeginMap;
  emit_calibrated(y, b_.p, hash_, scale_);
  y << YAML::Key << "ore" << YAML::Value << ore_.str("name");
  y << YAML::Key << "converged" << YAML::Value << b_.converged;
  y << YAML::Key << "targets" << YAML::Value << YAML::BeginMap;
  y << YAML::Key << "youngs_modulus" << YAML::Value << t_.E << YAML::Key << "poisson_ratio"
    << YAML::Value << t_.nu << YAML::Key << "ucs" << YAML::Value << t_.ucs << YAML::Key
    << "tensile_strength" << YAML::Value << t_.tensile;
  if (t_.toughness > 0) y << YAML::Key << "fracture_toughness" << YAML::Value << t_.toughness;
  y << YAML::EndMap;
  y << YAML::Key << "achieved" << YAML::Value << YAML::BeginMap;
  y << YAML::Key << "youngs_modulus" << YAML::Value << bm_.E << YAML::Key << "poisson_ratio"
    << YAML::Value << bm_.nu << YAML::Key << "ucs" << YAML::Value << bm_.ucs << YAML::Key
    << "tensile_strength" << YAML::Value << bm_.tensile;
  if (b_.scb) y << YAML::Key << "fracture_toughness" << YAML::Value << b_.scb->toughness;
  y << YAML::EndMap;
  y << YAML::Key << "specimen" << YAML::Value << YAML::BeginMap;
  y << YAML::Key << "elements" << YAML::Value << n_;
  y << YAML::Key << "ucs_cylinder_diameter_m" << YAML::Value << info_or_zero(ui_, "diameter");
  y << YAML::Key << "ucs_cylinder_height_m" << YAML::Value << info_or_zero(ui_, "height");
  y << YAML::Key << "brazilian_disc_diameter_m" << YAML::Value << info_or_zero(bi_, "diameter");
  y << YAML::Key << "brazilian_disc_thickness_m" << YAML::Value << info_or_zero(bi_, "thickness");
  y << YAML::Key << "mean_element_radius_m" << YAML::Value << sp_.mean_radius;
  y << YAML::Key << "seed" << YAML::Value << d_.integer("calibrate.seed");
  y << YAML::EndMap;
  y << YAML::Key << "strain_rate" << YAML::Value << rate_;
  y << YAML::EndMap;
  return y.c_str();
}

// Markdown report: targets against achieved values, then the details.
std::string Report::markdown() const {
  std::ostringstream md;
  md << fmt::format("# Calibration of {} ({} elements per specimen)\n\n", ore_.str("name"), n_);
  md << fmt::format("{} after {} iteration(s); best: iteration {}. Wall time {}.\n\n",
                    b_.converged ? "All targets within tolerance" : "**Not all targets reached**",
                    hist_.size(), best_ + 1, Progress::duration(wall_));
  md << "| property | target | achieved | error | tolerance | ok |\n|---|---|---|---|---|---|\n";
  md << fmt::format("| E (GPa) | {:.2f} | {:.2f} | {:.1f}% | {:.0f}% | {} |\n", t_.E / 1e9,
                    bm_.E / 1e9, 100 * b_.err_E, 100 * tol_, b_.err_E <= tol_ ? "yes" : "no");
  md << fmt::format("| nu | {:.3f} | {:.3f} | {:.3f} | {:.2f} | {} |\n", t_.nu, bm_.nu, b_.err_nu,
                    kNuTolerance, b_.err_nu <= kNuTolerance ? "yes" : "no");
  md << fmt::format("| UCS (MPa) | {:.1f} | {:.1f} | {:.1f}% | {:.0f}% | {} |\n", t_.ucs / 1e6,
                    bm_.ucs / 1e6, 100 * b_.err_ucs, 100 * tol_, b_.err_ucs <= tol_ ? "yes" : "no");
  md << fmt::format("| {} (MPa) | {:.2f} | {:.2f} | {:.1f}% | {:.0f}% | {} |\n",
                    t_.direct ? "direct tensile" : "tensile", t_.tensile / 1e6, bm_.tensile / 1e6,
                    100 * b_.err_t, 100 * tol_, b_.err_t <= tol_ ? "yes" : "no");
  if (t_.direct && b_.tension) {
    const double disc = brazilian_mean(b_);
    md << (std::isfinite(disc)
               ? fmt::format(
                     "| Brazilian tensile (MPa; the card's, not fitted) | {:.2f} | {:.2f} | "
                     "{:.1f}% | - | check |\n",
                     t_.disc_tensile() / 1e6, disc / 1e6,
                     100 * post::RelativeError(disc, t_.disc_tensile()))
               : fmt::format("| Brazilian tensile (MPa; the card's, not fitted) | {:.2f} | a disc "
                             "did not split (notes) | - | - | check |\n",
                             t_.disc_tensile() / 1e6));
  }
  if (t_.toughness > 0 && b_.scb)
    md << fmt::format(
        "| K_IC (MPa m^0.5; semi-circular bend, mean of {} half discs +- its standard error) | "
        "{:.3f} | {:.3f} +- {:.3f} | {:.1f}% | {:.0f}% | {} |\n",
        b_.scb->discs.size(), t_.toughness / 1e6, b_.scb->toughness / 1e6,
        b_.scb->toughness_sem / 1e6, 100 * b_.err_kic, 100 * tol_,
        b_.err_kic <= tol_ ? "yes" : "no");
  md << "\n";
  if (t_.direct)
    md << fmt::format(
        "The tensile target is the direct tension test's (calibrate.tensile_test direct: the UCS "
        "cylinder pulled apart by its end layers): {:.2f} MPa, from the card's Brazilian {:.2f} "
        "MPa (x {:.2f}: its direct_tensile_strength, or rock_class by Perras & Diederichs 2014). "
        "The Brazilian test still runs; its strength is a check.\n\n",
        t_.tensile / 1e6, t_.disc_tensile() / 1e6, t_.tensile / t_.disc_tensile());
  md << "## Bond parameters (calibrated.yaml)\n\n| parameter | value |\n|---|---|\n";
  md << fmt::format(
      "| bond model (lump.bond_model) | {} |\n| bond modulus (GPa) | {:.3f} |\n| kn/ks | {:.3f} "
      "|\n| bond tensile strength (MPa) | {:.3f} |\n"
      "| bond cohesion (MPa) | {:.3f} |\n| bond friction angle (deg) | {:.1f} |\n{}| radius "
      "multiplier | {:g} |\n\n",
      bond_model_text(b_.p), b_.p.modulus / 1e9, b_.p.stiffness_ratio, b_.p.tensile / 1e6,
      b_.p.cohesion / 1e6, b_.p.friction_angle_deg,
      b_.p.model == BondModel::parallel
          ? fmt::format("| moment factor | {:g} |\n", b_.p.moment_factor)
          : fmt::format("| tension softening lambda (1: brittle) | {:.3g} |\n", b_.p.softening),
      b_.p.radius_multiplier);
  // The toughness fit adds a K_IC column.
  const bool kic = t_.toughness > 0;
  md << "## Iterations\n\n";
  if (!b_.more.empty())
    md << fmt::format(
        "E, nu, UCS and tensile: the means over the fit's {} specimen packings "
        "(calibrate.fit_packings), what the fit aims at the card; each packing's in report.json "
        "(iterations[].packings).\n\n",
        b_.more.size() + 1);
  md << fmt::format(
      "| it | E_b (GPa) | kn/ks | sigma_b (MPa) | c (MPa) | {}phi (deg) | beta | "
      "E (GPa) | nu | UCS (MPa) | tensile (MPa) | UCS/tensile | {}"
      "wall (s) |\n|---|---|---|---|---|---|---|---|---|---|---|---|{}---|\n",
      kic ? "lambda | " : "", kic ? "K_IC (MPa m^0.5) | " : "", kic ? "---|---|" : "");
  for (size_t i = 0; i < hist_.size(); ++i) {
    const auto& it = hist_[i];
    const Measured m = it.measured();
    md << fmt::format(
        "| {} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {}{:.0f} | {:g} | {:.2f} | {:.3f} | {:.2f} | "
        "{:.2f} | {:.2f} | {}{:.0f} |\n",
        i + 1, it.p.modulus / 1e9, it.p.stiffness_ratio, it.p.tensile / 1e6, it.p.cohesion / 1e6,
        kic ? fmt::format("{:.3g} | ", it.p.softening) : std::string(), it.p.friction_angle_deg,
        it.p.moment_factor, m.E / 1e9, m.nu, m.ucs / 1e6, m.tensile / 1e6, m.ucs / m.tensile,
        !kic     ? std::string()
        : it.scb ? fmt::format("{:.3f} | ", it.scb->toughness / 1e6)
                 : std::string("- | "),
        iteration_seconds(it));
  }
  if (half_)
    md << fmt::format(
        "\n## Loading rate\n\nUCS at {:g} 1/s: {:.2f} MPa; at {:g} 1/s: {:.2f} MPa; change {:.1f}% "
        "({}).\n",
        rate_, b_.ucs.r.ucs / 1e6, 0.5 * rate_, half_->r.ucs / 1e6, 100 * rate_change_,
        rate_ok_ ? "below 5%: quasi-static" : "5% or more: lower calibrate.strain_rate");
  else
    md << "\n## Loading rate\n\nNot checked (calibrate.rate_check: false).\n";
  md << (o_.packing ? packing_markdown(*o_.packing)
                    : std::string("\n## Packing check\n\nNot run (calibrate.packing_check: 0).\n"));
  if (!o_.sensitivity.empty())
    md << sensitivity_markdown(b_, o_.sensitivity, tol_, noise_);
  else
    md << "\n## Lever sensitivities\n\nNot measured (calibrate.sensitivity: false).\n";
  md << checks_markdown(o_.checks, b_.ucs.r.ucs);
  md << energy_markdown(o_);
  md << fmt::format(
      "\n## Specimens\n\nCarved from a ball of {} elements (seed {}), mean element radius {:.3f} "
      "mm (as the "
      "lump). UCS cylinder: {:g} elements, diameter {:.2f} mm, height {:.2f} mm. Brazilian disc: "
      "{:g} "
      "elements, diameter {:.2f} mm, thickness {:.2f} mm.\n",
      sp_.ball_elements, d_.integer("calibrate.seed"), sp_.mean_radius * 1e3,
      info_or_zero(ui_, "atoms"), info_or_zero(ui_, "diameter") * 1e3,
      info_or_zero(ui_, "height") * 1e3, info_or_zero(bi_, "atoms"),
      info_or_zero(bi_, "diameter") * 1e3, info_or_zero(bi_, "thickness") * 1e3);
  if (!missed_.empty()) {
    md << "\n## Not reached\n\n";
    for (const auto& m : missed_) md << "- " << m << "\n";
  }
  if (!notes_.empty()) {
    md << "\n## Notes\n\n";
    for (const auto& n : notes_) md << "- " << n << "\n";
  }
  return md.str();
}

// Curves of every run (aggregated; the plots read only this and report.json).
std::string Report::curves() const {
  std::ostringstream cv;
  cv << "run,iteration,test,strain_rate,displacement_m,force_N,strain,stress_Pa,lateral_strain\n";
  for (size_t i = 0; i < hist_.size(); ++i) {
    const auto& it = hist_[i];
    append_curves(cv, fmt::format("it{}_ucs", i + 1), static_cast<int>(i + 1), "ucs", rate_,
                  it.ucs.curve, it.ucs.ss.strain, it.ucs.ss.stress);
    const double D = info_or_zero(it.br.info, "diameter"),
                 th = info_or_zero(it.br.info, "thickness");
    std::vector<double> strain, stress;
    for (size_t j = 0; j < it.br.curve.size(); ++j) {
      strain.push_back(it.br.curve.displacement[j] / D);
      stress.push_back(post::BrazilianTensileStrength(it.br.curve.force(j), D, th));
    }
    append_curves(cv, fmt::format("it{}_brazilian", i + 1), static_cast<int>(i + 1), "brazilian",
                  rate_, it.br.curve, strain, stress);
    if (it.tension)
      append_curves(cv, fmt::format("it{}_tension", i + 1), static_cast<int>(i + 1), "tension",
                    rate_, it.tension->curve, it.tension->ss.strain, it.tension->ss.stress);
  }
  if (half_)
    append_curves(cv, "rate_check_ucs", static_cast<int>(best_ + 1), "ucs", 0.5 * rate_,
                  half_->curve, half_->ss.strain, half_->ss.stress);
  for (const TriaxialRun& t : o_.checks.triaxial) {
    const post::StressStrain ss = post::ToStressStrain(
        t.curve, info_or_zero(t.info, "gauge_length"), info_or_zero(t.info, "end_area"));
    append_curves(cv, t.tag, static_cast<int>(best_ + 1), "triaxial", rate_, t.curve, ss.strain,
                  ss.stress);
  }
  return cv.str();
}

// The one-line result for the log.
std::string Report::summary() const {
  return fmt::format(
      "[calibrate] {}: E {:.2f} GPa, nu {:.3f}, UCS {:.1f} MPa, tensile {:.2f} MPa "
      "(iteration {}){}{}",
      b_.converged ? "converged" : "NOT all targets reached", bm_.E / 1e9, bm_.nu, bm_.ucs / 1e6,
      bm_.tensile / 1e6, best_ + 1,
      half_ ? fmt::format("; rate check: UCS changes {:.1f}% at half the rate", 100 * rate_change_)
            : "",
      o_.checks.mc ? fmt::format("; envelope (a check, not fitted): friction angle {:.1f} deg, "
                                 "cohesion {:.2f} MPa",
                                 o_.checks.mc->friction_angle_deg, o_.checks.mc->cohesion / 1e6)
                   : "");
}

}  // namespace

// calibrated.yaml, report.json, report.md, curves.csv and plots in the job folder.
void write_outputs(StageContext& ctx, const fs::path& dir, const Fitting& fit, const Outcome& o) {
  const Report r(ctx.cfg, fit, o);
  jobs::atomic_write(dir / "curves.csv", r.curves());
  jobs::atomic_write(dir / "report.json", r.json().dump(2) + "\n");
  jobs::atomic_write(dir / "report.md", r.markdown());
  engine::run_python(ctx.runner, ctx.cfg.project_dir / "postprocess" / "plot_lab_tests.py",
                     {"--curves", (dir / "curves.csv").string(), "--report",
                      (dir / "report.json").string(), "--out", (dir / "plots").string()},
                     dir / "plots.log", "calibrate/plots");
  // Last: the file the breakage stage reads.
  jobs::atomic_write(
      dir / "calibrated.yaml",
      "# Bond (micro) parameters fitted by `orchestrate --stage calibrate` (docs/calibration.md).\n"
      "# The calibrated: map may be pasted into the ore card; input_hash ties it to the card's\n"
      "# macro properties.\n" +
          r.yaml() + "\n");
  ctx.progress.info(r.summary());
  for (const auto& m : r.missed()) ctx.progress.warn("[calibrate] not reached: " + m);
  if (!o.checks.envelope_error.empty())
    ctx.progress.warn("[calibrate] check: no failure envelope from the triaxial peaks: " +
                      o.checks.envelope_error);
}

// The card's own calibrated.* section, copied (no fitting).
void copy_from_card(StageContext& ctx, const fs::path& dir) {
  const auto& o = ctx.cfg.ore;
  const std::string hash = calibration_hash(ctx.cfg);
  YAML::Emitter y;
  y.SetDoublePrecision(8);
  y << YAML::BeginMap;
  emit_calibrated(y, read_calibrated(o, BondParams{}), hash, lump_scale(ctx.cfg));
  y << YAML::Key << "ore" << YAML::Value << o.str("name") << YAML::Key << "source" << YAML::Value
    << "ore card " + ctx.cfg.ore_file.string() << YAML::EndMap;
  const nlohmann::json report = {
      {"ore", o.str("name")},
      {"input_hash", hash},
      {"source", "ore card"},
      {"ore_card", ctx.cfg.ore_file.string()},
      {"note", "the ore card carries calibrated.* fitted to its own properties: no fitting run"}};
  jobs::atomic_write(dir / "report.json", report.dump(2) + "\n");
  jobs::atomic_write(
      dir / "report.md",
      fmt::format(
          "# Calibration of {}\n\nTaken from the ore card {} (its calibrated.input_hash matches "
          "the card's properties): no virtual lab tests were run.\n",
          o.str("name"), ctx.cfg.ore_file.string()));
  jobs::atomic_write(
      dir / "calibrated.yaml",
      "# Copied from the ore card's calibrated: section.\n" + std::string(y.c_str()) + "\n");
}

}  // namespace mill::calibrate
