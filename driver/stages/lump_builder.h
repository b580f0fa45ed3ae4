// The bonded lump of the breakage stage: packed once per (lump keys, packing)
// by liggghts_inputs/lump_build.in.tmpl, cached under <run>/breakage/lumps/
// and shared by every impact of a campaign (a file lock serialises builders).
#pragma once

#include <filesystem>
#include <string>

#include "stages/stage.h"

namespace mill {

struct LumpInfo {
  std::filesystem::path data;  // LIGGGHTS data file
  long elements = 0;
  double outer_radius = 0;     // m, from the centre to the outermost element surface
  double mean_radius = 0;      // m, mean element radius
  double solid_fraction = 0;   // solid volume / bounding-sphere volume
  long bonds = 0;              // bonds made with the impact deck's rule
  double coordination = 0;     // 2 bonds / elements
  std::string label;
};

// What decides a packing (its job inputs).
struct LumpSpec {
  long n_elements;
  double diameter;
  double spread;
  long seed;
  double bond_gap;
  long max_bonds;
  double density;
  double nu;
};

LumpSpec lump_spec(const config::CaseConfig& cfg);

// The five radius classes of the builder deck, relative to the mean.
double class_factor(int k, double spread);
// Mean of (r / r_mean)^3 over the five classes.
double mean_cube_factor(double spread);
// A prime > 20000 from a seed (LIGGGHTS wants distinct primes > 10000 for its
// random fixes, and aborts without a message when two share one).
long prime_seed(long base);

// Mean element radius for N elements to fill a ball of the given diameter,
// with the solid fraction of a random packing in its bounding sphere
// (0.62 (1 - 1.23 N^(-1/3))^3, fitted to this builder; the rest follows).
double target_mean_radius(long n, double diameter, double spread);

// Build (or reuse) packing `packing` of the lump; returns its description.
LumpInfo ensure_lump(StageContext& ctx, const LumpSpec& spec, int packing, const std::string& requester);

// Parse the builder's info line (lump_info.txt).
LumpInfo parse_lump_info(const std::filesystem::path& file);

}  // namespace mill
