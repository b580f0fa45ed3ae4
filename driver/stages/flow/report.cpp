// flow_report.json of a solved flow case (docs/flow.md, "flow_report.json").
#include "stages/flow/report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "progress.h"
#include "stages/flow/foam_results.h"

namespace mill::flow {
namespace fs = std::filesystem;

namespace {

// Min, max and mean of a series over its last `fraction` of iterations (at
// least 20 values), scaled: how steady a reported figure was at the end.
nlohmann::json tail_spread(const std::vector<std::pair<double, double>>& series, double scale,
                           double fraction = 0.1) {
  nlohmann::json out;
  if (series.empty()) return out;
  const size_t n =
      std::min(series.size(), std::max<size_t>(20, static_cast<size_t>(fraction * series.size())));
  double lo = INFINITY, hi = -INFINITY, sum = 0;
  for (size_t i = series.size() - n; i < series.size(); ++i) {
    const double v = series[i].second * scale;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    sum += v;
  }
  out["from_iteration"] = series[series.size() - n].first;
  out["to_iteration"] = series.back().first;
  out["min"] = lo;
  out["max"] = hi;
  out["mean"] = sum / n;
  out["spread_relative"] = sum != 0 ? (hi - lo) / std::abs(sum / n) : 0.0;
  return out;
}

// The net fluxes of the openings: phi as the solver wrote it (m^3/s for
// simpleFoam, kg/s for rhoSimpleFoam) and the factor to kg/s.
struct Fluxes {
  double to_mass = 1;
  double in_flux = 0, out_flux = 0;  // of the solved domain
  double m_in = 0, m_out = 0;        // kg/s, whole mill
};

// What was solved: case, mesh, scheme, iterations and residuals.
nlohmann::json run_entries(const JobSettings& s, long cells, const Solution& sol) {
  nlohmann::json rep;
  rep["rpm"] = s.rpm;
  rep["omega_rad_s"] = s.omega;
  rep["gas_model"] = s.doc.str("gas.model");
  rep["solver"] = s.solver;
  rep["mesh_preset"] = s.preset.name;
  rep["np"] = s.np;
  rep["cells"] = cells;  // of the solved mesh (the half for flow.domain = half)
  rep["domain"] = s.half ? "half" : "full";
  rep["mirrored"] = s.half;
  if (s.half)
    rep["mirror_note"] =
        "solved z >= 0 with a symmetryPlane at z = 0; mass_flow_kg_s and patch_area_m2 are for "
        "the whole mill (2 x the solved half, see solved_half); cells, rim and y_plus are of the "
        "solved half";
  rep["rotor_angle_deg"] = s.doc.real("flow.rotor_angle");
  rep["iterations"] = sol.log.iterations;
  rep["momentum_scheme"] =
      s.preset.second_order
          ? (sol.first_order > 0
                 ? fmt::format("upwind for {} iterations, then linearUpwind", sol.first_order_done)
                 : std::string("linearUpwind"))
          : std::string("upwind");
  rep["max_iterations"] = s.max_it;
  rep["residual_target"] = s.target;
  rep["converged"] = sol.converged;
  rep["final_initial_residuals"] = sol.log.initial_residual;
  return rep;
}

// Mass flows through the openings, their history at the end, and backflow.
Fluxes add_mass_flows(nlohmann::json& rep, const JobSettings& s, const fs::path& work) {
  const double rho = s.doc.real("gas.density");
  const double mirror = s.mirror;
  Fluxes f;
  f.to_mass = s.comp ? 1.0 : rho;  // simpleFoam's phi is m^3/s
  const double to_mass = f.to_mass;
  f.in_flux = read_flux(work, "inletFlow");
  f.out_flux = read_flux(work, "outletFlow");
  f.m_in = -f.in_flux * to_mass * mirror;
  f.m_out = f.out_flux * to_mass * mirror;
  const double denom = std::max(std::abs(f.m_in), std::abs(f.m_out));
  const double imbalance = denom > 0 ? std::abs(f.m_in - f.m_out) / denom : 0.0;
  rep["mass_flow_kg_s"] = {
      {"inlet_in", f.m_in}, {"outlet_out", f.m_out}, {"imbalance_relative", imbalance}};
  // How steady the figures were at the end: min/max over the last tenth of
  // the iterations (a converged solve has a spread near 0).
  rep["history_last_tenth"] = {
      {"mass_flow_inlet_kg_s",
       tail_spread(function_object_series(work, "inletFlow", ".dat", 1), -to_mass * mirror)},
      {"shaft_torque_Nm",
       tail_spread(function_object_series(work, "flywheelForces", "moment.dat", 3), -mirror)}};
  // Backflow: phi summed with its sign (net) and as |phi| (sum of both
  // directions) gives each direction: inflow through the outlet, outflow
  // through the inlet (zero when the opening passes gas one way only).
  const double in_mag = read_flux(work, "inletFlowMag"), out_mag = read_flux(work, "outletFlowMag");
  const double in_back = 0.5 * (in_mag + f.in_flux) * to_mass * mirror;  // leaving via the inlet
  const double out_back =
      0.5 * (out_mag - f.out_flux) * to_mass * mirror;  // entering via the outlet
  rep["backflow_kg_s"] = {{"inlet_out", in_back},
                          {"outlet_in", out_back},
                          {"inlet_abs_flux", in_mag * to_mass * mirror},
                          {"outlet_abs_flux", out_mag * to_mass * mirror},
                          {"note",
                           "gas leaving through the inlet and entering through the outlet "
                           "(sum of |phi| beside the net flux)"}};
  return f;
}

// Shaft torque and power: the gas's moment on the flywheel about the axis
// (pressure + viscous, forces function object); the rotor turns at +omega
// about +z, so the motor supplies T = -M_z and P = T omega. For the half
// domain the mirrored half doubles M_z.
void add_shaft(nlohmann::json& rep, const JobSettings& s, const fs::path& work) {
  const auto moment = read_moment(work);
  if (moment.size() != 3) return;
  const double torque = -moment[2] * s.mirror;
  rep["shaft"] = {{"torque_Nm", torque},
                  {"power_W", torque * s.omega},
                  {"power_kW", torque * s.omega * 1e-3},
                  {"note",
                   "aerodynamic torque of the gas on the flywheel (pressure + viscous, about "
                   "the axis) at the last iteration; the motor power the gas alone takes, "
                   "without ore, bearings or windage outside the housing"}};
}

// Energy balance (compressible): the rotor's work must leave as a total
// temperature rise of the through-flow, dT0 = P / (m cp), walls adiabatic.
void add_energy_balance(nlohmann::json& rep, const fs::path& work, double m_out) {
  const auto ti = last_values(work, "inletTemperature");
  const auto to = last_values(work, "outletTemperature");
  if (ti.size() < 3 || to.size() < 3) return;
  constexpr double cp = 1005.0;  // constant/thermophysicalProperties
  const double t_in = std::stod(ti[1]), t_out = std::stod(to[1]);
  const double t0_in = t_in + 0.5 * std::stod(ti[2]) / cp,
               t0_out = t_out + 0.5 * std::stod(to[2]) / cp;
  const double expected = m_out > 0 ? rep["shaft"]["power_W"].get<double>() / (m_out * cp) : NAN;
  rep["energy_balance"] = {
      {"inlet_T_K", t_in},
      {"outlet_T_K", t_out},
      {"total_temperature_rise_K", t0_out - t0_in},
      {"expected_rise_from_shaft_power_K", expected},
      {"note",
       "mass-flux-weighted over each opening; expected = shaft power / (mass flow x cp 1005 "
       "J/kg/K) with adiabatic walls. OpenFOAM v1912's rhoSimpleFoam has no work term for the "
       "MRF zone, so the rotor's work does not enter the energy equation: "
       "total_temperature_rise_K stays near 0, far below expected_rise_from_shaft_power_K, "
       "and T is not a heat balance; docs/flow.md, \"Compressible gas\""}};
}

// Temperature range of the gas (compressible) against the start-up guard
// of system/fvOptions: a guard still clipping at the end is reported.
void add_temperature(StageContext& ctx, nlohmann::json& rep, const JobSettings& s,
                     const fs::path& work) {
  const auto tmin = last_values(work, "minTemperature");
  const auto tmax = last_values(work, "maxTemperature");
  if (tmin.size() < 2 || tmax.size() < 2) return;
  const double t_ref = s.doc.real("gas.temperature");
  const double lo = std::stod(tmin[1]), hi = std::stod(tmax[1]);
  const double guard_lo = kTGuardMin * t_ref, guard_hi = kTGuardMax * t_ref;
  const bool clipped = lo <= guard_lo * 1.0001 || hi >= guard_hi * 0.9999;
  rep["temperature_K"] = {{"min", lo},
                          {"max", hi},
                          {"guard_limits", {guard_lo, guard_hi}},
                          {"guard_clipping_at_end", clipped},
                          {"note",
                           "lowest and highest T in the gas at the last iteration; the guard "
                           "(system/fvOptions limitT) only holds the first iterations of the "
                           "layered meshes and must not clip at the end"}};
  if (clipped)
    ctx.progress.warn(fmt::format(
        "{}: the temperature guard still clips at the last iteration (T {:.1f}-{:.1f} K, "
        "limits {:.1f}-{:.1f} K): the solution is not trustworthy; see docs/flow.md",
        s.tag, lo, hi, guard_lo, guard_hi));
}

// Opening areas (whole mill, and the solved half's own figures).
void add_areas(nlohmann::json& rep, const JobSettings& s, const fs::path& work, const Fluxes& f) {
  const double a_in = read_patch_area(work, "inletFlow");
  const double a_out = read_patch_area(work, "outletFlow");
  rep["patch_area_m2"] = {{"inlet", a_in * s.mirror},
                          {"outlet", a_out * s.mirror},
                          {"inlet_nominal", s.geo.inlet_size * s.geo.inlet_size},
                          {"outlet_nominal", s.geo.outlet_size * s.geo.outlet_size}};
  if (s.half)
    rep["solved_half"] = {
        {"mass_flow_kg_s",
         {{"inlet_in", -f.in_flux * f.to_mass}, {"outlet_out", f.out_flux * f.to_mass}}},
        {"patch_area_m2", {{"inlet", a_in}, {"outlet", a_out}}}};
}

}  // namespace

// The report of one rotor speed, after the solve.
nlohmann::json flow_report(StageContext& ctx, const JobSettings& s, const fs::path& work,
                           long cells, const Solution& sol, const WallTimes& times) {
  nlohmann::json rep = run_entries(s, cells, sol);
  const Fluxes f = add_mass_flows(rep, s, work);
  add_shaft(rep, s, work);
  if (s.comp && rep.contains("shaft")) add_energy_balance(rep, work, f.m_out);
  if (s.comp) add_temperature(ctx, rep, s, work);
  add_areas(rep, s, work, f);
  rep["rim"] = read_rim(work, s.geo, s.omega);
  rep["y_plus"] = read_yplus(work);
  // ExecutionTime: steadier than wall time on a shared machine
  rep["solver_cpu_s_rank0"] = sol.log.cpu_seconds;
  const double total =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - times.start).count();
  rep["wall_time_s"] = {
      {"mesh", times.mesh_seconds}, {"solve", times.solve_seconds}, {"total", total}};
  rep["case"] = "case";
  rep["geometry"] = {{"dir", "geometry"},
                     {"files", {"housing.stl", "flywheel.stl", "inlet.stl", "outlet.stl"}},
                     {"units", "m"},
                     {"normals", "into the gas"}};
  return rep;
}

// The closing lines of a job, once its outputs are published.
void announce_result(StageContext& ctx, const JobSettings& s, const nlohmann::json& rep,
                     const Solution& sol, const fs::path& solver_log) {
  const auto& yp = rep["y_plus"];
  auto ypl = [&](const char* p) {
    return yp.contains(p) ? fmt::format("{:.0f}", yp[p]["average"].get<double>())
                          : std::string("?");
  };
  const auto& rim = rep["rim"];
  const auto& mass = rep["mass_flow_kg_s"];
  const auto& back = rep["backflow_kg_s"];
  ctx.progress.info(fmt::format(
      "{}: {} after {} iterations (p {:.2g}, U {:.2g}; target {:g}); {}mass flow in "
      "{:.4g} kg/s, out {:.4g} kg/s, "
      "imbalance {:.2f}%; backflow in {:.3g} / out {:.3g} kg/s; shaft power {}; gas "
      "speed near rim {:.1f} m/s = {:.2f} x tip speed; mean y+ "
      "flywheel {}, housing {}; "
      "{} cells; {}",
      s.tag, sol.converged ? "converged" : "NOT converged", sol.log.iterations, sol.p_res,
      sol.u_res, s.target, s.half ? "half domain mirrored: " : "", mass["inlet_in"].get<double>(),
      mass["outlet_out"].get<double>(), 100 * mass["imbalance_relative"].get<double>(),
      back["inlet_out"].get<double>(), back["outlet_in"].get<double>(),
      rep.contains("shaft")
          ? fmt::format("{:.3g} kW ({:.3g} N m)", rep["shaft"]["power_kW"].get<double>(),
                        rep["shaft"]["torque_Nm"].get<double>())
          : std::string("? (no moment.dat)"),
      rim.value("gas_speed_mean_m_s", 0.0), rim.value("ratio_speed_to_tip_speed", 0.0),
      ypl("flywheel"), ypl("housing"), rep["cells"].get<long>(),
      Progress::duration(rep["wall_time_s"]["total"].get<double>())));
  if (!sol.converged)
    ctx.progress.warn(fmt::format("{}: not converged within flow.max_iterations = {} (see {})",
                                  s.tag, s.max_it, solver_log.string()));
}

}  // namespace mill::flow
