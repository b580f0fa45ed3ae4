// The virtual lab tests of the calibrate stage: the UCS and Brazilian decks
// (liggghts_inputs/{ucs,brazilian}.in.tmpl) of the fit, and the triaxial and
// semi-circular bend decks ({triaxial,scb}.in.tmpl) of the checks, run on the
// carved specimens, their curves read and analysed, their energy ledgers
// summarised (docs/calibration.md, steps 3 and 4, "Checks after the fit" and
// "Energy ledger").
#pragma once

#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "engine/runner.h"
#include "lump/material.h"
#include "postprocess/energy_ledger.h"
#include "postprocess/lab_tests.h"
#include "stages/calibrate/specimen.h"
#include "stages/stage.h"

namespace mill::calibrate {

// The ore card's macro properties: what the lab tests measure and the fit aims at.
struct Targets {
  double E, nu, ucs, tensile;
  // Mode-I fracture toughness K_IC [Pa m^0.5] of the card when the fit aims
  // at it too (calibrate.fit_toughness, flat joints), 0 when not a target.
  double toughness = 0;
};

// What every lab test gives: the deck's info line, load curve and energy ledger.
struct LabRun {
  std::string tag;  // its folder <dir>/runs/<tag> (RunStep::tag)
  std::map<std::string, double> info;
  std::filesystem::path info_file;  // where `info` was read (named in errors)
  post::LoadCurve curve;
  post::LedgerSummary energy;  // the run's ledger.csv, summarised
  double seconds = 0;
  bool peaked = true;  // false: the run reached its strain cap still loading
};

struct UcsRun : LabRun {
  post::UcsResult r;
  post::StressStrain ss;
  double area = 0, gauge = 0;
};

struct BrazilianRun : LabRun {
  post::BrazilianResult r;
};

struct TriaxialRun : LabRun {
  double pressure = 0;  // Pa, the confining pressure asked
  post::TriaxialResult r;
};

struct ScbRun : LabRun {
  post::ScbResult r;
};

// A semi-circular bend specimen too coarse for the test (no element under
// the load point or over a support).
struct ScbTooCoarse : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// One run of a lab test: its folder <dir>/runs/<tag>, what the progress line
// shows, and the fraction of the job done before it.
struct RunStep {
  std::string tag, what;
  double done = 0;
};

// Runs the lab tests of one calibration job on its specimens.
class LabBench {
 public:
  LabBench(StageContext& ctx, const std::string& job_label, const std::filesystem::path& dir,
           const Specimen& sp, const Targets& t)
      : ctx_(ctx), job_label_(job_label), dir_(dir), sp_(sp), t_(t) {}

  // A UCS test with bond parameters p at the given strain rate.
  UcsRun ucs(const BondParams& p, double rate, const RunStep& step);
  // A Brazilian test with bond parameters p at the given strain rate.
  BrazilianRun brazilian(const BondParams& p, double rate, const RunStep& step);
  // A triaxial test on the UCS cylinder under confining pressure `pressure` [Pa].
  TriaxialRun triaxial(const BondParams& p, double rate, double pressure, const RunStep& step);
  // A semi-circular bend test on a half disc of the Brazilian disc's radius.
  ScbRun scb(const BondParams& p, double rate, const RunStep& step);

 private:
  struct Test;
  std::filesystem::path run_test(const Test& test, const BondParams& p, double rate,
                                 const RunStep& step, LabRun& out);
  engine::Result run_lab_deck(const std::string& deck, const std::filesystem::path& work,
                              std::vector<std::pair<std::string, std::string>> vars,
                              const RunStep& step);

  StageContext& ctx_;
  std::string job_label_;
  std::filesystem::path dir_;
  Specimen sp_;
  Targets t_;
};

}  // namespace mill::calibrate
