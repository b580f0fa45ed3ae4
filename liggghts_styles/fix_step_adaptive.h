// fix step/adaptive: a time step that follows the bonds still intact, for
// LIGGGHTS 3.8. See docs/styles/fix_step_adaptive.md.
//
// At the end of every run (and, with `every N`, every N steps) the step is
// re-evaluated from the bond fix's exact critical step over the bonds left
// (fix bond/breakable, step_limit.h): the smallest of safety x that step, a
// given bound dt_max (the contacts' and the speed's) and growth x the current
// step. A change is applied the way LAMMPS's fix dt/reset does: the elapsed
// time is banked first (Update::update_time), then update->dt is set and the
// pair style and every fix are told (reset_dt), so fix nve/sphere's cached
// half steps and fix energy/ledger's bookkeeping follow, also between runs
// continued with `run N pre no`.
#ifndef MILL_FIX_STEP_ADAPTIVE_H
#define MILL_FIX_STEP_ADAPTIVE_H

#include <cstdio>
#include <string>

#include "fix.h"
#include "step_limit.h"

namespace LAMMPS_NS {

class FixBondBreakable;

class FixStepAdaptive : public Fix {
 public:
  FixStepAdaptive(class LAMMPS *lmp, int narg, char **arg);
  ~FixStepAdaptive() override;

  static const char *style_name() { return "step/adaptive"; }

  int setmask() override;
  void init() override;
  void end_of_step() override;
  void post_run() override;
  double compute_vector(int n) override;

 private:
  // Re-evaluates the step now (collective); applies and logs a change.
  void reevaluate();
  void apply(double dt);
  // Within a run: asks the frequency variables of the dumps that use one
  // again (the decks' dumps in simulated time were scheduled at the old step).
  void reschedule_dumps();

  std::string bonds_id_;
  FixBondBreakable *bonds_ = nullptr;
  mill::step_limit::StepRule rule_;
  int every_ = 0;     // also every this many steps (0: at the end of runs only)
  std::string file_;  // log of the evaluations (rank 0), "" = none
  FILE *out_ = nullptr;
  bigint last_step_ = -1;  // step of the last evaluation
  double dt_bonds_ = 0.0;  // the bonds' critical step at the last evaluation [s]
  double changes_ = 0.0;   // how often the step changed
};

}  // namespace LAMMPS_NS

#endif
