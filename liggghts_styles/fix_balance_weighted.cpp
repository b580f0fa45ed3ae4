// fix balance/weighted: the processor grid's cuts at the weighted median of
// the atoms (docs/styles/fix_balance_weighted.md).
#include "fix_balance_weighted.h"

#include <mpi.h>

#include <algorithm>
#include <vector>

#include "atom.h"
#include "balance_cuts.h"
#include "comm.h"
#include "domain.h"
#include "error.h"
#include "modify.h"
#include "neighbor.h"
#include "style_args.h"

using namespace LAMMPS_NS;
using namespace FixConst;

// Reads `fix ID group balance/weighted [bonds FIX_ID] [bond_weight W] [every N]`.
FixBalanceWeighted::FixBalanceWeighted(LAMMPS *lmp, int narg, char **arg) : Fix(lmp, narg, arg) {
  const mill::StyleArgs args(error, "balance/weighted");
  for (int k = 3; k < narg; k += 2) {
    const std::string key = arg[k];
    if (k + 1 >= narg)
      error->all(FLERR, ("fix balance/weighted: keyword " + key + " needs a value").c_str());
    const char *val = arg[k + 1];
    if (key == "bonds") {
      bonds_id_ = val;
    } else if (key == "bond_weight") {
      bond_weight_ = args.real("bond_weight", val);
      if (!(bond_weight_ >= 0))
        error->all(FLERR, ("fix balance/weighted: bond_weight must be >= 0 (the work of one "
                           "intact bond end over one atom's), got " +
                           std::string(val))
                              .c_str());
    } else if (key == "every") {
      every_ = args.integer("every", val, 1, 1000000000);
    } else {
      error->all(FLERR, ("fix balance/weighted: unknown keyword '" + key +
                         "' (expected bonds, bond_weight, every)")
                            .c_str());
    }
  }
  vector_flag = 1;
  size_vector = 3;
  global_freq = 1;
  extvector = 0;
}

int FixBalanceWeighted::setmask() { return PRE_EXCHANGE; }

void FixBalanceWeighted::init() {
  if (domain->triclinic)
    error->all(FLERR,
               "fix balance/weighted: expected an orthogonal box (triclinic boxes are not "
               "supported)");
  bonds_ = nullptr;
  if (bonds_id_.empty()) return;
  bonds_ = modify->find_fix_id(bonds_id_.c_str());
  if (!bonds_ || !bonds_->peratom_flag || bonds_->size_peratom_cols != 0)
    error->all(FLERR, ("fix balance/weighted: bonds " + bonds_id_ +
                       ": expected the ID of a fix with a per-atom vector (fix bond/breakable or "
                       "bond/flatjoint: the intact bonds of each atom)")
                          .c_str());
}

void FixBalanceWeighted::setup_pre_exchange() { rebalance(); }

void FixBalanceWeighted::pre_exchange() {
  if (++calls_ % every_ == 0) rebalance();
}

void FixBalanceWeighted::rebalance() {
  if (comm->nprocs == 1) return;
  // The cuts in box coordinates before the box is wrapped again: atoms are
  // owned by them (to within half the skin).
  double *split[3] = {comm->xsplit, comm->ysplit, comm->zsplit};
  std::vector<double> old[3];
  for (int d = 0; d < 3; ++d)
    for (int k = 0; k <= comm->procgrid[d]; ++k)
      old[d].push_back(domain->boxlo[d] + domain->prd[d] * split[d][k]);
  // The box as this step's exchange will see it (shrink-wrapped boundaries).
  domain->pbc();
  domain->reset_box();

  const int nlocal = atom->nlocal;
  const double *count = bonds_ ? bonds_->vector_atom : nullptr;
  std::vector<double> w(nlocal, 1.0);
  double mine = 0.0;
  for (int i = 0; i < nlocal; ++i) {
    if (count) w[i] += bond_weight_ * count[i];
    mine += w[i];
  }
  double sum = 0.0, most = 0.0;
  MPI_Allreduce(&mine, &sum, 1, MPI_DOUBLE, MPI_SUM, world);
  MPI_Allreduce(&mine, &most, 1, MPI_DOUBLE, MPI_MAX, world);
  imbalance_ = sum > 0 ? most * comm->nprocs / sum : 1.0;
  imbalance_max_ = std::max(imbalance_max_, imbalance_);

  std::vector<int> counts(comm->nprocs), offsets(comm->nprocs);
  const int mine_n = 2 * nlocal;
  MPI_Allgather(&mine_n, 1, MPI_INT, counts.data(), 1, MPI_INT, world);
  int all = 0;
  for (int p = 0; p < comm->nprocs; ++p) {
    offsets[p] = all;
    all += counts[p];
  }
  std::vector<double> send(mine_n), recv(all);
  const double margin = 0.5 * neighbor->skin;
  for (int d = 0; d < 3; ++d) {
    const int parts = comm->procgrid[d];
    if (parts < 2) continue;
    for (int i = 0; i < nlocal; ++i) {
      send[2 * i] = atom->x[i][d];
      send[2 * i + 1] = w[i];
    }
    MPI_Allgatherv(send.data(), mine_n, MPI_DOUBLE, recv.data(), counts.data(), offsets.data(),
                   MPI_DOUBLE, world);
    std::vector<mill::balance::Point> points(all / 2);
    for (std::size_t j = 0; j < points.size(); ++j) points[j] = {recv[2 * j], recv[2 * j + 1]};
    const std::vector<double> cuts = mill::balance::weighted_cuts(points, parts);
    if (cuts.empty()) continue;
    // Each cut moves at most to beside its neighbours' old places, and the
    // fractions stay increasing within the box.
    const double lo = domain->boxlo[d], prd = domain->prd[d], thin = 1e-6;
    for (int k = 1; k < parts; ++k) {
      const double cut = mill::balance::limited_cut(old[d], k, cuts[k - 1], margin);
      const double f = (cut - lo) / prd;
      split[d][k] = std::clamp(f, split[d][k - 1] + thin, 1.0 - (parts - k) * thin);
    }
    split[d][0] = 0.0;
    split[d][parts] = 1.0;
  }
  comm->uniform = 0;
  domain->set_local_box();
  // With a fixed box the integrator sets up the communication and the bins
  // only when the box changes: here the sub-domains did.
  if (!domain->box_change) {
    comm->setup();
    if (neighbor->style) neighbor->setup_bins();
  }
  balances_ += 1.0;
}

// f_ID[1]: max / mean rank weight found at the last re-balance (before it
// moved the cuts: how well the cuts before it held); [2] the largest such;
// [3] re-balances done.
double FixBalanceWeighted::compute_vector(int n) {
  if (n == 0) return imbalance_;
  if (n == 1) return imbalance_max_;
  return balances_;
}
