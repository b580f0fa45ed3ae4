// The mill's energy per tonne of feed per rotor speed
// (docs/population_balance.md, "Energy per tonne").
#include "stages/breakage/mill_energy.h"

#include <fstream>

#include "jobs/job_store.h"
#include "stages/breakage/in_mill_runs.h"
#include "stages/stage_util.h"

namespace mill::breakage {
namespace fs = std::filesystem;

namespace {

constexpr double kJoulePerKWh = 3.6e6;

nlohmann::json read_json_file(const fs::path& f) {
  std::ifstream in(f);
  return nlohmann::json::parse(in);
}

}  // namespace

std::map<double, MillEnergy> read_mill_energy(const StageContext& ctx,
                                              const std::vector<JobSpec>& jobs) {
  const jobs::JobStore store(ctx.stage_dir);
  std::map<double, MillEnergy> out;
  for (const auto& job : jobs) {
    if (!is_in_mill_job(job)) continue;
    const auto j = read_json_file(store.job_dir(job.label) / "in_mill.json");
    MillEnergy& e = out[job.inputs.at("rpm").get<double>()];
    e.beater_work_J += j.at("energy").at("work_beater_J").get<double>();
    e.lump_mass_kg += j.at("element_mass_kg").get<double>();
    ++e.lumps;
  }
  for (auto& [rpm, e] : out) {
    const fs::path f = ctx.run_dir / "flow" / rpm_label(rpm) / "flow_report.json";
    if (!fs::exists(f)) continue;
    const auto rep = read_json_file(f);
    if (rep.contains("shaft") && rep.at("shaft").contains("power_W") &&
        rep.at("shaft").at("power_W").is_number()) {
      e.has_gas = true;
      e.gas_shaft_power_W = rep.at("shaft").at("power_W").get<double>();
    }
  }
  return out;
}

nlohmann::json energy_json(const MillEnergy& e, double rate_tph) {
  const double rate_kg_s = rate_tph * 1000.0 / 3600.0;
  const double w = e.beater_work_J / e.lump_mass_kg;  // J per kg of lump
  const double ore_W = w * rate_kg_s;
  const double total_W = ore_W + (e.has_gas ? e.gas_shaft_power_W : 0.0);
  const double lump_kg = e.lump_mass_kg / e.lumps;
  return {{"specific_energy_kWh_t", total_W / 1000.0 / rate_tph},
          {"ore_specific_energy_kWh_t", w * 1000.0 / kJoulePerKWh},
          {"ore_power_W", ore_W},
          {"gas_shaft_power_W",
           e.has_gas ? nlohmann::json(e.gas_shaft_power_W) : nlohmann::json(nullptr)},
          {"beater_work_J_per_kg", w},
          {"lumps_per_second", rate_kg_s / lump_kg},
          {"in_mill_lumps", e.lumps},
          {"definition",
           "(gas shaft power + ore power) / feed rate; ore power = the beater's work on the "
           "in-mill lumps (work_beater_J) per kg of lump x the feed rate in kg/s (each tonne fed "
           "counted once); gas shaft power from flow/<rpm>/flow_report.json (null when that flow "
           "did not run: then the ore's alone)"}};
}

}  // namespace mill::breakage
