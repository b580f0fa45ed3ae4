// The headline numbers and their words; see headline.h.
#include "report/headline.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "report/html.h"

namespace mill::report {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// Rotor-speed folders of a stage ("rpm1500", "rpm2000"), slowest first.
std::vector<std::string> rpm_dirs(const fs::path& stage) {
  std::vector<std::pair<double, std::string>> found;
  if (!fs::is_directory(stage)) return {};
  for (const auto& e : fs::directory_iterator(stage)) {
    const std::string name = e.path().filename().string();
    if (!e.is_directory() || name.rfind("rpm", 0) != 0) continue;
    try {
      found.push_back({std::stod(name.substr(3)), name});
    } catch (const std::exception&) {
    }
  }
  std::sort(found.begin(), found.end());
  std::vector<std::string> out;
  for (const auto& f : found) out.push_back(f.second);
  return out;
}

// The keys of a per-rpm object, slowest first ("rpm500" before "rpm1500").
std::vector<std::string> rpm_keys(const json& j) {
  std::vector<std::pair<double, std::string>> found;
  if (!j.is_object()) return {};
  for (auto it = j.begin(); it != j.end(); ++it) {
    try {
      found.push_back({std::stod(it.key().substr(3)), it.key()});
    } catch (const std::exception&) {
      found.push_back({0.0, it.key()});
    }
  }
  std::sort(found.begin(), found.end());
  std::vector<std::string> out;
  for (const auto& f : found) out.push_back(f.second);
  return out;
}

bool num(const json& v) { return v.is_number(); }
double d(const json& v) { return v.get<double>(); }

// A number with about three significant figures, no exponent for everyday sizes.
std::string g3(double x) {
  return std::abs(x) >= 100 ? fmt::format("{:.0f}", x) : fmt::format("{:.3g}", x);
}

// A speed in whole m/s (two figures below 10 m/s).
std::string speed(double v) {
  return std::abs(v) >= 10 ? fmt::format("{:.0f}", v) : fmt::format("{:.2g}", v);
}

// "2000 rpm" from "rpm2000".
std::string rpm_words(const std::string& key) { return key.substr(3) + " rpm"; }

std::string percent(double fraction) { return fmt::format("{:.0f}%", 100 * fraction); }

// A fraction as a percentage with about three significant figures.
std::string percent3(double fraction) { return g3(100 * fraction) + "%"; }

// The comminution efficiency per angle (breakage/comminution_efficiency.json):
// at the critical speed, with its range over the sweep, and the ledgers'
// largest residual (group and brief are set by the caller's add).
std::vector<HeadlineRow> efficiency_rows(const json& eff) {
  std::vector<HeadlineRow> rows;
  if (!eff.is_array()) return rows;
  for (const auto& e : eff) {
    if (!num(pick(e, "mean"))) continue;
    const std::string at =
        num(pick(e, "angle_deg")) ? fmt::format(", {:g} deg", d(e.at("angle_deg"))) : "";
    const std::string range = num(pick(e, "min")) && num(pick(e, "max"))
                                  ? fmt::format("{}-{} over the sweep", percent3(d(e.at("min"))),
                                                percent3(d(e.at("max"))))
                                  : "";
    rows.push_back({"", "comminution efficiency at the critical speed" + at,
                    num(pick(e, "at_critical_speed"))
                        ? fmt::format("{} of the energy given went into broken bonds ({})",
                                      percent3(d(e.at("at_critical_speed"))), range)
                        : "critical speed not reached; " + range,
                    true});
    if (num(pick(e, "ledger_residual_fraction_max")))
      rows.push_back({"", "energy ledger residual, largest of the impacts" + at,
                      percent3(d(e.at("ledger_residual_fraction_max"))) + " of the energy given",
                      false});
  }
  return rows;
}

// headline.json's "flow": per rotor speed, the flow report's figures.
void flow_json(const fs::path& run, Problems* problems, json& h) {
  for (const auto& rpm : rpm_dirs(run / "flow")) {
    const auto f = read_json(run / "flow" / rpm / "flow_report.json", problems);
    if (f.is_null()) continue;
    json e = {{"domain", pick(f, "domain")},
              {"cells", pick(f, "cells")},
              {"iterations", pick(f, "iterations")},
              {"converged", pick(f, "converged")},
              {"residual_target", pick(f, "residual_target")},
              {"mass_imbalance_relative", pick(pick(f, "mass_flow_kg_s"), "imbalance_relative")},
              {"inlet_mass_flow_kg_s", pick(pick(f, "mass_flow_kg_s"), "inlet_in")},
              {"rim_gas_speed_to_tip_speed", pick(pick(f, "rim"), "ratio_speed_to_tip_speed")}};
    // The flywheel's shaft torque and power (flow_report.json "shaft"), and
    // the backflow through the openings ("backflow_kg_s").
    const json shaft = pick(f, "shaft");
    if (num(pick(shaft, "power_W"))) e["shaft_power_W"] = pick(shaft, "power_W");
    if (num(pick(shaft, "torque_Nm"))) e["shaft_torque_Nm"] = pick(shaft, "torque_Nm");
    const json back = pick(f, "backflow_kg_s");
    if (num(pick(back, "outlet_in"))) e["backflow_outlet_in_kg_s"] = pick(back, "outlet_in");
    if (num(pick(back, "inlet_out"))) e["backflow_inlet_out_kg_s"] = pick(back, "inlet_out");
    // How settled the mass flow was (last tenth of the iterations) and, for
    // the compressible gas, the energy balance of the openings.
    const json spread =
        pick(pick(pick(f, "history_last_tenth"), "mass_flow_inlet_kg_s"), "spread_relative");
    if (num(spread)) e["mass_flow_spread_last_tenth"] = spread;
    e["gas_model"] = pick(f, "gas_model");
    const json eb = pick(f, "energy_balance");
    if (num(pick(eb, "total_temperature_rise_K")) &&
        num(pick(eb, "expected_rise_from_shaft_power_K"))) {
      e["gas_temperature_rise_K"] = pick(eb, "total_temperature_rise_K");
      e["gas_temperature_rise_adiabatic_K"] = pick(eb, "expected_rise_from_shaft_power_K");
    }
    h["flow"][rpm] = e;
  }
}

// headline.json's "transport": per rotor speed, the transport summary's figures.
void transport_json(const fs::path& run, Problems* problems, json& h) {
  for (const auto& rpm : rpm_dirs(run / "transport")) {
    const auto t = read_json(run / "transport" / rpm / "summary.json", problems);
    if (t.is_null()) continue;
    h["transport"][rpm] = {
        {"lumps", pick(t, "n_particles")},
        {"flywheel_impacts", pick(t, "n_flywheel_impacts")},
        {"wall_impacts", pick(t, "n_wall_impacts")},
        {"flywheel_impact_speed_mean_m_s", pick(t, "flywheel_impact_speed_mean_m_s")},
        {"flywheel_impact_speed_std_m_s", pick(t, "flywheel_impact_speed_std_m_s")},
        {"flywheel_normal_speed_mean_m_s", pick(t, "flywheel_normal_speed_mean_m_s")},
        {"flywheel_angle_mean_deg", pick(t, "flywheel_angle_mean_deg")},
        {"flywheel_first_strike_speed_mean_m_s", pick(t, "flywheel_first_strike_speed_mean_m_s")},
        {"flywheel_rebound_speed_lab_mean_m_s", pick(t, "flywheel_rebound_speed_lab_mean_m_s")},
        {"flywheel_rebound_speed_lab_std_m_s", pick(t, "flywheel_rebound_speed_lab_std_m_s")},
        {"strike_to_housing_speed_mean_m_s", pick(t, "strike_to_housing_speed_mean_m_s")},
        {"strike_to_housing_speed_std_m_s", pick(t, "strike_to_housing_speed_std_m_s")},
        {"strike_to_housing_angle_mean_deg", pick(t, "strike_to_housing_angle_mean_deg")},
        {"strike_to_housing_flight_time_mean_s", pick(t, "strike_to_housing_flight_time_mean_s")},
        {"n_strike_to_housing", pick(t, "n_strike_to_housing")},
        {"sliding_contacts", pick(t, "sliding_contacts")},
        {"sliding_threshold_m_s", pick(t, "sliding_threshold_m_s")},
        {"flow_converged", pick(t, "flow_converged")}};
  }
}

// headline.json's "calibration": the calibration report's targets and results.
void calibration_json(const fs::path& run, Problems* problems, json& h) {
  const auto cal = read_json(run / "calibrate" / "report.json", problems);
  if (!cal.is_null())
    h["calibration"] = {{"source", pick(cal, "source")},
                        {"converged", pick(cal, "converged")},
                        {"targets", pick(cal, "targets")},
                        {"achieved", pick(cal, "achieved")},
                        {"within_tolerance", pick(cal, "within_tolerance")}};
  // The packing check without its runs: each property's values and spread.
  const json pc = cal.is_null() ? json() : pick(cal, "packing_check");
  if (pc.is_object()) {
    json c = pc;
    c.erase("runs");
    h["calibration"]["packing_check"] = c;
  }
}

// headline.json's "breakage": critical speeds, comminution efficiency, JK fit.
void breakage_json(const fs::path& run, Problems* problems, json& h) {
  const auto crit = read_json(run / "breakage" / "critical_velocity.json", problems);
  if (crit.is_array()) {
    json c = json::array();
    for (const auto& e : crit)
      c.push_back({{"angle_deg", pick(e, "angle_deg")},
                   {"critical_velocity_m_s", pick(e, "critical_velocity_m_s")},
                   {"min_m_s", pick(e, "min_m_s")},
                   {"max_m_s", pick(e, "max_m_s")},
                   {"largest_fraction_threshold", pick(e, "threshold")},
                   {"upper_bound", pick(e, "upper_bound")}});
    h["breakage"]["critical_speed"] = c;
  }
  // With calibrate.starts > 1: each entry's band over the parameter sets.
  const auto sets = read_json(run / "breakage" / "calibration_sets.json", problems);
  if (sets.is_object() && pick(sets, "entries").is_array()) {
    json c = json::array();
    for (const auto& e : sets.at("entries"))
      c.push_back({{"angle_deg", pick(e, "angle_deg")},
                   {"sets", pick(sets, "sets")},
                   {"sets_crossing", pick(e, "sets_crossing")},
                   {"min_m_s", pick(e, "min_m_s")},
                   {"max_m_s", pick(e, "max_m_s")},
                   {"upper_bound", pick(e, "upper_bound")},
                   {"sets_meeting_card", pick(e, "sets_meeting_card")},
                   {"min_meeting_card_m_s", pick(e, "min_meeting_card_m_s")},
                   {"max_meeting_card_m_s", pick(e, "max_meeting_card_m_s")},
                   {"within_15_percent", pick(e, "within_15_percent")}});
    h["breakage"]["critical_speed_over_sets"] = c;
  }
  const auto eff = read_json(run / "breakage" / "comminution_efficiency.json", problems);
  if (eff.is_array()) {
    json c = json::array();
    for (const auto& e : eff) {
      json x = json::object();
      for (const char* k : {"angle_deg", "critical_velocity_m_s", "at_critical_speed", "mean",
                            "min", "max", "impacts", "ledger_residual_fraction_max"})
        x[k] = pick(e, k);
      c.push_back(x);
    }
    h["breakage"]["comminution_efficiency"] = c;
  }
  const auto jk = read_json(run / "breakage" / "jk_fit.json", problems);
  if (jk.is_array()) {
    json c = json::array();
    for (const auto& e : jk) {
      json x = {{"angle_deg", pick(e, "angle_deg")},
                {"fitted", pick(e, "fitted")},
                {"ore_card", pick(e, "ore_card")}};
      for (const char* k : {"A_percent", "b_t_per_kWh", "A_times_b", "over_repeats",
                            "repeats_fitted", "reason", "points_used", "points"})
        if (e.contains(k)) x[k] = e.at(k);
      c.push_back(x);
    }
    h["breakage"]["jk"] = c;
  }
}

// headline.json's "product": per rotor speed, the mill product (and the in-mill runs').
void product_json(const fs::path& run, Problems* problems, json& h) {
  const auto prod = read_json(run / "breakage" / "product.json", problems);
  if (prod.is_array())
    for (const auto& p : prod)
      if (num(pick(p, "rpm")))
        h["product"][fmt::format("rpm{:g}", d(pick(p, "rpm")))] = {
            {"fully_shredded_mass_fraction", pick(p, "fully_shredded_mass_fraction")},
            {"largest_piece_mass_fraction", pick(p, "largest_piece_mass_fraction")},
            {"t10_percent", pick(p, "t10_percent")},
            {"conditions", pick(p, "conditions")},
            {"p50_mm", pick(p, "p50_mm")},
            {"p80_mm", pick(p, "p80_mm")},
            {"finest_sieve_mm", pick(p, "sieves_mm").is_array() && !pick(p, "sieves_mm").empty()
                                    ? pick(p, "sieves_mm")[0]
                                    : json(nullptr)}};
  // In-mill breakage (breakage.in_mill): the product of lumps run in the mill.
  if (prod.is_array())
    for (const auto& p : prod)
      if (num(pick(p, "rpm")) && pick(p, "in_mill").is_object()) {
        const json& m = p.at("in_mill");
        json x;
        for (const char* k :
             {"lumps", "fully_shredded_mass_fraction", "largest_piece_mass_fraction", "t10_percent",
              "t10_resolved", "bonds_broken_at_strike_fraction", "p50_mm", "p80_mm"})
          x[k] = pick(m, k);
        h["product"][fmt::format("rpm{:g}", d(pick(p, "rpm")))]["in_mill"] = x;
      }
}

// headline.json's "circuit": with a feed, per rotor speed the closed
// circuit's steady product (breakage/circuit.json).
void circuit_json(const fs::path& run, Problems* problems, json& h) {
  const fs::path f = run / "breakage" / "circuit.json";
  if (!fs::exists(f)) return;
  const auto c = read_json(f, problems);
  if (!c.is_object() || !pick(c, "rotor_speeds").is_array()) return;
  const json sieves = pick(c, "sieves_mm");
  for (const auto& e : c.at("rotor_speeds")) {
    if (!num(pick(e, "rpm"))) continue;
    json x = {
        {"steady", pick(e, "steady")},
        {"finest_sieve_mm", sieves.is_array() && !sieves.empty() ? sieves[0] : json(nullptr)}};
    for (const char* k : {"p50_mm", "p80_mm", "circulating_load", "mass_balance_residual",
                          "product_total_t_h", "problem", "p80_set_by_elements"})
      if (e.contains(k)) x[k] = e.at(k);
    for (const char* k :
         {"specific_energy_kWh_t", "ore_power_W", "gas_shaft_power_W", "passes_per_tonne"})
      if (pick(e, "energy").is_object()) x[k] = pick(e.at("energy"), k);
    if (pick(e, "band").is_object()) {
      x["p80_band_mm"] = pick(e.at("band"), "p80_mm");
      x["specific_energy_band_kWh_t"] = pick(e.at("band"), "specific_energy_kWh_t");
    }
    h["circuit"][fmt::format("rpm{:g}", d(e.at("rpm")))] = x;
  }
  // The finest size the lumps resolve: one element.
  const json res = pick(pick(c, "resolution"), "element_piece_mm");
  if (num(pick(res, "smallest")) && num(pick(res, "largest")))
    h["circuit_resolution"] = {{"element_piece_mm", {res.at("smallest"), res.at("largest")}}};
  // With feed.target_p80_mm: the lowest rotor speed that meets it.
  const json dec = pick(c, "decision");
  if (dec.is_object())
    h["circuit_decision"] = {{"target_p80_mm", pick(dec, "target_p80_mm")},
                             {"kind", pick(dec, "kind")},
                             {"rpm", pick(dec, "rpm")},
                             {"specific_energy_kWh_t", pick(dec, "specific_energy_kWh_t")},
                             {"energy_ore_only", pick(dec, "energy_ore_only")},
                             {"band", pick(dec, "band")},
                             {"sentence", pick(dec, "sentence")}};
}

// Appends rows under the titles of headline_groups().
struct RowAdder {
  std::vector<HeadlineRow>& rows;
  void operator()(size_t group, std::string what, std::string value, bool brief = true) const {
    rows.push_back({headline_groups()[group].title, std::move(what), std::move(value), brief});
  }
};

// The rows of the gas flow, per rotor speed.
void flow_rows(const json& h, const RowAdder& add) {
  const json flow = pick(h, "flow");
  for (const auto& rpm : rpm_keys(flow)) {
    const json& f = flow.at(rpm);
    const std::string at = ", " + rpm_words(rpm);
    if (num(pick(f, "inlet_mass_flow_kg_s")))
      add(0, "gas mass flow through the mill" + at,
          fmt::format("{} kg/s", g3(d(f.at("inlet_mass_flow_kg_s")))) +
              (num(pick(f, "mass_imbalance_relative"))
                   ? (d(f.at("mass_imbalance_relative")) < 1e-4
                          ? std::string(" (in/out differ by < 0.01%)")
                          : fmt::format(" (in/out differ by {:.2g}%)",
                                        100 * d(f.at("mass_imbalance_relative"))))
                   : "") +
              (num(pick(f, "mass_flow_spread_last_tenth"))
                   ? fmt::format("; varied by {:.2g}% over the last tenth of the iterations",
                                 100 * d(f.at("mass_flow_spread_last_tenth")))
                   : ""));
    if (num(pick(f, "gas_temperature_rise_K")) && num(pick(f, "gas_temperature_rise_adiabatic_K")))
      add(0, "gas heating (not predicted)" + at,
          fmt::format(
              "solved {} K; the shaft power would heat the gas by {} K with adiabatic walls, "
              "but the rotor's work does not enter the solver's energy equation (docs/flow.md)",
              g3(d(f.at("gas_temperature_rise_K"))),
              g3(d(f.at("gas_temperature_rise_adiabatic_K")))),
          false);
    if (num(pick(f, "shaft_power_W")))
      add(0, "flywheel shaft power (gas only)" + at,
          fmt::format("{} kW", g3(d(f.at("shaft_power_W")) / 1000)) +
              (num(pick(f, "shaft_torque_Nm"))
                   ? fmt::format(" ({} N m)", g3(d(f.at("shaft_torque_Nm"))))
                   : ""));
    if (num(pick(f, "backflow_outlet_in_kg_s")) && num(pick(f, "backflow_inlet_out_kg_s")))
      add(0, "backflow: in through the outlet, out through the inlet" + at,
          fmt::format("{} / {} kg/s", g3(d(f.at("backflow_outlet_in_kg_s"))),
                      g3(d(f.at("backflow_inlet_out_kg_s")))),
          false);
    if (num(pick(f, "iterations"))) {
      std::string mesh;
      if (pick(f, "domain").is_string()) mesh = f.at("domain").get<std::string>() + " domain";
      if (num(pick(f, "cells")))
        mesh += (mesh.empty() ? "" : ", ") + std::to_string(f.at("cells").get<long>()) + " cells";
      add(0, "flow solution" + at,
          fmt::format("{} {} iterations{}",
                      pick(f, "converged") == true ? "converged in" : "not converged after",
                      f.at("iterations").get<long>(), mesh.empty() ? "" : " (" + mesh + ")"),
          false);
    }
    if (num(pick(f, "rim_gas_speed_to_tip_speed")))
      add(0, "gas speed near the rim" + at,
          fmt::format("{:.2f} x the tip speed", d(f.at("rim_gas_speed_to_tip_speed"))), false);
  }
}

// The rows of the lumps' transport, per rotor speed.
void transport_rows(const json& h, const RowAdder& add) {
  const json tr = pick(h, "transport");
  for (const auto& rpm : rpm_keys(tr)) {
    const json& t = tr.at(rpm);
    const std::string at = ", " + rpm_words(rpm);
    if (num(pick(t, "lumps")))
      add(1, "lumps and their impacts" + at,
          fmt::format("{} lumps: {} impacts on the flywheel, {} on the walls",
                      t.at("lumps").get<long>(),
                      num(pick(t, "flywheel_impacts")) ? t.at("flywheel_impacts").get<long>() : 0L,
                      num(pick(t, "wall_impacts")) ? t.at("wall_impacts").get<long>() : 0L),
          false);
    if (num(pick(t, "flywheel_impact_speed_mean_m_s")))
      add(1, "flywheel impact speed" + at,
          fmt::format(
              "{} m/s{}{}{}", speed(d(t.at("flywheel_impact_speed_mean_m_s"))),
              num(pick(t, "flywheel_impact_speed_std_m_s"))
                  ? fmt::format(" ± {} (sd)", speed(d(t.at("flywheel_impact_speed_std_m_s"))))
                  : "",
              num(pick(t, "flywheel_normal_speed_mean_m_s"))
                  ? fmt::format(", normal part {} m/s",
                                speed(d(t.at("flywheel_normal_speed_mean_m_s"))))
                  : "",
              num(pick(t, "flywheel_angle_mean_deg"))
                  ? fmt::format(", {:.0f} deg to the surface", d(t.at("flywheel_angle_mean_deg")))
                  : "") +
              (num(pick(t, "flywheel_first_strike_speed_mean_m_s"))
                   ? fmt::format("; first strike of a lump {} m/s",
                                 speed(d(t.at("flywheel_first_strike_speed_mean_m_s"))))
                   : ""));
    if (num(pick(t, "flywheel_rebound_speed_lab_mean_m_s")))
      add(1, "speed of the lumps leaving the beaters (lab frame)" + at,
          fmt::format(
              "{} m/s{}", speed(d(t.at("flywheel_rebound_speed_lab_mean_m_s"))),
              num(pick(t, "flywheel_rebound_speed_lab_std_m_s"))
                  ? fmt::format(" ± {} (sd)", speed(d(t.at("flywheel_rebound_speed_lab_std_m_s"))))
                  : ""));
    if (num(pick(t, "strike_to_housing_speed_mean_m_s")) && num(pick(t, "n_strike_to_housing")) &&
        t.at("n_strike_to_housing").get<long>() > 0)
      add(1, "housing impact after a beater strike" + at,
          fmt::format(
              "{} m/s{}{}{}", speed(d(t.at("strike_to_housing_speed_mean_m_s"))),
              num(pick(t, "strike_to_housing_speed_std_m_s"))
                  ? fmt::format(" ± {} (sd)", speed(d(t.at("strike_to_housing_speed_std_m_s"))))
                  : "",
              num(pick(t, "strike_to_housing_angle_mean_deg"))
                  ? fmt::format(", {:.0f} deg to the wall",
                                d(t.at("strike_to_housing_angle_mean_deg")))
                  : "",
              num(pick(t, "strike_to_housing_flight_time_mean_s"))
                  ? fmt::format(", {} ms after leaving the beater",
                                g3(1e3 * d(t.at("strike_to_housing_flight_time_mean_s"))))
                  : ""));
    if (num(pick(t, "sliding_contacts")))
      add(1, "sliding contacts (left out of the impact figures)" + at,
          fmt::format(
              "{}{}", t.at("sliding_contacts").get<long>(),
              num(pick(t, "sliding_threshold_m_s"))
                  ? fmt::format(" below {:g} m/s normal speed", d(t.at("sliding_threshold_m_s")))
                  : ""),
          false);
  }
}

// The rows of the calibration: the bonds' source, or each target's result.
// The packing check: the result on further specimen packings. Beyond the
// tolerance it names each property's range (a brief row: what the fit met
// on its packing, another does not); within, one line.
void packing_row(const json& pc, const RowAdder& add) {
  if (!pc.is_object() || !pick(pc, "seeds").is_array()) return;
  const size_t n = pc.at("seeds").size();
  struct P {
    const char* key;
    const char* what;
    double scale;
    const char* unit;
  };
  std::string ranges, tol;
  for (const P& p : {P{"youngs_modulus", "E", 1e-9, " GPa"}, P{"poisson_ratio", "nu", 1, ""},
                     P{"ucs", "UCS", 1e-6, " MPa"},
                     P{"tensile_strength", "tensile strength", 1e-6, " MPa"}}) {
    const json q = pick(pc, p.key);
    if (!q.is_object() || !pick(q, "values").is_array() || pick(q, "values").empty()) continue;
    if (tol.empty() && pick(q, "spread_is_absolute") == false && num(pick(q, "limit")))
      tol = percent(d(q.at("limit")));
    if (pick(q, "within") != false) continue;
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (const auto& v : q.at("values")) {
      lo = std::min(lo, v.get<double>());
      hi = std::max(hi, v.get<double>());
    }
    ranges += fmt::format("{}{} {}-{}{}", ranges.empty() ? "" : ", ", p.what, g3(lo * p.scale),
                          g3(hi * p.scale), p.unit);
  }
  const std::string tol_text = tol.empty() ? "the fit's tolerance" : "the " + tol + " tolerance";
  // A fit on the mean of several packings (calibrate.fit_packings) says so.
  const json fitted = pick(pc, "fit_packings");
  const std::string of =
      num(fitted) && d(fitted) > 1
          ? fmt::format("{} packings (the fit read the mean of {})", n, d(fitted))
          : fmt::format("{} packings", n);
  if (ranges.empty())
    add(2, "calibration over specimen packings", fmt::format("within {} over {}", tol_text, of),
        false);
  else
    add(2, "calibration over specimen packings",
        fmt::format("{} over {}: beyond {}, the specimens are too small for it", ranges, of,
                    tol_text));
}

void calibration_rows(const json& h, const RowAdder& add) {
  const json cal = pick(h, "calibration");
  if (cal.is_object()) {
    if (pick(cal, "source") == "ore card") {
      add(2, "bond parameters", "from the ore card's calibrated section (no fitting run)");
    } else {
      struct P {
        const char* key;
        const char* what;
        double scale;
        const char* unit;
        bool brief;
      };
      for (const P& p : {P{"ucs", "calibrated UCS", 1e-6, "MPa", true},
                         P{"tensile_strength", "calibrated tensile strength", 1e-6, "MPa", true},
                         P{"youngs_modulus", "calibrated Young's modulus", 1e-9, "GPa", false},
                         P{"poisson_ratio", "calibrated Poisson's ratio", 1, "", false}}) {
        const json a = pick(pick(cal, "achieved"), p.key), t = pick(pick(cal, "targets"), p.key);
        if (!num(a)) continue;
        const json ok = pick(pick(cal, "within_tolerance"), p.key);
        add(2, p.what,
            fmt::format("{} of {}{}{}", g3(d(a) * p.scale), num(t) ? g3(d(t) * p.scale) : "?",
                        *p.unit ? " " : "", p.unit) +
                (ok.is_boolean() ? (ok.get<bool>() ? ": met" : ": not met") : ""),
            p.brief);
      }
      packing_row(pick(cal, "packing_check"), add);
    }
  }
}

// The rows of one lump's breakage: critical speeds, efficiency, JK parameters.
void breakage_rows(const json& h, const RowAdder& add) {
  const json crit = pick(pick(h, "breakage"), "critical_speed");
  if (crit.is_array())
    for (const auto& c : crit) {
      const json thr = pick(c, "largest_fraction_threshold");
      std::string what =
          "critical impact speed" + (num(thr) ? " (largest piece < " + percent(d(thr)) + ")" : "");
      if (num(pick(c, "angle_deg"))) what += fmt::format(", {:g} deg", d(c.at("angle_deg")));
      std::string v = "not reached in the sweep";
      if (num(pick(c, "critical_velocity_m_s")) && pick(c, "upper_bound") == true) {
        v = "at most " + speed(d(c.at("critical_velocity_m_s"))) +
            " m/s (shattered at the slowest speed swept: sweep slower speeds)";
      } else if (num(pick(c, "critical_velocity_m_s"))) {
        v = speed(d(c.at("critical_velocity_m_s"))) + " m/s";
        if (num(pick(c, "min_m_s")) && num(pick(c, "max_m_s")) &&
            d(c.at("min_m_s")) < d(c.at("max_m_s")))
          v += fmt::format(" ({}-{} over repeats)", speed(d(c.at("min_m_s"))),
                           speed(d(c.at("max_m_s"))));
      }
      add(3, what, v);
    }
  const json over_sets = pick(pick(h, "breakage"), "critical_speed_over_sets");
  if (over_sets.is_array())
    for (const auto& c : over_sets) {
      std::string what = "critical impact speed over the calibration's parameter sets";
      if (num(pick(c, "angle_deg"))) what += fmt::format(", {:g} deg", d(c.at("angle_deg")));
      const int n = num(pick(c, "sets")) ? pick(c, "sets").get<int>() : 0;
      const int met = num(pick(c, "sets_meeting_card")) ? pick(c, "sets_meeting_card").get<int>() : 0;
      const int crossing = num(pick(c, "sets_crossing")) ? pick(c, "sets_crossing").get<int>() : 0;
      std::string v = fmt::format("no set's sweep reached it ({} sets)", n);
      if (num(pick(c, "min_m_s")) && num(pick(c, "max_m_s"))) {
        const std::string lo = speed(d(c.at("min_m_s"))), hi = speed(d(c.at("max_m_s")));
        v = fmt::format("{} m/s over {} of {} calibrations from different starts",
                        lo == hi ? lo : lo + "-" + hi, crossing, n);
      }
      if (pick(c, "upper_bound") == true)
        v += " (a set shattered at the slowest speed swept: its value is an upper bound)";
      v += met == n ? fmt::format("; all {} meet the ore card", n)
                    : fmt::format("; {} of {} meet the ore card", met, n);
      if (num(pick(c, "min_meeting_card_m_s")) && met < n) {
        const std::string lo = speed(d(c.at("min_meeting_card_m_s")));
        const std::string hi = speed(d(c.at("max_meeting_card_m_s")));
        v += lo == hi ? fmt::format(" ({} m/s for {})", lo, met == 1 ? "that one" : "those")
                      : fmt::format(" ({}-{} m/s over those)", lo, hi);
      }
      add(3, what, v);
    }
  for (const auto& e : efficiency_rows(pick(pick(h, "breakage"), "comminution_efficiency")))
    add(3, e.what, e.value, e.brief);
  const json jk = pick(pick(h, "breakage"), "jk");
  json card = nullptr;
  if (jk.is_array())
    for (const auto& j : jk) {
      std::string what = "JK breakage parameters";
      if (num(pick(j, "angle_deg"))) what += fmt::format(", {:g} deg", d(j.at("angle_deg")));
      if (pick(j, "fitted") == true) {
        std::string v = fmt::format("A {}%, b {} t/kWh, A x b {}", g3(d(j.at("A_percent"))),
                                    g3(d(j.at("b_t_per_kWh"))), g3(d(j.at("A_times_b"))));
        const json ab = pick(pick(j, "over_repeats"), "A_times_b");
        const json n = pick(j, "repeats_fitted");
        if (num(n) && n.get<int>() > 1 && num(pick(ab, "min")))
          v += fmt::format(" (A x b {}-{} over {} repeats)", g3(d(ab.at("min"))),
                           g3(d(ab.at("max"))), n.get<int>());
        add(3, what, v);
      } else {
        add(3, what,
            "not fitted: " + (pick(j, "reason").is_string() ? j.at("reason").get<std::string>()
                                                            : std::string("?")));
      }
      if (pick(j, "ore_card").is_object()) card = j.at("ore_card");
    }
  if (card.is_object())
    add(3, "JK breakage parameters measured (ore card)",
        fmt::format("A {}%, b {} t/kWh, A x b {}", g3(d(card.at("A_percent"))),
                    g3(d(card.at("b_t_per_kWh"))), g3(d(card.at("A_times_b")))));
}

// The rows of the mill product, per rotor speed.
void product_rows(const json& h, const RowAdder& add) {
  const json prod = pick(h, "product");
  for (const auto& rpm : rpm_keys(prod)) {
    const json& p = prod.at(rpm);
    const std::string at = ", " + rpm_words(rpm);
    auto size = [&](const char* k) {
      if (num(pick(p, k))) return g3(d(p[k])) + " mm";
      if (num(pick(p, "finest_sieve_mm"))) return "< " + g3(d(p.at("finest_sieve_mm"))) + " mm";
      return std::string("?");
    };
    if (p.contains("p80_mm"))
      add(4, "product P80" + at, size("p80_mm") + " (P50 " + size("p50_mm") + ")");
    if (num(pick(p, "fully_shredded_mass_fraction")))
      add(4, "fully shredded (single elements)" + at,
          percent(d(p.at("fully_shredded_mass_fraction"))) + " of the mass");
    if (num(pick(p, "t10_percent")))
      add(4, "t10 (finer than a tenth of the feed)" + at,
          fmt::format("{:.0f}%", d(p.at("t10_percent"))), false);
    if (num(pick(p, "largest_piece_mass_fraction")))
      add(4, "largest piece" + at,
          percent(d(p.at("largest_piece_mass_fraction"))) +
              " of a lump (mean over the impact conditions)",
          false);
    // Beside it, the lumps run in the mill: the strike and what follows.
    const json m = pick(p, "in_mill");
    if (m.is_object() && num(pick(m, "fully_shredded_mass_fraction"))) {
      std::string v =
          fmt::format("fully shredded {} of the mass, largest piece {}, t10 {:.0f}%{}",
                      percent(d(m.at("fully_shredded_mass_fraction"))),
                      num(pick(m, "largest_piece_mass_fraction"))
                          ? percent(d(m.at("largest_piece_mass_fraction")))
                          : std::string("?"),
                      num(pick(m, "t10_percent")) ? d(m.at("t10_percent")) : 0.0,
                      pick(m, "t10_resolved").is_boolean() && !m.at("t10_resolved").get<bool>()
                          ? " (unresolved: elements too coarse)"
                          : "");
      if (num(pick(m, "bonds_broken_at_strike_fraction")))
        v += fmt::format("; {} of the broken bonds broke at the beater strike",
                         percent(d(m.at("bonds_broken_at_strike_fraction"))));
      const int lumps = num(pick(m, "lumps")) ? static_cast<int>(d(m.at("lumps"))) : 0;
      add(4,
          fmt::format("in the mill ({} lump{}, strike and housing impacts){}", lumps,
                      lumps == 1 ? "" : "s", at),
          v);
    }
  }
}

// The rows of the closed circuit with the feed, per rotor speed.
void circuit_rows(const json& h, const RowAdder& add) {
  const json dec = pick(h, "circuit_decision");
  if (num(pick(dec, "target_p80_mm")) && pick(dec, "sentence").is_string())
    add(5,
        fmt::format("lowest rotor speed for a product P80 <= {} mm",
                    g3(d(dec.at("target_p80_mm")))),
        dec.at("sentence").get<std::string>());
  const json circ = pick(h, "circuit");
  // The finest size the lumps resolve, and the speeds whose P80 it sets.
  const json span = pick(pick(h, "circuit_resolution"), "element_piece_mm");
  if (span.is_array() && span.size() == 2 && num(span[0]) && num(span[1])) {
    std::vector<std::string> at;
    for (const auto& rpm : rpm_keys(circ))
      if (pick(circ.at(rpm), "p80_set_by_elements").is_boolean() && circ.at(rpm).at("p80_set_by_elements").get<bool>())
        at.push_back(rpm.substr(3));
    std::string bound;
    for (size_t i = 0; i < at.size(); ++i)
      bound += (i == 0 ? "" : i + 1 == at.size() ? " and " : ", ") + at[i];
    if (!bound.empty()) bound += " rpm";
    add(5, "finest size the lumps resolve",
        fmt::format("one element, {}-{} mm{}", g3(d(span[0])), g3(d(span[1])),
                    bound.empty() ? std::string()
                                  : "; the P80 at " + bound +
                                        " is below 2 x the coarsest, so it follows the element size (the "
                                        "calibration's), not the rock"));
  }
  for (const auto& rpm : rpm_keys(circ)) {
    const json& c = circ.at(rpm);
    const std::string at = ", " + rpm_words(rpm);
    if (num(pick(c, "specific_energy_kWh_t")) && num(pick(c, "ore_power_W")))
      add(5, "energy per tonne of feed" + at,
          fmt::format("{} kWh/t ({}ore {} kW{})", g3(d(c.at("specific_energy_kWh_t"))),
                      num(pick(c, "gas_shaft_power_W"))
                          ? "gas shaft " + g3(d(c.at("gas_shaft_power_W")) / 1000) + " kW + "
                          : std::string("no gas flow run: "),
                      g3(d(c.at("ore_power_W")) / 1000),
                      num(pick(c, "passes_per_tonne"))
                          ? ", " + g3(d(c.at("passes_per_tonne"))) + " passes per tonne"
                          : std::string()));
    if (pick(c, "steady").is_boolean() && !c.at("steady").get<bool>()) {
      add(5, "closed circuit" + at,
          "no steady state: " + (pick(c, "problem").is_string() ? c.at("problem").get<std::string>()
                                                                : std::string("?")));
      continue;
    }
    auto size = [&](const char* k) {
      if (num(pick(c, k))) return g3(d(c[k])) + " mm";
      if (num(pick(c, "finest_sieve_mm"))) return "< " + g3(d(c.at("finest_sieve_mm"))) + " mm";
      return std::string("?");
    };
    add(5, "product P80, closed circuit" + at, size("p80_mm") + " (P50 " + size("p50_mm") + ")");
    if (num(pick(c, "circulating_load")))
      add(5, "circulating load" + at,
          fmt::format(
              "{} t per t of fresh feed (mass balance closes to {:.1g})",
              g3(d(c.at("circulating_load"))),
              num(pick(c, "mass_balance_residual")) ? d(c.at("mass_balance_residual")) : NAN),
          false);
  }
}

}  // namespace

const std::vector<HeadlineGroup>& headline_groups() {
  static const std::vector<HeadlineGroup> g = {
      {"flow", "Gas flow (stage 1a)"},
      {"transport", "Ore lumps through the mill (stage 1b)"},
      {"calibrate", "Calibration of the bond model"},
      {"breakage", "Breakage of one lump (stage 2)"},
      {"breakage", "Mill product, one pass (stages 1 and 2)"},
      {"breakage", "Mill product, closed circuit with the feed"}};
  return g;
}

json headline_json(const fs::path& run, Problems* problems) {
  json h = json::object();
  flow_json(run, problems, h);
  transport_json(run, problems, h);
  calibration_json(run, problems, h);
  breakage_json(run, problems, h);
  product_json(run, problems, h);
  circuit_json(run, problems, h);
  return h;
}

std::vector<HeadlineRow> headline_rows(const json& h) {
  std::vector<HeadlineRow> rows;
  const RowAdder add{rows};
  flow_rows(h, add);
  transport_rows(h, add);
  calibration_rows(h, add);
  breakage_rows(h, add);
  product_rows(h, add);
  circuit_rows(h, add);
  return rows;
}

}  // namespace mill::report
