// The breakage matrix per rotor speed from the in-mill runs' pieces
// (docs/population_balance.md, "Breakage matrix from the in-mill runs").
#include "stages/breakage/breakage_matrix.h"

#include <fmt/format.h>

#include "jobs/job_store.h"
#include "postprocess/breakage_results.h"
#include "progress.h"
#include "stages/breakage/in_mill_runs.h"

namespace mill::breakage {
namespace fs = std::filesystem;

namespace {

// What the runs of one class at one rotor speed gave.
struct ClassRuns {
  std::vector<post::LumpPieces> lumps;
  double mass_kg = 0;
};

// The pieces of an in-mill run in mm: d/D of its impact.h5 times the lump's
// diameter, the convention of the breakage stage's size fractions
// (breakage/product.json: sizes are d/D x lump.diameter).
post::LumpPieces job_pieces(const fs::path& job_dir, double lump_mm) {
  const post::ImpactPieces p = post::ReadImpactPieces((job_dir / "impact.h5").string());
  post::LumpPieces out;
  out.mass_kg = p.mass_kg;
  for (double d : p.d_rel) out.size_mm.push_back(d * lump_mm);
  return out;
}

nlohmann::json classes_json(const post::SizeClasses& c) {
  nlohmann::json a = nlohmann::json::array();
  for (std::size_t i = 0; i < c.size(); ++i)
    a.push_back({{"class", i},
                 {"name", c.name(i)},
                 {"upper_mm", c.upper_mm[i]},
                 {"lower_mm", c.lower_mm(i)},
                 {"representative_mm", post::RepresentativeSize(c, i)}});
  return a;
}

}  // namespace

std::map<double, post::AssembledMatrix> write_breakage_matrices(StageContext& ctx,
                                                                const std::vector<JobSpec>& jobs) {
  const config::Feed& feed = ctx.cfg.feed.value();
  const post::SizeClasses classes = post::SizeClassesFromSieves(feed.sizes_mm);
  const jobs::JobStore store(ctx.stage_dir);
  const double lump_mm = 1000 * ctx.cfg.doc.real("lump.diameter");
  const std::size_t lump_class = config::lump_feed_class(ctx.cfg.doc, feed);
  std::map<double, std::map<std::size_t, ClassRuns>> runs;
  for (const auto& job : jobs) {
    if (!is_in_mill_job(job)) continue;
    ClassRuns& r = runs[job.inputs.at("rpm").get<double>()][lump_class];
    r.lumps.push_back(job_pieces(store.job_dir(job.label), lump_mm));
    for (double m : r.lumps.back().mass_kg) r.mass_kg += m;
  }
  std::map<double, post::AssembledMatrix> out;
  if (runs.empty()) return out;
  nlohmann::json speeds = nlohmann::json::array();
  std::string csv =
      "rpm,from_class,from_upper_mm,to_class,to_upper_mm,mass_fraction,column_origin,"
      "scaled_from_class\n";
  for (const auto& [rpm, by_class] : runs) {
    std::map<std::size_t, std::vector<double>> measured;
    for (const auto& [j, r] : by_class)
      measured[j] = post::MeasuredBreakageColumn(classes, j, r.lumps);
    const post::AssembledMatrix a = post::AssembleBreakageMatrix(classes, measured);
    nlohmann::json columns = nlohmann::json::array();
    for (std::size_t j = 0; j < classes.size(); ++j) {
      nlohmann::json col = {{"class", j}, {"origin", a.origin[j].kind}};
      if (a.origin[j].kind == "measured") {
        col["lumps"] = by_class.at(j).lumps.size();
        col["lump_mass_kg"] = by_class.at(j).mass_kg;
      } else if (a.origin[j].kind == "scaled") {
        col["scaled_from_class"] = a.origin[j].from;
      }
      columns.push_back(col);
      for (std::size_t i = j; i < classes.size(); ++i)
        csv += fmt::format("{:g},{},{:g},{},{:g},{:.12g},{},{}\n", rpm, j, classes.upper_mm[j], i,
                           classes.upper_mm[i], a.b[i][j], a.origin[j].kind,
                           a.origin[j].kind == "scaled" ? std::to_string(a.origin[j].from) : "");
    }
    speeds.push_back({{"rpm", rpm}, {"matrix", a.b}, {"columns", columns}});
    const auto& m = a.b[lump_class][lump_class];
    ctx.progress.info(fmt::format(
        "[breakage] breakage matrix at {:g} rpm: the {} class measured by {} in-mill lump(s) "
        "({:.1f}% stays in its class), {} class(es) scaled from it",
        rpm, classes.name(lump_class), by_class.at(lump_class).lumps.size(), 100 * m,
        classes.size() - 1 - by_class.size()));
    out[rpm] = a;
  }
  const nlohmann::json j = {
      {"sizes_mm", feed.sizes_mm},
      {"classes", classes_json(classes)},
      {"rotor_speeds", speeds},
      {"definitions",
       {{"matrix",
         "matrix[i][j]: the mass fraction of class j's mill input that leaves one pass through the "
         "rotor in class i; classes coarsest first (class 0 the coarsest), each [lower, upper)"},
        {"measured",
         "the in-mill runs' pieces of the class, binned by size (d/D x the lump's diameter), "
         "summed over the runs over their mass"},
        {"scaled",
         "a normalised breakage function (Austin, Klimpel & Luckie 1984): b_ij depends on x_i / "
         "x_j only; the measured column's passing read at relative size sieve / representative "
         "size, log-linear between its sieves, its pan held below its finest sieve"},
        {"finest", "the finest class cannot get finer: (0, ..., 0, 1)"}}}};
  jobs::atomic_write(ctx.stage_dir / "breakage_matrix.json", j.dump(2) + "\n");
  jobs::atomic_write(ctx.stage_dir / "breakage_matrix.csv", csv);
  return out;
}

}  // namespace mill::breakage
