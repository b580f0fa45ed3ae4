// fix step/adaptive: the time step re-evaluated from the bonds left
// (docs/styles/fix_step_adaptive.md).
#include "fix_step_adaptive.h"

#include <algorithm>
#include <cstring>

#include "comm.h"
#include "dump.h"
#include "error.h"
#include "fix_bond_breakable.h"
#include "force.h"
#include "input.h"
#include "modify.h"
#include "output.h"
#include "pair.h"
#include "style_args.h"
#include "update.h"
#include "variable.h"

using namespace LAMMPS_NS;
using namespace FixConst;

// Reads `fix ID group step/adaptive bonds ID safety S max DT [growth G] [every N] [file F]`.
FixStepAdaptive::FixStepAdaptive(LAMMPS *lmp, int narg, char **arg) : Fix(lmp, narg, arg) {
  const mill::StyleArgs args(error, "step/adaptive");
  bool have_safety = false, have_max = false;
  for (int k = 3; k < narg; k += 2) {
    const std::string key = arg[k];
    if (k + 1 >= narg)
      error->all(FLERR, ("fix step/adaptive: keyword " + key + " needs a value").c_str());
    const char *val = arg[k + 1];
    if (key == "bonds") {
      bonds_id_ = val;
    } else if (key == "safety") {
      rule_.safety = args.positive("safety", val);
      if (rule_.safety > 1.0)
        error->all(FLERR, ("fix step/adaptive: safety must be in (0, 1] (velocity Verlet is "
                           "unstable above the bonds' critical step), got " +
                           std::string(val))
                              .c_str());
      have_safety = true;
    } else if (key == "max") {
      rule_.dt_max = args.positive("max", val, "s");
      have_max = true;
    } else if (key == "growth") {
      rule_.growth = args.real("growth", val);
      if (!(rule_.growth >= 1.0))
        error->all(FLERR, ("fix step/adaptive: growth must be >= 1 (the most the step may grow "
                           "per re-evaluation), got " +
                           std::string(val))
                              .c_str());
    } else if (key == "every") {
      every_ = args.integer("every", val, 0, 1000000000);
    } else if (key == "file") {
      file_ = val;
    } else {
      error->all(FLERR, ("fix step/adaptive: unknown keyword '" + key +
                         "' (expected bonds, safety, max, growth, every, file)")
                            .c_str());
    }
  }
  if (bonds_id_.empty() || !have_safety || !have_max)
    error->all(FLERR,
               "fix step/adaptive: expected `fix ID group step/adaptive bonds BOND_FIX safety S "
               "max DT_MAX [growth G] [every N] [file F]` (bonds, safety and max are required)");
  vector_flag = 1;
  size_vector = 3;
  global_freq = 1;
  extvector = 0;
  nevery = every_ > 0 ? every_ : 1;
  if (comm->me == 0 && !file_.empty()) {
    out_ = fopen(file_.c_str(), "w");
    if (!out_) error->one(FLERR, ("fix step/adaptive: cannot open file '" + file_ + "'").c_str());
    fprintf(
        out_,
        "# fix step/adaptive: the step at each re-evaluation (docs/styles/fix_step_adaptive.md)\n"
        "step,time_s,dt_s,dt_bonds_s,intact_bonds\n");
    fflush(out_);
  }
}

FixStepAdaptive::~FixStepAdaptive() {
  if (out_) fclose(out_);
}

int FixStepAdaptive::setmask() { return every_ > 0 ? END_OF_STEP : 0; }

void FixStepAdaptive::init() {
  bonds_ = dynamic_cast<FixBondBreakable *>(modify->find_fix_id(bonds_id_.c_str()));
  if (!bonds_)
    error->all(FLERR, ("fix step/adaptive: bonds " + bonds_id_ +
                       ": no fix bond/breakable or bond/flatjoint with that ID")
                          .c_str());
}

void FixStepAdaptive::end_of_step() { reevaluate(); }

// Between runs (`run N pre no` continues with the step set here).
void FixStepAdaptive::post_run() { reevaluate(); }

void FixStepAdaptive::reevaluate() {
  if (!bonds_ || last_step_ == update->ntimestep) return;
  last_step_ = update->ntimestep;
  dt_bonds_ = bonds_->critical_step();
  const double dt = mill::step_limit::next_step(update->dt, dt_bonds_, rule_);
  if (dt != update->dt) {
    apply(dt);
    // Between runs the next run's output setup asks the variables again.
    if (update->ntimestep < update->laststep) reschedule_dumps();
  }
  if (out_) {
    fprintf(out_, BIGINT_FORMAT ",%.10g,%.10g,%.10g,%.0f\n", update->ntimestep,
            update->get_cur_time(), update->dt, dt_bonds_, bonds_->compute_vector(0));
    fflush(out_);
  }
}

// As fix dt/reset: bank the elapsed time at the old step, then tell the pair
// style and every fix (fix nve/sphere's dtv/dtf, the ledger's books).
void FixStepAdaptive::apply(double dt) {
  update->update_time();
  update->dt = dt;
  if (force->pair) force->pair->reset_dt();
  for (int i = 0; i < modify->nfix; i++) modify->fix[i]->reset_dt();
  changes_ += 1.0;
}

// A dump whose frequency is an equal-style variable (`dump_modify ID every
// v_name`: the next step to write) learnt it at the old step; the decks' dump
// in simulated time (the first step at or after the next multiple of the
// interval) would then come early or late. Each such dump not due this step
// is asked again, as Output::setup asks at the start of a run (a dump due
// now is written after end_of_step and asks its variable then).
void FixStepAdaptive::reschedule_dumps() {
  const bigint now = update->ntimestep;
  bool changed = false;
  for (int i = 0; i < output->ndump; ++i) {
    if (output->every_dump[i] != 0 || output->next_dump[i] <= now) continue;
    modify->clearstep_compute();
    const bigint next = static_cast<bigint>(input->variable->compute_equal(output->ivar_dump[i]));
    if (next <= now)
      error->all(FLERR, (std::string("fix step/adaptive: dump ") + output->dump[i]->id +
                         ": its frequency variable " + output->var_dump[i] +
                         " gave a step not after the current one")
                            .c_str());
    output->next_dump[i] = next;
    modify->addstep_compute_all(next);
    changed = true;
  }
  if (!changed) return;
  output->next_dump_any = output->next_dump[0];
  for (int i = 1; i < output->ndump; ++i)
    output->next_dump_any = std::min(output->next_dump_any, output->next_dump[i]);
  // Output::next also covers restarts and thermo (not visible here): it may
  // only move earlier; a step it keeps that has nothing due writes nothing.
  output->next = std::min(output->next, output->next_dump_any);
}

// Global outputs: 1 the step now [s], 2 the bonds' critical step at the last
// evaluation [s] (0: no bond left), 3 how often the step changed.
double FixStepAdaptive::compute_vector(int n) {
  switch (n) {
    case 0:
      return update->dt;
    case 1:
      return dt_bonds_;
    case 2:
      return changes_;
    default:
      return 0.0;
  }
}
