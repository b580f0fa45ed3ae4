// The levers' sensitivities: the runs, the arithmetic and the reports.
#include "stages/calibrate/sensitivity.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <sstream>
#include <stdexcept>

#include "engine/runner.h"
#include "stages/stage_util.h"

#include "postprocess/lab_tests.h"
#include "stages/calibrate/energy_report.h"

namespace mill::calibrate {

namespace {

// The targets in report order: report.json key, report.md name.
struct TargetName {
  const char* json;
  const char* md;
};
constexpr TargetName kTargets[] = {{"youngs_modulus", "E"},
                                   {"poisson_ratio", "nu"},
                                   {"ucs", "UCS"},
                                   {"tensile_strength", "tensile"}};

// The responses of s in the order of kTargets.
const TargetResponse* responses(const LeverSensitivity& s, size_t k) {
  const TargetResponse* r[] = {&s.E, &s.nu, &s.ucs, &s.tensile};
  return r[k];
}

// The noise of the target k of kTargets.
double noise_of(const Noise& n, size_t k) {
  const double v[] = {n.E, n.nu, n.ucs, n.tensile};
  return v[k];
}

// The tolerance per step of target k: relative, nu absolute.
double tolerance_of(double tol, size_t k) { return k == 1 ? kNuTolerance : tol; }

// The items separated by `sep`.
std::string join(const std::vector<std::string>& items, const char* sep) {
  std::string out;
  for (const std::string& i : items) out += (out.empty() ? "" : sep) + i;
  return out;
}

// The lever's name: its calibrated.yaml key.
std::string lever_name(const Lever& l) { return l.row->calibrated; }

// A value of the lever in its unit, Pa shown in MPa or GPa.
std::string lever_value(const Lever& l, double v) {
  const std::string unit = l.row->unit;
  if (unit == "Pa")
    return std::abs(v) >= 1e9 ? fmt::format("{:.4g} GPa", v / 1e9)
                              : fmt::format("{:.4g} MPa", v / 1e6);
  return unit.empty() ? fmt::format("{:.4g}", v) : fmt::format("{:.4g} {}", v, unit);
}

}  // namespace

// The step in words: "x1.2 (57.8 GPa -> 69.36 GPa)" or "+5 deg (60 deg -> 65 deg)".
std::string step_text(const Lever& l) {
  const std::string unit = l.row->unit;
  const std::string how =
      l.multiplicative
          ? fmt::format("x{:g}", l.to / l.from)
          : fmt::format("{:+g}{}", l.to - l.from, unit.empty() ? "" : " " + unit);
  return fmt::format("{} ({} -> {})", how, lever_value(l, l.from), lever_value(l, l.to));
}

namespace {

// The documented default of a lever: the table's start, or where it comes from.
std::string lever_default(const Lever& l) {
  return std::isnan(l.row->start) ? std::string("the closed-form estimate from the card")
                                  : lever_value(l, l.row->start);
}

}  // namespace

std::vector<Lever> sensitivity_levers(const BondParams& p) {
  std::vector<Lever> levers;
  for (const BondParameter& row : kBondParameters) {
    if (!row.calibrated) continue;  // not fitted: the case sets it
    if (row.parallel_only && p.model != BondModel::parallel) continue;
    if (row.joint_only && p.model != BondModel::flat_joint) continue;
    Lever l;
    l.row = &row;
    l.from = p.*row.value;
    const std::string json = row.json;
    if (json == "friction_angle_deg") {
      l.multiplicative = false;
      l.to = l.from + kFrictionStepDeg < row.range.max ? l.from + kFrictionStepDeg
                                                       : l.from - kFrictionStepDeg;
    } else if (json == "moment_factor") {
      l.multiplicative = false;
      l.to = l.from > 0.0 ? std::clamp(l.from - kMomentFactorStep, 0.0, 1.0)
                          : kMomentFactorStep;
    } else {
      // A scale (a modulus, a ratio, a strength): positive, stepped by a factor.
      if (!(l.from > 0.0))
        throw std::logic_error(fmt::format(
            "sensitivity: lever {} is {:g}, not positive: no multiplicative step", json, l.from));
      l.to = kSensitivityFactor * l.from;
    }
    levers.push_back(l);
  }
  return levers;
}

BondParams perturbed(const BondParams& p, const Lever& l) {
  BondParams q = p;
  q.*(l.row->value) = l.to;
  q.origin = fmt::format("{} with {} {}", p.origin, lever_name(l), step_text(l));
  return q;
}

Noise sensitivity_noise(const UcsRun& result, const UcsRun* half) {
  Noise n;
  if (!half) return n;
  n.E = std::max(n.E, post::RelativeError(half->r.youngs_modulus, result.r.youngs_modulus));
  n.nu = std::max(n.nu, std::abs(half->r.poisson_ratio - result.r.poisson_ratio));
  n.ucs = std::max(n.ucs, post::RelativeError(half->r.ucs, result.r.ucs));
  n.tensile = std::max(n.tensile, post::RelativeError(half->r.ucs, result.r.ucs));
  return n;
}

LeverSensitivity lever_sensitivity(const Iteration& base, const LeverRun& run) {
  const Lever& l = run.lever;
  LeverSensitivity s;
  s.lever = l;
  // Per unit of the lever: its relative step (multiplicative) or its step.
  const double dx = l.multiplicative ? l.to / l.from - 1.0 : l.to - l.from;
  const double dlnx = l.multiplicative ? std::log(l.to / l.from) : l.to - l.from;
  auto relative = [&](double now, double before) {
    TargetResponse r;
    r.change = now / before - 1.0;
    r.value = r.change / dx;
    return r;
  };
  s.E = relative(run.ucs.r.youngs_modulus, base.ucs.r.youngs_modulus);
  s.ucs = relative(run.ucs.r.ucs, base.ucs.r.ucs);
  s.tensile = relative(run.br.r.tensile_strength, base.br.r.tensile_strength);
  s.nu.change = run.ucs.r.poisson_ratio - base.ucs.r.poisson_ratio;
  s.nu.value = s.nu.change / dlnx;
  return s;
}

std::string sensitivity_unit(const Lever& l, bool nu) {
  if (l.multiplicative) return nu ? "1 per e-fold (d nu / d ln x)" : "elasticity (dT/T)/(dx/x)";
  const std::string per = *l.row->unit ? l.row->unit : "unit";
  return nu ? "d nu per " + per : "dT/T per " + per;
}

LeverVerdict lever_verdict(const LeverSensitivity& s, double tol, const Noise& noise) {
  LeverVerdict v;
  for (size_t k = 0; k < std::size(kTargets); ++k) {
    const double change = std::abs(responses(s, k)->change);
    if (change > tolerance_of(tol, k)) v.strong.push_back(kTargets[k].md);
    if (change > noise_of(noise, k)) v.above_noise.push_back(kTargets[k].md);
  }
  return v;
}

nlohmann::json sensitivity_json(const Iteration& base, const std::vector<LeverRun>& runs,
                                double tol, const Noise& noise) {
  nlohmann::json levers = nlohmann::json::object();
  nlohmann::json not_free = nlohmann::json::array();
  for (const LeverRun& run : runs) {
    const LeverSensitivity s = lever_sensitivity(base, run);
    const LeverVerdict v = lever_verdict(s, tol, noise);
    const Lever& l = run.lever;
    nlohmann::json targets = nlohmann::json::object();
    for (size_t k = 0; k < std::size(kTargets); ++k)
      targets[kTargets[k].json] = {{"value", responses(s, k)->value},
                                   {"change", responses(s, k)->change},
                                   {"unit", sensitivity_unit(l, k == 1)}};
    levers[lever_name(l)] = {
        {"step",
         {{"kind", l.multiplicative ? "multiply" : "add"},
          {"size", l.multiplicative ? l.to / l.from : l.to - l.from},
          {"from", l.from},
          {"to", l.to},
          {"unit", l.row->unit}}},
        {"targets", targets},
        {"achieved",
         {{"youngs_modulus", run.ucs.r.youngs_modulus},
          {"poisson_ratio", run.ucs.r.poisson_ratio},
          {"ucs", run.ucs.r.ucs},
          {"tensile_strength", run.br.r.tensile_strength}}},
        {"moves_beyond_tolerance", v.strong},
        {"moves_beyond_noise", v.above_noise},
        {"free", v.free()},
        {"default", std::isnan(l.row->start) ? nlohmann::json("from the card")
                                             : nlohmann::json(l.row->start)},
        {"runs", {run.ucs.tag, run.br.tag}},
        {"ucs_peaked", run.ucs.peaked},
        {"brazilian_peaked", run.br.peaked},
        {"energy",
         {{"ucs", lab_energy_json(run.ucs.energy)}, {"brazilian", lab_energy_json(run.br.energy)}}},
        {"wall_seconds", run.ucs.seconds + run.br.seconds}};
    if (!v.free()) not_free.push_back(lever_name(l));
  }
  double wall = 0;
  for (const LeverRun& run : runs) wall += run.ucs.seconds + run.br.seconds;
  return {
      {"definition",
       "each fitted bond parameter stepped alone from the result's (a UCS and a Brazilian test "
       "each); value: for a multiplied lever the elasticity (dT/T)/(dx/x) of E, UCS and tensile "
       "strength and d nu / d ln x of nu; for an added one (friction angle, moment factor) dT/T "
       "and d nu per unit of the lever (per deg); change: what the step did (dT/T; nu: d nu)"},
      {"noise",
       {{"youngs_modulus", noise.E},
        {"poisson_ratio", noise.nu},
        {"ucs", noise.ucs},
        {"tensile_strength", noise.tensile},
        {"note",
         "run-to-run noise of a step's change: at least 1 % (nu 0.005), raised to the rate "
         "check's changes (the UCS's also for the tensile strength)"}}},
      {"tolerance", {{"relative", tol}, {"poisson_ratio_absolute", kNuTolerance}}},
      {"levers", levers},
      {"not_free", not_free},
      {"wall_seconds", wall}};
}

std::string sensitivity_markdown(const Iteration& base, const std::vector<LeverRun>& runs,
                                 double tol, const Noise& noise) {
  std::ostringstream md;
  md << "\n## Lever sensitivities\n\n"
        "Each fitted bond parameter stepped alone from the result's, one UCS and one Brazilian "
        "test each (runs `sens_<lever>_ucs`, `sens_<lever>_brazilian`). A multiplied lever (x) "
        "gives the elasticity (dT/T)/(dx/x) of E, UCS and tensile strength and d nu / d ln x of "
        "nu; an added one (+) gives dT/T and d nu per unit of the lever (friction angle: per "
        "deg; moment factor: per unit of beta). In brackets what the step did: dT/T (nu: d "
        "nu).\n\n"
        "| lever | step | E | nu | UCS | tensile | free |\n|---|---|---|---|---|---|---|\n";
  std::vector<std::string> strong_lines, not_free;
  for (const LeverRun& run : runs) {
    const LeverSensitivity s = lever_sensitivity(base, run);
    const LeverVerdict v = lever_verdict(s, tol, noise);
    const auto rel = [](const TargetResponse& r) {
      return fmt::format("{:+.3g} ({:+.1f}%)", r.value, 100 * r.change);
    };
    md << fmt::format("| {} | {} | {} | {:+.3g} ({:+.3f}) | {} | {} | {} |\n", lever_name(s.lever),
                      step_text(s.lever), rel(s.E), s.nu.value, s.nu.change, rel(s.ucs),
                      rel(s.tensile), v.free() ? "yes" : "**no**");
    if (!v.strong.empty())
      strong_lines.push_back(fmt::format("{} ({})", lever_name(s.lever),
                                         join(v.strong, ", ")));
    if (!v.free())
      not_free.push_back(fmt::format("{} (default: {})", lever_name(s.lever),
                                     lever_default(s.lever)));
  }
  md << fmt::format("\nMoving a target by more than the tolerance ({:g} %, nu {:g}) per step: {}.",
                    100 * tol, kNuTolerance,
                    strong_lines.empty() ? std::string("no lever")
                                         : join(strong_lines, "; "));
  const std::string noise_text =
      fmt::format("E {:.2g} %, nu {:.2g}, UCS {:.2g} %, tensile {:.2g} %", 100 * noise.E,
                  noise.nu, 100 * noise.ucs, 100 * noise.tensile);
  if (not_free.empty())
    md << fmt::format(
        " Every lever moves at least one target by more than the run-to-run noise ({}).\n",
        noise_text);
  else
    md << fmt::format(
        " Moving no target by more than the run-to-run noise ({}): {}. {} not free: {} should "
        "stay at {} documented default{} (docs/calibration.md, \"The bond parameters\").\n",
        noise_text, join(not_free, ", "), not_free.size() == 1 ? "It is" : "They are",
        not_free.size() == 1 ? "it" : "they", not_free.size() == 1 ? "its" : "their",
        not_free.size() == 1 ? "" : "s");
  return md.str();
}

std::vector<LeverRun> run_sensitivity(LabBench& lab, const BondParams& p, double rate, double done,
                                      double step_share) {
  const std::vector<Lever> levers = sensitivity_levers(p);
  std::vector<LeverRun> runs(levers.size());
  // Every lever's two tests are independent runs: as many at once as the
  // job has lanes.
  std::vector<std::function<void()>> tasks;
  for (size_t k = 0; k < levers.size(); ++k) {
    const Lever& l = levers[k];
    runs[k].lever = l;
    const std::string name = lever_name(l), tag = "sens_" + name;
    const double at = done + 2.0 * static_cast<double>(k) * step_share;
    const auto named = [name, tag](const std::function<void()>& f) {
      return [f, name, tag] {
        try {
          f();
        } catch (const engine::Interrupted&) {
          throw;
        } catch (const std::exception& e) {
          throw std::runtime_error(
              fmt::format("sensitivity of {} (runs/{}_*): {}", name, tag, e.what()));
        }
      };
    };
    tasks.push_back(named([&lab, &runs, &levers, &p, rate, k, name, tag, at] {
      runs[k].ucs = lab.ucs(perturbed(p, levers[k]), rate,
                            {tag + "_ucs",
                             fmt::format("sensitivity {}/{}: {} {}: UCS", k + 1, levers.size(),
                                         name, step_text(levers[k])),
                             at});
    }));
    tasks.push_back(named([&lab, &runs, &levers, &p, rate, k, name, tag, at, step_share] {
      runs[k].br = lab.brazilian(perturbed(p, levers[k]), rate,
                                 {tag + "_brazilian",
                                  fmt::format("sensitivity {}/{}: {} {}: Brazilian", k + 1,
                                              levers.size(), name, step_text(levers[k])),
                                  at + step_share});
    }));
  }
  run_concurrently(tasks, lab.lanes());
  return runs;
}

}  // namespace mill::calibrate
