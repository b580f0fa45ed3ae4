// The merged results of a sweep of single impacts.
#include "stages/breakage/campaign.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "engine/liggghts.h"
#include "jobs/job_store.h"
#include "postprocess/impact_stats.h"
#include "progress.h"

namespace mill::breakage {
namespace fs = std::filesystem;

namespace {

// The comminution efficiency of the impacts of one entry of
// critical_velocity.json `c` (an angle, or all conditions pooled): on the
// repeat-averaged curve at the critical speed (null when the sweep does not
// reach it), mean, min and max over the impacts, and the largest |residual|
// of their ledgers as a share of the energy given.
nlohmann::json efficiency_entry(const std::vector<post::ImpactSummary>& rows,
                                const nlohmann::json& c) {
  std::vector<post::SweepPoint> pts;
  double residual = 0, sum = 0, lo = INFINITY, hi = -INFINITY;
  for (const auto& s : rows) {
    if (!(c["angle_deg"].is_null() || s.angle_deg == c["angle_deg"].get<double>())) continue;
    if (!std::isfinite(s.comminution_efficiency)) continue;
    pts.push_back({s.velocity_m_s, s.repeat, s.comminution_efficiency});
    sum += s.comminution_efficiency;
    lo = std::min(lo, s.comminution_efficiency);
    hi = std::max(hi, s.comminution_efficiency);
    if (std::isfinite(s.ledger_residual_fraction))
      residual = std::max(residual, std::abs(s.ledger_residual_fraction));
  }
  const nlohmann::json none = nullptr;
  std::optional<double> at;
  if (c["critical_velocity_m_s"].is_number())
    at = post::MeanCurveAt(pts, c["critical_velocity_m_s"].get<double>());
  return {{"angle_deg", c["angle_deg"]},
          {"critical_velocity_m_s", c["critical_velocity_m_s"]},
          {"impacts", pts.size()},
          {"at_critical_speed", at ? nlohmann::json(*at) : none},
          {"mean", pts.empty() ? none : nlohmann::json(sum / pts.size())},
          {"min", pts.empty() ? none : nlohmann::json(lo)},
          {"max", pts.empty() ? none : nlohmann::json(hi)},
          {"ledger_residual_fraction_max", pts.empty() ? none : nlohmann::json(residual)},
          {"definition",
           "bond_released_J / (input_J + max(work_other_J, 0)) at the end of each impact (its "
           "energy ledger); at "
           "the critical speed: the repeat-averaged curve, linear between sweep speeds"}};
}

// plots/energy_ledger_fastest.png: the energy ledger plot of the fastest
// impact of the sweep (the first repeat of it), for the report.
void publish_fastest_ledger_plot(StageContext& ctx, const std::vector<post::ImpactSummary>& rows,
                                 const std::vector<fs::path>& row_dirs) {
  const auto fastest = std::max_element(rows.begin(), rows.end(), [](const auto& a, const auto& b) {
    return a.velocity_m_s < b.velocity_m_s;
  });
  if (fastest == rows.end()) return;
  const fs::path from = row_dirs[static_cast<size_t>(fastest - rows.begin())] / "energy_ledger.png";
  const fs::path to = ctx.stage_dir / "plots" / "energy_ledger_fastest.png";
  fs::create_directories(to.parent_path());
  fs::copy_file(from, to.string() + ".tmp", fs::copy_options::overwrite_existing);
  fs::rename(to.string() + ".tmp", to);
}

// One critical_velocity.json entry: the curve of `pts` (one angle, or all
// pooled) against threshold `thr`, logged in the progress.
nlohmann::json critical_entry(StageContext& ctx, double angle,
                              const std::vector<post::SweepPoint>& pts, double thr, bool pooled) {
  const auto c = post::FindCriticalVelocity(pts, thr);
  const std::string where =
      pooled ? "over all conditions, angles pooled," : fmt::format("at {:g} deg", angle);
  nlohmann::json e = {{"angle_deg", pooled ? nlohmann::json(nullptr) : nlohmann::json(angle)},
                      {"threshold", thr},
                      {"repeats_crossing", c.n_crossed}};
  if (pooled)
    e["note"] = "conditions binned from transport: every bin has its own speed and angle; pooled";
  e["critical_velocity_m_s"] =
      c.of_mean_curve ? nlohmann::json(*c.of_mean_curve) : nlohmann::json(nullptr);
  // Shattered at the slowest speed swept: the value is an upper bound.
  const bool upper_bound = post::BelowAtSlowest(pts, thr);
  e["upper_bound"] = upper_bound;
  if (upper_bound)
    e["upper_bound_note"] =
        "the largest piece is already below the threshold at the slowest speed of the sweep: "
        "the critical speed is at or below it; sweep slower speeds to find it";
  e["min_m_s"] = c.min ? nlohmann::json(*c.min) : nlohmann::json(nullptr);
  e["max_m_s"] = c.max ? nlohmann::json(*c.max) : nlohmann::json(nullptr);
  ctx.progress.info(
      c.of_mean_curve
          ? fmt::format("[breakage] critical velocity {} (largest piece < {:g}%): {}{:.1f} m/s{}",
                        where, 100 * thr, upper_bound ? "at most " : "", *c.of_mean_curve,
                        c.min && c.max && *c.min != *c.max
                            ? fmt::format(" (repeats {:.1f}-{:.1f} m/s)", *c.min, *c.max)
                            : "")
          : fmt::format("[breakage] {} the largest piece never fell below {:g}% in the sweep",
                        where, 100 * thr));
  return e;
}

}  // namespace

Campaign merge_impacts(StageContext& ctx, const std::vector<JobSpec>& jobs) {
  const fs::path dir = ctx.stage_dir;
  const jobs::JobStore store(dir);
  Campaign c;
  std::vector<std::string> h5;
  std::string fractions_text;
  for (const auto& j : jobs) {
    const fs::path jd = store.job_dir(j.label);
    h5.push_back((jd / "impact.h5").string());
    for (const auto& s : post::ReadSummaryCsv((jd / "summary.csv").string())) {
      c.rows.push_back(s);
      c.row_dirs.push_back(jd);
    }
    for (const auto& f : post::ReadFractionsCsv((jd / "fractions.csv").string())) {
      fractions_text += post::FractionsCsvLine(f) + "\n";
      c.fractions.push_back(f);
    }
  }
  std::string header;
  for (const auto& col : post::FractionsCsvColumns()) header += (header.empty() ? "" : ",") + col;
  fractions_text = header + "\n" + fractions_text;
  const fs::path stmp = dir / "summary.csv.part";
  fs::remove(stmp);
  for (const auto& s : c.rows) post::AppendSummaryCsv(stmp.string(), s);
  fs::rename(stmp, dir / "summary.csv");
  jobs::atomic_write(dir / "fractions.csv", fractions_text);
  post::MergeBreakageH5Files((dir / "breakage.h5").string(), h5);
  return c;
}

nlohmann::json write_critical_velocity(StageContext& ctx,
                                       const std::vector<post::ImpactSummary>& rows, bool pooled) {
  // Critical velocity per angle: largest piece falls below the threshold.
  // Conditions binned from transport each have their own speed and angle, so
  // they are pooled into one curve over impact speed (angle_deg null).
  constexpr double kPooled = -1.0;
  const double thr = ctx.cfg.doc.real("breakage.critical_largest_fraction");
  nlohmann::json crit = nlohmann::json::array();
  std::map<double, std::vector<post::SweepPoint>> by_angle;
  for (const auto& s : rows)
    by_angle[pooled ? kPooled : s.angle_deg].push_back(
        {s.velocity_m_s, s.repeat, s.largest_mass_fraction});
  for (const auto& [angle, pts] : by_angle)
    crit.push_back(critical_entry(ctx, angle, pts, thr, pooled));
  jobs::atomic_write(ctx.stage_dir / "critical_velocity.json", crit.dump(2) + "\n");
  return crit;
}

void write_comminution_efficiency(StageContext& ctx, const std::vector<post::ImpactSummary>& rows,
                                  const nlohmann::json& crit) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& c : crit) {
    out.push_back(efficiency_entry(rows, c));
    const auto& e = out.back();
    if (e["at_critical_speed"].is_number())
      ctx.progress.info(fmt::format(
          "[breakage] comminution efficiency at the critical speed {:.1f} m/s: {:.2g}%",
          c["critical_velocity_m_s"].get<double>(), 100 * e["at_critical_speed"].get<double>()));
  }
  jobs::atomic_write(ctx.stage_dir / "comminution_efficiency.json", out.dump(2) + "\n");
}

void plot_campaign(StageContext& ctx, const Campaign& camp, bool pooled) {
  // Plots from the merged CSVs (matplotlib, Debian's python3).
  const fs::path dir = ctx.stage_dir;
  std::vector<std::string> args = {
      "--summary",   (dir / "summary.csv").string(),
      "--passing",   (dir / "size_distributions.csv").string(),
      "--out",       (dir / "plots").string(),
      "--threshold", engine::num(ctx.cfg.doc.real("breakage.critical_largest_fraction"))};
  if (pooled) args.push_back("--pool-angles");
  engine::run_python(ctx.runner, ctx.cfg.project_dir / "postprocess" / "plot_breakage.py", args,
                     dir / "plots.log", "breakage/plots");
  publish_fastest_ledger_plot(ctx, camp.rows, camp.row_dirs);
}

}  // namespace mill::breakage
