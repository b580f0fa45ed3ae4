// The ball packing shared by the breakage lump and the calibrate specimens:
// polydisperse elements packed into a ball by liggghts_inputs/lump_build.in.tmpl
// (docs/breakage.md, "Lump builder"), with the one rule that turns a packing's
// seed stream into the deck's LIGGGHTS seeds. Nothing here knows a stage.
#pragma once

#include <filesystem>
#include <string>

namespace mill {
class Progress;
namespace engine {
class Runner;
}

// A packed ball as the builder deck describes it (its info file).
struct LumpInfo {
  std::filesystem::path data;  // LIGGGHTS data file
  long elements = 0;
  double outer_radius = 0;    // m, from the centre to the outermost element surface
  double mean_radius = 0;     // m, mean element radius
  double solid_fraction = 0;  // solid volume / bounding-sphere volume
  long bonds = 0;             // bonds made with the impact deck's rule
  double coordination = 0;    // 2 bonds / elements
  std::string label;
};

// The five radius classes of the builder deck, relative to the mean.
double class_factor(int k, double spread);
// Mean of (r / r_mean)^3 over the five classes.
double mean_cube_factor(double spread);
// A prime > 20000 from a seed (LIGGGHTS wants distinct primes > 10000 for its
// random fixes, and aborts without a message when two share one).
long prime_seed(long base);

// The two LIGGGHTS seeds of one packing run (its two random fixes).
struct PackingSeeds {
  long dist = 0;  // fix particledistribution/discrete
  long ins = 0;   // fix insert/pack
};

// The one seed rule of every packing, from the packing's seed stream s:
//   dist = prime_seed(s)      (the first prime >= 20000 + 7 s)
//   ins  = prime_seed(s + 1), or the next prime above dist when the two
//          coincide (no prime lies in [20000 + 7 s, 20000 + 7 s + 7))
// so the two always differ. A lump's packing k takes the stream
// 2 (lump.seed + k); the calibrate specimen prime_stream(calibrate.seed).
// Both keep the seeds every lump and specimen has been packed with.
PackingSeeds packing_seeds(long stream);

// The stream whose slot [20000 + 7 t, 20000 + 7 t + 7) holds prime_seed(seed):
// packing_seeds(prime_stream(s)) gives the first fix prime_seed(s) and the
// second the first prime of the next slot.
long prime_stream(long seed);

// Mean element radius for N elements to fill a ball of the given diameter,
// with the solid fraction of a random packing in its bounding sphere
// (0.62 (1 - 1.23 N^(-1/3))^3, fitted to this builder; the rest follows).
double target_mean_radius(long n, double diameter, double spread);

// The element count whose target_mean_radius in a ball of `diameter` is
// nearest `radius` (the inverse of the above: the solid fraction rises with
// the count, so a lump of 8 x the elements in 2 x the diameter has slightly
// larger elements, and one of the same element size slightly more of them).
// At least 15: below it the rule's radius no longer falls with the count.
long elements_for_radius(double radius, double diameter, double spread);

// What decides one ball packing.
struct BallPacking {
  long n_elements = 0;
  double mean_radius = 0;  // m: the classes are mean_radius x class_factor(k, spread)
  double spread = 0;       // lump.radius_spread
  double density = 0;      // kg/m^3
  double nu = 0;           // Poisson's ratio
  double bond_gap = 0;     // the impact deck's bonding rule, to count the bonds
  long max_bonds = 0;
  long seed_stream = 0;  // packing_seeds(seed_stream)
};

// What a packing run needs from its caller: the engine, the log and the
// project folder (liggghts_inputs/lump_build.in.tmpl).
struct PackingEnv {
  engine::Runner& runner;
  Progress& progress;
  std::filesystem::path project_dir;
};

// Packs `b` in `workdir` (emptied first) into <stem>.data and <stem>_info.txt;
// `job` names the run in the engine's log, `label` in the progress. Returns
// the ball's description (data = workdir/<stem>.data); throws naming the log
// when fewer elements than asked could be inserted.
LumpInfo pack_ball(const PackingEnv& env, const BallPacking& b,
                   const std::filesystem::path& workdir, const std::string& stem,
                   const std::string& job, const std::string& label);

// Parse the builder's info line (<stem>_info.txt).
LumpInfo parse_lump_info(const std::filesystem::path& file);

}  // namespace mill
