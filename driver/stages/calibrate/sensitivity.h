// The levers' sensitivities after the fit (docs/calibration.md, "Lever
// sensitivities"): with the result's bond parameters p*, one UCS and one
// Brazilian test per fitted bond parameter (row of kBondParameters with a
// calibrated name; the parallel-bond-only rows for the parallel bond only),
// each parameter stepped alone; per lever and target, the change per change
// in the lever. A lever that moves no target by more than the run-to-run
// noise is not free: it should stay at its documented default.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "lump/bond_parameters.h"
#include "stages/calibrate/fitting.h"
#include "stages/calibrate/lab_runs.h"

namespace mill::calibrate {

// Multiplicative step of the levers that scale (modulus, kn/ks, strengths).
inline constexpr double kSensitivityFactor = 1.2;
// Additive step of the friction angle [deg].
inline constexpr double kFrictionStepDeg = 5.0;
// Additive step of the moment factor (down, clamped into [0, 1]; up from 0).
inline constexpr double kMomentFactorStep = 0.25;
// Floors of the run-to-run noise: a relative change of E, UCS, tensile
// strength, an absolute change of nu (the rate check raises them).
inline constexpr double kNoiseFloorRelative = 0.01;
inline constexpr double kNoiseFloorNu = 0.005;

// One lever: a fitted row of kBondParameters and its step from p*.
struct Lever {
  const BondParameter* row = nullptr;
  bool multiplicative = true;  // x kSensitivityFactor; else an additive step
  double from = 0, to = 0;     // the lever's value in p* and in the perturbed run
};

// The levers of p's model, in table order, each with its step from p.
std::vector<Lever> sensitivity_levers(const BondParams& p);
// p with lever l at its stepped value.
BondParams perturbed(const BondParams& p, const Lever& l);

// A lever's two runs with p* perturbed.
struct LeverRun {
  Lever lever;
  UcsRun ucs;
  BrazilianRun br;
};

// The run-to-run noise of each target: the change that moves nothing.
// E, ucs, tensile relative; nu absolute.
struct Noise {
  double E = kNoiseFloorRelative, nu = kNoiseFloorNu, ucs = kNoiseFloorRelative,
         tensile = kNoiseFloorRelative;
};
// The floors, raised to the rate check's changes of E, nu and UCS (the
// UCS's also for the tensile strength) when it ran: a change of the loading
// that should not matter. `half` may be null.
Noise sensitivity_noise(const UcsRun& result, const UcsRun* half);

// One target's response to one lever.
struct TargetResponse {
  double change = 0;  // per step: dT/T (E, UCS, tensile) or d nu (nu)
  double value = 0;   // the sensitivity (units: sensitivity_unit)
};
// One lever's responses, in the order E, nu, UCS, tensile.
struct LeverSensitivity {
  Lever lever;
  TargetResponse E, nu, ucs, tensile;
};

// The sensitivities of one lever from the result's iteration `base` and the
// perturbed runs: for a multiplicative lever (dT/T)/(dx/x) for E, UCS and
// tensile strength, d nu / d ln x for nu; for an additive one dT/T (d nu)
// per unit of the lever (deg for the friction angle).
LeverSensitivity lever_sensitivity(const Iteration& base, const LeverRun& run);

// A lever's step in words: "x1.2 (57.8 GPa -> 69.36 GPa)", "+5 deg (60 deg -> 65 deg)".
std::string step_text(const Lever& l);

// The unit of a lever's sensitivities of E, UCS, tensile (nu = false) or of nu.
std::string sensitivity_unit(const Lever& l, bool nu);

// What a lever's steps moved: the targets moved by more than the tolerance
// (nu: kNuTolerance) per step, and whether it moved any by more than noise.
struct LeverVerdict {
  std::vector<std::string> strong;  // target names (E, nu, UCS, tensile)
  std::vector<std::string> above_noise;
  bool free() const { return !above_noise.empty(); }
};
LeverVerdict lever_verdict(const LeverSensitivity& s, double tol, const Noise& noise);

// report.json's `sensitivity` object.
nlohmann::json sensitivity_json(const Iteration& base, const std::vector<LeverRun>& runs,
                                double tol, const Noise& noise);

// report.md's "Lever sensitivities" section.
std::string sensitivity_markdown(const Iteration& base, const std::vector<LeverRun>& runs,
                                 double tol, const Noise& noise);

// Runs a UCS and a Brazilian test per lever of p at `rate`; run k's
// progress starts at done + k x step_share of the job (two steps per lever).
std::vector<LeverRun> run_sensitivity(LabBench& lab, const BondParams& p, double rate, double done,
                                      double step_share);

}  // namespace mill::calibrate
