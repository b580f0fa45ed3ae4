// Calibrations from several starts (docs/calibration.md, "Parameter sets
// from different starts").
#include "stages/calibrate/starts.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "stages/calibrate/fitting.h"

namespace mill::calibrate {

std::string start_label(int k) {
  return k <= 1 ? "calibration" : fmt::format("calibration_start{}", k);
}

int start_of(const JobSpec& job) {
  return job.inputs.contains("start_index") ? job.inputs.at("start_index").get<int>() : 1;
}

namespace {
// Radical inverse of n in base b: the Halton coordinate (Halton 1960).
double radical_inverse(int n, int b) {
  double h = 0, f = 1.0 / b;
  for (; n > 0; n /= b, f /= b) h += f * (n % b);
  return h;
}
}  // namespace

std::array<double, 4> start_factors(int k) {
  std::array<double, 4> f{1, 1, 1, 1};
  if (k <= 1) return f;
  const int bases[4] = {2, 3, 5, 7};
  for (int m = 0; m < 4; ++m) f[m] = std::pow(kStartSpread, 2.0 * radical_inverse(k, bases[m]) - 1);
  return f;
}

BondParams start_params(const BondParams& estimate, int k) {
  BondParams p = estimate;
  if (k <= 1) return p;
  const auto f = start_factors(k);
  const double ratio = std::clamp(estimate.cohesion / estimate.tensile * f[3], kMinCohesionRatio,
                                  kMaxCohesionRatio);
  p.modulus = estimate.modulus * f[0];
  p.stiffness_ratio =
      std::clamp(estimate.stiffness_ratio * f[1], kMinStiffnessRatio, kMaxStiffnessRatio);
  p.tensile = estimate.tensile * f[2];
  p.cohesion = ratio * p.tensile;
  p.origin = fmt::format("start {}: closed-form estimate x ({:.3g}, {:.3g}, {:.3g}, {:.3g})", k,
                         f[0], f[1], f[2], f[3]);
  return p;
}

nlohmann::json sets_json(const std::vector<StartResult>& starts) {
  nlohmann::json sets = nlohmann::json::array();
  int meeting = 0;
  for (const auto& s : starts) {
    const nlohmann::json& r = s.report;
    const bool met = r.value("converged", false);
    meeting += met ? 1 : 0;
    const auto f = start_factors(s.start);
    sets.push_back({{"start", s.start},
                    {"job", start_label(s.start)},
                    {"start_factors",
                     {{"bond_modulus", f[0]},
                      {"stiffness_ratio", f[1]},
                      {"bond_tensile_strength", f[2]},
                      {"cohesion_ratio", f[3]}}},
                    {"calibrated", r.value("calibrated", nlohmann::json(nullptr))},
                    {"achieved", r.value("achieved", nlohmann::json(nullptr))},
                    {"within_tolerance", r.value("within_tolerance", nlohmann::json(nullptr))},
                    {"meets_card", met},
                    {"not_reached", r.value("not_reached", nlohmann::json::array())},
                    {"best_iteration", r.value("best_iteration", nlohmann::json(nullptr))},
                    {"iterations", r.contains("iterations") ? r["iterations"].size() : 0},
                    {"calibrated_yaml", (s.dir / "calibrated.yaml").string()}});
  }
  return {{"sets", sets},
          {"starts", starts.size()},
          {"meeting_card", meeting},
          {"targets", starts.empty() ? nlohmann::json(nullptr)
                                     : starts.front().report.value("targets", nlohmann::json())},
          {"definition",
           "one fit per start (calibrate.starts): start 1 from the closed-form estimate, start k "
           "from it scaled by start_factors (Halton points in log space within x/÷ 2); "
           "meets_card: every target within tolerance"}};
}

namespace {
// A value of report.json's `achieved` map, scaled, or "-".
std::string cell(const nlohmann::json& achieved, const char* key, double scale, const char* f) {
  if (!achieved.is_object() || !achieved.contains(key) || !achieved[key].is_number()) return "-";
  return fmt::format(fmt::runtime(f), achieved[key].get<double>() * scale);
}
}  // namespace

std::string sets_markdown(const nlohmann::json& sets) {
  // A K_IC column when the fits aimed at it (calibrate.fit_toughness).
  bool kic = false;
  for (const auto& s : sets["sets"])
    kic = kic || (s["achieved"].is_object() && s["achieved"].contains("fracture_toughness"));
  std::string md = fmt::format(
      "\n## Parameter sets from different starts\n\n{} start(s), {} meeting every target of the "
      "ore card. The breakage stage runs its sweep with each set and reports the band of critical "
      "impact speeds (breakage/calibration_sets.json).\n\n"
      "| start | start factors (E_b, kn/ks, sigma_b, c/sigma_b) | E (GPa) | nu | UCS (MPa) | "
      "tensile (MPa) | UCS/T | {}meets the card |\n|---|---|---|---|---|---|---|{}---|\n",
      sets.value("starts", 0), sets.value("meeting_card", 0), kic ? "K_IC (MPa m^0.5) | " : "",
      kic ? "---|" : "");
  for (const auto& s : sets["sets"]) {
    const auto& f = s["start_factors"];
    const auto& a = s["achieved"];
    std::string ratio = "-";
    if (a.is_object() && a.contains("ucs") && a.contains("tensile_strength") &&
        a["ucs"].is_number() && a["tensile_strength"].is_number() &&
        a["tensile_strength"].get<double>() > 0)
      ratio = fmt::format("{:.2f}", a["ucs"].get<double>() / a["tensile_strength"].get<double>());
    std::string missed;
    for (const auto& m : s["not_reached"])
      missed += (missed.empty() ? "" : "; ") + m.get<std::string>();
    md += fmt::format("| {} | {:.3g}, {:.3g}, {:.3g}, {:.3g} | {} | {} | {} | {} | {} | {}{} |\n",
                      s["start"].get<int>(), f["bond_modulus"].get<double>(),
                      f["stiffness_ratio"].get<double>(), f["bond_tensile_strength"].get<double>(),
                      f["cohesion_ratio"].get<double>(), cell(a, "youngs_modulus", 1e-9, "{:.2f}"),
                      cell(a, "poisson_ratio", 1.0, "{:.3f}"), cell(a, "ucs", 1e-6, "{:.1f}"),
                      cell(a, "tensile_strength", 1e-6, "{:.2f}"), ratio,
                      kic ? cell(a, "fracture_toughness", 1e-6, "{:.3f}") + " | " : "",
                      s["meets_card"].get<bool>() ? "yes" : "no: " + missed);
  }
  return md;
}

}  // namespace mill::calibrate
