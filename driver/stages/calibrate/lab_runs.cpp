// The calibrate stage's lab tests: one shared run of a UCS, Brazilian,
// triaxial or semi-circular bend deck.
#include "stages/calibrate/lab_runs.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <regex>
#include <utility>

#include "engine/liggghts.h"
#include "progress.h"
#include "stages/stage_util.h"

namespace mill::calibrate {
namespace fs = std::filesystem;
using engine::num;

// What tells the lab tests apart.
struct LabBench::Test {
  std::string name;    // deck <name>.in.tmpl; it writes <name>_info.txt and <name>_curve.txt
  double carve_r;      // m, carve radius of the specimen
  double peak_strain;  // strain expected at the peak
  double cap;          // the run stops at cap x peak_strain at the latest
  std::vector<std::pair<std::string, std::string>> extra = {};  // further deck variables
};

// Run one lab deck in `work`, showing its progress as `step.what`.
engine::Result LabBench::run_lab_deck(const std::string& deck, const fs::path& work,
                                      std::vector<std::pair<std::string, std::string>> vars,
                                      const RunStep& step) {
  fs::remove_all(work);
  fs::create_directories(work);
  engine::DeckRun run;
  run.deck = ctx_.cfg.project_dir / "liggghts_inputs" / deck;
  run.workdir = work;
  run.np = ctx_.opts.np;
  run.job = "calibrate/" + job_label_ + "/" + work.filename().string();
  run.vars = std::move(vars);
  if (!fs::exists(run.deck))
    throw std::runtime_error(fmt::format("deck template {} not found", run.deck.string()));
  const std::string label = job_label_;
  const std::string& what = step.what;
  const double base = step.done;
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

// Run one lab test with bond parameters p at the given strain rate; read
// what its deck wrote into `out`: info line and energy ledger (the curve is
// left to the caller: the triaxial deck writes one more column). Returns the
// run's folder.
fs::path LabBench::run_test(const Test& test, const BondParams& p, double rate, const RunStep& step,
                            LabRun& out) {
  const config::Document& d = ctx_.cfg.doc;
  auto vars = material_vars(ctx_.cfg.ore, p, ctx_.cfg.doc);
  for (auto kv : std::initializer_list<std::pair<std::string, std::string>>{
           {"specimen_file", fs::absolute(sp_.ball).string()},
           {"carve_r", num(test.carve_r)},
           {"strain_rate", num(rate)},
           {"max_strain", num(test.cap * test.peak_strain)},
           {"sample_time", num(test.peak_strain / rate / 300.0)},
           {"skin", num(0.3 * sp_.mean_radius)},
           {"bond_gap", num(d.real("lump.bond_gap"))},
           {"max_bonds", std::to_string(d.integer("lump.max_bonds"))},
           {"deck_dir", fs::absolute(ctx_.cfg.project_dir / "liggghts_inputs").string()}})
    vars.push_back(kv);
  vars.insert(vars.end(), test.extra.begin(), test.extra.end());
  const fs::path work = dir_ / "runs" / step.tag;
  const engine::Result res = run_lab_deck(test.name + ".in.tmpl", work, vars, step);
  out.tag = step.tag;
  out.seconds = res.seconds;
  out.info_file = work / (test.name + "_info.txt");
  out.info = read_info(out.info_file);
  out.energy = post::SummariseLedger(read_run_ledger(work));
  return work;
}

namespace {

// The cylinder's curve, size and analysis (the UCS and the direct tension
// tests): what the deck <name>.in.tmpl wrote in `work`.
void read_cylinder(UcsRun& u, const fs::path& work, const std::string& name) {
  u.curve = post::ReadLoadCurve((work / (name + "_curve.txt")).string());
  const double D = info_at(u.info, "diameter", u.info_file);
  u.gauge = info_at(u.info, "gauge_length", u.info_file);
  u.area = M_PI * D * D / 4.0;
  u.ss = post::ToStressStrain(u.curve, u.gauge, u.area);
  u.r = post::AnalyseUcs(u.ss);
  u.peaked = u.r.peak_index + 1 < u.ss.stress.size();
}

}  // namespace

// A UCS test with bond parameters p at the given strain rate.
UcsRun LabBench::ucs(const BondParams& p, double rate, const RunStep& step) {
  UcsRun u;
  read_cylinder(u, run_test({"ucs", sp_.cyl_r, t_.ucs / t_.E, 4.0}, p, rate, step, u), "ucs");
  return u;
}

// A direct tension test: the UCS cylinder pulled apart, its strain at the
// peak about tensile / E (the target's), the cap eight times as far.
UcsRun LabBench::tension(const BondParams& p, double rate, const RunStep& step) {
  UcsRun u;
  read_cylinder(u, run_test({"tension", sp_.cyl_r, t_.tensile / t_.E, 8.0}, p, rate, step, u),
                "tension");
  return u;
}

// A Brazilian test with bond parameters p at the given strain rate.
BrazilianRun LabBench::brazilian(const BondParams& p, double rate, const RunStep& step) {
  BrazilianRun b;
  // Closure/D at the peak is about 4 tensile / E.
  const fs::path work =
      run_test({"brazilian", sp_.disc_r, 4.0 * t_.disc_tensile() / t_.E, 5.0}, p, rate, step, b);
  b.curve = post::ReadLoadCurve((work / "brazilian_curve.txt").string());
  b.r = post::AnalyseBrazilian(b.curve, info_at(b.info, "diameter", b.info_file),
                               info_at(b.info, "thickness", b.info_file));
  b.peaked = b.r.peak_index + 1 < b.curve.size();
  return b;
}

// A triaxial test under confining pressure `pressure` [Pa]: the UCS cylinder,
// its axial strain at the peak about (UCS + 5 p) / E (a Mohr-Coulomb slope q
// up to about 6), the cap as in the UCS test.
TriaxialRun LabBench::triaxial(const BondParams& p, double rate, double pressure,
                               const RunStep& step) {
  TriaxialRun t;
  t.pressure = pressure;
  const fs::path work = run_test({"triaxial",
                                  sp_.cyl_r,
                                  (t_.ucs + 5.0 * pressure) / t_.E,
                                  4.0,
                                  {{"confining_pressure", num(pressure)}}},
                                 p, rate, step, t);
  const post::TriaxialCurve c = post::ReadTriaxialCurve((work / "triaxial_curve.txt").string());
  t.curve = c.load;
  t.r = post::AnalyseTriaxial(c, info_at(t.info, "gauge_length", t.info_file),
                              info_at(t.info, "end_area", t.info_file),
                              info_at(t.info, "lateral_area", t.info_file));
  t.peaked = t.r.peak_index + 1 < c.load.size();
  return t;
}

// A half disc too coarse for the three-point bend has no element under the
// load point (even with the deck's doubled arc) or over a support: its
// "peak" would be noise. Measured: the disc-radius half disc of
// 200-element specimens (56 elements) left the load point empty; at 1.2 x
// (about 110 elements) every orientation has one.
void check_scb_layers(const std::map<std::string, double>& info,
                      const std::filesystem::path& info_file) {
  for (const char* layer : {"load_layer", "support_layer"})
    if (info_at(info, layer, info_file) < 1)
      throw ScbTooCoarse(fmt::format(
          "{}: the semi-circular bend specimen ({:g} elements) has no element in its {} "
          "(load_layer {:g}, support_layer {:g}): calibrate.n_elements is too few for the "
          "toughness test; use at least 400, or drop fracture_toughness from the ore card",
          info_file.string(), info_at(info, "atoms", info_file), layer,
          info_at(info, "load_layer", info_file), info_at(info, "support_layer", info_file)));
}

// The semi-circular bend test: `orientations` half discs of kScbRadiusFactor
// x the Brazilian disc's carve radius, each carved from the ball turned by
// 180 deg / orientations more about the load axis (the notch planes then cut
// the packing in different places); its load-point closure over 2R at the
// peak taken as the Brazilian disc's (4 tensile / E), the cap ten times as
// far: bending is more compliant.
ScbRun LabBench::scb(const BondParams& p, double rate, int orientations, const RunStep& step) {
  std::vector<ScbDisc> discs;
  run_concurrently(scb_tasks(p, rate, orientations, step, discs), lanes_);
  return ScbRun::of(std::move(discs));
}

std::vector<std::function<void()>> LabBench::scb_tasks(const BondParams& p, double rate,
                                                       int orientations, const RunStep& step,
                                                       std::vector<ScbDisc>& discs) {
  if (orientations < 1)
    throw std::runtime_error(
        fmt::format("calibrate.scb_orientations: expected at least 1, got {}", orientations));
  discs.assign(static_cast<std::size_t>(orientations), ScbDisc{});
  std::vector<std::function<void()>> tasks;
  // Copies of what the tasks read: they run after this returns.
  for (int k = 0; k < orientations; ++k)
    tasks.push_back([this, &discs, p, rate, orientations, step, k] {
      ScbDisc& d = discs[static_cast<std::size_t>(k)];
      d.angle_deg = 180.0 * k / orientations;
      const RunStep disc_step{
          k == 0 ? step.tag : fmt::format("{}_o{}", step.tag, k),
          orientations == 1 ? step.what : fmt::format("{} {}/{}", step.what, k + 1, orientations),
          step.done};
      const fs::path work = run_test({"scb",
                                      kScbRadiusFactor * sp_.disc_r,
                                      4.0 * t_.disc_tensile() / t_.E,
                                      10.0,
                                      {{"carve_angle", num(d.angle_deg)}}},
                                     p, rate, disc_step, d);
      check_scb_layers(d.info, d.info_file);
      d.curve = post::ReadLoadCurve((work / "scb_curve.txt").string());
      d.r = post::AnalyseScb(d.curve, info_at(d.info, "radius", d.info_file),
                             info_at(d.info, "thickness", d.info_file),
                             info_at(d.info, "notch", d.info_file),
                             info_at(d.info, "half_span", d.info_file));
      d.peaked = d.r.peak_index + 1 < d.curve.size();
    });
  return tasks;
}

ScbRun ScbRun::of(std::vector<ScbDisc> discs) {
  if (discs.empty()) throw std::logic_error("ScbRun::of: no half disc");
  ScbRun s;
  s.discs = std::move(discs);
  const double n = static_cast<double>(s.discs.size());
  for (const ScbDisc& d : s.discs) {
    s.toughness += d.r.toughness / n;
    s.peak_force += d.r.peak_force / n;
    s.seconds += d.seconds;
    s.peaked = s.peaked && d.peaked;
  }
  if (s.discs.size() > 1) {
    double ss = 0;
    for (const ScbDisc& d : s.discs)
      ss += (d.r.toughness - s.toughness) * (d.r.toughness - s.toughness);
    s.toughness_sem = std::sqrt(ss / (n - 1) / n);
  }
  return s;
}

std::string ScbRun::summary() const {
  if (discs.size() == 1) return fmt::format("{:.3f} MPa m^0.5 (one half disc)", toughness / 1e6);
  const auto [lo, hi] = std::minmax_element(
      discs.begin(), discs.end(),
      [](const ScbDisc& a, const ScbDisc& b) { return a.r.toughness < b.r.toughness; });
  return fmt::format("{:.3f} MPa m^0.5 +- {:.3f} ({:.3f}-{:.3f} over {} half discs)",
                     toughness / 1e6, toughness_sem / 1e6, lo->r.toughness / 1e6,
                     hi->r.toughness / 1e6, discs.size());
}

}  // namespace mill::calibrate
