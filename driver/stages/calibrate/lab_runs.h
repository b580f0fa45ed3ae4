// The virtual lab tests of the calibrate stage: the UCS and Brazilian decks
// (liggghts_inputs/{ucs,brazilian}.in.tmpl) of the fit, and the triaxial and
// semi-circular bend decks ({triaxial,scb}.in.tmpl) of the checks, run on the
// carved specimens, their curves read and analysed, their energy ledgers
// summarised (docs/calibration.md, steps 3 and 4, "Checks after the fit" and
// "Energy ledger").
#pragma once

#include <filesystem>
#include <functional>
#include <map>
#include <optional>
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
  // tensile: what the fit's tensile test aims at (lump/material.h,
  // tensile_target): the card's Brazilian strength, or with `direct` its
  // direct tensile strength.
  double E, nu, ucs, tensile;
  bool direct =
      false;  // the fit's tensile test is the direct tension test (calibrate.tensile_test)
  double brazilian = 0;  // Pa, the card's (Brazilian) tensile strength; 0: `tensile`
  // The Brazilian strength the disc tests expect (their strain scale).
  double disc_tensile() const { return brazilian > 0 ? brazilian : tensile; }
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

// The UCS and Brazilian tests of one set of bond parameters on one specimen
// packing (a further packing of the fit, or of the packing check).
struct PackingRun {
  long seed = 0;  // the packing's first seed (Specimen::seed)
  UcsRun ucs;
  BrazilianRun br;
  // The direct tension test (calibrate.tensile_test direct): the UCS
  // cylinder pulled; its r.ucs is the direct tensile strength.
  std::optional<UcsRun> tension;
};

struct TriaxialRun : LabRun {
  double pressure = 0;  // Pa, the confining pressure asked
  post::TriaxialResult r;
};

// One half disc of the semi-circular bend test.
struct ScbDisc : LabRun {
  post::ScbResult r;
  double angle_deg = 0;  // the ball turned this far about the load axis before carving
};

// The semi-circular bend test: calibrate.scb_orientations half discs carved
// from the one packed ball turned about the load axis (kScbRadiusFactor x
// the Brazilian disc's radius), K_IC their mean. One half disc of a few
// hundred elements scatters K_IC by tens of per cent with where its notch
// cuts the packing (bench/README.md, "The bend test over several half
// discs").
struct ScbRun {
  std::vector<ScbDisc> discs;
  double toughness = 0;      // Pa m^0.5, mean over the discs
  double toughness_sem = 0;  // Pa m^0.5, standard error of that mean (0 with one disc)
  double peak_force = 0;     // N, mean over the discs
  double seconds = 0;        // all discs
  bool peaked = true;        // every disc peaked before its cap
  const std::string& tag() const { return discs.front().tag; }
  // The test of these discs: means, the standard error s / sqrt(n) (s the
  // sample standard deviation), total seconds, all peaked.
  static ScbRun of(std::vector<ScbDisc> discs);
  // "0.412 MPa m^0.5 +- 0.031 (0.268-0.504 over 6 half discs)".
  std::string summary() const;
};

// The half disc's radius over the Brazilian disc's: the larger of the two
// that fit in the packed ball (its corners reach 1.16 R from the ball's
// centre); measured against 1.0: K_IC's mean the same, its scatter over six
// orientations 22 % against 37 % (bench/README.md).
constexpr double kScbRadiusFactor = 1.2;

// A semi-circular bend specimen too coarse for the test (no element under
// the load point or over a support).
struct ScbTooCoarse : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Throws ScbTooCoarse, naming the info file, calibrate.n_elements and the
// way out, when a half disc's info line (scb.in.tmpl) has no element in its
// load_layer or support_layer.
void check_scb_layers(const std::map<std::string, double>& info,
                      const std::filesystem::path& info_file);

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
  // A direct tension test (tension.in.tmpl: the UCS cylinder pulled apart by
  // its end layers) with bond parameters p: its r.ucs is the direct tensile
  // strength (the peak before failure), r.youngs_modulus the modulus in
  // tension.
  UcsRun tension(const BondParams& p, double rate, const RunStep& step);
  // A Brazilian test with bond parameters p at the given strain rate.
  BrazilianRun brazilian(const BondParams& p, double rate, const RunStep& step);
  // A triaxial test on the UCS cylinder under confining pressure `pressure` [Pa].
  TriaxialRun triaxial(const BondParams& p, double rate, double pressure, const RunStep& step);
  // A semi-circular bend test on `orientations` half discs (kScbRadiusFactor
  // x the Brazilian disc's radius), the ball turned by 180 deg / orientations
  // about the load axis from one to the next; tags <step.tag>, <step.tag>_o1, ...
  ScbRun scb(const BondParams& p, double rate, int orientations, const RunStep& step);
  // The same half discs as tasks, for a caller that runs them side by side
  // with other tests (run_concurrently): each task fills its entry of
  // `discs` (resized here to `orientations`); ScbRun::of(discs) then gives
  // what scb() returns.
  std::vector<std::function<void()>> scb_tasks(const BondParams& p, double rate, int orientations,
                                               const RunStep& step, std::vector<ScbDisc>& discs);

  // How many lab runs the job may have going at once (the half discs of a
  // bend test; callers run independent tests side by side with
  // run_concurrently): resources.jobs; the stage's runner shares that many
  // engine runs among the stage's fits (docs/calibration.md, "Runs at once").
  // Each run writes its own folder, so the results do not depend on it.
  int lanes() const { return lanes_; }
  void set_lanes(int lanes) { lanes_ = lanes < 1 ? 1 : lanes; }

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
  int lanes_ = 1;
};

}  // namespace mill::calibrate
