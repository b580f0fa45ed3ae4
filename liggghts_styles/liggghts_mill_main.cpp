// liggghts-mill: LIGGGHTS 3.8 (Debian's libliggghts) plus the project's styles.
// Same command line as `liggghts` (-in, -var, -log, -echo, -screen, ...).
#include <mpi.h>
#include <signal.h>

#include <cstdio>
#include <cstring>

#include "input.h"
#include "lammps.h"
#include "signal_handling.h"
#include "style_registry.h"

using LAMMPS_NS::LAMMPS;

namespace {

// Installs LIGGGHTS's own handlers: SIGINT/SIGTERM end the run cleanly, SIGUSR1
// requests a restart file (as the stock `liggghts` binary does).
void install_signal_handlers() {
  struct sigaction int_action, usr1_action;
  std::memset(&int_action, 0, sizeof(int_action));
  std::memset(&usr1_action, 0, sizeof(usr1_action));
  int_action.sa_handler = LAMMPS_NS::SignalHandler::int_handler;
  sigaction(SIGINT, &int_action, nullptr);
  sigaction(SIGTERM, &int_action, nullptr);  // mpirun turns SIGINT into SIGTERM
  usr1_action.sa_handler = LAMMPS_NS::SignalHandler::usr1_handler;
  sigaction(SIGUSR1, &usr1_action, nullptr);
}

}  // namespace

// Runs one LIGGGHTS instance over MPI_COMM_WORLD with the project styles added.
int main(int argc, char **argv) {
#if defined(MILL_NEEDS_AVX)
  // Built with -DMILL_AVX=ON (or AUTO on a machine with AVX): the bond
  // kernel uses AVX instructions, which this CPU must have.
  if (!__builtin_cpu_supports("avx")) {
    std::fprintf(stderr,
                 "liggghts-mill: this build's bond kernel needs AVX, which this CPU lacks; "
                 "rebuild with cmake -DMILL_AVX=OFF (docs/styles/fix_bond_breakable.md, "
                 "\"lanes\")\n");
    return 1;
  }
#endif
  install_signal_handlers();
  MPI_Init(&argc, &argv);
  LAMMPS *lmp = new LAMMPS(argc, argv, MPI_COMM_WORLD);
  mill::register_mill_styles(lmp);
  lmp->input->file();
  delete lmp;
  MPI_Finalize();
  return 0;
}
