// Stage 'transport': ore lumps through the sampled flow.
#include "stages/transport_stage.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <numeric>
#include <sstream>

#include "config/case_config.h"
#include "engine/liggghts.h"
#include "geometry/mill_geometry.h"
#include "jobs/job_store.h"
#include "jobs/output_checks.h"
#include "postprocess/flow_field_io.h"
#include "postprocess/impact_stats.h"
#include "postprocess/transport_h5.h"
#include "progress.h"
#include "stages/stage_util.h"

namespace mill {
namespace fs = std::filesystem;
using engine::num;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.81;
constexpr int kDeckVersion = 5;  // 5: impact/recorder writes contact ends (contact_ends.csv)

// One lump of the injection schedule.
struct Lump {
  double t = 0;               // insertion time, s
  std::array<double, 3> x{};  // centre, m
  std::array<double, 3> v{};  // initial velocity (local gas velocity), m/s
};

// Lumps spread evenly over the inlet square and over the injection time: k x k
// insertion spots on the inlet (inset by a lump radius), k = ceil(sqrt(n)) but
// no closer than 1.05 lump diameters; lump i tries spot (i * p) mod k^2 first
// (p coprime to k^2, near 0.618 k^2: consecutive lumps land far apart), then
// the following spots, and takes the first that none of the lumps inserted in
// the last 50 ms is predicted to occupy (free flight from its start: lumps
// leave the inlet sideways with the gas, across other spots). Each lump starts
// at the gas velocity of the field at its spot (the mean inlet velocity where
// the field has none), without an upward component (lumps are fed in).
std::vector<Lump> injection_schedule(const geometry::MillGeometry& g, const post::FlowField& field,
                                     long n, double diameter, double duration,
                                     std::vector<std::string>& notes) {
  const double r = 0.5 * diameter;
  const double half = 0.5 * g.inlet_size - 1.1 * r;
  if (half < 0)
    throw config::ConfigError(
        fmt::format("injection.lump_diameter: {:g} m lumps do not fit through the {:g} m inlet "
                    "(mill.inlet.size)",
                    diameter, g.inlet_size));
  const long k_fit = 1 + static_cast<long>(std::floor(2 * half / (1.05 * diameter)));
  const long k = std::max(
      1L, std::min(k_fit, static_cast<long>(std::ceil(std::sqrt(static_cast<double>(n))))));
  const long cells = k * k;
  long p = std::max(1L, std::lround(0.618034 * cells));
  while (std::gcd(p, cells) != 1) ++p;

  // The spots and the gas velocity there.
  std::vector<Lump> spots(cells);
  std::vector<bool> found(cells, false);
  std::array<double, 3> mean{0, 0, 0};
  long nfound = 0;
  for (long c = 0; c < cells; ++c) {
    const double fx = k > 1 ? static_cast<double>(c % k) / (k - 1) : 0.5;
    const double fz = k > 1 ? static_cast<double>(c / k) / (k - 1) : 0.5;
    Lump& l = spots[c];
    l.x = {g.inlet_x - half + 2 * half * fx, g.height - 1.1 * r, -half + 2 * half * fz};
    // The field lattice may stop short of the roof: look a little lower too.
    for (int tries = 0; tries < 4 && !found[c]; ++tries) {
      std::array<double, 3> q = l.x;
      q[1] -= tries * field.spacing[1];
      found[c] = field.velocity_at(q, l.v);
    }
    if (found[c]) {
      for (int d = 0; d < 3; ++d) mean[d] += l.v[d];
      ++nfound;
    }
  }
  if (nfound > 0)
    for (auto& m : mean) m /= static_cast<double>(nfound);
  if (nfound < cells) {
    notes.push_back(fmt::format(
        "{} of {} insertion spots have no gas velocity in the field; lumps there start at the "
        "mean inlet gas velocity ({:.3g}, {:.3g}, {:.3g}) m/s",
        cells - nfound, cells, mean[0], mean[1], mean[2]));
    for (long c = 0; c < cells; ++c)
      if (!found[c]) spots[c].v = mean;
  }
  long clamped = 0;
  for (auto& l : spots)
    if (l.v[1] > 0) {
      l.v[1] = 0;
      ++clamped;
    }
  if (clamped > 0)
    notes.push_back(fmt::format(
        "the gas at {} of {} insertion spots flows up (out through the inlet); lumps there "
        "start with its horizontal part only",
        clamped, cells));

  // Lumps in time order, each on a spot that the recent lumps have left.
  const double window = 0.05, clear = 1.2 * diameter;
  std::vector<Lump> lumps;
  long crowded = 0;
  for (long i = 0; i < n; ++i) {
    const double t = duration * static_cast<double>(i) / static_cast<double>(n);
    long best = -1;
    double best_gap = -1;
    for (long m = 0; m < cells; ++m) {
      const long c = (i * p + m) % cells;
      double gap = 1e300;
      for (auto j = lumps.rbegin(); j != lumps.rend() && t - j->t < window; ++j) {
        const double dt = t - j->t;
        double d2 = 0;
        for (int d = 0; d < 3; ++d) {
          const double q = j->x[d] + j->v[d] * dt - (d == 1 ? 0.5 * kG * dt * dt : 0.0);
          d2 += (q - spots[c].x[d]) * (q - spots[c].x[d]);
        }
        gap = std::min(gap, std::sqrt(d2));
      }
      if (gap > best_gap) {
        best_gap = gap;
        best = c;
      }
      if (gap >= clear) break;
    }
    if (best_gap < clear) ++crowded;
    Lump l = spots[best];
    l.t = t;
    lumps.push_back(l);
  }
  if (crowded > 0)
    notes.push_back(fmt::format(
        "{} of {} lumps found no insertion spot clear of the lumps before them (predicted "
        "in free flight); raise injection.duration",
        crowded, n));
  return lumps;
}

// The LIGGGHTS commands that insert the lumps one by one (included by the
// deck): each lump is created as atom type 3, sized and set moving through
// the group of type 3, then made ore (type 1), so no atom ID is assumed.
std::string insert_commands(const std::vector<Lump>& lumps, double diameter, double density,
                            double dt) {
  std::ostringstream o;
  o << "# Written by orchestrate (transport stage): one block per lump.\n";
  long long step = 0;
  for (size_t i = 0; i < lumps.size(); ++i) {
    const Lump& l = lumps[i];
    o << fmt::format("# lump {} at t = {:.6g} s\n", i + 1, l.t)
      << fmt::format("create_atoms 3 single {} {} {} units box\n", num(l.x[0]), num(l.x[1]),
                     num(l.x[2]))
      << "group lump_new type 3\n"
      << fmt::format("set group lump_new diameter {} density {}\n", num(diameter), num(density))
      << fmt::format("velocity lump_new set {} {} {} units box\n", num(l.v[0]), num(l.v[1]),
                     num(l.v[2]))
      << "set group lump_new type 1\n"
      << "group lump_new delete\n";
    if (i + 1 < lumps.size()) {
      const long long next = std::llround(lumps[i + 1].t / dt);
      if (next > step) o << fmt::format("run {} post no\n", next - step);
      step = std::max(step, next);
    }
  }
  return o.str();
}

// "transport-end time T remaining N exited M masked K" from the deck's end.txt.
std::array<double, 4> read_end(const fs::path& f) {
  std::ifstream in(f);
  std::string word;
  std::array<double, 4> v{-1, -1, -1, -1};
  std::string tag;
  if (!(in >> tag >> word >> v[0] >> word >> v[1] >> word >> v[2] >> word >> v[3]) ||
      tag != "transport-end")
    throw std::runtime_error(f.string() + ": no end line (the deck did not finish)");
  return v;
}

// Whether the flow behind the sampled field converged (sample_report.json's
// flow_converged; null when the sample stage wrote no report). An unconverged
// flow stops the stage unless flow.allow_unconverged, as in the sample stage.
nlohmann::json check_flow_converged(const StageContext& ctx, const std::string& label) {
  const fs::path rep_file = ctx.run_dir / "sample" / label / "sample_report.json";
  if (!fs::exists(rep_file)) return nullptr;
  std::ifstream in(rep_file);
  const auto rep = nlohmann::json::parse(in, nullptr, false);
  if (!rep.is_object() || !rep.contains("flow_converged") || !rep["flow_converged"].is_boolean())
    return nullptr;
  const bool converged = rep["flow_converged"].get<bool>();
  if (!converged && !ctx.cfg.doc.boolean("flow.allow_unconverged"))
    throw std::runtime_error(fmt::format(
        "sample/{} holds the gas field of flow/{}, which did not converge (flow_converged: false "
        "in {}); its gas field is not a prediction. Raise flow.max_iterations or choose another "
        "flow.mesh_preset and rerun --stage flow and --stage sample, or set "
        "flow.allow_unconverged: true in {} to go on with it (the report then says so at the top)",
        label, label, rep_file.string(), ctx.cfg.doc.file()));
  return converged;
}

// JSON of one MeanStd-valued statistic pair.
void put(nlohmann::json& j, const std::string& prefix, const post::MeanStd& m,
         const std::string& unit) {
  j[prefix + "_mean_" + unit] = m.mean;
  j[prefix + "_std_" + unit] = m.std;
}

// summary.json keys of the sliding contacts, the struck parts, the beater
// strikes and the housing impacts that follow them.
void strike_keys(nlohmann::json& j, const post::TransportStats& st, double sliding_threshold) {
  const post::StrikeStats& k = st.strikes;
  j["sliding_threshold_m_s"] = sliding_threshold;
  j["sliding_contacts"] = st.sliding_contacts;
  j["sliding_contacts_flywheel"] = st.sliding.at("flywheel");
  j["sliding_contacts_housing"] = st.sliding.at("housing");
  nlohmann::json parts = nlohmann::json::object();
  for (const auto& p : post::PartNames()) {
    const auto it = st.impacts_per_part.find(p);
    parts[p] = it == st.impacts_per_part.end() ? 0LL : it->second;
  }
  j["impacts_per_part"] = parts;
  j["n_flywheel_first_strikes"] = k.n_first;
  j["n_flywheel_later_strikes"] = k.n_later;
  put(j, "flywheel_first_strike_speed", k.first_speed, "m_s");
  put(j, "flywheel_later_strike_speed", k.later_speed, "m_s");
  j["n_flywheel_strikes_with_contact_end"] = k.n_with_end;
  put(j, "flywheel_rebound_speed_lab", k.rebound_speed_lab, "m_s");
  put(j, "flywheel_rebound_normal_speed", k.rebound_normal_speed, "m_s");
  put(j, "flywheel_contact_duration", k.contact_duration, "s");
  j["n_strike_to_housing"] = k.n_to_housing;
  put(j, "strike_to_housing_speed", k.housing_speed, "m_s");
  put(j, "strike_to_housing_angle", k.housing_angle, "deg");
  put(j, "strike_to_housing_flight_time", k.flight_time, "s");
  j["strike_note"] =
      "a strike is a flywheel impact at or above the sliding threshold (normal speed); the "
      "rebound is the lab speed at the end of its contact; strike_to_housing: the lump's next "
      "housing impact after it left the beater and before its next strike (lab speed, angle to "
      "the wall, time since the contact ended)";
}

}  // namespace

Plan TransportStage::plan(const StageContext& ctx) const {
  Plan p;
  for (double rpm : ctx.cfg.doc.reals("rotor.rpm")) {
    nlohmann::json in =
        case_keys(ctx.cfg.doc, {"mill.", "gas.", "flow.", "sample.", "injection.", "transport."});
    in["rotor.rpm"] = rpm;
    in["ore"] = ore_keys(ctx.cfg.ore);
    in["deck_version"] = kDeckVersion;
    p.jobs.push_back(
        {rpm_label(rpm), in,
         fmt::format("{} lumps of {:g} mm through the mill at {}",
                     ctx.cfg.doc.integer("injection.n_lumps"),
                     ctx.cfg.doc.real("injection.lump_diameter") * 1e3, rpm_label(rpm))});
  }
  return p;
}

// transport/<label>/{impacts.csv, contact_ends.csv, transport.h5, summary.json}:
// exist and read.
std::string TransportStage::damaged_outputs(const StageContext& ctx, const JobSpec& job) const {
  const fs::path out = ctx.stage_dir / job.label;
  if (auto r = jobs::first_problem(
          {jobs::check_json(out / "summary.json"), jobs::check_hdf5(out / "transport.h5"),
           jobs::check_file(out / "impacts.csv"), jobs::check_file(out / "contact_ends.csv")});
      !r.empty())
    return r;
  try {
    post::ReadImpactsCsv((out / "impacts.csv").string());
    post::ReadContactEndsCsv((out / "contact_ends.csv").string());
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

// Runs the lumps through the mill at one rotor speed and writes the results
// into transport/<label>/ (each file complete or absent).
void TransportStage::run_job(StageContext& ctx, const JobSpec& job, const fs::path& job_dir) {
  const auto& d = ctx.cfg.doc;
  const double rpm = job.inputs.at("rotor.rpm").get<double>();
  const std::string label = job.label;
  const fs::path field_file = ctx.run_dir / "sample" / label / "field.h5";
  if (!fs::exists(field_file))
    throw MissingInput(fmt::format(
        "stage transport ({}) needs {} (the sampled gas field at {:g} rpm); make it with "
        "`orchestrate --case {} --stage sample --output {}` (after --stage flow)",
        label, field_file.string(), rpm, d.file(), ctx.run_dir.string()));
  const nlohmann::json flow_converged = check_flow_converged(ctx, label);
  // injection.time_limit > duration and the time step: checked with the case.
  const double duration = d.real("injection.duration"), t_limit = d.real("injection.time_limit");
  const geometry::MillGeometry g = geometry::MillGeometry::from_config(d);
  const double omega = rpm * 2 * kPi / 60.0;
  const long n = d.integer("injection.n_lumps");
  const double diameter = d.real("injection.lump_diameter"), dt = d.real("injection.timestep");
  const double density = ctx.cfg.ore.real("density");

  const fs::path work = job_dir / "run";
  fs::remove_all(work);
  fs::create_directories(work);
  const geometry::StlSet stl = geometry::write_stl_set(g, work / "stl");
  const post::FlowField field = post::read_flow_field(field_file);
  std::vector<std::string> notes;
  const std::vector<Lump> lumps = injection_schedule(g, field, n, diameter, duration, notes);
  for (const auto& s : notes) ctx.progress.warn(fmt::format("transport {}: {}", label, s));
  jobs::atomic_write(work / "insert.in", insert_commands(lumps, diameter, density, dt));

  const double margin = std::max(0.05, diameter);
  const auto steps = [dt](double seconds) {
    return std::to_string(std::max(0LL, std::llround(seconds / dt)));
  };
  engine::DeckRun run;
  run.deck = ctx.cfg.project_dir / "liggghts_inputs" / "transport.in.tmpl";
  run.workdir = work;
  run.np = ctx.opts.np;
  run.job = "transport/" + label;
  run.vars = {{"housing_stl", fs::absolute(stl.housing).string()},
              {"flywheel_stl", fs::absolute(stl.flywheel).string()},
              {"outlet_stl", fs::absolute(stl.outlet).string()},
              {"xlo", num(-0.5 * g.width - margin)},
              {"xhi", num(0.5 * g.width + margin)},
              {"ylo", num(-0.3)},
              {"yhi", num(g.height + margin)},
              {"zlo", num(-0.5 * g.depth - margin)},
              {"zhi", num(0.5 * g.depth + margin)},
              {"axis_x", num(g.axis_x)},
              {"axis_y", num(g.axis_height)},
              {"omega", num(omega)},
              {"field_file", fs::absolute(field_file).string()},
              {"viscosity", num(d.real("gas.viscosity"))},
              {"insert_file", "insert.in"},
              {"n_lumps", std::to_string(n)},
              {"t_limit", num(t_limit)},
              {"dt", num(dt)},
              {"skin", num(std::max(0.25 * diameter, 0.002))},
              {"traj_every", steps(d.real("transport.trajectory_interval"))},
              {"vtk_every", steps(d.real("transport.vtk_interval"))},
              {"density", num(density)},
              {"E", num(ctx.cfg.ore.real("youngs_modulus"))},
              {"nu", num(ctx.cfg.ore.real("poisson_ratio"))},
              {"restitution", num(ctx.cfg.ore.real("restitution"))},
              {"friction", num(ctx.cfg.ore.real("friction"))}};
  const engine::Result res = engine::run_deck(ctx.runner, run, ctx.progress, label);
  const auto end = read_end(work / "end.txt");

  // Statistics.
  std::vector<double> insert_time;
  for (const auto& l : lumps) insert_time.push_back(l.t);
  auto records = post::ReadImpactsCsv((work / "impacts.csv").string());
  const auto ends = post::ReadContactEndsCsv((work / "contact_ends.csv").string());
  const auto traj = post::ReadTrajectoryDump((work / "traj.dump").string(), dt);
  post::MillShape shape;
  shape.height = g.height;
  shape.width = g.width;
  shape.depth = g.depth;
  shape.axis_x = g.axis_x;
  shape.axis_y = g.axis_height;
  shape.hub_radius = g.hub_radius();
  shape.tip_radius = g.tip_radius();
  const double sliding_threshold = d.real("transport.sliding_threshold");
  post::LabelImpacts(records, shape, sliding_threshold);
  const post::TransportStats st = post::ComputeTransportStats(records, insert_time, ends);
  const post::SurfaceStats& fly = st.surfaces.at("flywheel");
  const post::SurfaceStats& wall = st.surfaces.at("housing");

  // Cross-check (method.md): rim speed, and a ballistic impact speed: the lump
  // falls from the inlet to the rotor top (drag neglected) and meets a plate
  // moving at omega r_struck across its path.
  double v_in = 0;
  for (const auto& l : lumps) v_in += -l.v[1] / static_cast<double>(lumps.size());
  const double fall = std::max(0.0, g.height - 0.5 * diameter - (g.axis_height + g.tip_radius()));
  const double v_approach = std::sqrt(std::max(0.0, v_in) * std::max(0.0, v_in) + 2 * kG * fall);
  const double r_struck = fly.n > 0 ? fly.axis_distance.mean : g.tip_radius();
  const double v_rotor = omega * r_struck;
  const double v_ballistic = std::hypot(v_approach, v_rotor);

  nlohmann::json j;
  j["rpm"] = rpm;
  j["n_particles"] = st.n_particles;
  j["n_exited"] = std::llround(end[2]);
  j["n_remaining"] = std::llround(end[1]);
  j["n_lost_elsewhere"] = st.n_particles - std::llround(end[2]) - std::llround(end[1]);
  j["end_time_s"] = end[0];
  j["drag_masked_particle_steps"] = std::llround(end[3]);
  j["n_flywheel_impacts"] = fly.n;
  j["n_wall_impacts"] = wall.n;
  put(j, "flywheel_impact_speed", fly.speed, "m_s");
  put(j, "flywheel_normal_speed", fly.normal_speed, "m_s");
  put(j, "flywheel_tangential_speed", fly.tangential_speed, "m_s");
  put(j, "flywheel_angle", fly.angle, "deg");
  put(j, "flywheel_axis_distance", fly.axis_distance, "m");
  put(j, "wall_impact_speed", wall.speed, "m_s");
  put(j, "wall_normal_speed", wall.normal_speed, "m_s");
  put(j, "wall_angle", wall.angle, "deg");
  strike_keys(j, st, sliding_threshold);
  j["flow_converged"] = flow_converged;
  j["flow_allow_unconverged"] = d.boolean("flow.allow_unconverged");
  long long gentle_fly = 0,
            gentle_wall = 0;  // touch-downs, rolling and chatter rather than impacts
  for (const auto& r : records)
    if (r.normal_speed_m_s < 1.0) ++(r.surface == "flywheel" ? gentle_fly : gentle_wall);
  long long outliers = 0;  // a lump struck by the rotor reaches at most about twice the rim speed
  for (const auto& r : records)
    if (r.particle_speed_m_s > 3 * omega * g.tip_radius()) ++outliers;
  j["n_impacts_above_3x_rim_speed"] = outliers;
  if (outliers > 0)
    ctx.progress.warn(fmt::format(
        "transport {}: {} impacts of lumps faster than 3x the rim speed (numerical: lumps "
        "created overlapping, or a too large injection.timestep)",
        label, outliers));
  j["n_flywheel_contacts_below_1m_s"] = gentle_fly;
  j["n_wall_contacts_below_1m_s"] = gentle_wall;
  j["impacts_per_particle_mean"] = st.impacts_per_particle_mean;
  j["flywheel_impacts_per_particle_mean"] = st.flywheel_impacts_per_particle_mean;
  j["first_impact_time_mean_s"] = st.first_impact_time_mean_s;
  j["first_impact_time_note"] =
      "time from insertion to the first impact (any surface; sliding contacts are not impacts), over particles with one";
  j["particles_with_impact"] = st.particles_with_impact;
  j["cross_check"] = {{"rim_speed_m_s", omega * g.tip_radius()},
                      {"inlet_velocity_down_mean_m_s", v_in},
                      {"ballistic_approach_speed_m_s", v_approach},
                      {"struck_radius_m", r_struck},
                      {"rotor_speed_at_struck_radius_m_s", v_rotor},
                      {"ballistic_impact_speed_m_s", v_ballistic},
                      {"simulated_approach_speed_mean_m_s", fly.particle_speed.mean}};
  j["timestep_s"] = dt;
  j["wall_seconds"] = res.seconds;
  j["units"] = "SI; angles in degrees to the surface plane (90 = normal)";

  post::TransportMeta meta;
  meta.scalars = {{"rpm", rpm},
                  {"omega", omega},
                  {"rim_speed", omega * g.tip_radius()},
                  {"timestep", dt},
                  {"lump_diameter", diameter},
                  {"lump_density", density},
                  {"end_time", end[0]}};
  meta.units = {{"rpm", "1/min"},  {"omega", "rad/s"},     {"rim_speed", "m/s"},
                {"timestep", "s"}, {"lump_diameter", "m"}, {"lump_density", "kg/m^3"},
                {"end_time", "s"}};
  meta.geometry = {{"housing_height", g.height},
                   {"housing_width", g.width},
                   {"housing_depth", g.depth},
                   {"tip_radius", g.tip_radius()},
                   {"hub_radius", g.hub_radius()},
                   {"axis_x", g.axis_x},
                   {"axis_y", g.axis_height},
                   {"inlet_x", g.inlet_x},
                   {"inlet_size", g.inlet_size},
                   {"outlet_x", g.outlet_x},
                   {"outlet_size", g.outlet_size},
                   {"n_plates", static_cast<double>(g.n_plates)},
                   {"plate_thickness", g.plate_thickness}};

  // Outputs: transport/<label>/, each file complete or absent.
  const fs::path out = ctx.stage_dir / label;
  fs::create_directories(out);
  for (const char* f : {"summary.json", "impacts.csv", "contact_ends.csv", "transport.h5"})
    fs::remove(out / f);
  post::WriteTransportH5((out / "transport.h5").string(), records, st, insert_time, traj, meta,
                         ends);
  post::WriteImpactsCsv((out / "impacts.csv").string(), records);
  {
    std::ifstream in(work / "contact_ends.csv");
    std::stringstream ss;
    ss << in.rdbuf();
    jobs::atomic_write(out / "contact_ends.csv", ss.str());
  }
  engine::Command c;
  c.argv = {"/usr/bin/python3",
            (ctx.cfg.project_dir / "postprocess" / "plot_transport.py").string(),
            "--h5",
            (out / "transport.h5").string(),
            "--out",
            (out / "plots").string()};
  c.cwd = out;
  c.log = out / "plots.log";
  c.job = "transport/" + label + "/plots";
  ctx.runner.run(c);
  jobs::atomic_write(out / "summary.json", j.dump(2) + "\n");

  ctx.progress.info(fmt::format(
      "[transport] {}: {} lumps, {} exited, {} flywheel impacts ({:.2f} per lump): speed {:.1f} +- "
      "{:.1f} m/s, "
      "normal {:.1f} m/s, angle {:.1f} deg; {} wall impacts; {} sliding contacts (below {:g} m/s "
      "normal); first impact after {:.3f} s [{:.1f} s]",
      label, st.n_particles, std::llround(end[2]), fly.n, st.flywheel_impacts_per_particle_mean,
      fly.speed.mean, fly.speed.std, fly.normal_speed.mean, fly.angle.mean, wall.n,
      st.sliding_contacts, sliding_threshold, st.first_impact_time_mean_s, res.seconds));
  ctx.progress.info(fmt::format(
      "[transport] {}: {} first and {} later beater strikes (first {:.1f} m/s); lumps leave the "
      "beaters at {:.1f} +- {:.1f} m/s (lab); {} strikes reach the housing next, at {:.1f} +- "
      "{:.1f} m/s, {:.0f} deg, after {:.1f} ms",
      label, st.strikes.n_first, st.strikes.n_later, st.strikes.first_speed.mean,
      st.strikes.rebound_speed_lab.mean, st.strikes.rebound_speed_lab.std, st.strikes.n_to_housing,
      st.strikes.housing_speed.mean, st.strikes.housing_speed.std, st.strikes.housing_angle.mean,
      1e3 * st.strikes.flight_time.mean));
  ctx.progress.info(fmt::format(
      "[transport] {}: cross-check: rim speed {:.1f} m/s; ballistic estimate {:.1f} m/s (approach "
      "{:.1f} m/s, "
      "rotor {:.1f} m/s at r = {:.3f} m) vs simulated mean {:.1f} m/s",
      label, omega * g.tip_radius(), v_ballistic, v_approach, v_rotor, r_struck, fly.speed.mean));
  ctx.progress.info(fmt::format(
      "[transport] results: {}/{{impacts.csv, contact_ends.csv, transport.h5, summary.json, "
      "plots/*.png}}",
      out.string()));
}

}  // namespace mill
