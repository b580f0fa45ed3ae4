// The ball packing of the lump and the specimens, and its seed rule.
#include "lump/packing.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "engine/liggghts.h"

namespace mill {
namespace fs = std::filesystem;
using engine::num;

double class_factor(int k, double spread) { return 1.0 + spread * (k - 2) / 2.0; }

double mean_cube_factor(double spread) {
  double s = 0;
  for (int k = 0; k < 5; ++k) s += std::pow(class_factor(k, spread), 3);
  return s / 5.0;
}

namespace {
bool is_prime(long n) {
  if (n < 2) return false;
  for (long i = 2; i * i <= n; ++i)
    if (n % i == 0) return false;
  return true;
}
long next_prime(long n) {
  while (!is_prime(n)) ++n;
  return n;
}
}  // namespace

// LIGGGHTS wants distinct prime seeds > 10000; the deck's own templates use 10007-10061.
long prime_seed(long base) { return next_prime(20000 + (base % 1000000) * 7); }

PackingSeeds packing_seeds(long stream) {
  PackingSeeds s;
  s.dist = prime_seed(stream);
  s.ins = prime_seed(stream + 1);
  if (s.ins == s.dist) s.ins = next_prime(s.dist + 1);
  return s;
}

long prime_stream(long seed) { return (prime_seed(seed) - 20000) / 7; }

double target_mean_radius(long n, double diameter, double spread) {
  const double R = diameter / 2;
  const double phi = 0.62 * std::pow(1.0 - 1.23 * std::pow(static_cast<double>(n), -1.0 / 3.0), 3);
  return R * std::cbrt(phi / (static_cast<double>(n) * mean_cube_factor(spread)));
}

long elements_for_radius(double radius, double diameter, double spread) {
  // target_mean_radius is R (0.62 / c)^(1/3) x (1 - 1.23 x), x = n^(-1/3):
  // it falls with n from n = 15 on (x below 1 / 2.46), the packings the
  // rule was fitted to. Bisect there for the last n whose radius is at
  // least `radius`, then take the nearer of it and the next.
  constexpr long kFirst = 15;
  if (target_mean_radius(kFirst, diameter, spread) <= radius) return kFirst;
  long lo = kFirst, hi = 2 * kFirst;
  while (target_mean_radius(hi, diameter, spread) >= radius && hi < (1L << 40)) {
    lo = hi;
    hi *= 2;
  }
  while (hi - lo > 1) {
    const long mid = lo + (hi - lo) / 2;
    (target_mean_radius(mid, diameter, spread) >= radius ? lo : hi) = mid;
  }
  return target_mean_radius(lo, diameter, spread) - radius <= radius - target_mean_radius(hi, diameter, spread)
             ? lo
             : hi;
}

LumpInfo parse_lump_info(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  if (!std::getline(in, line))
    throw std::runtime_error(file.string() +
                             ": empty packing info (the builder deck did not finish)");
  std::istringstream ss(line);
  LumpInfo li;
  std::string key;
  double v;
  while (ss >> key >> v) {
    if (key == "atoms")
      li.elements = static_cast<long>(v);
    else if (key == "outer_radius")
      li.outer_radius = v;
    else if (key == "mean_radius")
      li.mean_radius = v;
    else if (key == "solid_fraction")
      li.solid_fraction = v;
    else if (key == "bonds")
      li.bonds = static_cast<long>(v);
    else if (key == "coordination")
      li.coordination = v;
  }
  if (li.elements <= 0 || li.outer_radius <= 0)
    throw std::runtime_error(file.string() + ": packing info lacks atoms/outer_radius: " + line);
  return li;
}

namespace {

// The builder deck's -var pairs for `b`: elements inserted loosely (25 %
// solid) into a sphere, pulled together by a central force with a soft
// modulus and a time step of 20 % of Rayleigh's, then relaxed viscously.
std::vector<std::pair<std::string, std::string>> packing_vars(const BallPacking& b,
                                                              const std::string& stem) {
  const double rm = b.mean_radius;
  const double rmin = rm * class_factor(0, b.spread);
  const double solid = b.n_elements * 4.0 / 3.0 * M_PI * rm * rm * rm * mean_cube_factor(b.spread);
  const double r_insert = std::cbrt(solid / 0.25 * 3.0 / (4.0 * M_PI));  // loose: 25% solid
  // Packing runs with a soft modulus (1e8 Pa): time step 20% of Rayleigh's.
  const double E_build = 1e8, G = E_build / (2 * (1 + b.nu));
  const double dt = 0.2 * M_PI * rmin * std::sqrt(b.density / G) / (0.1631 * b.nu + 0.8766);
  const double pull = 200.0;                                     // m/s^2
  const double t_pull = 2.5 * std::sqrt(2.0 * r_insert / pull);  // time to jam, with margin
  const double m_mean = b.density * 4.0 / 3.0 * M_PI * rm * rm * rm;
  const double gamma = m_mean / 0.03;  // viscous relaxation time 30 ms
  const PackingSeeds seeds = packing_seeds(b.seed_stream);
  std::vector<std::pair<std::string, std::string>> v = {
      {"n_elements", std::to_string(b.n_elements)},
      {"r_insert", num(r_insert)},
      {"density", num(b.density)},
      {"nu", num(b.nu)},
      {"E_build", num(E_build)},
      {"dt", num(dt)},
      {"pull_accel", num(pull)},
      {"gamma", num(gamma)},
      {"n_compact", std::to_string(static_cast<long>(std::ceil(t_pull / dt)))},
      {"n_relax", std::to_string(static_cast<long>(std::ceil(0.3 * t_pull / dt)))},
      {"skin", num(0.3 * rm)},
      {"seed_dist", std::to_string(seeds.dist)},
      {"seed_ins", std::to_string(seeds.ins)},
      {"bond_gap", num(b.bond_gap)},
      {"max_bonds", std::to_string(b.max_bonds)},
      {"r_mean", num(rm)},
      {"out", stem + ".data"},
      {"info", stem + "_info.txt"}};
  for (int k = 0; k < 5; ++k)
    v.push_back({fmt::format("r{}", k), num(rm * class_factor(k, b.spread))});
  return v;
}

}  // namespace

LumpInfo pack_ball(const PackingEnv& env, const BallPacking& b, const fs::path& workdir,
                   const std::string& stem, const std::string& job, const std::string& label) {
  fs::remove_all(workdir);
  engine::DeckRun run;
  run.deck = env.project_dir / "liggghts_inputs" / "lump_build.in.tmpl";
  run.workdir = workdir;
  run.np = 1;  // packing is cheap; one rank keeps it reproducible
  run.job = job;
  run.vars = packing_vars(b, stem);
  engine::run_deck(env.runner, run, env.progress, label);
  LumpInfo li = parse_lump_info(workdir / (stem + "_info.txt"));
  if (li.elements != b.n_elements)
    throw std::runtime_error(
        fmt::format("{}: only {} of {} elements could be inserted into the packing sphere (see {})",
                    job, li.elements, b.n_elements, (workdir / "liggghts.log").string()));
  li.data = workdir / (stem + ".data");
  return li;
}

}  // namespace mill
