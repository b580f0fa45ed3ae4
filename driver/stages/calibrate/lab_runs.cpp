// The calibrate stage's lab tests: one shared run of a UCS, Brazilian,
// triaxial or semi-circular bend deck.
#include "stages/calibrate/lab_runs.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
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
           {"max_bonds", std::to_string(d.integer("lump.max_bonds"))}})
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

// A UCS test with bond parameters p at the given strain rate.
UcsRun LabBench::ucs(const BondParams& p, double rate, const RunStep& step) {
  UcsRun u;
  const fs::path work = run_test({"ucs", sp_.cyl_r, t_.ucs / t_.E, 4.0}, p, rate, step, u);
  u.curve = post::ReadLoadCurve((work / "ucs_curve.txt").string());
  const double D = info_at(u.info, "diameter", u.info_file);
  u.gauge = info_at(u.info, "gauge_length", u.info_file);
  u.area = M_PI * D * D / 4.0;
  u.ss = post::ToStressStrain(u.curve, u.gauge, u.area);
  u.r = post::AnalyseUcs(u.ss);
  u.peaked = u.r.peak_index + 1 < u.ss.stress.size();
  return u;
}

// A Brazilian test with bond parameters p at the given strain rate.
BrazilianRun LabBench::brazilian(const BondParams& p, double rate, const RunStep& step) {
  BrazilianRun b;
  // Closure/D at the peak is about 4 tensile / E.
  const fs::path work =
      run_test({"brazilian", sp_.disc_r, 4.0 * t_.tensile / t_.E, 5.0}, p, rate, step, b);
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

// A semi-circular bend test on a half disc of the Brazilian disc's carve
// radius; its load-point closure over 2R at the peak taken as the Brazilian
// disc's (4 tensile / E), the cap twice as far: bending is more compliant.
ScbRun LabBench::scb(const BondParams& p, double rate, const RunStep& step) {
  ScbRun s;
  const fs::path work =
      run_test({"scb", sp_.disc_r, 4.0 * t_.tensile / t_.E, 10.0}, p, rate, step, s);
  // A half disc too coarse for the three-point bend has no element under
  // the load point or over a support: its "peak" would be noise. Measured:
  // 200-element specimens (56 elements in the half disc) leave the load
  // point empty; 400 give 2 and 6.
  for (const char* layer : {"load_layer", "support_layer"})
    if (info_at(s.info, layer, s.info_file) < 1)
      throw ScbTooCoarse(fmt::format(
          "{}: the semi-circular bend specimen ({:g} elements) has no element in its {} "
          "(load_layer {:g}, support_layer {:g}): calibrate.n_elements is too few for the "
          "toughness test; use at least 400, or drop fracture_toughness from the ore card",
          s.info_file.string(), info_at(s.info, "atoms", s.info_file), layer,
          info_at(s.info, "load_layer", s.info_file),
          info_at(s.info, "support_layer", s.info_file)));
  s.curve = post::ReadLoadCurve((work / "scb_curve.txt").string());
  s.r = post::AnalyseScb(
      s.curve, info_at(s.info, "radius", s.info_file), info_at(s.info, "thickness", s.info_file),
      info_at(s.info, "notch", s.info_file), info_at(s.info, "half_span", s.info_file));
  s.peaked = s.r.peak_index + 1 < s.curve.size();
  return s;
}

}  // namespace mill::calibrate
