// Stage 'calibrate': bond parameters from the ore card's macro properties (issue 5).
#include "stages/calibrate_stage.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <regex>
#include <sstream>

#include "engine/liggghts.h"
#include "jobs/job_store.h"
#include "postprocess/lab_tests.h"
#include "progress.h"
#include "stages/lump_builder.h"
#include "stages/material.h"
#include "stages/stage_util.h"

namespace mill {
namespace fs = std::filesystem;
using engine::num;

namespace {

// Bumped when a deck or the fitting scheme changes what a calibration gives.
constexpr int kDeckVersion = 1;
// Ball packed for the specimens: this many times calibrate.n_elements, so
// that a height/diameter-2 cylinder of n elements fits well inside it.
constexpr double kBallFactor = 4.5;
// Tolerance on Poisson's ratio (absolute).
constexpr double kNuTolerance = 0.05;
// Cap on cohesion / bond tensile strength (the UCS lever).
constexpr double kMaxCohesionRatio = 50.0;

const char* kCalibratedKeys[] = {"calibrated.bond_modulus",          "calibrated.stiffness_ratio",
                                 "calibrated.bond_tensile_strength", "calibrated.bond_cohesion",
                                 "calibrated.bond_friction_angle",   "calibrated.input_hash"};

// True when the ore card carries a complete calibrated.* section fitted to
// its own macro properties (same input_hash).
bool card_is_calibrated(const config::CaseConfig& cfg) {
  for (const char* k : kCalibratedKeys)
    if (!cfg.ore.has(k)) return false;
  return cfg.ore.str("calibrated.input_hash") == ore_hash(cfg.ore);
}

// True when the card carries a complete calibrated.* section fitted to other
// properties (a stale calibration): the fit then starts from it.
bool card_has_stale_calibration(const config::CaseConfig& cfg) {
  for (const char* k : kCalibratedKeys)
    if (!cfg.ore.has(k)) return false;
  return !card_is_calibrated(cfg);
}

// The five radius classes of lump_build.in.tmpl, relative to the mean.
double class_factor(int k, double spread) { return 1.0 + spread * (k - 2) / 2.0; }

// Mean of (r / r_mean)^3 over the five classes.
double mean_cube_factor(double spread) {
  double s = 0;
  for (int k = 0; k < 5; ++k) s += std::pow(class_factor(k, spread), 3);
  return s / 5.0;
}

// A prime > 20000 from a seed (LIGGGHTS wants distinct primes > 10000 for its
// random fixes, and aborts without a message when two share one).
long prime_seed(long base) {
  auto is_prime = [](long n) {
    for (long i = 2; i * i <= n; ++i)
      if (n % i == 0) return false;
    return n > 1;
  };
  long n = 20000 + (base % 1000000) * 7;
  while (!is_prime(n)) ++n;
  return n;
}

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

struct Targets {
  double E, nu, ucs, tensile;
};

struct Specimen {
  fs::path ball;  // packed ball (LIGGGHTS data file)
  long ball_elements = 0;
  double ball_outer_radius = 0;
  double mean_radius = 0;  // m, asked (lump's element size)
  double cyl_r = 0, disc_r = 0;
};

struct UcsRun {
  post::UcsResult r;
  std::map<std::string, double> info;
  post::StressStrain ss;
  post::LoadCurve curve;
  double area = 0, gauge = 0;
  double seconds = 0;
  bool peaked = true;  // false: the run reached max_strain still loading
};

struct BrazilianRun {
  post::BrazilianResult r;
  std::map<std::string, double> info;
  post::LoadCurve curve;
  double seconds = 0;
  bool peaked = true;
};

struct Iteration {
  BondParams p;
  UcsRun ucs;
  BrazilianRun br;
  double err_E = 0, err_ucs = 0, err_t = 0, err_nu = 0;
  bool converged = false;
  double score = 0;  // worst error in units of its tolerance
};

// Bond parameters as JSON, with the calibrated.yaml key names.
nlohmann::json bond_json(const BondParams& b) {
  return {{"bond_modulus", b.modulus},
          {"stiffness_ratio", b.stiffness_ratio},
          {"bond_tensile_strength", b.tensile},
          {"bond_cohesion", b.cohesion},
          {"bond_friction_angle", b.friction_angle_deg},
          {"radius_multiplier", b.radius_multiplier}};
}

// Everything one calibration run needs, gathered from the case.
class Calibration {
 public:
  // Targets and settings from the case and its ore card.
  Calibration(StageContext& ctx, const JobSpec& job, const fs::path& dir)
      : ctx_(ctx), job_(job), dir_(dir), d_(ctx.cfg.doc), ore_(ctx.cfg.ore) {
    t_ = {ore_.real("youngs_modulus"), ore_.real("poisson_ratio"), ore_.real("ucs"),
          ore_.real("tensile_strength")};
    tol_ = d_.real("calibrate.tolerance");
    n_ = d_.integer("calibrate.n_elements");
    rate_ = d_.real("calibrate.strain_rate");
    max_it_ = static_cast<int>(d_.integer("calibrate.max_iterations"));
  }

  // The whole calibration: specimen, iterations, rate check, outputs.
  void run();

 private:
  Specimen pack();
  UcsRun run_ucs(const BondParams& p, double rate, const std::string& tag, const std::string& what);
  BrazilianRun run_brazilian(const BondParams& p, const std::string& tag, const std::string& what);
  engine::Result run_lab_deck(const std::string& deck, const fs::path& work,
                              std::vector<std::pair<std::string, std::string>> vars,
                              const std::string& what);
  void score(Iteration& it) const;
  BondParams update(const std::vector<Iteration>& hist, std::vector<std::string>& notes) const;
  void write_outputs(const std::vector<Iteration>& hist, size_t best,
                     const std::optional<UcsRun>& half, double wall,
                     const std::vector<std::string>& notes);

  StageContext& ctx_;
  const JobSpec& job_;
  fs::path dir_;
  const config::Document& d_;
  const config::Document& ore_;
  Targets t_{};
  double tol_ = 0.1, rate_ = 0.5;
  long n_ = 0;
  int max_it_ = 1;
  Specimen sp_;
  double progress_ = 0;  // fraction of the job done, for the status line
};

// Pack a ball of polydisperse elements with the lump builder's deck and
// procedure (same radius classes, spread and element size as the lump).
Specimen Calibration::pack() {
  Specimen s;
  const double spread = d_.real("lump.radius_spread");
  const double rm =
      target_mean_radius(d_.integer("lump.n_elements"), d_.real("lump.diameter"), spread);
  const long nb = static_cast<long>(std::ceil(kBallFactor * static_cast<double>(n_)));
  const double rho = ore_.real("density"), nu = ore_.real("poisson_ratio");
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
  const long seed = d_.integer("calibrate.seed");
  // Two distinct primes (prime_seed of neighbouring bases can coincide).
  const long seed_dist = prime_seed(seed), seed_ins = prime_seed((seed_dist - 20000) / 7 + 1);
  const fs::path work = dir_ / "specimen";
  fs::remove_all(work);
  engine::DeckRun run;
  run.deck = ctx_.cfg.project_dir / "liggghts_inputs" / "lump_build.in.tmpl";
  run.workdir = work;
  run.np = 1;
  run.job = "calibrate/" + job_.label + "/specimen";
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
              {"bond_gap", num(d_.real("lump.bond_gap"))},
              {"max_bonds", std::to_string(d_.integer("lump.max_bonds"))},
              {"r_mean", num(rm)},
              {"out", "ball.data"},
              {"info", "ball_info.txt"}};
  for (int k = 0; k < 5; ++k)
    run.vars.push_back({fmt::format("r{}", k), num(rm * class_factor(k, spread))});
  ctx_.progress.job_step(job_.label, fmt::format("packing a ball of {} elements", nb), 0.0);
  ctx_.progress.info(fmt::format(
      "[calibrate] packing a ball of {} elements (mean radius {:.3f} mm, as the lump) to carve "
      "the specimens from",
      nb, rm * 1e3));
  engine::run_deck(ctx_.runner, run, ctx_.progress, job_.label);
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
  s.cyl_r = carve_radius(centres, n_, true);
  s.disc_r = carve_radius(centres, n_, false);
  // The cylinder's rim must stay inside the ball's dense core.
  const double reach = std::sqrt(5.0) * s.cyl_r;
  if (reach > li.outer_radius - li.mean_radius)
    ctx_.progress.warn(fmt::format(
        "[calibrate] the {}-element cylinder reaches {:.1f} mm from the centre of a ball of "
        "{:.1f} mm: its corners sit in the ball's looser surface layer",
        n_, reach * 1e3, li.outer_radius * 1e3));
  return s;
}

// Run one lab deck in `work`, showing its progress as `what`.
engine::Result Calibration::run_lab_deck(const std::string& deck, const fs::path& work,
                                         std::vector<std::pair<std::string, std::string>> vars,
                                         const std::string& what) {
  fs::remove_all(work);
  fs::create_directories(work);
  engine::DeckRun run;
  run.deck = ctx_.cfg.project_dir / "liggghts_inputs" / deck;
  run.workdir = work;
  run.np = ctx_.opts.np;
  run.job = "calibrate/" + job_.label + "/" + work.filename().string();
  run.vars = std::move(vars);
  if (!fs::exists(run.deck))
    throw std::runtime_error(fmt::format("deck template {} not found", run.deck.string()));
  const std::string label = job_.label;
  const double base = progress_;
  auto poll = [&](const fs::path& log) {
    std::ifstream in(log);
    std::string line, last;
    long total = 0;
    static const std::regex nsteps_re("nsteps ([0-9]+)");
    static const std::regex step_re("^\\s+([0-9]+)\\s+[-0-9.e+]+");
    std::smatch m;
    while (std::getline(in, line)) {
      if (std::regex_search(line, m, nsteps_re))
        total = std::stol(m[1]);
      else if (std::regex_search(line, m, step_re))
        last = m[1];
    }
    ctx_.progress.job_step(label,
                           total > 0 && !last.empty()
                               ? fmt::format("{}: step {} (at most {})", what, last, total)
                               : what,
                           base);
  };
  return ctx_.runner.run(engine::deck_command(run), poll);
}

// A UCS test with bond parameters p at the given strain rate.
UcsRun Calibration::run_ucs(const BondParams& p, double rate, const std::string& tag,
                            const std::string& what) {
  const double peak_strain = t_.ucs / t_.E;
  auto vars = material_vars(ore_, p);
  for (auto kv : std::initializer_list<std::pair<std::string, std::string>>{
           {"specimen_file", fs::absolute(sp_.ball).string()},
           {"carve_r", num(sp_.cyl_r)},
           {"strain_rate", num(rate)},
           {"max_strain", num(4.0 * peak_strain)},
           {"sample_time", num(peak_strain / rate / 300.0)},
           {"skin", num(0.3 * sp_.mean_radius)},
           {"bond_gap", num(d_.real("lump.bond_gap"))},
           {"max_bonds", std::to_string(d_.integer("lump.max_bonds"))}})
    vars.push_back(kv);
  const fs::path work = dir_ / "runs" / tag;
  const engine::Result res = run_lab_deck("ucs.in.tmpl", work, vars, what);
  UcsRun u;
  u.seconds = res.seconds;
  u.info = read_info(work / "ucs_info.txt");
  const double D = info_at(u.info, "diameter", work / "ucs_info.txt");
  u.gauge = info_at(u.info, "gauge_length", work / "ucs_info.txt");
  u.area = M_PI * D * D / 4.0;
  u.curve = post::ReadLoadCurve((work / "ucs_curve.txt").string());
  u.ss = post::ToStressStrain(u.curve, u.gauge, u.area);
  u.r = post::AnalyseUcs(u.ss);
  u.peaked = u.r.peak_index + 1 < u.ss.stress.size();
  return u;
}

// A Brazilian test with bond parameters p at the case's rate.
BrazilianRun Calibration::run_brazilian(const BondParams& p, const std::string& tag,
                                        const std::string& what) {
  const double peak_strain = 4.0 * t_.tensile / t_.E;  // closure/D at the peak, about
  auto vars = material_vars(ore_, p);
  for (auto kv : std::initializer_list<std::pair<std::string, std::string>>{
           {"specimen_file", fs::absolute(sp_.ball).string()},
           {"carve_r", num(sp_.disc_r)},
           {"strain_rate", num(rate_)},
           {"max_strain", num(5.0 * peak_strain)},
           {"sample_time", num(peak_strain / rate_ / 300.0)},
           {"skin", num(0.3 * sp_.mean_radius)},
           {"bond_gap", num(d_.real("lump.bond_gap"))},
           {"max_bonds", std::to_string(d_.integer("lump.max_bonds"))}})
    vars.push_back(kv);
  const fs::path work = dir_ / "runs" / tag;
  const engine::Result res = run_lab_deck("brazilian.in.tmpl", work, vars, what);
  BrazilianRun b;
  b.seconds = res.seconds;
  b.info = read_info(work / "brazilian_info.txt");
  b.curve = post::ReadLoadCurve((work / "brazilian_curve.txt").string());
  b.r = post::AnalyseBrazilian(b.curve, info_at(b.info, "diameter", work / "brazilian_info.txt"),
                               info_at(b.info, "thickness", work / "brazilian_info.txt"));
  b.peaked = b.r.peak_index + 1 < b.curve.size();
  return b;
}

// Errors of one iteration against the ore card and whether all are met.
void Calibration::score(Iteration& it) const {
  it.err_E = post::RelativeError(it.ucs.r.youngs_modulus, t_.E);
  it.err_ucs = post::RelativeError(it.ucs.r.ucs, t_.ucs);
  it.err_t = post::RelativeError(it.br.r.tensile_strength, t_.tensile);
  it.err_nu = std::abs(it.ucs.r.poisson_ratio - t_.nu);
  it.score =
      std::max({it.err_E / tol_, it.err_ucs / tol_, it.err_t / tol_, it.err_nu / kNuTolerance});
  it.converged = it.score <= 1.0;
}

// Next micro parameters: one damped log-space secant step per parameter,
// each driven by its own macro property (bond modulus -> E, stiffness ratio
// -> nu, bond tensile strength -> Brazilian strength, cohesion -> UCS), all
// from the same pair of tests. The friction angle stays at its estimate.
BondParams Calibration::update(const std::vector<Iteration>& hist,
                               std::vector<std::string>& notes) const {
  const Iteration& now = hist.back();
  const Iteration* prev = hist.size() > 1 ? &hist[hist.size() - 2] : nullptr;
  auto pt = [](double x, double y) { return post::SecantPoint{x, y}; };
  auto prev_pt = [&](double x, double y) -> std::optional<post::SecantPoint> { return pt(x, y); };
  BondParams p = now.p;
  // E scales with the bond modulus (all bond springs do), so the slope is near 1.
  const post::SecantRule e_rule{true, 1.0, 0.5, 1.5, std::log(4.0)};
  // nu rises with kn/ks; about +0.1 per e-fold at these ratios (first guess).
  const post::SecantRule nu_rule{false, 0.1, 0.02, 0.5, 0.7};
  // Strengths scale with bond strengths when the failure mode stays the same
  // (the closed-form start can be an order of magnitude off: wide cap).
  const post::SecantRule s_rule{true, 1.0, 0.3, 2.0, std::log(16.0)};
  p.modulus = post::SecantUpdate(
                  e_rule, pt(now.p.modulus, now.ucs.r.youngs_modulus),
                  prev ? prev_pt(prev->p.modulus, prev->ucs.r.youngs_modulus) : std::nullopt, t_.E)
                  .x_new;
  p.stiffness_ratio = std::clamp(
      post::SecantUpdate(
          nu_rule, pt(now.p.stiffness_ratio, now.ucs.r.poisson_ratio),
          prev ? prev_pt(prev->p.stiffness_ratio, prev->ucs.r.poisson_ratio) : std::nullopt, t_.nu)
          .x_new,
      0.5, 20.0);
  p.tensile =
      post::SecantUpdate(
          s_rule, pt(now.p.tensile, now.br.r.tensile_strength),
          prev ? prev_pt(prev->p.tensile, prev->br.r.tensile_strength) : std::nullopt, t_.tensile)
          .x_new;
  // Cohesion acts on the UCS through the ratio c / sigma_b (the tensile lever
  // moves both strengths). It moves last, once E and the tensile strength are
  // within tolerance (most sensitive first), in damped steps: below
  // c ~ sigma_b shear failures weaken the Brazilian disc too.
  const double ratio_now = now.p.cohesion / now.p.tensile;
  double ratio = ratio_now;
  if (now.err_E <= tol_ && now.err_t <= tol_) {
    const post::SecantRule c_rule{true, 1.0, 0.5, 2.0, std::log(2.0)};
    const bool prev_moved =
        prev && std::abs(std::log(prev->p.cohesion / prev->p.tensile / ratio_now)) > 1e-6;
    ratio = post::SecantUpdate(c_rule, pt(ratio_now, now.ucs.r.ucs / now.br.r.tensile_strength),
                               prev_moved ? prev_pt(prev->p.cohesion / prev->p.tensile,
                                                    prev->ucs.r.ucs / prev->br.r.tensile_strength)
                                          : std::nullopt,
                               t_.ucs / t_.tensile)
                .x_new;
  }
  if (ratio > kMaxCohesionRatio) {
    ratio = kMaxCohesionRatio;
    notes.push_back(
        fmt::format("cohesion capped at {:g} x the bond tensile strength", kMaxCohesionRatio));
  }
  p.cohesion = ratio * p.tensile;
  p.origin = "calibrate iteration " + std::to_string(hist.size() + 1);
  return p;
}

// The calibration: pack, iterate the two tests, check the rate, write.
void Calibration::run() {
  const auto t0 = std::chrono::steady_clock::now();
  fs::create_directories(dir_ / "runs");
  sp_ = pack();
  ctx_.progress.info(
      fmt::format("[calibrate] specimens of {} elements carved from the ball: cylinder {:.1f} mm x "
                  "{:.1f} mm (centres), disc "
                  "{:.1f} mm x {:.1f} mm",
                  n_, 2e3 * sp_.cyl_r, 4e3 * sp_.cyl_r, 2e3 * sp_.disc_r, 1e3 * sp_.disc_r));
  std::vector<Iteration> hist;
  std::vector<std::string> notes;
  BondParams p = estimate_bond_params(ore_, d_.real("lump.bond_radius_multiplier"));
  if (card_has_stale_calibration(ctx_.cfg)) {
    // A changed card: start from its previous calibration, not from scratch.
    p.modulus = ore_.real("calibrated.bond_modulus");
    p.stiffness_ratio = ore_.real("calibrated.stiffness_ratio");
    p.tensile = ore_.real("calibrated.bond_tensile_strength");
    p.cohesion = ore_.real("calibrated.bond_cohesion");
    p.friction_angle_deg = ore_.real("calibrated.bond_friction_angle");
    notes.push_back(
        "started from the ore card's calibrated.* section, fitted to other properties (stale "
        "input_hash)");
    ctx_.progress.info(
        "[calibrate] the ore card's calibrated.* was fitted to other properties (stale "
        "input_hash): "
        "starting the fit from it");
  }
  // Steps of the job: 2 tests per iteration plus the half-rate UCS (twice as long).
  const double steps_total = 2.0 * max_it_ + 2.0;
  for (int k = 1; k <= max_it_; ++k) {
    Iteration it;
    it.p = p;
    progress_ = (2.0 * (k - 1)) / steps_total;
    it.ucs = run_ucs(p, rate_, fmt::format("it{}_ucs", k),
                     fmt::format("iteration {}/{}: UCS", k, max_it_));
    progress_ = (2.0 * (k - 1) + 1) / steps_total;
    it.br = run_brazilian(p, fmt::format("it{}_brazilian", k),
                          fmt::format("iteration {}/{}: Brazilian", k, max_it_));
    score(it);
    hist.push_back(it);
    ctx_.progress.info(fmt::format(
        "[calibrate] iteration {}/{}: E {:.2f} GPa (target {:.2f}), nu {:.3f} ({:.2f}), UCS {:.1f} "
        "MPa ({:.1f}), tensile "
        "{:.2f} MPa ({:.2f}){} [{:.0f} s + {:.0f} s]",
        k, max_it_, it.ucs.r.youngs_modulus / 1e9, t_.E / 1e9, it.ucs.r.poisson_ratio, t_.nu,
        it.ucs.r.ucs / 1e6, t_.ucs / 1e6, it.br.r.tensile_strength / 1e6, t_.tensile / 1e6,
        it.converged ? ": all within tolerance" : "", it.ucs.seconds, it.br.seconds));
    if (!it.ucs.peaked)
      notes.push_back(
          fmt::format("iteration {}: the UCS test reached its strain cap still loading", k));
    if (!it.br.peaked)
      notes.push_back(
          fmt::format("iteration {}: the Brazilian test reached its cap still loading", k));
    if (it.converged || k == max_it_) break;
    p = update(hist, notes);
  }
  // The best iteration: most targets within tolerance, then the smallest
  // worst error (in tolerance units): an unreachable target must not hide
  // the iteration that meets the others.
  auto met = [&](const Iteration& it) {
    return (it.err_E <= tol_) + (it.err_ucs <= tol_) + (it.err_t <= tol_) +
           (it.err_nu <= kNuTolerance);
  };
  size_t best = 0;
  for (size_t i = 1; i < hist.size(); ++i)
    if (met(hist[i]) > met(hist[best]) ||
        (met(hist[i]) == met(hist[best]) && hist[i].score < hist[best].score))
      best = i;
  // Rate check: the best parameters at half the strain rate.
  progress_ = 2.0 * max_it_ / steps_total;
  std::optional<UcsRun> half;
  if (d_.boolean("calibrate.rate_check"))
    half = run_ucs(hist[best].p, 0.5 * rate_, "rate_check_ucs",
                   "rate check: UCS at half the strain rate");
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_outputs(hist, best, half, wall, notes);
}

// One row per sample of every test run, for the plots and spreadsheets.
void append_curves(std::ostream& o, const std::string& run, int iteration, const std::string& test,
                   double rate, const post::LoadCurve& c, const std::vector<double>& strain,
                   const std::vector<double>& stress) {
  for (size_t i = 0; i < c.size(); ++i)
    o << fmt::format("{},{},{},{:.6g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n", run, iteration, test,
                     rate, c.displacement[i], c.force(i), strain[i], stress[i],
                     c.lateral_strain[i]);
}

// calibrated.yaml, report.json, report.md, curves.csv and plots in the job folder.
void Calibration::write_outputs(const std::vector<Iteration>& hist, size_t best,
                                const std::optional<UcsRun>& half, double wall,
                                const std::vector<std::string>& notes_in) {
  const Iteration& b = hist[best];
  std::vector<std::string> notes = notes_in;
  const double rate_change = half ? post::RelativeError(half->r.ucs, b.ucs.r.ucs) : 0.0;
  const bool rate_ok = rate_change < 0.05;
  const std::string hash = ore_hash(ore_);

  // Why a target was missed, in words (docs/calibration.md explains).
  std::vector<std::string> missed;
  if (b.err_E > tol_)
    missed.push_back(fmt::format("E {:.2f} GPa is {:.0f}% off the target after {} iterations",
                                 b.ucs.r.youngs_modulus / 1e9, 100 * b.err_E, hist.size()));
  if (b.err_nu > kNuTolerance)
    missed.push_back(
        fmt::format("nu {:.3f} is {:.3f} off the target: kn/ks {:.2f} (kept in [0.5, 20])",
                    b.ucs.r.poisson_ratio, b.err_nu, b.p.stiffness_ratio));
  if (b.err_t > tol_)
    missed.push_back(fmt::format("tensile strength {:.2f} MPa is {:.0f}% off the target",
                                 b.br.r.tensile_strength / 1e6, 100 * b.err_t));
  if (b.err_ucs > tol_) {
    const double ratio = b.ucs.r.ucs / b.br.r.tensile_strength, want = t_.ucs / t_.tensile;
    // Measured sensitivity of the UCS to the cohesion ratio (last two iterations that moved it).
    std::string lever;
    for (size_t i = hist.size(); i-- > 1;) {
      const double r1 = hist[i - 1].p.cohesion / hist[i - 1].p.tensile,
                   r2 = hist[i].p.cohesion / hist[i].p.tensile;
      if (std::abs(std::log(r2 / r1)) < 1e-3) continue;
      lever = fmt::format(
          "; raising cohesion/tensile from {:.2f} to {:.2f} changed the UCS by {:+.1f}%{}", r1, r2,
          100 * (hist[i].ucs.r.ucs / hist[i - 1].ucs.r.ucs - 1),
          std::abs(hist[i].ucs.r.ucs / hist[i - 1].ucs.r.ucs - 1) < 0.05
              ? ": the bonds fail in tension (bending included), so the shear strength cannot "
                "raise the UCS"
              : "");
      break;
    }
    missed.push_back(post::RelativeError(ratio, want) > tol_
                         ? fmt::format("UCS {:.1f} MPa is {:.0f}% off the target: UCS/tensile "
                                       "reached {:.1f} against {:.1f} on "
                                       "the card (parallel-bond packings of spheres struggle to "
                                       "pass UCS/tensile ~ 4-10; the "
                                       "Mohr-Coulomb shear strength, cohesion, is the lever{}{})",
                                       b.ucs.r.ucs / 1e6, 100 * b.err_ucs, ratio, want,
                                       b.p.cohesion / b.p.tensile >= kMaxCohesionRatio * 0.999
                                           ? ", at its cap"
                                           : "",
                                       lever)
                         : fmt::format("UCS {:.1f} MPa is {:.0f}% off the target (UCS/tensile "
                                       "{:.1f} is right: the strength level "
                                       "needs more iterations)",
                                       b.ucs.r.ucs / 1e6, 100 * b.err_ucs, ratio));
  }

  auto macro = [](const Iteration& it) {
    return nlohmann::json{{"youngs_modulus", it.ucs.r.youngs_modulus},
                          {"poisson_ratio", it.ucs.r.poisson_ratio},
                          {"ucs", it.ucs.r.ucs},
                          {"tensile_strength", it.br.r.tensile_strength}};
  };
  nlohmann::json iters = nlohmann::json::array();
  for (size_t i = 0; i < hist.size(); ++i) {
    const auto& it = hist[i];
    iters.push_back({{"iteration", i + 1},
                     {"bond", bond_json(it.p)},
                     {"achieved", macro(it)},
                     {"errors",
                      {{"youngs_modulus", it.err_E},
                       {"poisson_ratio", it.err_nu},
                       {"ucs", it.err_ucs},
                       {"tensile_strength", it.err_t}}},
                     {"within_tolerance", it.converged},
                     {"ucs_fit_window_Pa", {it.ucs.r.fit_stress_lo, it.ucs.r.fit_stress_hi}},
                     {"ucs_fit_r2", it.ucs.r.fit.r2},
                     {"strain_at_peak", it.ucs.r.strain_at_peak},
                     {"brazilian_peak_force_N", it.br.r.peak_force},
                     {"ucs_peaked", it.ucs.peaked},
                     {"brazilian_peaked", it.br.peaked},
                     {"wall_seconds", it.ucs.seconds + it.br.seconds}});
  }
  const auto& ui = b.ucs.info;
  const auto& bi = b.br.info;
  auto get = [](const std::map<std::string, double>& m, const char* k) {
    auto it = m.find(k);
    return it == m.end() ? 0.0 : it->second;
  };
  nlohmann::json specimen = {{"seed", d_.integer("calibrate.seed")},
                             {"ball_elements", sp_.ball_elements},
                             {"ball_outer_radius_m", sp_.ball_outer_radius},
                             {"mean_element_radius_m", sp_.mean_radius},
                             {"ucs_cylinder",
                              {{"elements", get(ui, "atoms")},
                               {"diameter_m", get(ui, "diameter")},
                               {"height_m", get(ui, "height")},
                               {"gauge_length_m", get(ui, "gauge_length")},
                               {"bonds", get(ui, "bonds")},
                               {"platen_layer_elements", get(ui, "top_layer")}}},
                             {"brazilian_disc",
                              {{"elements", get(bi, "atoms")},
                               {"diameter_m", get(bi, "diameter")},
                               {"thickness_m", get(bi, "thickness")},
                               {"bonds", get(bi, "bonds")},
                               {"jaw_elements", get(bi, "top_layer")}}}};
  nlohmann::json targets = {{"youngs_modulus", t_.E},
                            {"poisson_ratio", t_.nu},
                            {"ucs", t_.ucs},
                            {"tensile_strength", t_.tensile}};
  nlohmann::json within = {{"youngs_modulus", b.err_E <= tol_},
                           {"poisson_ratio", b.err_nu <= kNuTolerance},
                           {"ucs", b.err_ucs <= tol_},
                           {"tensile_strength", b.err_t <= tol_}};
  nlohmann::json report = {
      {"ore", ore_.str("name")},
      {"input_hash", hash},
      {"source", "fitted"},
      {"targets", targets},
      {"achieved", macro(b)},
      {"within_tolerance", within},
      {"tolerance", {{"relative", tol_}, {"poisson_ratio_absolute", kNuTolerance}}},
      {"converged", b.converged},
      {"best_iteration", best + 1},
      {"iterations", iters},
      {"calibrated", bond_json(b.p)},
      {"specimen", specimen},
      {"strain_rate_1_s", rate_},
      {"rate_check",
       half ? nlohmann::json{{"strain_rate_1_s", 0.5 * rate_},
                             {"ucs", half->r.ucs},
                             {"youngs_modulus", half->r.youngs_modulus},
                             {"ucs_change", rate_change},
                             {"youngs_modulus_change",
                              post::RelativeError(half->r.youngs_modulus, b.ucs.r.youngs_modulus)},
                             {"below_5_percent", rate_ok},
                             {"wall_seconds", half->seconds}}
            : nlohmann::json(nullptr)},
      {"not_reached", missed},
      {"notes", notes},
      {"wall_seconds", wall}};

  // calibrated.yaml: the calibrated: map is what material.cpp reads (and
  // what may be pasted into the ore card); the rest documents the fit.
  YAML::Emitter y;
  y.SetDoublePrecision(8);
  y << YAML::BeginMap;
  y << YAML::Key << "calibrated" << YAML::Value << YAML::BeginMap;
  y << YAML::Key << "bond_modulus" << YAML::Value << b.p.modulus;
  y << YAML::Key << "stiffness_ratio" << YAML::Value << b.p.stiffness_ratio;
  y << YAML::Key << "bond_tensile_strength" << YAML::Value << b.p.tensile;
  y << YAML::Key << "bond_cohesion" << YAML::Value << b.p.cohesion;
  y << YAML::Key << "bond_friction_angle" << YAML::Value << b.p.friction_angle_deg;
  y << YAML::Key << "input_hash" << YAML::Value << hash;
  y << YAML::EndMap;
  y << YAML::Key << "ore" << YAML::Value << ore_.str("name");
  y << YAML::Key << "converged" << YAML::Value << b.converged;
  y << YAML::Key << "targets" << YAML::Value << YAML::BeginMap;
  y << YAML::Key << "youngs_modulus" << YAML::Value << t_.E << YAML::Key << "poisson_ratio"
    << YAML::Value << t_.nu << YAML::Key << "ucs" << YAML::Value << t_.ucs << YAML::Key
    << "tensile_strength" << YAML::Value << t_.tensile;
  y << YAML::EndMap;
  y << YAML::Key << "achieved" << YAML::Value << YAML::BeginMap;
  y << YAML::Key << "youngs_modulus" << YAML::Value << b.ucs.r.youngs_modulus << YAML::Key
    << "poisson_ratio" << YAML::Value << b.ucs.r.poisson_ratio << YAML::Key << "ucs" << YAML::Value
    << b.ucs.r.ucs << YAML::Key << "tensile_strength" << YAML::Value << b.br.r.tensile_strength;
  y << YAML::EndMap;
  y << YAML::Key << "specimen" << YAML::Value << YAML::BeginMap;
  y << YAML::Key << "elements" << YAML::Value << n_;
  y << YAML::Key << "ucs_cylinder_diameter_m" << YAML::Value << get(ui, "diameter");
  y << YAML::Key << "ucs_cylinder_height_m" << YAML::Value << get(ui, "height");
  y << YAML::Key << "brazilian_disc_diameter_m" << YAML::Value << get(bi, "diameter");
  y << YAML::Key << "brazilian_disc_thickness_m" << YAML::Value << get(bi, "thickness");
  y << YAML::Key << "mean_element_radius_m" << YAML::Value << sp_.mean_radius;
  y << YAML::Key << "seed" << YAML::Value << d_.integer("calibrate.seed");
  y << YAML::EndMap;
  y << YAML::Key << "strain_rate" << YAML::Value << rate_;
  y << YAML::EndMap;

  // Markdown report: targets against achieved values.
  std::ostringstream md;
  md << fmt::format("# Calibration of {} ({} elements per specimen)\n\n", ore_.str("name"), n_);
  md << fmt::format("{} after {} iteration(s); best: iteration {}. Wall time {}.\n\n",
                    b.converged ? "All targets within tolerance" : "**Not all targets reached**",
                    hist.size(), best + 1, Progress::duration(wall));
  md << "| property | target | achieved | error | tolerance | ok |\n|---|---|---|---|---|---|\n";
  md << fmt::format("| E (GPa) | {:.2f} | {:.2f} | {:.1f}% | {:.0f}% | {} |\n", t_.E / 1e9,
                    b.ucs.r.youngs_modulus / 1e9, 100 * b.err_E, 100 * tol_,
                    b.err_E <= tol_ ? "yes" : "no");
  md << fmt::format("| nu | {:.3f} | {:.3f} | {:.3f} | {:.2f} | {} |\n", t_.nu,
                    b.ucs.r.poisson_ratio, b.err_nu, kNuTolerance,
                    b.err_nu <= kNuTolerance ? "yes" : "no");
  md << fmt::format("| UCS (MPa) | {:.1f} | {:.1f} | {:.1f}% | {:.0f}% | {} |\n", t_.ucs / 1e6,
                    b.ucs.r.ucs / 1e6, 100 * b.err_ucs, 100 * tol_,
                    b.err_ucs <= tol_ ? "yes" : "no");
  md << fmt::format("| tensile (MPa) | {:.2f} | {:.2f} | {:.1f}% | {:.0f}% | {} |\n\n",
                    t_.tensile / 1e6, b.br.r.tensile_strength / 1e6, 100 * b.err_t, 100 * tol_,
                    b.err_t <= tol_ ? "yes" : "no");
  md << "## Bond parameters (calibrated.yaml)\n\n| parameter | value |\n|---|---|\n";
  md << fmt::format(
      "| bond modulus (GPa) | {:.3f} |\n| kn/ks | {:.3f} |\n| bond tensile strength (MPa) | {:.3f} "
      "|\n"
      "| bond cohesion (MPa) | {:.3f} |\n| bond friction angle (deg) | {:.1f} |\n| radius "
      "multiplier | {:g} |\n\n",
      b.p.modulus / 1e9, b.p.stiffness_ratio, b.p.tensile / 1e6, b.p.cohesion / 1e6,
      b.p.friction_angle_deg, b.p.radius_multiplier);
  md << "## Iterations\n\n| it | E_b (GPa) | kn/ks | sigma_b (MPa) | c (MPa) | E (GPa) | nu | UCS "
        "(MPa) | tensile (MPa) | "
        "wall (s) |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (size_t i = 0; i < hist.size(); ++i) {
    const auto& it = hist[i];
    md << fmt::format(
        "| {} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {:.3f} | {:.2f} | {:.2f} | {:.0f} |\n",
        i + 1, it.p.modulus / 1e9, it.p.stiffness_ratio, it.p.tensile / 1e6, it.p.cohesion / 1e6,
        it.ucs.r.youngs_modulus / 1e9, it.ucs.r.poisson_ratio, it.ucs.r.ucs / 1e6,
        it.br.r.tensile_strength / 1e6, it.ucs.seconds + it.br.seconds);
  }
  if (half)
    md << fmt::format(
        "\n## Loading rate\n\nUCS at {:g} 1/s: {:.2f} MPa; at {:g} 1/s: {:.2f} MPa; change {:.1f}% "
        "({}).\n",
        rate_, b.ucs.r.ucs / 1e6, 0.5 * rate_, half->r.ucs / 1e6, 100 * rate_change,
        rate_ok ? "below 5%: quasi-static" : "5% or more: lower calibrate.strain_rate");
  else
    md << "\n## Loading rate\n\nNot checked (calibrate.rate_check: false).\n";
  md << fmt::format(
      "\n## Specimens\n\nCarved from a ball of {} elements (seed {}), mean element radius {:.3f} "
      "mm (as the "
      "lump). UCS cylinder: {:g} elements, diameter {:.2f} mm, height {:.2f} mm. Brazilian disc: "
      "{:g} "
      "elements, diameter {:.2f} mm, thickness {:.2f} mm.\n",
      sp_.ball_elements, d_.integer("calibrate.seed"), sp_.mean_radius * 1e3, get(ui, "atoms"),
      get(ui, "diameter") * 1e3, get(ui, "height") * 1e3, get(bi, "atoms"),
      get(bi, "diameter") * 1e3, get(bi, "thickness") * 1e3);
  if (!missed.empty()) {
    md << "\n## Not reached\n\n";
    for (const auto& m : missed) md << "- " << m << "\n";
  }
  if (!notes.empty()) {
    md << "\n## Notes\n\n";
    for (const auto& n : notes) md << "- " << n << "\n";
  }

  // Curves of every run (aggregated; the plots read only this and report.json).
  std::ostringstream cv;
  cv << "run,iteration,test,strain_rate,displacement_m,force_N,strain,stress_Pa,lateral_strain\n";
  for (size_t i = 0; i < hist.size(); ++i) {
    const auto& it = hist[i];
    append_curves(cv, fmt::format("it{}_ucs", i + 1), static_cast<int>(i + 1), "ucs", rate_,
                  it.ucs.curve, it.ucs.ss.strain, it.ucs.ss.stress);
    const double D = get(it.br.info, "diameter"), th = get(it.br.info, "thickness");
    std::vector<double> strain, stress;
    for (size_t j = 0; j < it.br.curve.size(); ++j) {
      strain.push_back(it.br.curve.displacement[j] / D);
      stress.push_back(post::BrazilianTensileStrength(it.br.curve.force(j), D, th));
    }
    append_curves(cv, fmt::format("it{}_brazilian", i + 1), static_cast<int>(i + 1), "brazilian",
                  rate_, it.br.curve, strain, stress);
  }
  if (half)
    append_curves(cv, "rate_check_ucs", static_cast<int>(best + 1), "ucs", 0.5 * rate_, half->curve,
                  half->ss.strain, half->ss.stress);

  jobs::atomic_write(dir_ / "curves.csv", cv.str());
  jobs::atomic_write(dir_ / "report.json", report.dump(2) + "\n");
  jobs::atomic_write(dir_ / "report.md", md.str());
  engine::Command c;
  c.argv = {"/usr/bin/python3",
            (ctx_.cfg.project_dir / "postprocess" / "plot_lab_tests.py").string(),
            "--curves",
            (dir_ / "curves.csv").string(),
            "--report",
            (dir_ / "report.json").string(),
            "--out",
            (dir_ / "plots").string()};
  c.cwd = dir_;
  c.log = dir_ / "plots.log";
  c.job = "calibrate/plots";
  ctx_.runner.run(c);
  // Last: the file the breakage stage reads.
  jobs::atomic_write(
      dir_ / "calibrated.yaml",
      "# Bond (micro) parameters fitted by `orchestrate --stage calibrate` (docs/calibration.md).\n"
      "# The calibrated: map may be pasted into the ore card; input_hash ties it to the card's\n"
      "# macro properties.\n" +
          std::string(y.c_str()) + "\n");
  ctx_.progress.info(fmt::format(
      "[calibrate] {}: E {:.2f} GPa, nu {:.3f}, UCS {:.1f} MPa, tensile {:.2f} MPa "
      "(iteration {}){}",
      b.converged ? "converged" : "NOT all targets reached", b.ucs.r.youngs_modulus / 1e9,
      b.ucs.r.poisson_ratio, b.ucs.r.ucs / 1e6, b.br.r.tensile_strength / 1e6, best + 1,
      half ? fmt::format("; rate check: UCS changes {:.1f}% at half the rate", 100 * rate_change)
           : ""));
  for (const auto& m : missed) ctx_.progress.warn("[calibrate] not reached: " + m);
}

// The card's own calibrated.* section, copied (no fitting).
void copy_from_card(StageContext& ctx, const fs::path& dir) {
  const auto& o = ctx.cfg.ore;
  const std::string hash = ore_hash(o);
  YAML::Emitter y;
  y.SetDoublePrecision(8);
  y << YAML::BeginMap << YAML::Key << "calibrated" << YAML::Value << YAML::BeginMap;
  y << YAML::Key << "bond_modulus" << YAML::Value << o.real("calibrated.bond_modulus");
  y << YAML::Key << "stiffness_ratio" << YAML::Value << o.real("calibrated.stiffness_ratio");
  y << YAML::Key << "bond_tensile_strength" << YAML::Value
    << o.real("calibrated.bond_tensile_strength");
  y << YAML::Key << "bond_cohesion" << YAML::Value << o.real("calibrated.bond_cohesion");
  y << YAML::Key << "bond_friction_angle" << YAML::Value
    << o.real("calibrated.bond_friction_angle");
  y << YAML::Key << "input_hash" << YAML::Value << hash;
  y << YAML::EndMap << YAML::Key << "ore" << YAML::Value << o.str("name") << YAML::Key << "source"
    << YAML::Value << "ore card " + ctx.cfg.ore_file.string() << YAML::EndMap;
  const nlohmann::json report = {
      {"ore", o.str("name")},
      {"input_hash", hash},
      {"source", "ore card"},
      {"ore_card", ctx.cfg.ore_file.string()},
      {"note", "the ore card carries calibrated.* fitted to its own properties: no fitting run"}};
  jobs::atomic_write(dir / "report.json", report.dump(2) + "\n");
  jobs::atomic_write(
      dir / "report.md",
      fmt::format(
          "# Calibration of {}\n\nTaken from the ore card {} (its calibrated.input_hash matches "
          "the card's properties): no virtual lab tests were run.\n",
          o.str("name"), ctx.cfg.ore_file.string()));
  jobs::atomic_write(
      dir / "calibrated.yaml",
      "# Copied from the ore card's calibrated: section.\n" + std::string(y.c_str()) + "\n");
}

}  // namespace

// One job, "calibration"; its summary says whether it fits or copies the card's section.
Plan CalibrateStage::plan(const StageContext& ctx) const {
  Plan p;
  nlohmann::json in = case_keys(ctx.cfg.doc, {"calibrate.", "lump."});
  in["ore"] = ore_keys(ctx.cfg.ore);
  in["deck_version"] = kDeckVersion;
  const bool from_card = card_is_calibrated(ctx.cfg);
  if (card_has_stale_calibration(ctx.cfg)) {
    // The fit starts from the card's stale calibration: part of the inputs.
    nlohmann::json start = nlohmann::json::object();
    for (const char* k : kCalibratedKeys)
      if (std::string(k) != "calibrated.input_hash") start[k] = ctx.cfg.ore.real(k);
    in["start"] = start;
  }
  if (from_card) {
    in["from_card"] = true;
    p.note =
        "the ore card carries calibrated.* fitted to its properties: the job copies them, no lab "
        "tests";
  }
  p.jobs.push_back(
      {"calibration", in,
       from_card
           ? fmt::format("copy calibrated.* from the ore card of {}", ctx.cfg.ore.str("name"))
           : fmt::format("UCS + Brazilian tests on {} elements, fit to {}",
                         ctx.cfg.doc.integer("calibrate.n_elements"), ctx.cfg.ore.str("name"))});
  return p;
}

// Fit (or copy the card's calibration) into the job folder.
void CalibrateStage::run_job(StageContext& ctx, const JobSpec& job, const fs::path& job_dir) {
  fs::create_directories(job_dir);
  for (const char* f : {"calibrated.yaml", "report.json", "report.md", "curves.csv"})
    fs::remove(job_dir / f);
  if (job.inputs.contains("from_card")) {
    ctx.progress.info(
        fmt::format("[calibrate] the ore card {} carries calibrated.* fitted to its properties "
                    "(input_hash matches): copied, no fitting",
                    ctx.cfg.ore_file.string()));
    copy_from_card(ctx, job_dir);
    return;
  }
  Calibration(ctx, job, job_dir).run();
}

// Publish the job's outputs as the stage's: calibrate/calibrated.yaml, reports, plots.
void CalibrateStage::finalize(StageContext& ctx, const std::vector<JobSpec>& jobs) {
  if (jobs.empty()) return;
  const jobs::JobStore store(ctx.stage_dir);
  const fs::path src = store.job_dir(jobs.front().label), dst = ctx.stage_dir;
  auto copy = [&](const fs::path& from, const fs::path& to) {
    std::ifstream in(from, std::ios::binary);
    if (!in) return;
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    jobs::atomic_write(to, text);
  };
  // Plots and tables first; calibrated.yaml (the declared output) last.
  fs::remove_all(dst / "plots");
  if (fs::exists(src / "plots")) {
    fs::create_directories(dst / "plots");
    for (const auto& e : fs::directory_iterator(src / "plots"))
      copy(e.path(), dst / "plots" / e.path().filename());
  }
  for (const char* f : {"curves.csv", "report.json", "report.md"})
    if (fs::exists(src / f))
      copy(src / f, dst / f);
    else
      fs::remove(dst / f);
  copy(src / "calibrated.yaml", dst / "calibrated.yaml");
  ctx.progress.info(fmt::format("[calibrate] results: {}/calibrated.yaml, report.md, report.json{}",
                                dst.string(), fs::exists(src / "plots") ? ", plots/*.png" : ""));
}

}  // namespace mill
