// The checks after the fit (docs/calibration.md, "Checks after the fit"):
// with the result's bond parameters, triaxial tests at the case's confining
// pressures (fractions of the UCS reached) give the failure envelope (Mohr-Coulomb friction angle
// and cohesion, Hoek-Brown m_i, from the UCS and the triaxial peaks) and, when the ore card gives
// K_IC, a semi-circular bend test gives the toughness. They are compared with the card's optional
// friction_angle, hoek_brown_mi and fracture_toughness; no lever moves on them.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "config/case_config.h"
#include "postprocess/lab_tests.h"
#include "stages/calibrate/lab_runs.h"

namespace mill::calibrate {

// The card's optional targets of the checks; absent keys are empty.
struct CheckTargets {
  std::optional<double> friction_angle_deg, hoek_brown_mi, fracture_toughness;
};

CheckTargets check_targets(const config::Document& ore);

// What the checks measured.
struct Checks {
  CheckTargets targets;
  std::vector<TriaxialRun> triaxial;    // one per confining pressure that ran, in the case's order
  std::vector<std::string> failed;      // the triaxial runs that failed, each with its reason
  std::optional<post::MohrCoulomb> mc;  // from the UCS and the triaxial peaks
  std::optional<post::HoekBrown> hb;    // from the same points
  std::string envelope_error;           // why an envelope could not be fitted, else ""
  std::optional<ScbRun> scb;            // only when the card gives fracture_toughness
  std::vector<std::string> notes;       // what limits the checks' meaning, in words
  bool toughness_fitted = false;        // K_IC was a target of the fit (calibrate.fit_toughness)
};

// The confining pressures [Pa] of the checks: calibrate.confining_pressures
// (fractions) x the UCS the result reached, so that a fit that missed the
// card's UCS is still confined within the range where the virtual test
// follows Mohr-Coulomb (below about UCS/4); with the UCS met it is the card's.
std::vector<double> confining_pressures(const config::Document& d, double ucs_reached);

// Runs the checks with bond parameters p; `ucs` is the result's UCS test
// (the envelope's point at sigma_3 = 0). Each run's progress starts at
// done + k x step_share of the job. The bend test (a card with K_IC) runs
// scb_orientations half discs, unless `fitted_scb` is given: the result's own
// bend test from the fit (calibrate.fit_toughness), which the check reports
// instead of repeating it.
Checks run_checks(LabBench& lab, const BondParams& p, const UcsRun& ucs, double rate,
                  const std::vector<double>& pressures, const CheckTargets& targets, double done,
                  double step_share, int scb_orientations, const ScbRun* fitted_scb = nullptr);

// report.json's `checks` object.
nlohmann::json checks_json(const Checks& c, double ucs_peak);

// report.md's "Checks after the fit" section.
std::string checks_markdown(const Checks& c, double ucs_peak);

}  // namespace mill::calibrate
