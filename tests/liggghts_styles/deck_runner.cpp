#include "deck_runner.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "temp_dir.h"

namespace mill_test {

namespace {

// Run directories made by this process and not yet removed; in_test: made
// while a test ran (else, e.g. in SetUpTestSuite, they last the program).
struct RunDir {
  std::string path;
  bool in_test;
};
std::vector<RunDir> &run_dirs() {
  static std::vector<RunDir> dirs;
  return dirs;
}

// Removes the run directories a test made when it ends, if it passed; keeps
// them for inspection, printing their paths, after a failure or when
// MILL_KEEP_TEST_DIRS is set. Those made outside a test go at the end of a
// passing test program.
class RunDirCleanup : public ::testing::EmptyTestEventListener {
 public:
  void OnTestEnd(const ::testing::TestInfo &test) override { sweep(true, test.result()->Failed()); }
  void OnTestProgramEnd(const ::testing::UnitTest &unit) override { sweep(false, unit.Failed()); }

 private:
  static void sweep(bool test_only, bool failed) {
    auto &dirs = run_dirs();
    for (auto it = dirs.begin(); it != dirs.end();) {
      if (test_only && !it->in_test) {
        ++it;
        continue;
      }
      mill::test::remove_unless_failed(it->path, failed);
      it = dirs.erase(it);
    }
  }
};

const bool kCleanup =
    (::testing::UnitTest::GetInstance()->listeners().Append(new RunDirCleanup), true);

}  // namespace

// Makes a unique run directory under /tmp.
std::string make_run_dir(const std::string &name) {
  std::string templ = "/tmp/styles_" + name + "_XXXXXX";
  std::vector<char> buf(templ.begin(), templ.end());
  buf.push_back('\0');
  if (!mkdtemp(buf.data())) throw std::runtime_error("mkdtemp failed for " + templ);
  run_dirs().push_back(
      {buf.data(), ::testing::UnitTest::GetInstance()->current_test_info() != nullptr});
  return std::string(buf.data());
}

// Runs the deck; mpirun gets --oversubscribe (and --allow-run-as-root as root).
RunResult run_deck(const std::string &dir, const std::string &deck, int nprocs,
                   const std::string &exe, const std::string &extra_args) {
  {
    std::ofstream out(dir + "/in.deck");
    out << deck;
  }
  // Own Open MPI session base per run: concurrent singletons otherwise race
  // on creating /tmp/ompi.<host>.<uid> ("File exists", orte_init fails).
  std::string cmd = "cd '" + dir + "' && mkdir -p ompi && OMPI_MCA_orte_tmpdir_base='" + dir + "/ompi' ";
  if (nprocs > 1) {
    cmd += std::string(MILL_MPIEXEC) + " -np " + std::to_string(nprocs) + " --oversubscribe ";
    if (geteuid() == 0) cmd += "--allow-run-as-root ";
  }
  cmd += (exe.empty() ? std::string(MILL_LIGGGHTS_EXE) : exe) + " -in in.deck -log log.lammps " +
         extra_args + " > screen.txt 2>&1";
  RunResult r;
  const int status = std::system(cmd.c_str());
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(dir + "/screen.txt");
  std::stringstream ss;
  ss << in.rdbuf();
  r.screen = ss.str();
  return r;
}

// Reads numeric rows, skipping comments and lines that do not parse.
std::vector<std::vector<double>> read_table(const std::string &path) {
  std::vector<std::vector<double>> rows;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    std::vector<double> row;
    std::string tok;
    bool ok = true;
    while (ls >> tok) {
      char *end = nullptr;
      const double v = std::strtod(tok.c_str(), &end);
      if (*end != '\0') {
        ok = false;
        break;
      }
      row.push_back(v);
    }
    if (ok && !row.empty()) rows.push_back(row);
  }
  return rows;
}

// Reads the `tag_i tag_j` lines of a dump_bonds file.
std::vector<std::pair<int, int>> read_bonds(const std::string &path) {
  std::vector<std::pair<int, int>> bonds;
  for (const auto &row : read_table(path))
    if (row.size() == 2) bonds.emplace_back(static_cast<int>(row[0]), static_cast<int>(row[1]));
  return bonds;
}

// Union-find over atoms 1..natoms.
int count_fragments(int natoms, const std::vector<std::pair<int, int>> &bonds) {
  std::vector<int> parent(natoms + 1);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&parent](int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  int fragments = natoms;
  for (const auto &b : bonds) {
    const int ra = find(b.first), rb = find(b.second);
    if (ra != rb) {
      parent[ra] = rb;
      --fragments;
    }
  }
  return fragments;
}

// Deck head shared by all tests.
std::string deck_head(double half_box, double youngs, const std::string &boundary) {
  std::ostringstream d;
  d.precision(17);
  d << "units si\n"
    << "atom_style sphere\n"
    << "atom_modify map array\n"
    << "boundary " << boundary << "\n"
    << "newton off\n"
    << "communicate single vel yes\n"
    << "region box block " << -half_box << " " << half_box << " " << -half_box << " " << half_box
    << " " << -half_box << " " << half_box << " units box\n"
    << "create_box 1 box\n"
    << "neighbor 0.0002 bin\n"
    << "neigh_modify delay 0\n"
    << "hard_particles yes\n"
    << "fix m1 all property/global youngsModulus peratomtype " << youngs << "\n"
    << "fix m2 all property/global poissonsRatio peratomtype 0.25\n"
    << "fix m3 all property/global coefficientRestitution peratomtypepair 1 0.5\n"
    << "fix m4 all property/global coefficientFriction peratomtypepair 1 0.5\n"
    << "pair_style gran model hertz tangential history\n"
    << "pair_coeff * *\n";
  return d.str();
}

void write_rect_stl(const std::string &path, const double *p0, const double *e1, const double *e2) {
  std::ofstream o(path);
  o.precision(17);
  double p[4][3];
  for (int k = 0; k < 3; ++k) {
    p[0][k] = p0[k];
    p[1][k] = p0[k] + e1[k];
    p[2][k] = p0[k] + e1[k] + e2[k];
    p[3][k] = p0[k] + e2[k];
  }
  const int tri[2][3] = {{0, 1, 2}, {0, 2, 3}};
  o << "solid rect\n";
  for (const auto &t : tri) {
    o << "facet normal 0 0 0\nouter loop\n";
    for (int v : t) o << "vertex " << p[v][0] << " " << p[v][1] << " " << p[v][2] << "\n";
    o << "endloop\nendfacet\n";
  }
  o << "endsolid rect\n";
}

}  // namespace mill_test
