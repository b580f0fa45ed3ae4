// The closed circuit's energy per tonne of feed; see circuit_energy.h and
// docs/population_balance.md, "Energy per tonne".
#include "postprocess/circuit_energy.h"

#include <fmt/format.h>

#include <cmath>

#include "postprocess/breakage_matrix.h"
#include "postprocess/fragments.h"

namespace mill::post {
namespace {

constexpr double kKgPerTonne = 1000.0;
constexpr double kSecondsPerHour = 3600.0;

}  // namespace

double BeaterWorkPerKg(const std::vector<LumpWork>& lumps) {
  if (lumps.empty()) throw PostError("beater work per kg: no lump");
  double work = 0.0, mass = 0.0;
  for (const LumpWork& l : lumps) {
    if (!std::isfinite(l.work_J))
      throw PostError(
          fmt::format("beater work per kg: a lump's work is {} J; expected a finite "
                      "value (its in_mill.json energy.work_beater_J)",
                      l.work_J));
    if (!std::isfinite(l.mass_kg) || !(l.mass_kg > 0.0))
      throw PostError(
          fmt::format("beater work per kg: a lump's mass is {} kg; expected > 0 (its "
                      "in_mill.json element_mass_kg)",
                      l.mass_kg));
    work += l.work_J;
    mass += l.mass_kg;
  }
  return work / mass;
}

std::vector<ClassWork> BeaterWorkPerClass(const SizeClasses& classes,
                                          const std::map<std::size_t, double>& measured_J_per_kg) {
  if (measured_J_per_kg.empty())
    throw PostError("beater work per class: no class has in-mill lumps");
  std::vector<std::size_t> have;
  for (const auto& [m, w] : measured_J_per_kg) {
    if (m >= classes.size())
      throw PostError(
          fmt::format("beater work per class: class {} of {} size classes", m, classes.size()));
    have.push_back(m);
  }
  std::vector<ClassWork> out(classes.size());
  for (std::size_t i = 0; i < classes.size(); ++i) {
    const bool own = measured_J_per_kg.count(i) > 0;
    const std::size_t from = own ? i : NearestMeasuredClass(classes, i, have);
    out[i] = {measured_J_per_kg.at(from), own, from};
  }
  return out;
}

CircuitEnergy MillEnergyPerTonne(const std::vector<double>& mill_input_t_h,
                                 const std::vector<ClassWork>& work, std::optional<double> gas_W,
                                 double feed_t_h) {
  if (mill_input_t_h.size() != work.size())
    throw PostError(
        fmt::format("mill energy: {} classes of mill input, {} of beater work; "
                    "expected one of each per class",
                    mill_input_t_h.size(), work.size()));
  if (!std::isfinite(feed_t_h) || !(feed_t_h > 0.0))
    throw PostError(fmt::format("mill energy: feed rate {} t/h; expected > 0", feed_t_h));
  CircuitEnergy e;
  double through = 0.0;
  for (std::size_t i = 0; i < work.size(); ++i) {
    const double kg_s = mill_input_t_h[i] * kKgPerTonne / kSecondsPerHour;
    e.ore_power_W.push_back(kg_s * work[i].J_per_kg);
    e.ore_W += e.ore_power_W.back();
    through += mill_input_t_h[i];
  }
  e.gas_W = gas_W;
  e.ore_kWh_t = e.ore_W / 1000.0 / feed_t_h;
  e.total_kWh_t = (e.ore_W + gas_W.value_or(0.0)) / 1000.0 / feed_t_h;
  e.passes_per_tonne = through / feed_t_h;
  return e;
}

std::optional<double> ValueAtDecision(const TargetDecision& d,
                                      const std::map<double, double>& value_by_rpm) {
  using K = TargetDecision::Kind;
  const auto at = [&](double rpm) -> std::optional<double> {
    const auto it = value_by_rpm.find(rpm);
    if (it == value_by_rpm.end() || !std::isfinite(it->second)) return std::nullopt;
    return it->second;
  };
  if (d.kind == K::not_met) return std::nullopt;
  if (d.kind == K::met_at_lowest || !d.interpolated) return at(d.rpm);
  const auto lo = at(d.below_rpm), hi = at(d.above_rpm);
  if (!lo || !hi) return std::nullopt;
  // The weights of the decided rpm between the two simulated speeds.
  const double t = (d.rpm - d.below_rpm) / (d.above_rpm - d.below_rpm);
  return *lo + t * (*hi - *lo);
}

DecisionEnergy EnergyAtDecision(const TargetDecision& d,
                                const std::map<double, CircuitEnergy>& by_rpm, bool with_gas) {
  DecisionEnergy out;
  out.ore_only = !with_gas;
  std::map<double, double> value;
  for (const auto& [rpm, e] : by_rpm) value[rpm] = with_gas ? e.total_kWh_t : e.ore_kWh_t;
  out.kWh_t = ValueAtDecision(d, value);
  return out;
}

std::string DecisionSentence(const TargetDecision& d, std::optional<double> kWh_t, bool ore_only) {
  std::string s = DecisionSentence(d);
  if (kWh_t)
    s += fmt::format(", at {:.3g} kWh/t{}", *kWh_t,
                     ore_only ? " (ore only: not every speed has a gas flow run)" : "");
  return s;
}

}  // namespace mill::post
