// What the fix bond/breakable tests share (test_fix_bond_breakable.cpp,
// test_bond_analytic.cpp, test_bond_contacts.cpp): the element and bond
// constants, the standard fix line, and decks whose initial positions,
// velocities and spins come from a data file (read_data; LIGGGHTS 3.8's `set`
// has no omega keyword).
#ifndef MILL_TESTS_BOND_TEST_UTIL_H
#define MILL_TESTS_BOND_TEST_UTIL_H

#include <array>
#include <map>
#include <string>
#include <vector>

#include "deck_runner.h"

namespace mill_test {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kR = 1e-3;        // element radius [m]
inline constexpr double kRho = 2500.0;    // density [kg/m3]
inline constexpr double kEb = 2e10;       // bond modulus [Pa]
inline constexpr double kRatio = 2.5;     // kn/ks
inline constexpr double kSigmaT = 2e7;    // tensile strength [Pa]
inline constexpr double kCohesion = 2e7;  // cohesion [Pa]
inline constexpr double kPhiDeg = 30.0;   // friction angle [deg]
inline constexpr double kGap = 0.2;       // bonding gap, x min radius
inline constexpr double kL0 = 2.1e-3;     // centre distance of a bonded pair [m]

inline constexpr double kKn = kEb / kL0;                    // normal stiffness per area [Pa/m]
inline constexpr double kKs = kKn / kRatio;                 // shear stiffness per area [Pa/m]
inline constexpr double kArea = kPi * kR * kR;              // bond area [m2]
inline constexpr double kInertia = 0.25 * kArea * kR * kR;  // bond I [m4]
inline constexpr double kPolar = 2.0 * kInertia;            // bond J [m4]

// Mass [kg] and moment of inertia 0.4 m r^2 [kg m2] of a sphere of radius r.
double sphere_mass(double r);
double sphere_inertia(double r);

// Fix line with the tests' coefficients (kEb, kRatio, kPhiDeg, kGap, no
// damping, max_bonds 16) plus extra keywords.
std::string bond_fix(const std::string &extra = "", double sigma_t = kSigmaT,
                     double cohesion = kCohesion);

// The same bond as a flat joint (fix bond/flatjoint, `elements rings
// sectors`), with extra keywords.
std::string flat_joint_fix(const std::string &extra = "", double sigma_t = kSigmaT,
                           double cohesion = kCohesion, int rings = 2, int sectors = 4);

// Deck head of a bonded simple-cubic ball (lattice kL0, radius 4.2 kL0,
// centre at z = 0.0105 m; about 300 elements of radius kR) in a box of
// half width half_xy from z = -0.002 to z_top, 2 ranks split at x = 0, Hertz
// contacts; the deck adds velocities, walls, the integrator and the bonds.
std::string bonded_ball_head(double half_xy, double z_top);

// One sphere of the data file.
struct Sphere {
  std::array<double, 3> x{};  // position [m]
  std::array<double, 3> v{};  // velocity [m/s]
  std::array<double, 3> w{};  // angular velocity [rad/s]
  double r = kR;              // radius [m]
};

// deck_head with `processors * 1 1`: a 2-rank run splits the box at x = 0.
std::string head_split_x(double half_box);

// deck_head() with the box read from data.txt instead of made by
// region/create_box; split_x adds `processors * 1 1` (2 ranks split at x = 0).
std::string head_data(double half_box, bool split_x = false);

// LIGGGHTS data file (atom_style sphere) in a cubic box of half width half_box.
std::string data_text(const std::vector<Sphere> &atoms, double half_box);

// Writes data.txt and runs head_data() + body in dir.
RunResult run_with_data(const std::string &dir, const std::vector<Sphere> &atoms,
                        const std::string &body, double half_box = 0.01, int nprocs = 1,
                        bool split_x = false);

// Two spheres on the x axis at centre distance kL0 with spins wa, wb.
std::vector<Sphere> spinning_pair(const std::array<double, 3> &wa, const std::array<double, 3> &wb);

// Rows of a fix print table of the last run, keyed by step (column 0): a
// step printed twice keeps its last row. (fix print does not print at the
// setup of a run: the first row is step 1.)
std::vector<std::vector<double>> last_run_rows(const std::string &path);

// Times where column col crosses level upwards (linear interpolation; column 0 = time).
std::vector<double> crossings_up(const std::vector<std::vector<double>> &rows, int col,
                                 double level);

// Final positions (id -> xyz) from a `dump custom id x y z` file (the last snapshot).
std::map<int, std::array<double, 3>> read_positions(const std::string &path);

}  // namespace mill_test

#endif
