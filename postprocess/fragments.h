// Fragments of a bonded ore lump after an impact: the connected components of
// its elements over the bonds that are still intact (method.md, stage 2).
// Used by the breakage stage once per impact, after LIGGGHTS has finished.
#pragma once

#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

namespace mill::post {

inline constexpr double kPi = 3.14159265358979323846;

// Mass of a solid sphere of radius r (m) and density rho (kg/m3), in kg.
inline double SphereMass(double radius_m, double density_kg_m3) {
  return density_kg_m3 * 4.0 / 3.0 * kPi * radius_m * radius_m * radius_m;
}

// Any problem with post-processing inputs (bad file, inconsistent data). The
// text names the file, line or key and the offending value.
struct PostError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// One spherical element of the lump, as read from the final dump.
struct Element {
  long long id = 0;           // atom id (tag)
  int type = 1;               // atom type
  double radius = 0.0;        // m
  double mass = 0.0;          // kg
  std::array<double, 3> x{};  // position, m
  std::array<double, 3> v{};  // velocity, m/s
};

// An intact bond between two atom ids.
struct Bond {
  long long i = 0;
  long long j = 0;
};

// A piece of the broken lump: elements still joined by intact bonds.
struct Fragment {
  std::vector<long long> ids;        // element ids, ascending
  double mass = 0.0;                 // kg
  double diameter = 0.0;             // equal-volume sphere of the solid, m
  std::array<double, 3> velocity{};  // centre-of-mass velocity, m/s
  std::size_t n_elements() const { return ids.size(); }
};

// Equivalent diameter of a piece: the sphere holding the same volume of solid
// ore, d = (6 m / (pi rho))^(1/3). Pores between elements are not counted, so
// a single element of radius r made with the same density has d = 2 r.
double EquivalentDiameter(double mass_kg, double density_kg_m3);

// Groups elements into fragments by union-find over the intact bonds. Called
// once per impact. Throws PostError naming `bond_source` and the id when a bond
// names an element that is not in `elements`, or when ids repeat. Fragments
// come out heaviest first (ties: smallest first id first).
std::vector<Fragment> FindFragments(const std::vector<Element>& elements,
                                    const std::vector<Bond>& bonds, double density_kg_m3,
                                    const std::string& bond_source = "bond list");

}  // namespace mill::post
