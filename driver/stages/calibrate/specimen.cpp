// Specimens of the calibrate stage: the packed ball and the carve radii.
#include "stages/calibrate/specimen.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <vector>

#include "lump/packing.h"
#include "progress.h"

namespace mill::calibrate {
namespace fs = std::filesystem;

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

namespace {

// The ball the specimens are carved from: kBallFactor x n elements of the
// lump's size (same radius classes, spread and mean radius as the lump),
// seed stream prime_stream(calibrate.seed) (packing_seeds).
// The seed stream of packing k: k = 0 calibrate.seed's (prime_stream), k > 0
// the k-th later stream whose first seed is new.
long specimen_stream(long seed, int packing) {
  long stream = prime_stream(seed);
  std::set<long> used{packing_seeds(stream).dist};
  for (int k = 0; k < packing; ++k) {
    while (used.count(packing_seeds(stream).dist)) ++stream;
    used.insert(packing_seeds(stream).dist);
  }
  return stream;
}

BallPacking specimen_ball(const config::CaseConfig& cfg, long n, int packing) {
  const config::Document& d = cfg.doc;
  BallPacking b;
  b.spread = d.real("lump.radius_spread");
  b.mean_radius =
      target_mean_radius(d.integer("lump.n_elements"), d.real("lump.diameter"), b.spread);
  b.n_elements = static_cast<long>(std::ceil(kBallFactor * static_cast<double>(n)));
  b.density = cfg.ore.real("density");
  b.nu = cfg.ore.real("poisson_ratio");
  b.bond_gap = d.real("lump.bond_gap");
  b.max_bonds = d.integer("lump.max_bonds");
  b.seed_stream = specimen_stream(d.integer("calibrate.seed"), packing);
  return b;
}

}  // namespace

// Pack a ball of polydisperse elements with the lump's packing (pack_ball)
// and carve the n-element specimens from it.
Specimen pack_specimen(StageContext& ctx, const std::string& job_label, const fs::path& dir,
                       long n, int packing) {
  Specimen s;
  const BallPacking ball = specimen_ball(ctx.cfg, n, packing);
  const long nb = ball.n_elements;
  s.seed = packing_seeds(ball.seed_stream).dist;
  const std::string sub =
      packing == 0 ? std::string("specimen") : fmt::format("specimen_seed{}", s.seed);
  const fs::path work = dir / sub;
  ctx.progress.job_step(job_label, fmt::format("packing a ball of {} elements", nb), 0.0);
  ctx.progress.info(fmt::format(
      "[calibrate] packing a ball of {} elements (mean radius {:.3f} mm, as the lump) to carve "
      "the specimens from",
      nb, ball.mean_radius * 1e3));
  const LumpInfo li = pack_ball({ctx.runner, ctx.progress, ctx.cfg.project_dir}, ball, work, "ball",
                                "calibrate/" + job_label + "/" + sub, job_label);
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
