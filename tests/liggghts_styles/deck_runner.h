// Helpers for the style tests: temporary run directories, running
// `liggghts-mill` on a deck (optionally under mpirun) and reading its outputs.
#ifndef MILL_TESTS_DECK_RUNNER_H
#define MILL_TESTS_DECK_RUNNER_H

#include <string>
#include <utility>
#include <vector>

namespace mill_test {

struct RunResult {
  int exit_code = -1;
  std::string screen;  // stdout + stderr of the run
};

// Creates a fresh directory /tmp/styles_<name>_XXXXXX and returns its path;
// it is removed when the test that made it passes, kept when it fails.
std::string make_run_dir(const std::string &name);

// Writes `deck` to dir/in.deck and runs liggghts-mill on it with nprocs ranks;
// `exe` replaces liggghts-mill and `extra_args` is appended to its command line.
RunResult run_deck(const std::string &dir, const std::string &deck, int nprocs = 1,
                   const std::string &exe = "", const std::string &extra_args = "");

// Numeric rows of a whitespace table; lines starting with '#' are skipped.
std::vector<std::vector<double>> read_table(const std::string &path);

// Intact bonds (tag_i, tag_j) from a dump_bonds file.
std::vector<std::pair<int, int>> read_bonds(const std::string &path);

// Number of fragments among atoms 1..natoms joined by the given bonds.
int count_fragments(int natoms, const std::vector<std::pair<int, int>> &bonds);

// Common deck head: SI units, sphere atoms with a map, ghost velocities, box,
// granular Hertz contacts (Young's modulus youngs Pa) and hard_particles.
std::string deck_head(double half_box, double youngs = 5e9, const std::string &boundary = "f f f");

// Writes an ASCII STL rectangle (two triangles) spanned by corner p0 and edges e1, e2.
void write_rect_stl(const std::string &path, const double *p0, const double *e1, const double *e2);

}  // namespace mill_test

#endif
