// The mill product per rotor speed from the binned single impacts.
#include "stages/breakage/mill_product.h"

#include <fmt/format.h>

#include "engine/runner.h"
#include "jobs/job_store.h"
#include "postprocess/breakage_results.h"
#include "postprocess/impact_conditions.h"
#include "progress.h"
#include "stages/breakage/summaries.h"

namespace mill::breakage {
namespace fs = std::filesystem;

namespace {

// A job's mass per size fraction (its fractions.csv), one entry per fraction
// of the case's breakage.size_fraction_edges.
std::vector<double> job_fractions(const fs::path& jd, size_t n_fractions) {
  std::vector<double> frac(n_fractions, 0.0);
  for (const auto& f : post::ReadFractionsCsv((jd / "fractions.csv").string())) {
    if (f.index >= static_cast<int>(frac.size()))
      throw std::runtime_error(fmt::format("{}: fraction {} beyond the case's {} size fractions",
                                           (jd / "fractions.csv").string(), f.index, frac.size()));
    frac[f.index] = f.mass_fraction;
  }
  return frac;
}

// Per rotor speed, its bins' conditions: each bin's impacts averaged over
// the repeats, with the bin's share of impacts as weight.
std::map<double, std::vector<post::ConditionBreakage>> binned_conditions(
    const StageContext& ctx, const std::vector<JobSpec>& jobs, size_t n_fractions) {
  const jobs::JobStore store(ctx.stage_dir);
  struct Acc {
    post::ConditionBreakage c;
    int n = 0;
  };
  std::map<double, std::map<int, Acc>> by_rpm;
  for (const auto& j : jobs) {
    const fs::path jd = store.job_dir(j.label);
    const auto rows = post::ReadSummaryCsv((jd / "summary.csv").string());
    if (rows.empty()) throw std::runtime_error((jd / "summary.csv").string() + ": no row");
    const std::vector<double> frac = job_fractions(jd, n_fractions);
    Acc& a = by_rpm[j.inputs.at("rpm").get<double>()][j.inputs.at("bin").get<int>()];
    a.c.weight = j.inputs.at("weight").get<double>();
    if (a.c.fraction_mass.empty()) a.c.fraction_mass.assign(frac.size(), 0.0);
    for (size_t k = 0; k < frac.size(); ++k) a.c.fraction_mass[k] += frac[k];
    a.c.single_mass_fraction += rows[0].single_mass_fraction;
    a.c.largest_mass_fraction += rows[0].largest_mass_fraction;
    a.c.t10_percent += rows[0].t10_percent;
    ++a.n;
  }
  std::map<double, std::vector<post::ConditionBreakage>> out;
  for (auto& [rpm, bins] : by_rpm)
    for (auto& [bin, a] : bins) {
      for (auto& f : a.c.fraction_mass) f /= a.n;
      a.c.single_mass_fraction /= a.n;
      a.c.largest_mass_fraction /= a.n;
      a.c.t10_percent /= a.n;
      out[rpm].push_back(a.c);
    }
  return out;
}

// The product against rotor speed (postprocess/plot_product.py, matplotlib,
// Debian's python3).
void plot_product(StageContext& ctx) {
  const fs::path dir = ctx.stage_dir;
  engine::run_python(
      ctx.runner, ctx.cfg.project_dir / "postprocess" / "plot_product.py",
      {"--product", (dir / "product.json").string(), "--out", (dir / "plots").string()},
      dir / "plot_product.log", "breakage/product plot");
}

}  // namespace

void write_mill_product(StageContext& ctx, const std::vector<JobSpec>& jobs,
                        const std::map<double, nlohmann::json>& in_mill) {
  const fs::path dir = ctx.stage_dir;
  const auto edges = ctx.cfg.doc.reals("breakage.size_fraction_edges");
  nlohmann::json out = nlohmann::json::array();
  const double d_mm = 1000 * ctx.cfg.doc.real("lump.diameter");
  const auto sieves = sieves_mm(edges, d_mm);
  std::string csv =
      "rpm,fraction_index,d_low_rel,d_high_rel,mass_fraction,d_high_mm,passing_percent\n";
  for (const auto& [rpm, conds] : binned_conditions(ctx, jobs, edges.size() - 1)) {
    const auto prod = post::CombineProduct(conds);
    const nlohmann::json pass = passing_json(sieves, prod.fraction_mass);
    for (size_t k = 0; k < prod.fraction_mass.size(); ++k)
      csv +=
          fmt::format("{:g},{},{:g},{:g},{:.9g},{:.6g},{:.6g}\n", rpm, k, edges[k], edges[k + 1],
                      prod.fraction_mass[k], sieves[k], pass["passing_percent"][k].get<double>());
    nlohmann::json e = {{"rpm", rpm},
                        {"conditions", conds.size()},
                        {"fraction_edges_rel", edges},
                        {"fraction_mass", prod.fraction_mass},
                        {"fully_shredded_mass_fraction", prod.single_mass_fraction},
                        {"largest_piece_mass_fraction", prod.largest_mass_fraction},
                        {"t10_percent", prod.t10_percent},
                        {"lump_diameter_mm", d_mm}};
    e.update(pass);
    if (auto it = in_mill.find(rpm); it != in_mill.end()) e["in_mill"] = it->second;
    out.push_back(e);
    const auto mm = [&](const char* k) {
      return pass[k].is_number() ? fmt::format("{:.3g} mm", pass[k].get<double>())
                                 : fmt::format("< {:.3g} mm", sieves.front());
    };
    ctx.progress.info(fmt::format(
        "[breakage] mill product at {:g} rpm ({} conditions): P80 {}, P50 {}, fully shredded "
        "{:.1f}% of the mass, largest piece {:.1f}%, t10 {:.1f}%",
        rpm, conds.size(), mm("p80_mm"), mm("p50_mm"), 100 * prod.single_mass_fraction,
        100 * prod.largest_mass_fraction, prod.t10_percent));
  }
  jobs::atomic_write(dir / "product.csv", csv);
  jobs::atomic_write(dir / "product.json", out.dump(2) + "\n");
  plot_product(ctx);
}

}  // namespace mill::breakage
