// The band of critical impact speeds over the calibration's parameter sets.
#include "stages/breakage/calibration_sets.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>

#include "jobs/job_store.h"
#include "lump/material.h"
#include "postprocess/distributions.h"
#include "progress.h"
#include "stages/breakage/in_mill_runs.h"

namespace mill::breakage {
namespace fs = std::filesystem;

namespace {
// The band the issue of a rock model asks for: every set's critical speed
// within this share of the primary set's.
constexpr double kBandTolerance = 0.15;
// Angle key of pooled entries (conditions binned from transport).
constexpr double kPooled = -1.0;

std::string set_prefix(int k) { return fmt::format("set{}_", k); }
}  // namespace

int calibration_set_of(const JobSpec& job) {
  return job.inputs.contains("calibration_set") ? job.inputs.at("calibration_set").get<int>() : 1;
}

void plan_calibration_sets(const StageContext& ctx, Plan& p) {
  const int starts = static_cast<int>(ctx.cfg.doc.integer("calibrate.starts"));
  if (starts < 2) return;
  std::vector<JobSpec> primary;
  for (const auto& j : p.jobs)
    if (calibration_set_of(j) == 1 && !is_in_mill_job(j)) primary.push_back(j);
  for (int k = 2; k <= starts; ++k) {
    if (!fs::exists(set_calibration_file(ctx.run_dir, k))) {
      p.note += (p.note.empty() ? "" : "; ") +
                fmt::format("the impacts of calibration set {} wait for {} (orchestrate --stage "
                            "calibrate)",
                            k, set_calibration_file(ctx.run_dir, k).string());
      continue;
    }
    const nlohmann::json bond = bond_json(bond_params_for_set(ctx.cfg, ctx.run_dir, k),
                                          BondNames::job);
    for (const auto& j : primary) {
      JobSpec c = j;
      c.label = set_prefix(k) + j.label;
      c.inputs["bond"] = bond;
      c.inputs["calibration_set"] = k;
      c.summary = fmt::format("calibration set {}: {}", k, j.summary);
      p.jobs.push_back(std::move(c));
    }
  }
}

nlohmann::json calibration_sets_json(const nlohmann::json& primary_crit,
                                     const std::vector<SetRows>& sets,
                                     const nlohmann::json& calib_sets, double threshold,
                                     bool pooled) {
  // Which sets meet every target of the ore card (calibrate/sets.json).
  std::map<int, bool> meets;
  if (calib_sets.is_object() && calib_sets.contains("sets"))
    for (const auto& s : calib_sets["sets"])
      meets[s.value("start", 0)] = s.value("meets_card", false);
  nlohmann::json entries = nlohmann::json::array();
  for (const auto& c : primary_crit) {
    const double angle = c["angle_deg"].is_null() ? kPooled : c["angle_deg"].get<double>();
    nlohmann::json per_set = nlohmann::json::array();
    std::optional<double> lo, hi, lo_met, hi_met;
    int crossing = 0, n_met = 0;
    bool any_upper = false;  // a set already shattered at the slowest speed
    for (const auto& s : sets) {
      std::vector<post::SweepPoint> pts;
      for (const auto& r : s.rows)
        if (pooled || r.angle_deg == angle)
          pts.push_back({r.velocity_m_s, r.repeat, r.largest_mass_fraction});
      const auto v = post::FindCriticalVelocity(pts, threshold).of_mean_curve;
      const bool met = meets.count(s.set) ? meets[s.set] : false;
      const bool upper = post::BelowAtSlowest(pts, threshold);
      any_upper = any_upper || upper;
      per_set.push_back({{"set", s.set},
                         {"impacts", pts.size()},
                         {"critical_velocity_m_s", v ? nlohmann::json(*v) : nlohmann::json()},
                         {"upper_bound", upper},
                         {"meets_card", met}});
      if (met) ++n_met;
      if (!v) continue;
      ++crossing;
      lo = std::min(lo.value_or(*v), *v);
      hi = std::max(hi.value_or(*v), *v);
      if (met) {
        lo_met = std::min(lo_met.value_or(*v), *v);
        hi_met = std::max(hi_met.value_or(*v), *v);
      }
    }
    auto opt = [](const std::optional<double>& x) {
      return x ? nlohmann::json(*x) : nlohmann::json();
    };
    const nlohmann::json ref = c["critical_velocity_m_s"];
    nlohmann::json within = nullptr;
    if (ref.is_number() && crossing == static_cast<int>(sets.size()) && lo && hi && !any_upper)
      within = *lo >= (1 - kBandTolerance) * ref.get<double>() &&
               *hi <= (1 + kBandTolerance) * ref.get<double>();
    entries.push_back({{"angle_deg", c["angle_deg"]},
                       {"critical_velocity_m_s", ref},
                       {"sets", per_set},
                       {"sets_crossing", crossing},
                       {"min_m_s", opt(lo)},
                       {"max_m_s", opt(hi)},
                       {"upper_bound", any_upper},
                       {"sets_meeting_card", n_met},
                       {"min_meeting_card_m_s", opt(lo_met)},
                       {"max_meeting_card_m_s", opt(hi_met)},
                       {"within_15_percent", within}});
  }
  return {{"entries", entries},
          {"sets", sets.size()},
          {"threshold", threshold},
          {"definition",
           "the sweep's impacts repeated with each parameter set of the calibration "
           "(calibrate.starts, calibrate/sets.json); per set the critical speed of its "
           "repeat-averaged curve (the largest piece below the threshold); the band: min and max "
           "over the sets whose sweep crosses; upper_bound: a set already below the threshold at the "
           "slowest speed swept (its value bounds the critical speed from above); "
           "within_15_percent: every set within +-15 % of set 1 (null when a set's sweep does not "
           "cross or only bounds it)"}};
}

void write_calibration_sets(StageContext& ctx, const std::vector<JobSpec>& set_jobs,
                            const std::vector<post::ImpactSummary>& primary_rows,
                            const nlohmann::json& primary_crit, bool pooled) {
  const fs::path out = ctx.stage_dir / "calibration_sets.json";
  if (set_jobs.empty()) {
    fs::remove(out);
    return;
  }
  std::map<int, SetRows> by_set;
  by_set[1] = {1, primary_rows};
  const jobs::JobStore store(ctx.stage_dir);
  for (const auto& j : set_jobs) {
    const int k = calibration_set_of(j);
    by_set[k].set = k;
    for (const auto& r : post::ReadSummaryCsv((store.job_dir(j.label) / "summary.csv").string()))
      by_set[k].rows.push_back(r);
  }
  std::vector<SetRows> sets;
  for (auto& [k, s] : by_set) sets.push_back(std::move(s));
  nlohmann::json calib = nullptr;
  const fs::path cs = ctx.run_dir / "calibrate" / "sets.json";
  if (fs::exists(cs)) {
    std::ifstream in(cs);
    calib = nlohmann::json::parse(in, nullptr, false);
    if (calib.is_discarded())
      throw std::runtime_error(cs.string() +
                               ": damaged (not JSON); rerun `orchestrate --stage calibrate`");
  }
  const nlohmann::json j = calibration_sets_json(
      primary_crit, sets, calib, ctx.cfg.doc.real("breakage.critical_largest_fraction"), pooled);
  jobs::atomic_write(out, j.dump(2) + "\n");
  for (const auto& e : j["entries"]) {
    const std::string where =
        e["angle_deg"].is_null() ? "pooled" : fmt::format("at {:g} deg", e["angle_deg"].get<double>());
    ctx.progress.info(
        e["min_m_s"].is_number()
            ? fmt::format("[breakage] critical velocity {} over {} parameter sets: {:.1f}-{:.1f} "
                          "m/s ({} of {} sets cross; {} meet the ore card){}",
                          where, sets.size(), e["min_m_s"].get<double>(),
                          e["max_m_s"].get<double>(), e["sets_crossing"].get<int>(), sets.size(),
                          e["sets_meeting_card"].get<int>(),
                          e["upper_bound"].get<bool>()
                              ? "; a set shattered at the slowest speed swept: an upper bound"
                              : "")
            : fmt::format("[breakage] critical velocity {}: no parameter set's sweep crosses",
                          where));
  }
}

}  // namespace mill::breakage
