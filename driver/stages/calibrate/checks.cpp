// The checks after the fit: triaxial envelope and semi-circular bend toughness.
#include "stages/calibrate/checks.h"

#include <fmt/format.h>

#include <functional>
#include <sstream>
#include <stdexcept>

#include "engine/runner.h"
#include "stages/stage_util.h"

#include "stages/calibrate/energy_report.h"

namespace mill::calibrate {

namespace {

// The card's value of an optional key, empty when absent.
std::optional<double> optional_real(const config::Document& ore, const std::string& key) {
  return ore.has(key) ? std::optional<double>(ore.real(key)) : std::nullopt;
}

// {target, achieved, relative_error}; target and error null without a target.
nlohmann::json compared(const std::optional<double>& target, std::optional<double> achieved) {
  nlohmann::json j = {{"target", target ? nlohmann::json(*target) : nlohmann::json(nullptr)},
                      {"achieved", achieved ? nlohmann::json(*achieved) : nlohmann::json(nullptr)},
                      {"relative_error", nullptr}};
  if (target && achieved) j["relative_error"] = post::RelativeError(*achieved, *target);
  return j;
}

// One row of report.md's comparison table.
std::string compared_row(const char* what, const std::optional<double>& target,
                         const std::optional<double>& achieved, double scale, int digits) {
  const auto v = [&](const std::optional<double>& x) {
    return x ? fmt::format("{:.{}f}", *x / scale, digits) : std::string("-");
  };
  return fmt::format("| {} | {} | {} | {} |\n", what, v(target), v(achieved),
                     target && achieved
                         ? fmt::format("{:.1f}%", 100 * post::RelativeError(*achieved, *target))
                         : std::string("-"));
}

}  // namespace

CheckTargets check_targets(const config::Document& ore) {
  return {optional_real(ore, "friction_angle"), optional_real(ore, "hoek_brown_mi"),
          optional_real(ore, "fracture_toughness")};
}

std::vector<double> confining_pressures(const config::Document& d, double ucs_reached) {
  std::vector<double> p;
  for (double f : d.reals("calibrate.confining_pressures")) p.push_back(f * ucs_reached);
  return p;
}

namespace {

// An engine failure in one line: its first line and the engine's own ERROR
// line from the log's tail (the run's folder keeps the whole log).
std::string engine_error_gist(const std::string& what) {
  std::istringstream in(what);
  std::string first, line, error;
  std::getline(in, first);
  while (std::getline(in, line)) {
    const auto at = line.find("ERROR");
    if (at != std::string::npos && error.empty()) error = line.substr(at);
  }
  return error.empty() ? first : first + ": " + error;
}

}  // namespace

// Triaxial runs, the envelope through their peaks and the UCS, then the SCB run.
Checks run_checks(LabBench& lab, const BondParams& p, const UcsRun& ucs, double rate,
                  const std::vector<double>& pressures, const CheckTargets& targets, double done,
                  double step_share, int scb_orientations, const ScbRun* fitted_scb) {
  Checks c;
  c.targets = targets;
  std::vector<post::StrengthPoint> points = {{0.0, ucs.r.ucs}};
  // The triaxial tests side by side when the job has lanes for them. A run
  // that fails (its engine stopped: e.g. the energy ledger found energy
  // created) is a failed check, named in the notes and left out of the
  // envelope; the fit it checks stands (the report says which check did
  // not run and why).
  std::vector<std::optional<TriaxialRun>> runs(pressures.size());
  std::vector<std::string> failed(pressures.size());
  std::vector<std::function<void()>> tasks;
  for (size_t k = 0; k < pressures.size(); ++k)
    tasks.push_back([&, k] {
      const std::string tag = fmt::format("triaxial_{}", k + 1);
      try {
        runs[k] =
            lab.triaxial(p, rate, pressures[k],
                         {tag, fmt::format("check: triaxial at {:.3g} MPa", pressures[k] / 1e6),
                          done + static_cast<double>(k) * step_share});
      } catch (const engine::Interrupted&) {
        throw;
      } catch (const std::exception& e) {
        failed[k] =
            fmt::format("{} (runs/{}, confinement {:.3g} MPa) failed, left out of the envelope: {}",
                        tag, tag, pressures[k] / 1e6, engine_error_gist(e.what()));
      }
    });
  run_concurrently(tasks, lab.lanes());
  for (size_t k = 0; k < pressures.size(); ++k) {
    if (!runs[k]) {
      c.notes.push_back(failed[k]);
      c.failed.push_back(failed[k]);
      continue;
    }
    const TriaxialRun& t = c.triaxial.emplace_back(std::move(*runs[k]));
    points.push_back({t.r.sigma3, t.r.sigma1});
    if (!t.peaked) c.notes.push_back(t.tag + ": reached its strain cap still loading");
  }
  try {
    c.mc = post::FitMohrCoulomb(points);
  } catch (const std::exception& e) {
    c.envelope_error = e.what();
  }
  try {
    c.hb = post::FitHoekBrown(points);
  } catch (const std::exception& e) {
    c.envelope_error += (c.envelope_error.empty() ? "" : "; ") + std::string(e.what());
  }
  if (targets.fracture_toughness && fitted_scb) {
    c.scb = *fitted_scb;
  } else if (targets.fracture_toughness) {
    try {
      c.scb = lab.scb(p, rate, scb_orientations,
                      {"scb", "check: semi-circular bend",
                       done + static_cast<double>(pressures.size()) * step_share});
    } catch (const ScbTooCoarse& e) {
      // A check on a specimen too coarse for it: no K_IC, said so (the
      // toughness fit stops on the same error instead).
      c.notes.push_back(fmt::format("scb: not measured: {}", e.what()));
    } catch (const std::exception& e) {
      throw std::runtime_error(fmt::format("check scb (runs/scb): {}", e.what()));
    }
  }
  if (c.scb && !c.scb->peaked) c.notes.push_back("scb: a half disc reached its cap still loading");
  return c;
}

// Runs, envelope, targets and their comparison.
nlohmann::json checks_json(const Checks& c, double ucs_peak) {
  nlohmann::json tri = nlohmann::json::array();
  nlohmann::json points = nlohmann::json::array({{{"sigma3_Pa", 0.0}, {"sigma1_Pa", ucs_peak}}});
  for (const TriaxialRun& t : c.triaxial) {
    tri.push_back({{"run", t.tag},
                   {"confining_pressure_Pa", t.pressure},
                   {"sigma3_Pa", t.r.sigma3},
                   {"sigma1_Pa", t.r.sigma1},
                   {"deviator_Pa", t.r.deviator},
                   {"strain_at_peak", t.r.strain_at_peak},
                   {"bonds_broken_by_confinement", t.r.broken_before_loading},
                   {"peaked", t.peaked},
                   {"energy", lab_energy_json(t.energy)},
                   {"wall_seconds", t.seconds}});
    points.push_back({{"sigma3_Pa", t.r.sigma3}, {"sigma1_Pa", t.r.sigma1}});
  }
  nlohmann::json env = {
      {"points", points},
      {"mohr_coulomb", c.mc ? nlohmann::json{{"friction_angle_deg", c.mc->friction_angle_deg},
                                             {"cohesion_Pa", c.mc->cohesion},
                                             {"ucs_Pa", c.mc->ucs},
                                             {"q", c.mc->q}}
                            : nlohmann::json(nullptr)},
      {"hoek_brown", c.hb ? nlohmann::json{{"m_i", c.hb->m_i}, {"sigma_ci_Pa", c.hb->sigma_ci}}
                          : nlohmann::json(nullptr)},
      {"error",
       c.envelope_error.empty() ? nlohmann::json(nullptr) : nlohmann::json(c.envelope_error)}};
  nlohmann::json scb = nullptr;
  if (c.scb) {
    nlohmann::json discs = nlohmann::json::array();
    for (const ScbDisc& d : c.scb->discs)
      discs.push_back({{"run", d.tag},
                       {"angle_deg", d.angle_deg},
                       {"elements", d.info.count("atoms") ? d.info.at("atoms") : 0.0},
                       {"radius_m", d.info.count("radius") ? d.info.at("radius") : 0.0},
                       {"peak_force_N", d.r.peak_force},
                       {"geometry_factor", d.r.geometry_factor},
                       {"fracture_toughness_Pa_m0.5", d.r.toughness},
                       {"peaked", d.peaked},
                       {"energy", lab_energy_json(d.energy)},
                       {"wall_seconds", d.seconds}});
    scb = {{"run", c.scb->tag()},
           {"half_discs", c.scb->discs.size()},
           {"peak_force_N", c.scb->peak_force},
           {"fracture_toughness_Pa_m0.5", c.scb->toughness},
           {"fracture_toughness_sem_Pa_m0.5", c.scb->toughness_sem},
           {"peaked", c.scb->peaked},
           {"discs", discs},
           {"wall_seconds", c.scb->seconds}};
  }
  const auto mc = [&](auto f) { return c.mc ? std::optional<double>(f(*c.mc)) : std::nullopt; };
  return {
      {"note",
       c.toughness_fitted
           ? "checks with the result's bond parameters; the envelope is not fitted (no bond "
             "parameter moves on it); K_IC was a target of the fit (calibrate.fit_toughness): its "
             "bend test here is the result's own, not run again"
           : "checks with the result's bond parameters, not fitted: not a lever yet (no bond "
             "parameter moves on them)"},
      {"toughness_fitted", c.toughness_fitted},
      {"triaxial", tri},
      {"envelope", env},
      {"scb", scb},
      {"notes", c.notes},
      {"failed", c.failed},
      {"against_card",
       {{"friction_angle",
         compared(c.targets.friction_angle_deg,
                  mc([](const post::MohrCoulomb& m) { return m.friction_angle_deg; }))},
        {"hoek_brown_mi",
         compared(c.targets.hoek_brown_mi, c.hb ? std::optional<double>(c.hb->m_i) : std::nullopt)},
        {"fracture_toughness",
         compared(c.targets.fracture_toughness,
                  c.scb ? std::optional<double>(c.scb->toughness) : std::nullopt)}}}};
}

// Peaks, envelope and the card's values, with what they are not.
std::string checks_markdown(const Checks& c, double ucs_peak) {
  std::ostringstream md;
  md << "\n## Checks after the fit (not a lever yet)\n\n"
        "The result's bond parameters in triaxial tests (confinement on the lateral shell, "
        "docs/calibration.md) and, when the ore card gives K_IC, a semi-circular bend test. ";
  md << (c.toughness_fitted
             ? "The envelope is a check, not fitted: no bond parameter moves on it. K_IC was a "
               "target of the fit (calibrate.fit_toughness): the bend test here is the "
               "result's own, not run again.\n\n"
             : "These are checks, not fitted: no bond parameter moves on them.\n\n");
  md << "| run | sigma_3 (MPa) | peak sigma_1 (MPa) | sigma_1 - sigma_3 (MPa) | peaked |\n"
        "|---|---|---|---|---|\n";
  md << fmt::format("| UCS (result) | 0 | {:.2f} | {:.2f} | |\n", ucs_peak / 1e6, ucs_peak / 1e6);
  for (const TriaxialRun& t : c.triaxial)
    md << fmt::format("| {} | {:.2f} | {:.2f} | {:.2f} | {} |\n", t.tag, t.r.sigma3 / 1e6,
                      t.r.sigma1 / 1e6, t.r.deviator / 1e6, t.peaked ? "yes" : "no (cap)");
  md << "\n";
  if (c.mc)
    md << fmt::format(
        "Mohr-Coulomb through the {} peaks: friction angle {:.1f} deg, cohesion {:.2f} MPa "
        "(sigma_1 = {:.2f} MPa + {:.2f} sigma_3). ",
        c.triaxial.size() + 1, c.mc->friction_angle_deg, c.mc->cohesion / 1e6, c.mc->ucs / 1e6,
        c.mc->q);
  if (c.hb)
    md << fmt::format("Hoek-Brown: m_i {:.1f}, sigma_ci {:.2f} MPa. ", c.hb->m_i,
                      c.hb->sigma_ci / 1e6);
  if (!c.envelope_error.empty()) md << "Not fitted: " << c.envelope_error << ".";
  md << "\n";
  if (c.scb)
    md << fmt::format("\nSemi-circular bend: mean peak {:.1f} N, K_IC {}{}.\n", c.scb->peak_force,
                      c.scb->summary(),
                      c.scb->peaked ? "" : " (a half disc reached its cap still loading)");
  md << "\n| property | ore card | achieved | error |\n|---|---|---|---|\n";
  md << compared_row("friction angle (deg)", c.targets.friction_angle_deg,
                     c.mc ? std::optional<double>(c.mc->friction_angle_deg) : std::nullopt, 1.0, 1);
  md << compared_row("Hoek-Brown m_i", c.targets.hoek_brown_mi,
                     c.hb ? std::optional<double>(c.hb->m_i) : std::nullopt, 1.0, 1);
  md << compared_row("K_IC (MPa m^0.5)", c.targets.fracture_toughness,
                     c.scb ? std::optional<double>(c.scb->toughness) : std::nullopt, 1e6, 3);
  if (!c.notes.empty()) md << "\n";
  for (const std::string& n : c.notes) md << "- " << n << "\n";
  return md.str();
}

}  // namespace mill::calibrate
