// Specimens of the calibrate stage: a ball packed like the lump, and the
// carve radii of the UCS cylinder and the Brazilian disc cut out of it
// (docs/calibration.md, steps 1 and 2).
#pragma once

#include <filesystem>
#include <map>
#include <string>

#include "stages/stage.h"

namespace mill::calibrate {

struct Specimen {
  std::filesystem::path ball;  // packed ball (LIGGGHTS data file)
  long ball_elements = 0;
  double ball_outer_radius = 0;
  double mean_radius = 0;  // m, asked (lump's element size)
  double cyl_r = 0, disc_r = 0;
  long seed = 0;  // the packing's first LIGGGHTS seed (fix particledistribution): its name
};

// Pack the ball in <dir>/specimen and carve n-element specimens from it;
// packing k > 0 (the packing check) packs another ball in
// <dir>/specimen_seed<seed>: the k-th seed stream after calibrate.seed's
// whose first seed differs from every earlier one (neighbouring seeds may
// share a prime, packing.h).
Specimen pack_specimen(StageContext& ctx, const std::string& job_label,
                       const std::filesystem::path& dir, long n, int packing = 0);

// "key value key value ..." from the first line of a deck's info file.
std::map<std::string, double> read_info(const std::filesystem::path& file);

// A value of the specimen info, or an error naming the file and key.
double info_at(const std::map<std::string, double>& m, const std::string& key,
               const std::filesystem::path& file);

}  // namespace mill::calibrate
