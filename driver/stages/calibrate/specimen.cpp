// Specimens of the calibrate stage: the packed ball and the carve radii.
#include "stages/calibrate/specimen.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <sstream>
#include <vector>

#include "engine/liggghts.h"
#include "progress.h"
#include "stages/lump_builder.h"

namespace mill::calibrate {
namespace fs = std::filesystem;
using engine::num;

namespace {

// Ball packed for the specimens: this many times calibrate.n_elements, so
// that a height/diameter-2 cylinder of n elements fits well inside it.
constexpr double kBallFactor = 4.5;

// Element centres of a LIGGGHTS data file (atom_style granular: id type
// diameter density x y z ...).
std::vector<std::array<double, 3>> read_centres(const fs::path& data) {
  std::ifstream in(data);
  if (!in) throw std::runtime_error("cannot open " + data.string());
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("Atoms", 0) == 0) break;
  std::vector<std::array<double, 3>> c;
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    double id, type, d, rho, x, y, z;
    if (!(ss >> id >> type >> d >> rho >> x >> y >> z)) {
      if (c.empty()) continue;  // the blank line after the header
      break;
    }
    c.push_back({x, y, z});
  }
  if (c.empty()) throw std::runtime_error(data.string() + ": no Atoms section");
  return c;
}

// The carve radius that keeps exactly n element centres in the specimen:
// for the UCS cylinder (axis z, half-height 2a) a centre is inside when
// max(rho_xy, |z|/2) < a; for the Brazilian disc (axis y, half-thickness a/2)
// when max(rho_xz, 2|y|) < a. Returns the midpoint between the n-th and
// (n+1)-th smallest of these norms.
double carve_radius(const std::vector<std::array<double, 3>>& c, long n, bool cylinder) {
  if (static_cast<long>(c.size()) <= n)
    throw std::runtime_error(fmt::format(
        "specimen: the packed ball has {} elements, fewer than the {} asked", c.size(), n));
  std::vector<double> s;
  s.reserve(c.size());
  for (const auto& p : c)
    s.push_back(cylinder ? std::max(std::hypot(p[0], p[1]), std::abs(p[2]) / 2)
                         : std::max(std::hypot(p[0], p[2]), 2 * std::abs(p[1])));
  std::nth_element(s.begin(), s.begin() + n, s.end());
  const double above = s[n];
  const double below = *std::max_element(s.begin(), s.begin() + n);
  return 0.5 * (below + above);
}

}  // namespace

// "key value key value ..." from the first line of a deck's info file.
std::map<std::string, double> read_info(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  if (!std::getline(in, line))
    throw std::runtime_error(file.string() + ": empty (the deck did not reach its first run)");
  std::istringstream ss(line);
  std::map<std::string, double> m;
  std::string key, val;
  while (ss >> key >> val) {
    try {
      m[key] = std::stod(val);
    } catch (const std::exception&) {
      // words such as "cylinder" carry no number
    }
  }
  return m;
}

// A value of the specimen info, or an error naming the file and key.
double info_at(const std::map<std::string, double>& m, const std::string& key,
               const fs::path& file) {
  auto it = m.find(key);
  if (it == m.end())
    throw std::runtime_error(file.string() + ": no '" + key + "' in the specimen info");
  return it->second;
}

// Pack a ball of polydisperse elements with the lump builder's deck and
// procedure (same radius classes, spread and element size as the lump).
Specimen pack_specimen(StageContext& ctx, const std::string& job_label, const fs::path& dir,
                       long n) {
  const config::Document& d = ctx.cfg.doc;
  const config::Document& ore = ctx.cfg.ore;
  Specimen s;
  const double spread = d.real("lump.radius_spread");
  const double rm =
      target_mean_radius(d.integer("lump.n_elements"), d.real("lump.diameter"), spread);
  const long nb = static_cast<long>(std::ceil(kBallFactor * static_cast<double>(n)));
  const double rho = ore.real("density"), nu = ore.real("poisson_ratio");
  const double rmin = rm * class_factor(0, spread);
  const double solid =
      static_cast<double>(nb) * 4.0 / 3.0 * M_PI * rm * rm * rm * mean_cube_factor(spread);
  const double r_insert = std::cbrt(solid / 0.25 * 3.0 / (4.0 * M_PI));  // loose: 25% solid
  // As in lump_builder.cpp: soft packing modulus, 20% of the Rayleigh step,
  // central pull until jammed, viscous relaxation.
  const double E_build = 1e8, G = E_build / (2 * (1 + nu));
  const double dt = 0.2 * M_PI * rmin * std::sqrt(rho / G) / (0.1631 * nu + 0.8766);
  const double pull = 200.0;
  const double t_pull = 2.5 * std::sqrt(2.0 * r_insert / pull);
  const double m_mean = rho * 4.0 / 3.0 * M_PI * rm * rm * rm;
  const long seed = d.integer("calibrate.seed");
  // Two distinct primes (prime_seed of neighbouring bases can coincide).
  const long seed_dist = prime_seed(seed), seed_ins = prime_seed((seed_dist - 20000) / 7 + 1);
  const fs::path work = dir / "specimen";
  fs::remove_all(work);
  engine::DeckRun run;
  run.deck = ctx.cfg.project_dir / "liggghts_inputs" / "lump_build.in.tmpl";
  run.workdir = work;
  run.np = 1;
  run.job = "calibrate/" + job_label + "/specimen";
  run.vars = {{"n_elements", std::to_string(nb)},
              {"r_insert", num(r_insert)},
              {"density", num(rho)},
              {"nu", num(nu)},
              {"E_build", num(E_build)},
              {"dt", num(dt)},
              {"pull_accel", num(pull)},
              {"gamma", num(m_mean / 0.03)},
              {"n_compact", std::to_string(static_cast<long>(std::ceil(t_pull / dt)))},
              {"n_relax", std::to_string(static_cast<long>(std::ceil(0.3 * t_pull / dt)))},
              {"skin", num(0.3 * rm)},
              {"seed_dist", std::to_string(seed_dist)},
              {"seed_ins", std::to_string(seed_ins)},
              {"bond_gap", num(d.real("lump.bond_gap"))},
              {"max_bonds", std::to_string(d.integer("lump.max_bonds"))},
              {"r_mean", num(rm)},
              {"out", "ball.data"},
              {"info", "ball_info.txt"}};
  for (int k = 0; k < 5; ++k)
    run.vars.push_back({fmt::format("r{}", k), num(rm * class_factor(k, spread))});
  ctx.progress.job_step(job_label, fmt::format("packing a ball of {} elements", nb), 0.0);
  ctx.progress.info(fmt::format(
      "[calibrate] packing a ball of {} elements (mean radius {:.3f} mm, as the lump) to carve "
      "the specimens from",
      nb, rm * 1e3));
  engine::run_deck(ctx.runner, run, ctx.progress, job_label);
  const LumpInfo li = parse_lump_info(work / "ball_info.txt");
  if (li.elements != nb)
    throw std::runtime_error(
        fmt::format("specimen: only {} of {} elements could be packed (see {})", li.elements, nb,
                    (work / "liggghts.log").string()));
  s.ball = work / "ball.data";
  s.ball_elements = li.elements;
  s.ball_outer_radius = li.outer_radius;
  s.mean_radius = li.mean_radius;
  const auto centres = read_centres(s.ball);
  s.cyl_r = carve_radius(centres, n, true);
  s.disc_r = carve_radius(centres, n, false);
  // The cylinder's rim must stay inside the ball's dense core.
  const double reach = std::sqrt(5.0) * s.cyl_r;
  if (reach > li.outer_radius - li.mean_radius)
    ctx.progress.warn(fmt::format(
        "[calibrate] the {}-element cylinder reaches {:.1f} mm from the centre of a ball of "
        "{:.1f} mm: its corners sit in the ball's looser surface layer",
        n, reach * 1e3, li.outer_radius * 1e3));
  return s;
}

}  // namespace mill::calibrate
