// Packing, bonding report and caching of the breakage lump.
#include "stages/lump_builder.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "engine/liggghts.h"
#include "jobs/job_store.h"
#include "progress.h"

namespace mill {
namespace fs = std::filesystem;
using engine::num;

LumpSpec lump_spec(const config::CaseConfig& cfg) {
  const auto& d = cfg.doc;
  return {d.integer("lump.n_elements"), d.real("lump.diameter"),  d.real("lump.radius_spread"),
          d.integer("lump.seed"),       d.real("lump.bond_gap"),  d.integer("lump.max_bonds"),
          cfg.ore.real("density"),      cfg.ore.real("poisson_ratio")};
}

// The five radius classes of the builder deck, relative to the mean.
double class_factor(int k, double spread) { return 1.0 + spread * (k - 2) / 2.0; }

// Mean of (r / r_mean)^3 over the five classes.
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
// Exclusive lock on a file for the lifetime of the object.
class FileLock {
 public:
  explicit FileLock(const fs::path& p) {
    fs::create_directories(p.parent_path());
    fd_ = open(p.c_str(), O_RDWR | O_CREAT, 0644);
    if (fd_ < 0 || flock(fd_, LOCK_EX) != 0) throw std::runtime_error("cannot lock " + p.string());
  }
  ~FileLock() {
    if (fd_ >= 0) {
      flock(fd_, LOCK_UN);
      close(fd_);
    }
  }
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

 private:
  int fd_ = -1;
};
}  // namespace

// LIGGGHTS wants distinct prime seeds > 10000; the deck's own templates use 10007-10061.
long prime_seed(long base) {
  long n = 20000 + (base % 1000000) * 7;
  while (!is_prime(n)) ++n;
  return n;
}

double target_mean_radius(long n, double diameter, double spread) {
  const double R = diameter / 2;
  const double phi = 0.62 * std::pow(1.0 - 1.23 * std::pow(static_cast<double>(n), -1.0 / 3.0), 3);
  return R * std::cbrt(phi / (static_cast<double>(n) * mean_cube_factor(spread)));
}

LumpInfo parse_lump_info(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(file.string() + ": empty lump info (builder did not finish)");
  std::istringstream ss(line);
  LumpInfo li;
  std::string key;
  double v;
  while (ss >> key >> v) {
    if (key == "atoms") li.elements = static_cast<long>(v);
    else if (key == "outer_radius") li.outer_radius = v;
    else if (key == "mean_radius") li.mean_radius = v;
    else if (key == "solid_fraction") li.solid_fraction = v;
    else if (key == "bonds") li.bonds = static_cast<long>(v);
    else if (key == "coordination") li.coordination = v;
  }
  if (li.elements <= 0 || li.outer_radius <= 0)
    throw std::runtime_error(file.string() + ": lump info lacks atoms/outer_radius: " + line);
  return li;
}

LumpInfo ensure_lump(StageContext& ctx, const LumpSpec& s, int packing, const std::string& requester) {
  const fs::path base = ctx.run_dir / "breakage" / "lumps";
  const std::string label = fmt::format("n{}_p{}", s.n_elements, packing);
  nlohmann::json in = {{"n_elements", s.n_elements}, {"diameter", s.diameter}, {"spread", s.spread},
                       {"seed", s.seed + packing},   {"bond_gap", s.bond_gap}, {"max_bonds", s.max_bonds},
                       {"density", s.density},       {"nu", s.nu},             {"deck_version", 2}};
  jobs::JobStore store(base);
  FileLock lock(base / (label + ".lock"));
  const fs::path dir = store.job_dir(label);
  if (store.decide(label, in, false).decision == jobs::Decision::Skip) {
    LumpInfo li = parse_lump_info(dir / "lump_info.txt");
    li.data = dir / "lump.data";
    li.label = label;
    return li;
  }
  store.mark_running(label, in);
  ctx.progress.info(fmt::format("[breakage] {}: building lump {} ({} elements, {:g} mm)", requester, label,
                                s.n_elements, s.diameter * 1e3));
  try {
    const double rm = target_mean_radius(s.n_elements, s.diameter, s.spread);
    const double rmin = rm * class_factor(0, s.spread);
    const double solid = s.n_elements * 4.0 / 3.0 * M_PI * rm * rm * rm * mean_cube_factor(s.spread);
    const double r_insert = std::cbrt(solid / 0.25 * 3.0 / (4.0 * M_PI));  // loose: 25% solid
    // Packing runs with a soft modulus (1e8 Pa): time step 20% of Rayleigh's.
    const double E_build = 1e8, G = E_build / (2 * (1 + s.nu));
    const double dt = 0.2 * M_PI * rmin * std::sqrt(s.density / G) / (0.1631 * s.nu + 0.8766);
    const double pull = 200.0;                                     // m/s^2
    const double t_pull = 2.5 * std::sqrt(2.0 * r_insert / pull);  // time to jam, with margin
    const double m_mean = s.density * 4.0 / 3.0 * M_PI * rm * rm * rm;
    const double gamma = m_mean / 0.03;  // viscous relaxation time 30 ms
    // Two distinct primes (two LIGGGHTS fixes sharing a seed abort silently).
    const long seed_dist = prime_seed(2 * (s.seed + packing));
    long seed_ins = prime_seed(2 * (s.seed + packing) + 1);
    if (seed_ins == seed_dist) seed_ins = next_prime(seed_dist + 1);
    fs::path tmp = dir / "build";
    fs::remove_all(tmp);
    engine::DeckRun run;
    run.deck = ctx.cfg.project_dir / "liggghts_inputs" / "lump_build.in.tmpl";
    run.workdir = tmp;
    run.np = 1;  // packing is cheap; one rank keeps it reproducible
    run.job = "breakage/lumps/" + label;
    run.vars = {{"n_elements", std::to_string(s.n_elements)},
                {"r_insert", num(r_insert)},
                {"density", num(s.density)},
                {"nu", num(s.nu)},
                {"E_build", num(E_build)},
                {"dt", num(dt)},
                {"pull_accel", num(pull)},
                {"gamma", num(gamma)},
                {"n_compact", std::to_string(static_cast<long>(std::ceil(t_pull / dt)))},
                {"n_relax", std::to_string(static_cast<long>(std::ceil(0.3 * t_pull / dt)))},
                {"skin", num(0.3 * rm)},
                {"seed_dist", std::to_string(seed_dist)},
                {"seed_ins", std::to_string(seed_ins)},
                {"bond_gap", num(s.bond_gap)},
                {"max_bonds", std::to_string(s.max_bonds)},
                {"r_mean", num(rm)},
                {"out", "lump.data"},
                {"info", "lump_info.txt"}};
    for (int k = 0; k < 5; ++k) run.vars.push_back({fmt::format("r{}", k), num(rm * class_factor(k, s.spread))});
    engine::run_deck(ctx.runner, run, ctx.progress, label);
    LumpInfo li = parse_lump_info(tmp / "lump_info.txt");
    if (li.elements != s.n_elements)
      throw std::runtime_error(fmt::format("lump {}: only {} of {} elements could be inserted (see {})", label,
                                           li.elements, s.n_elements, (tmp / "liggghts.log").string()));
    // Publish: data and info renamed into place, then STATUS done.
    fs::rename(tmp / "lump.data", dir / "lump.data");
    fs::rename(tmp / "lump_info.txt", dir / "lump_info.txt");
    fs::rename(tmp / "liggghts.log", dir / "build.log");
    fs::remove_all(tmp);
    store.mark_done(label);
    li.data = dir / "lump.data";
    li.label = label;
    ctx.progress.info(fmt::format(
        "[breakage] lump {}: {} elements, outer diameter {:.1f} mm (asked {:.1f} mm), mean element radius {:.3f} mm, "
        "solid fraction of the bounding sphere {:.2f}, {} bonds, mean coordination {:.2f}",
        label, li.elements, 2e3 * li.outer_radius, s.diameter * 1e3, li.mean_radius * 1e3, li.solid_fraction, li.bonds,
        li.coordination));
    return li;
  } catch (const std::exception& e) {
    store.mark_failed(label, e.what());
    throw;
  }
}

}  // namespace mill
