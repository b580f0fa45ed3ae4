// The breakage matrix per rotor speed from the in-mill runs' pieces
// (docs/population_balance.md, "Breakage matrix from the in-mill runs").
#include "stages/breakage/breakage_matrix.h"

#include <fmt/format.h>

#include <fstream>

#include "config/feed_classes.h"
#include "jobs/job_store.h"
#include "postprocess/breakage_results.h"
#include "progress.h"
#include "stages/breakage/in_mill_runs.h"

namespace mill::breakage {
namespace fs = std::filesystem;

namespace {

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

// The beater's work on an in-mill run's lump and the lump's mass
// (in_mill.json: energy.work_beater_J, element_mass_kg).
post::LumpWork job_work(const fs::path& job_dir) {
  const fs::path f = job_dir / "in_mill.json";
  try {
    std::ifstream in(f);
    const auto j = nlohmann::json::parse(in);
    return {j.at("energy").at("work_beater_J").get<double>(),
            j.at("element_mass_kg").get<double>()};
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(fmt::format(
        "{}: {}; expected energy.work_beater_J and element_mass_kg (rerun the job: orchestrate "
        "--stage breakage)",
        f.string(), e.what()));
  }
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

MeasuringRuns collect_measuring_runs(const StageContext& ctx, const std::vector<JobSpec>& in_mill,
                                     const std::vector<JobSpec>& class_runs) {
  const config::Feed& feed = ctx.cfg.feed.value();
  const jobs::JobStore store(ctx.stage_dir);
  MeasuringRuns runs;
  const auto add = [&](const JobSpec& job, std::size_t k, bool own) {
    ClassRuns& r = runs[job.inputs.at("rpm").get<double>()][k];
    r.own = own;
    r.lump_mm = 1000 * job.inputs.at("lump.diameter").get<double>();
    r.elements = job.inputs.at("lump.n_elements").get<long>();
    const fs::path dir = store.job_dir(job.label);
    post::LumpRun lump;
    lump.pieces = job_pieces(dir, r.lump_mm);
    lump.work = job_work(dir);
    r.lumps.push_back(std::move(lump));
    for (double m : r.lumps.back().pieces.mass_kg) r.mass_kg += m;
  };
  for (const auto& job : class_runs) add(job, in_mill_class(job).value(), true);
  // lump.diameter's runs measure its class where that class has no runs of
  // its own (a class outside the transport's lumps, or too little feed).
  if (!in_mill.empty()) {
    const std::size_t lump_class = config::lump_feed_class(ctx.cfg.doc, feed);
    for (const auto& job : in_mill) {
      const auto it = runs.find(job.inputs.at("rpm").get<double>());
      if (it != runs.end() && it->second.count(lump_class) && it->second.at(lump_class).own)
        continue;
      add(job, lump_class, false);
    }
  }
  return runs;
}

std::map<double, post::AssembledMatrix> write_breakage_matrices(StageContext& ctx,
                                                                const MeasuringRuns& runs) {
  const config::Feed& feed = ctx.cfg.feed.value();
  const post::SizeClasses classes = post::SizeClassesFromSieves(feed.sizes_mm);
  const std::vector<config::FeedClassRuns> plan = config::plan_feed_classes(ctx.cfg.doc, feed);
  std::map<double, post::AssembledMatrix> out;
  if (runs.empty()) return out;
  nlohmann::json speeds = nlohmann::json::array();
  std::string csv =
      "rpm,from_class,from_upper_mm,to_class,to_upper_mm,mass_fraction,column_origin,"
      "scaled_from_class\n";
  for (const auto& [rpm, by_class] : runs) {
    std::map<std::size_t, std::vector<double>> measured;
    for (const auto& [j, r] : by_class) {
      std::vector<post::LumpPieces> pieces;
      for (const auto& l : r.lumps) pieces.push_back(l.pieces);
      measured[j] = post::MeasuredBreakageColumn(classes, j, pieces);
    }
    const post::AssembledMatrix a = post::AssembleBreakageMatrix(classes, measured);
    nlohmann::json columns = nlohmann::json::array();
    std::string measured_text;
    for (std::size_t j = 0; j < classes.size(); ++j) {
      nlohmann::json col = {{"class", j}, {"origin", a.origin[j].kind}};
      if (a.origin[j].kind == "measured") {
        const ClassRuns& r = by_class.at(j);
        col["lumps"] = r.lumps.size();
        col["lump_mass_kg"] = r.mass_kg;
        col["lump_diameter_mm"] = r.lump_mm;
        col["lump_elements"] = r.elements;
        // Its mean element radius over the calibration's: 1 to the count's
        // rounding, above 1 for a class lump at feed.class_element_cap.
        if (r.own) col["element_size_vs_calibration"] = plan[j].element_size;
        col["runs"] = r.own ? "the class's own (its representative size)" : "lump.diameter's";
        measured_text += fmt::format("{}{} ({} lump(s) of {:.4g} mm, {:.1f}% stays)",
                                     measured_text.empty() ? "" : ", ", classes.name(j),
                                     r.lumps.size(), r.lump_mm, 100 * a.b[j][j]);
      } else if (a.origin[j].kind == "scaled") {
        col["scaled_from_class"] = a.origin[j].from;
        col["not_measured"] = plan[j].without_runs.empty()
                                  ? std::string("no in-mill run of its own at this rotor speed")
                                  : plan[j].without_runs;
      }
      columns.push_back(col);
      for (std::size_t i = j; i < classes.size(); ++i)
        csv += fmt::format("{:g},{},{:g},{},{:g},{:.12g},{},{}\n", rpm, j, classes.upper_mm[j], i,
                           classes.upper_mm[i], a.b[i][j], a.origin[j].kind,
                           a.origin[j].kind == "scaled" ? std::to_string(a.origin[j].from) : "");
    }
    speeds.push_back({{"rpm", rpm}, {"matrix", a.b}, {"columns", columns}});
    ctx.progress.info(
        fmt::format("[breakage] breakage matrix at {:g} rpm: measured {}; {} class(es) scaled", rpm,
                    measured_text, classes.size() - 1 - by_class.size()));
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
         "summed over the runs over their mass; runs: the class's own lumps (its representative "
         "size, the calibration's element size) or, for lump.diameter's class without runs of "
         "its own, the lumps of lump.diameter"},
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
