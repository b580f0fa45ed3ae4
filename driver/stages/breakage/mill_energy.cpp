// The mill's energy per tonne of feed per rotor speed
// (docs/population_balance.md, "Energy per tonne").
#include "stages/breakage/mill_energy.h"

#include <fmt/format.h>

#include <fstream>

#include "stages/stage_util.h"

namespace mill::breakage {
namespace fs = std::filesystem;

std::map<double, std::optional<double>> read_gas_shaft_power(const StageContext& ctx,
                                                             const std::vector<double>& rpms) {
  std::map<double, std::optional<double>> out;
  for (double rpm : rpms) {
    out[rpm] = std::nullopt;
    const fs::path f = ctx.run_dir / "flow" / rpm_label(rpm) / "flow_report.json";
    if (!fs::exists(f)) continue;
    std::ifstream in(f);
    nlohmann::json rep;
    try {
      rep = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {
      throw std::runtime_error(
          fmt::format("{}: {} (rerun the flow: orchestrate --stage flow)", f.string(), e.what()));
    }
    if (rep.contains("shaft") && rep.at("shaft").contains("power_W") &&
        rep.at("shaft").at("power_W").is_number())
      out[rpm] = rep.at("shaft").at("power_W").get<double>();
  }
  return out;
}

std::vector<post::ClassWork> class_work(const post::SizeClasses& classes,
                                        const std::map<std::size_t, ClassRuns>& runs) {
  std::map<std::size_t, double> w;
  for (const auto& [j, r] : runs) {
    std::vector<post::LumpWork> lumps;
    for (const auto& l : r.lumps) lumps.push_back(l.work);
    w[j] = post::BeaterWorkPerKg(lumps);
  }
  return post::BeaterWorkPerClass(classes, w);
}

nlohmann::json circuit_energy_json(const post::SizeClasses& classes, const post::CircuitEnergy& e,
                                   const std::vector<post::ClassWork>& work,
                                   const std::vector<double>& mill_input_t_h,
                                   const std::map<std::size_t, ClassRuns>& runs) {
  nlohmann::json per_class = nlohmann::json::array();
  int lumps = 0;
  for (const auto& [j, r] : runs) lumps += static_cast<int>(r.lumps.size());
  for (std::size_t k = classes.size(); k-- > 0;) {  // finest first
    const post::ClassWork& w = work[k];
    nlohmann::json c = {{"class", k},
                        {"name", classes.name(k)},
                        {"mill_input_t_h", mill_input_t_h[k]},
                        {"beater_work_J_per_kg", w.J_per_kg},
                        {"work_origin", w.measured ? "measured" : "nearest"},
                        {"work_from_class", w.from},
                        {"ore_power_W", e.ore_power_W[k]}};
    if (w.measured) {
      const ClassRuns& r = runs.at(k);
      c["lumps"] = r.lumps.size();
      c["runs"] = r.own ? "the class's own" : "lump.diameter's";
    }
    per_class.push_back(c);
  }
  return {{"specific_energy_kWh_t", e.total_kWh_t},
          {"ore_specific_energy_kWh_t", e.ore_kWh_t},
          {"ore_power_W", e.ore_W},
          {"gas_shaft_power_W", e.gas_W ? nlohmann::json(*e.gas_W) : nlohmann::json(nullptr)},
          {"passes_per_tonne", e.passes_per_tonne},
          {"in_mill_lumps", lumps},
          {"classes", per_class},
          {"definition",
           "(gas shaft power + ore power) / fresh feed rate. Ore power = sum over classes of the "
           "class's steady mill input (fresh feed plus returned load, kg/s: every pass through "
           "the rotor counted) x w, the beater's work on the in-mill lumps that measure the "
           "class (energy.work_beater_J) over their mass; a class without such lumps takes the "
           "w of the measured class nearest in log(representative size) (work_origin: nearest, "
           "work_from_class). Gas shaft power from flow/<rpm>/flow_report.json (null when that "
           "flow did not run: then the ore's alone)"}};
}

}  // namespace mill::breakage
