// The report's headline in words and units, from hand-made headline numbers.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "report/headline.h"
#include "temp_dir.h"

namespace {

using mill::report::headline_rows;
using mill::report::HeadlineRow;
using nlohmann::json;

// The value of the row `what`, or "" when there is none.
std::string value_of(const std::vector<HeadlineRow>& rows, const std::string& what) {
  for (const auto& r : rows)
    if (r.what == what) return r.value;
  return "";
}

TEST(Headline, SaysItInWordsAndUnitsWithTheSpread) {
  const json h = json::parse(R"({
    "flow": {"rpm2000": {"inlet_mass_flow_kg_s": 1.234, "mass_imbalance_relative": 0.004, "iterations": 742,
                         "converged": true, "domain": "half", "cells": 38754, "shaft_power_W": 41500}},
    "calibration": {"source": "fitted", "targets": {"ucs": 50e6, "tensile_strength": 5e6},
                    "achieved": {"ucs": 20.04e6, "tensile_strength": 4.9e6},
                    "within_tolerance": {"ucs": false, "tensile_strength": true}},
    "breakage": {"critical_speed": [{"angle_deg": null, "critical_velocity_m_s": 66.2, "min_m_s": 65.1,
                                     "max_m_s": 81.7, "largest_fraction_threshold": 0.05}],
                 "jk": [{"angle_deg": 90, "fitted": true, "A_percent": 52.3, "b_t_per_kWh": 0.912,
                         "A_times_b": 47.7, "repeats_fitted": 3,
                         "over_repeats": {"A_times_b": {"min": 40.2, "max": 55.0}},
                         "ore_card": {"A_percent": 60, "b_t_per_kWh": 0.8, "A_times_b": 48}}]},
    "product": {"rpm1500": {"p80_mm": null, "p50_mm": null, "finest_sieve_mm": 2},
                "rpm2000": {"p80_mm": 8.14, "p50_mm": 3.21, "fully_shredded_mass_fraction": 0.45}}})");
  const auto rows = headline_rows(h);
  EXPECT_EQ(value_of(rows, "gas mass flow through the mill, 2000 rpm"), "1.23 kg/s (in/out differ by 0.4%)");
  EXPECT_EQ(value_of(rows, "flywheel shaft power (gas only), 2000 rpm"), "41.5 kW");
  EXPECT_EQ(value_of(rows, "flow solution, 2000 rpm"), "converged in 742 iterations (half domain, 38754 cells)");
  EXPECT_EQ(value_of(rows, "calibrated UCS"), "20 of 50 MPa: not met");
  EXPECT_EQ(value_of(rows, "calibrated tensile strength"), "4.9 of 5 MPa: met");
  EXPECT_EQ(value_of(rows, "critical impact speed (largest piece < 5%)"), "66 m/s (65-82 over repeats)");
  EXPECT_EQ(value_of(rows, "JK breakage parameters, 90 deg"),
            "A 52.3%, b 0.912 t/kWh, A x b 47.7 (A x b 40.2-55 over 3 repeats)");
  EXPECT_EQ(value_of(rows, "JK breakage parameters measured (ore card)"), "A 60%, b 0.8 t/kWh, A x b 48");
  EXPECT_EQ(value_of(rows, "product P80, 2000 rpm"), "8.14 mm (P50 3.21 mm)");
  EXPECT_EQ(value_of(rows, "product P80, 1500 rpm"), "< 2 mm (P50 < 2 mm)");  // finer than the finest sieve
  EXPECT_EQ(value_of(rows, "fully shredded (single elements), 2000 rpm"), "45% of the mass");
  // Slower rotor speeds first; stage groups in pipeline order; no dotted keys.
  size_t p1500 = 0, p2000 = 0;
  for (size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].what == "product P80, 1500 rpm") p1500 = i;
    if (rows[i].what == "product P80, 2000 rpm") p2000 = i;
    EXPECT_EQ(rows[i].what.find('_'), std::string::npos) << rows[i].what;
  }
  EXPECT_LT(p1500, p2000);
  EXPECT_EQ(rows.front().group, "Gas flow (stage 1a)");
}

// The flow stage reports the shaft torque and power ("shaft") and the
// backflow; without them there is no power line.
TEST(Headline, ShaftPowerFromTheFlowReportWhenItHasIt) {
  namespace fs = std::filesystem;
  const mill::test::TempDir run("mill_headline_" + std::to_string(getpid()));
  fs::create_directories(run / "flow/rpm1500");
  fs::create_directories(run / "flow/rpm2000");
  std::ofstream(run / "flow/rpm1500/flow_report.json")
      << R"({"shaft": {"torque_Nm": 200.0, "power_W": 31416.0}, "backflow_kg_s": {"outlet_in": 0.012, "inlet_out": 0.0},
            "mass_flow_kg_s": {"inlet_in": 0.7763, "imbalance_relative": 1e-6},
            "history_last_tenth": {"mass_flow_inlet_kg_s": {"spread_relative": 0.0061}},
            "energy_balance": {"total_temperature_rise_K": 1.184, "expected_rise_from_shaft_power_K": 189.06}})";
  std::ofstream(run / "flow/rpm2000/flow_report.json") << R"({"iterations": 30, "converged": false})";
  const json h = mill::report::headline_json(run);
  EXPECT_NEAR(h.at("flow").at("rpm1500").at("shaft_power_W").get<double>(), 31416.0, 0.1);
  const auto rows = headline_rows(h);
  EXPECT_EQ(value_of(rows, "flywheel shaft power (gas only), 1500 rpm"), "31.4 kW (200 N m)");
  EXPECT_EQ(value_of(rows, "backflow: in through the outlet, out through the inlet, 1500 rpm"), "0.012 / 0 kg/s");
  // How settled the mass flow was, and the gas heating the solver leaves out.
  EXPECT_EQ(value_of(rows, "gas mass flow through the mill, 1500 rpm"),
            "0.776 kg/s (in/out differ by < 0.01%); varied by 0.61% over the last tenth of the iterations");
  EXPECT_EQ(value_of(rows, "gas heating (not predicted), 1500 rpm"),
            "solved 1.18 K; the shaft power would heat the gas by 189 K with adiabatic walls, but the rotor's "
            "work does not enter the solver's energy equation (docs/flow.md)");
  EXPECT_EQ(value_of(rows, "gas heating (not predicted), 2000 rpm"), "");
  EXPECT_EQ(value_of(rows, "flywheel shaft power (gas only), 2000 rpm"), "");
  EXPECT_EQ(value_of(rows, "flow solution, 2000 rpm"), "not converged after 30 iterations");
  EXPECT_TRUE(headline_rows(json::object()).empty());
}

// The comminution efficiency from breakage/comminution_efficiency.json: at
// the critical speed with its range over the sweep, or why there is none.
TEST(Headline, ComminutionEfficiencyAtTheCriticalSpeed) {
  namespace fs = std::filesystem;
  const mill::test::TempDir run("mill_headline_eff_" + std::to_string(getpid()));
  fs::create_directories(run / "breakage");
  std::ofstream(run / "breakage/comminution_efficiency.json")
      << R"([{"angle_deg": 90, "critical_velocity_m_s": 66.2, "impacts": 8, "at_critical_speed": 0.01234,
              "mean": 0.011, "min": 0.0021, "max": 0.0305, "ledger_residual_fraction_max": 0.00042,
              "definition": "..."},
             {"angle_deg": 45, "critical_velocity_m_s": null, "impacts": 8, "at_critical_speed": null,
              "mean": 0.004, "min": 0.001, "max": 0.008, "ledger_residual_fraction_max": 0.0001}])";
  const json h = mill::report::headline_json(run);
  EXPECT_NEAR(h.at("breakage").at("comminution_efficiency").at(0).at("at_critical_speed").get<double>(), 0.01234,
              1e-15);
  const auto rows = headline_rows(h);
  EXPECT_EQ(value_of(rows, "comminution efficiency at the critical speed, 90 deg"),
            "1.23% of the energy given went into broken bonds (0.21%-3.05% over the sweep)");
  EXPECT_EQ(value_of(rows, "comminution efficiency at the critical speed, 45 deg"),
            "critical speed not reached; 0.1%-0.8% over the sweep");
  EXPECT_EQ(value_of(rows, "energy ledger residual, largest of the impacts, 90 deg"), "0.042% of the energy given");
  for (const auto& r : rows) {
    EXPECT_EQ(r.group, "Breakage of one lump (stage 2)") << r.what;
    EXPECT_EQ(r.brief, r.what.rfind("comminution", 0) == 0) << r.what;
  }
}

TEST(Headline, NoJkFitSaysWhy) {
  const auto rows = headline_rows(json::parse(
      R"({"breakage": {"jk": [{"angle_deg": null, "fitted": false, "reason": "t10 not resolved at any impact"}]}})"));
  EXPECT_EQ(value_of(rows, "JK breakage parameters"), "not fitted: t10 not resolved at any impact");
}

// The transport's beater strikes: the lab speed leaving the beaters and the
// housing impact that follows, from summary.json through headline_json.
TEST(Headline, LumpsLeavingTheBeatersAndTheirNextHousingImpact) {
  namespace fs = std::filesystem;
  const mill::test::TempDir run("mill_headline_tr_" + std::to_string(getpid()));
  fs::create_directories(run / "transport/rpm2000");
  std::ofstream(run / "transport/rpm2000/summary.json")
      << R"({"n_particles": 360, "n_flywheel_impacts": 512, "n_wall_impacts": 2011,
            "flywheel_impact_speed_mean_m_s": 71.4, "flywheel_impact_speed_std_m_s": 18.2,
            "flywheel_first_strike_speed_mean_m_s": 98.6,
            "flywheel_rebound_speed_lab_mean_m_s": 131.7, "flywheel_rebound_speed_lab_std_m_s": 24.9,
            "strike_to_housing_speed_mean_m_s": 112.3, "strike_to_housing_speed_std_m_s": 30.1,
            "strike_to_housing_angle_mean_deg": 41.6, "strike_to_housing_flight_time_mean_s": 0.0123,
            "n_strike_to_housing": 402, "sliding_contacts": 1403, "sliding_threshold_m_s": 1.0,
            "flow_converged": true})";
  const auto rows = headline_rows(mill::report::headline_json(run));
  EXPECT_EQ(value_of(rows, "flywheel impact speed, 2000 rpm"), "71 m/s ± 18 (sd); first strike of a lump 99 m/s");
  EXPECT_EQ(value_of(rows, "speed of the lumps leaving the beaters (lab frame), 2000 rpm"), "132 m/s ± 25 (sd)");
  EXPECT_EQ(value_of(rows, "housing impact after a beater strike, 2000 rpm"),
            "112 m/s ± 30 (sd), 42 deg to the wall, 12.3 ms after leaving the beater");
  EXPECT_EQ(value_of(rows, "sliding contacts (left out of the impact figures), 2000 rpm"),
            "1403 below 1 m/s normal speed");
}

}  // namespace

namespace {

// In-mill breakage: a row beside the single-impact product, in words.
TEST(Headline, InMillProductBesideTheSingleImpacts) {
  const json h = json::parse(R"({"product": {"rpm2000": {"p80_mm": 8.14, "p50_mm": 3.21,
      "fully_shredded_mass_fraction": 0.45,
      "in_mill": {"lumps": 1, "fully_shredded_mass_fraction": 0.62, "largest_piece_mass_fraction": 0.08,
                  "t10_percent": 71.4, "t10_resolved": true, "bonds_broken_at_strike_fraction": 0.83}}}})");
  const auto rows = headline_rows(h);
  EXPECT_EQ(value_of(rows, "in the mill (1 lump, strike and housing impacts), 2000 rpm"),
            "fully shredded 62% of the mass, largest piece 8%, t10 71%; 83% of the broken bonds broke at the beater "
            "strike");
}

}  // namespace

namespace {
TEST(Headline, CriticalSpeedBandOverTheParameterSets) {
  const json h = json::parse(R"({
    "breakage": {"critical_speed": [{"angle_deg": null, "critical_velocity_m_s": 58.0,
                                     "largest_fraction_threshold": 0.05}],
                 "critical_speed_over_sets": [{"angle_deg": null, "sets": 3, "sets_crossing": 3,
                                               "min_m_s": 52.4, "max_m_s": 63.1, "sets_meeting_card": 1,
                                               "min_meeting_card_m_s": 58.0, "max_meeting_card_m_s": 58.0}]}})");
  const auto rows = headline_rows(h);
  EXPECT_EQ(value_of(rows, "critical impact speed over the calibration's parameter sets"),
            "52-63 m/s over 3 of 3 calibrations from different starts; 1 of 3 meet the ore card "
            "(58 m/s for that one)");
}
}  // namespace

namespace {
// Shattered at the slowest speed swept: the figure is an upper bound, said so.
TEST(Headline, CriticalSpeedAtTheSlowestSpeedIsAnUpperBound) {
  const json h = json::parse(R"({
    "breakage": {"critical_speed": [{"angle_deg": 90, "critical_velocity_m_s": 10.0, "upper_bound": true,
                                     "largest_fraction_threshold": 0.05}]}})");
  const auto rows = headline_rows(h);
  EXPECT_EQ(value_of(rows, "critical impact speed (largest piece < 5%), 90 deg"),
            "at most 10 m/s (shattered at the slowest speed swept: sweep slower speeds)");
}
}  // namespace

namespace {
// Every set shattered at the slowest speed: one speed, said to be a bound.
TEST(Headline, BandOfUpperBoundsReadsAsOneBound) {
  const json h = json::parse(R"({
    "breakage": {"critical_speed_over_sets": [{"angle_deg": 90, "sets": 3, "sets_crossing": 3,
                                               "min_m_s": 10.0, "max_m_s": 10.0, "upper_bound": true,
                                               "sets_meeting_card": 3}]}})");
  const auto rows = headline_rows(h);
  EXPECT_EQ(value_of(rows, "critical impact speed over the calibration's parameter sets, 90 deg"),
            "10 m/s over 3 of 3 calibrations from different starts (a set shattered at the slowest "
            "speed swept: its value is an upper bound); all 3 meet the ore card");
}
}  // namespace

namespace {

// The closed circuit with a feed: the energy row with the passes per tonne,
// and the decision's sentence, kWh/t and band from breakage/circuit.json.
TEST(Headline, ClosedCircuitEnergyAndDecisionWithItsKWhPerTonne) {
  namespace fs = std::filesystem;
  const mill::test::TempDir run("mill_headline_circuit_" + std::to_string(getpid()));
  fs::create_directories(run / "breakage");
  std::ofstream(run / "breakage/circuit.json") << R"({"sieves_mm": [2, 4, 8],
      "rotor_speeds": [{"rpm": 2000, "steady": true, "p50_mm": 3.1, "p80_mm": 6.2, "circulating_load": 0.8,
                        "mass_balance_residual": 1e-16, "product_total_t_h": 20,
                        "energy": {"specific_energy_kWh_t": 2.75, "ore_power_W": 25000, "gas_shaft_power_W": 30000,
                                   "passes_per_tonne": 1.8},
                        "band": {"p80_mm": [5.9, 6.6], "specific_energy_kWh_t": [2.6, 2.9]}}],
      "decision": {"target_p80_mm": 6.5, "kind": "met_at_lowest", "rpm": 2000, "specific_energy_kWh_t": 2.75,
                   "energy_ore_only": false, "band": {"defined": false, "reason": "1 lump per class: no band"},
                   "sentence": "met at every simulated speed: lowest simulated 2000 rpm, at 2.75 kWh/t; 1 lump per class: no band"}})";
  const json h = mill::report::headline_json(run);
  const json& dec = h.at("circuit_decision");
  EXPECT_EQ(dec.at("specific_energy_kWh_t").get<double>(), 2.75);
  EXPECT_EQ(dec.at("band").at("reason"), "1 lump per class: no band");
  EXPECT_EQ(h.at("circuit").at("rpm2000").at("p80_band_mm"), json::parse("[5.9, 6.6]"));
  EXPECT_EQ(h.at("circuit").at("rpm2000").at("passes_per_tonne").get<double>(), 1.8);
  const auto rows = headline_rows(h);
  EXPECT_EQ(value_of(rows, "lowest rotor speed for a product P80 <= 6.5 mm"),
            "met at every simulated speed: lowest simulated 2000 rpm, at 2.75 kWh/t; 1 lump per "
            "class: no band");
  EXPECT_EQ(value_of(rows, "energy per tonne of feed, 2000 rpm"),
            "2.75 kWh/t (gas shaft 30 kW + ore 25 kW, 1.8 passes per tonne)");
}

// The finest size the lumps resolve, one element, and the speeds whose P80
// lies within 2 x of it (circuit.json's resolution, p80_set_by_elements).
TEST(Headline, ClosedCircuitNamesThePeightyTheElementsSet) {
  namespace fs = std::filesystem;
  const mill::test::TempDir run("mill_headline_resolution_" + std::to_string(getpid()));
  fs::create_directories(run / "breakage");
  std::ofstream(run / "breakage/circuit.json") << R"({"sieves_mm": [2, 4, 8],
      "rotor_speeds": [{"rpm": 1500, "steady": true, "p50_mm": 5.1, "p80_mm": 9.2, "p80_set_by_elements": false},
                       {"rpm": 2000, "steady": true, "p50_mm": 3.1, "p80_mm": 4.1, "p80_set_by_elements": true}],
      "resolution": {"element_piece_mm": {"smallest": 2.31, "largest": 3.84}}})";
  const json h = mill::report::headline_json(run);
  EXPECT_EQ(h.at("circuit_resolution").at("element_piece_mm"), json::parse("[2.31, 3.84]"));
  const auto rows = headline_rows(h);
  EXPECT_EQ(value_of(rows, "finest size the lumps resolve"),
            "one element, 2.31-3.84 mm; the P80 at 2000 rpm is below 2 x the coarsest, so it follows "
            "the element size (the calibration's), not the rock");
  // Two speeds: "1500 and 2000 rpm".
  std::ofstream(run / "breakage/circuit.json") << R"({"sieves_mm": [2, 4, 8],
      "rotor_speeds": [{"rpm": 1500, "steady": true, "p50_mm": 5.1, "p80_mm": 4.8, "p80_set_by_elements": true},
                       {"rpm": 2000, "steady": true, "p50_mm": 3.1, "p80_mm": 4.1, "p80_set_by_elements": true}],
      "resolution": {"element_piece_mm": {"smallest": 2.31, "largest": 3.84}}})";
  EXPECT_NE(value_of(headline_rows(mill::report::headline_json(run)), "finest size the lumps resolve")
                .find("the P80 at 1500 and 2000 rpm is below"),
            std::string::npos);
  // No speed bound by it: the span alone.
  std::ofstream(run / "breakage/circuit.json") << R"({"sieves_mm": [2, 4, 8],
      "rotor_speeds": [{"rpm": 1500, "steady": true, "p50_mm": 5.1, "p80_mm": 9.2, "p80_set_by_elements": false}],
      "resolution": {"element_piece_mm": {"smallest": 2.31, "largest": 3.84}}})";
  EXPECT_EQ(value_of(headline_rows(mill::report::headline_json(run)), "finest size the lumps resolve"),
            "one element, 2.31-3.84 mm");
}

}  // namespace

// The calibration's packing check (docs/calibration.md, "Packing check"):
// beyond the tolerance the row names each property's range over the
// packings (the default case's figures of Nov 28); within, one line.
TEST(Headline, CalibrationOverSpecimenPackings) {
  json h = json::parse(R"({
    "calibration": {"source": "fitted", "targets": {"ucs": 50e6}, "achieved": {"ucs": 21.4e6},
      "within_tolerance": {"ucs": false},
      "packing_check": {"seeds": [34019, 34031, 34039], "within_tolerance": false,
        "youngs_modulus": {"values": [19.6e9, 16.4e9, 14.6e9], "spread": 0.298, "limit": 0.1,
                           "spread_is_absolute": false, "within": false},
        "poisson_ratio": {"values": [0.182, 0.194, 0.207], "spread": 0.025, "limit": 0.05,
                          "spread_is_absolute": true, "within": true},
        "ucs": {"values": [21.4e6, 18.0e6, 15.2e6], "spread": 0.34, "limit": 0.1,
                "spread_is_absolute": false, "within": false},
        "tensile_strength": {"values": [5.15e6, 4.87e6, 4.45e6], "spread": 0.147, "limit": 0.1,
                             "spread_is_absolute": false, "within": false}}}})");
  auto rows = headline_rows(h);
  EXPECT_EQ(value_of(rows, "calibration over specimen packings"),
            "E 14.6-19.6 GPa, UCS 15.2-21.4 MPa, tensile strength 4.45-5.15 MPa over 3 packings: "
            "beyond the 10% tolerance, the specimens are too small for it");
  for (const char* k : {"youngs_modulus", "ucs", "tensile_strength"})
    h["calibration"]["packing_check"][k]["within"] = true;
  rows = headline_rows(h);
  EXPECT_EQ(value_of(rows, "calibration over specimen packings"),
            "within the 10% tolerance over 3 packings");
  // A fit on the mean of three of them says so; one packing in the fit, as before.
  h["calibration"]["packing_check"]["fit_packings"] = 3;
  EXPECT_EQ(value_of(headline_rows(h), "calibration over specimen packings"),
            "within the 10% tolerance over 3 packings (the fit read the mean of 3)");
  h["calibration"]["packing_check"]["fit_packings"] = 1;
  EXPECT_EQ(value_of(headline_rows(h), "calibration over specimen packings"),
            "within the 10% tolerance over 3 packings");
  h["calibration"].erase("packing_check");  // a calibration before the check: no row
  EXPECT_EQ(value_of(headline_rows(h), "calibration over specimen packings"), "");
}
