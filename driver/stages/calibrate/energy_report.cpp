// The lab runs' energy ledgers in the calibration's reports.
#include "stages/calibrate/energy_report.h"

#include <fmt/format.h>

#include <cmath>
#include <sstream>

namespace mill::calibrate {

namespace {

// The run with the largest |residual_fraction_max|, nullptr when there is none.
const LabRun* worst_run(const std::vector<const LabRun*>& runs) {
  const LabRun* worst = nullptr;
  for (const LabRun* r : runs)
    if (!worst ||
        std::abs(r->energy.residual_fraction_max) > std::abs(worst->energy.residual_fraction_max))
      worst = r;
  return worst;
}

}  // namespace

// The summary's figures under report.json's keys.
nlohmann::json lab_energy_json(const post::LedgerSummary& e) {
  return {{"input_J", e.input_J},
          {"work_other_J", e.work_other_J},
          {"bond_released_J", e.bond_released_J},
          {"residual_J", e.residual_J},
          {"residual_fraction", e.residual_fraction},
          {"residual_fraction_max", e.residual_fraction_max},
          {"max_element_speed_m_s", e.max_speed_m_s},
          {"comminution_efficiency", e.comminution_efficiency},
          {"end_time_s", e.end_time_s}};
}

// Iterations in order, each UCS then Brazilian then direct tension (then
// those of the fit's further packings), the rate check, the packing
// check's pairs, the levers' sensitivity pairs, then the checks.
std::vector<const LabRun*> lab_runs(const Outcome& o) {
  std::vector<const LabRun*> runs;
  // A packing's tests: UCS, Brazilian (with calibrate.tensile_test direct,
  // on the kept parameters only: a run without a tag did not run), direct
  // tension.
  auto packing = [&](const UcsRun& ucs, const BrazilianRun& br,
                     const std::optional<UcsRun>& tension) {
    runs.push_back(&ucs);
    if (!br.tag.empty()) runs.push_back(&br);
    if (tension) runs.push_back(&*tension);
  };
  for (const Iteration& it : o.hist) {
    packing(it.ucs, it.br, it.tension);
    for (const PackingRun& p : it.more) packing(p.ucs, p.br, p.tension);
    if (it.scb)
      for (const ScbDisc& d : it.scb->discs) runs.push_back(&d);
  }
  if (o.half) runs.push_back(&*o.half);
  for (const PackingRun& p : o.packings) packing(p.ucs, p.br, p.tension);
  for (const LeverRun& l : o.sensitivity) {
    runs.push_back(&l.ucs);
    runs.push_back(&l.br);
  }
  for (const TriaxialRun& t : o.checks.triaxial) runs.push_back(&t);
  // The checks' bend test is the kept iteration's own when K_IC was fitted.
  if (o.checks.scb && !o.checks.toughness_fitted)
    for (const ScbDisc& d : o.checks.scb->discs) runs.push_back(&d);
  return runs;
}

// The worst residual, its run and the definitions.
nlohmann::json energy_summary_json(const Outcome& o) {
  const std::vector<const LabRun*> runs = lab_runs(o);
  const LabRun* worst = worst_run(runs);
  return {
      {"lab_runs", runs.size()},
      {"worst_residual_fraction_max",
       worst ? nlohmann::json(std::abs(worst->energy.residual_fraction_max)) : nullptr},
      {"worst_run", worst ? nlohmann::json(worst->tag) : nullptr},
      {"definitions",
       {{"ledgers",
         "jobs/calibration/runs/<run>/ledger.csv (fix energy/ledger, "
         "docs/styles/fix_energy_ledger.md); each run's figures are in its `energy` object "
         "(iterations[].energy.ucs, .brazilian, iterations[].packings[].energy, rate_check.energy, "
         "packing_check.runs[].energy, "
         "sensitivity.levers.<lever>.energy, checks.triaxial[].energy, checks.scb.discs[].energy)"},
        {"work_other_J",
         "the platens' drive: work done on the specimen by the moving platens (triaxial: and by "
         "the confining forces)"},
        {"residual_fraction", "residual_J / (input_J + |work_other_J|), last row"},
        {"residual_fraction_max", "largest |residual_J| / (input_J + |work_other_J|) of any row"},
        {"comminution_efficiency",
         "bond_released_J / (input_J + max(work_other_J, 0)) at the end of the run: the share of "
         "the energy given that went into broken bonds"}}}};
}

// The section: intro, one row per run, the worst residual.
std::string energy_markdown(const Outcome& o) {
  const std::vector<const LabRun*> runs = lab_runs(o);
  std::ostringstream md;
  md << "\n## Energy ledger\n\n"
        "Every lab run's energy ledger (`runs/<run>/ledger.csv`, fix energy/ledger): the energy "
        "at the start, the platens' work, what the broken bonds released, the residual (what "
        "does not close) as a share of the energy given (input + |platen work|) at the end and "
        "its largest of any row, the fastest element, and the share of the energy given that "
        "went into broken bonds. The result's runs are marked *.\n\n"
        "| run | input (J) | platen work (J) | bond released (J) | residual (J) | residual | "
        "largest residual | fastest element (m/s) | to broken bonds |\n"
        "|---|---|---|---|---|---|---|---|---|\n";
  const Iteration* best = o.hist.empty() ? nullptr : &o.hist[o.best];
  for (const LabRun* r : runs) {
    const post::LedgerSummary& e = r->energy;
    bool result = best && (r == &best->ucs || r == &best->br);
    if (best && best->scb)
      for (const ScbDisc& d : best->scb->discs) result = result || r == &d;
    md << fmt::format(
        "| {}{} | {:.4g} | {:.4g} | {:.4g} | {:.3g} | {:.3g}% | {:.3g}% | {:.3g} | {:.3g}% |\n",
        r->tag, result ? " *" : "", e.input_J, e.work_other_J, e.bond_released_J, e.residual_J,
        100 * e.residual_fraction, 100 * e.residual_fraction_max, e.max_speed_m_s,
        100 * e.comminution_efficiency);
  }
  if (const LabRun* worst = worst_run(runs))
    md << fmt::format("\nLargest residual of any lab run: {:.3g}% of the energy given ({}).\n",
                      100 * std::abs(worst->energy.residual_fraction_max), worst->tag);
  return md.str();
}

}  // namespace mill::calibrate
