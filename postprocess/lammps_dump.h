// Readers for what one LIGGGHTS breakage run leaves behind: the final
// `dump custom` text file and the intact-bond file of the bond fix.
#pragma once

#include <array>
#include <istream>
#include <string>
#include <vector>

#include "postprocess/fragments.h"

namespace mill::post {

// The last snapshot of a dump file.
struct DumpSnapshot {
  long long timestep = 0;
  std::array<double, 6> box{};  // xlo xhi ylo yhi zlo zhi, m
  std::vector<Element> elements;
  bool mass_from_density = false;  // true when the dump had no `mass` column
  int n_snapshots = 0;             // snapshots seen in the file
};

// Reads a LAMMPS/LIGGGHTS `dump custom` text file and returns its last
// snapshot. Columns are found by name (id, radius, vx, vy, vz required; type,
// mass, x/xu, y/yu, z/zu optional; others ignored). Without `mass`, the mass is
// density * 4/3 pi r^3. Throws PostError naming the file and line on bad input.
DumpSnapshot ReadDumpLastSnapshot(const std::string& path, double density_kg_m3);

// Same as ReadDumpLastSnapshot, from a stream; `label` names it in errors.
DumpSnapshot ParseDumpLastSnapshot(std::istream& in, const std::string& label,
                                   double density_kg_m3);

// Reads the bond fix's intact-bond file: `#` lines are comments, every other
// non-blank line is `tag_i tag_j`. Throws PostError naming file and line.
std::vector<Bond> ReadIntactBonds(const std::string& path);

// Same as ReadIntactBonds, from a stream; `label` names it in errors.
std::vector<Bond> ParseIntactBonds(std::istream& in, const std::string& label);

}  // namespace mill::post
