// JK fit and size distributions of a breakage campaign; see summaries.h.
#include "stages/breakage/summaries.h"

#include <fmt/format.h>

#include <algorithm>
#include <map>

#include "engine/runner.h"
#include "jobs/job_store.h"
#include "postprocess/distributions.h"
#include "postprocess/jk_fit.h"
#include "progress.h"

namespace mill::breakage {
namespace fs = std::filesystem;

namespace {

nlohmann::json opt_json(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

nlohmann::json spread_json(const std::optional<post::Spread>& s) {
  if (!s) return nullptr;
  return {{"min", s->min}, {"max", s->max}, {"mean", s->mean}, {"std", opt_json(s->stddev)}};
}

// "P80 12.3 mm" or "P80 < 1.2 mm" for the progress line.
std::string p_text(const char* name, const nlohmann::json& v, double finest) {
  return v.is_number() ? fmt::format("{} {:.3g} mm", name, v.get<double>())
                       : fmt::format("{} < {:.3g} mm", name, finest);
}

}  // namespace

std::vector<double> sieves_mm(const std::vector<double>& edges_rel, double lump_diameter_mm) {
  std::vector<double> out;
  for (size_t k = 1; k < edges_rel.size(); ++k) out.push_back(edges_rel[k] * lump_diameter_mm);
  return out;
}

nlohmann::json passing_json(const std::vector<double>& sieves,
                            const std::vector<double>& fraction_mass) {
  const auto passing = post::CumulativePassingPercent(fraction_mass);
  return {{"sieves_mm", sieves},
          {"passing_percent", passing},
          {"p50_mm", opt_json(post::SizeAtPercentPassing(sieves, passing, 50))},
          {"p80_mm", opt_json(post::SizeAtPercentPassing(sieves, passing, 80))}};
}

void write_jk_fit(StageContext& ctx, const std::vector<post::ImpactSummary>& rows, bool pooled) {
  const fs::path dir = ctx.stage_dir;
  const auto& ore = ctx.cfg.ore;
  nlohmann::json card = nullptr;
  if (ore.has("jk.A") && ore.has("jk.b"))
    card = {{"A_percent", ore.real("jk.A")},
            {"b_t_per_kWh", ore.real("jk.b")},
            {"A_times_b", ore.real("jk.A") * ore.real("jk.b")},
            {"source", ore.has("jk.source") ? nlohmann::json(ore.str("jk.source"))
                                            : nlohmann::json(nullptr)}};

  std::map<double, std::vector<const post::ImpactSummary*>> by_angle;
  for (const auto& s : rows) by_angle[pooled ? -1.0 : s.angle_deg].push_back(&s);
  nlohmann::json out = nlohmann::json::array();
  std::vector<post::JkFitRecord> records;
  std::string csv = "angle_deg,velocity_m_s,repeat,ecs_kWh_t,t10_percent,t10_resolved\n";
  for (const auto& [angle, list] : by_angle) {
    post::JkFitRecord rec;
    rec.name = pooled ? "all" : fmt::format("a{:g}", angle);
    std::vector<post::JkPoint> used;
    long lump_elements = 0;
    for (const auto* s : list) {
      const double e = post::SpecificEnergyKWhPerTonne(s->velocity_m_s);
      rec.ecs_kwh_t.push_back(e);
      rec.t10_percent.push_back(s->t10_percent);
      rec.repeat.push_back(s->repeat);
      rec.used.push_back(s->t10_resolved ? 1 : 0);
      if (s->t10_resolved) used.push_back({e, s->t10_percent, s->repeat});
      lump_elements = std::max(lump_elements, static_cast<long>(s->n_elements));
      csv += fmt::format("{:g},{:g},{},{:.9g},{:.9g},{}\n", s->angle_deg, s->velocity_m_s,
                         s->repeat, e, s->t10_percent, s->t10_resolved ? 1 : 0);
    }
    // Per repeat: the repeats at every speed (not those that only the speeds of
    // breakage.crossing_velocities have).
    std::vector<post::SweepPoint> speeds;
    for (const auto* s : list) speeds.push_back({s->velocity_m_s, s->repeat, 0.0});
    const std::set<int> whole = post::RepeatsAtEveryVelocity(speeds);
    rec.fit = post::FitJkSweep(used, &whole);
    const post::JkFit& f = rec.fit.pooled;
    std::string reason = f.reason;
    if (used.empty())
      reason = fmt::format(
          "t10 not resolved at any impact (the elements of a {}-element lump are coarser than a "
          "tenth of it; "
          "about 1000 elements or more resolve t10)",
          lump_elements);
    nlohmann::json e = {
        {"angle_deg", pooled ? nlohmann::json(nullptr) : nlohmann::json(angle)},
        {"relation",
         "t10 = A (1 - exp(-b Ecs)) (Napier-Munn et al. 1996, Mineral Comminution Circuits, "
         "JKMRC)"},
        {"energy", "Ecs = V^2/2 of the impact speed V, in kWh/t (1 kWh/t = 3600 J/kg)"},
        {"points", list.size()},
        {"points_used", used.size()},
        {"fitted", f.ok},
        {"ore_card", card}};
    if (pooled)
      e["note_conditions"] =
          "conditions binned from transport: every bin has its own speed and angle; pooled";
    if (f.ok) {
      e["A_percent"] = f.a_percent;
      e["b_t_per_kWh"] = f.b_t_per_kwh;
      e["A_times_b"] = f.ab();
      e["A_se_percent"] = f.a_se_percent;
      e["b_se_t_per_kWh"] = f.b_se_t_per_kwh;
      e["rms_residual_percent"] = f.rms_residual_percent;
      if (!f.note.empty()) e["note"] = f.note;
      e["uncertainty"] =
          "each repeat (one lump orientation over the whole sweep) fitted on its own; min, max, "
          "mean and std over the repeats that have a fit; standard errors from the pooled fit";
      e["repeats_fitted"] = rec.fit.n_repeats_fitted;
      e["over_repeats"] = {{"A_percent", spread_json(rec.fit.a_percent)},
                           {"b_t_per_kWh", spread_json(rec.fit.b_t_per_kwh)},
                           {"A_times_b", spread_json(rec.fit.ab)}};
      ctx.progress.info(fmt::format(
          "[breakage] JK fit{}: A {:.1f}%, b {:.3g} t/kWh, A x b {:.3g} ({} of {} impacts, {} "
          "repeats fitted)",
          pooled ? "" : fmt::format(" at {:g} deg", angle), f.a_percent, f.b_t_per_kwh, f.ab(),
          used.size(), list.size(), rec.fit.n_repeats_fitted));
    } else {
      e["reason"] = reason;
      ctx.progress.info("[breakage] no JK fit" +
                        (pooled ? std::string() : fmt::format(" at {:g} deg", angle)) + ": " +
                        reason);
    }
    out.push_back(e);
    records.push_back(std::move(rec));
  }
  jobs::atomic_write(dir / "jk_points.csv", csv);
  jobs::atomic_write(dir / "jk_fit.json", out.dump(2) + "\n");
  post::WriteJkFitH5((dir / "breakage.h5").string(), records);

  engine::run_python(ctx.runner, ctx.cfg.project_dir / "postprocess" / "plot_jk.py",
                     {"--points", (dir / "jk_points.csv").string(), "--fit",
                      (dir / "jk_fit.json").string(), "--out", (dir / "plots").string()},
                     dir / "plot_jk.log", "breakage/JK plot");
}

void write_size_distributions(StageContext& ctx, const std::vector<post::FractionRow>& fractions) {
  const fs::path dir = ctx.stage_dir;
  const double d_mm = 1000 * ctx.cfg.doc.real("lump.diameter");
  const auto edges = ctx.cfg.doc.reals("breakage.size_fraction_edges");
  const auto sieves = sieves_mm(edges, d_mm);
  // (speed, angle) -> repeat -> mass per fraction
  std::map<std::pair<double, double>, std::map<int, std::vector<double>>> by_cond;
  for (const auto& f : fractions) {
    if (f.index >= static_cast<int>(sieves.size()))
      throw std::runtime_error(
          fmt::format("fractions.csv: fraction {} beyond the case's {} size fractions", f.index,
                      sieves.size()));
    auto& m = by_cond[{f.conditions.velocity_m_s, f.conditions.angle_deg}][f.conditions.repeat];
    if (m.empty()) m.assign(sieves.size(), 0.0);
    m[f.index] = f.mass_fraction;
  }
  nlohmann::json conds = nlohmann::json::array();
  std::string csv =
      "velocity_m_s,angle_deg,sieve_mm,passing_percent,passing_percent_min,passing_percent_max\n";
  for (const auto& [va, reps] : by_cond) {
    std::vector<double> mean(sieves.size(), 0.0);
    std::vector<double> lo(sieves.size(), 1e300), hi(sieves.size(), -1e300);
    std::vector<double> p80s;
    for (const auto& [r, m] : reps) {
      const auto p = post::CumulativePassingPercent(m);
      for (size_t k = 0; k < m.size(); ++k) {
        mean[k] += m[k] / static_cast<double>(reps.size());
        lo[k] = std::min(lo[k], p[k]);
        hi[k] = std::max(hi[k], p[k]);
      }
      if (const auto p80 = post::SizeAtPercentPassing(sieves, p, 80)) p80s.push_back(*p80);
    }
    nlohmann::json c = passing_json(sieves, mean);
    c.erase("sieves_mm");
    c["velocity_m_s"] = va.first;
    c["angle_deg"] = va.second;
    c["repeats"] = reps.size();
    c["passing_percent_min"] = lo;
    c["passing_percent_max"] = hi;
    // P80 of each repeat's own curve (repeats finer than the finest sieve are left out).
    c["p80_mm_over_repeats"] =
        p80s.empty() ? nlohmann::json(nullptr)
                     : nlohmann::json{{"min", *std::min_element(p80s.begin(), p80s.end())},
                                      {"max", *std::max_element(p80s.begin(), p80s.end())},
                                      {"n", p80s.size()}};
    const auto& passing = c["passing_percent"];
    for (size_t k = 0; k < sieves.size(); ++k)
      csv += fmt::format("{:g},{:g},{:.6g},{:.6g},{:.6g},{:.6g}\n", va.first, va.second, sieves[k],
                         passing[k].get<double>(), lo[k], hi[k]);
    ctx.progress.info(fmt::format("[breakage] {:g} m/s at {:g} deg: {}, {}", va.first, va.second,
                                  p_text("P80", c["p80_mm"], sieves.front()),
                                  p_text("P50", c["p50_mm"], sieves.front())));
    conds.push_back(c);
  }
  const nlohmann::json out = {{"lump_diameter_mm", d_mm},
                              {"size_definition",
                               "d/D x lump.diameter: a piece's solid equal-volume diameter "
                               "relative to the whole lump's, times the lump "
                               "diameter, so an intact lump reads as the feed size"},
                              {"interpolation",
                               "P50 and P80 log-linear between adjacent sieves (passing linear in "
                               "log size); null when finer "
                               "than the finest sieve"},
                              {"sieves_mm", sieves},
                              {"finest_sieve_mm", sieves.front()},
                              {"conditions", conds}};
  jobs::atomic_write(dir / "size_distributions.csv", csv);
  jobs::atomic_write(dir / "size_distributions.json", out.dump(2) + "\n");
}

}  // namespace mill::breakage
