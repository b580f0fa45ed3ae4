// In-mill breakage jobs: start states, the run, the record, the product.
#include "stages/breakage/in_mill_runs.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>

#include "engine/liggghts.h"
#include "geometry/free_flight.h"
#include "geometry/mill_geometry.h"
#include "jobs/job_store.h"
#include "jobs/output_checks.h"
#include "postprocess/in_mill.h"
#include "postprocess/lammps_dump.h"
#include "progress.h"
#include "stages/breakage/in_mill_animation.h"
#include "stages/breakage/lump_run.h"
#include "stages/breakage/summaries.h"
#include "stages/stage_util.h"

namespace mill::breakage {
namespace fs = std::filesystem;
using engine::num;

namespace {

using post::kPi;
constexpr double kG = 9.81;
// Bumped whenever the in-mill deck changes what a run gives (git log of this
// line: what each version changed).
constexpr int kInMillDeckVersion = 6;
// Facets of the flywheel's hub circle in the in-mill runs (see run_in_mill).
constexpr int kHubFacets = 24;
// The lump's free flight ends this many of its bounding radii from the
// nearest surface (breakage.in_mill.skip_free_flight).
constexpr double kFreeFlightClearance = 0.5;
// Neighbour skin in mean element radii: the turning flywheel forces a list
// build whenever its tips have moved half the skin (every ~25 steps at 0.3
// radii and 105 m/s); one radius builds 3 x less often (bench/README.md).
constexpr double kSkinRadii = 1.0;
// Most an element may move in one step, as a share of the smallest element
// radius (as for the single impacts).
constexpr double kStepMove = 0.1;

double omega_of(double rpm) { return rpm * 2 * kPi / 60.0; }

std::array<double, 3> vec3(const nlohmann::json& j) {
  return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()};
}

// The columns of in_mill.csv, in order.
const std::vector<std::string>& csv_columns() {
  static const std::vector<std::string> c = {"rpm",
                                             "label",
                                             "particle_id",
                                             "strike_time_s",
                                             "strike_speed_m_s",
                                             "strike_angle_deg",
                                             "n_elements",
                                             "n_pieces",
                                             "n_single",
                                             "largest_mass_fraction",
                                             "single_mass_fraction",
                                             "t10_percent",
                                             "t10_resolved",
                                             "broken_bond_fraction",
                                             "bonds_broken_at_strike",
                                             "bonds_broken_later",
                                             "flywheel_contacts",
                                             "housing_contacts",
                                             "housing_normal_speed_mean_m_s",
                                             "mass_rotor",
                                             "mass_housing",
                                             "mass_outlet",
                                             "mass_inlet",
                                             "wall_seconds",
                                             "stop_time_s",
                                             "stop_reason"};
  return c;
}

}  // namespace

bool is_in_mill_job(const JobSpec& job) { return job.inputs.value("mode", "") == "in_mill"; }

std::optional<std::size_t> in_mill_class(const JobSpec& job) {
  if (!job.inputs.contains("feed_class")) return std::nullopt;
  return job.inputs.at("feed_class").get<std::size_t>();
}

void plan_in_mill(const StageContext& ctx, double rpm, Plan& plan,
                  const config::FeedClassRuns* cls) {
  const auto& d = ctx.cfg.doc;
  const long k = d.integer("breakage.in_mill.lumps");
  if (k <= 0) return;
  const fs::path f =
      transport_dir(ctx.run_dir, rpm, cls ? std::optional<std::size_t>(cls->cls) : std::nullopt) /
      "impacts.csv";
  if (cls && !fs::exists(f))
    throw MissingInput(fmt::format(
        "in-mill breakage of the feed {} at {} (breakage.in_mill.lumps {}) needs {} (the "
        "stage-1 impacts of its {:.4g} mm lumps); make it with `orchestrate --case {} --stage "
        "transport --output {}`",
        cls->name, rpm_label(rpm), k, f.string(), 1e3 * cls->diameter_m, d.file(),
        ctx.run_dir.string()));
  const geometry::MillGeometry g = geometry::MillGeometry::from_config(d);
  post::RotorMotion rotor;
  rotor.omega_rad_s = omega_of(rpm);
  rotor.origin = {g.axis_x, g.axis_height, 0.0};
  rotor.gravity_m_s2 = kG;
  std::vector<post::StrikeStart> starts;
  try {
    starts = post::SelectStrikeStarts(post::ReadImpactsCsv(f.string()), static_cast<int>(k),
                                      d.real("breakage.in_mill.lead_time"), rotor,
                                      d.real("transport.sliding_threshold"));
  } catch (const post::PostError& e) {
    throw MissingInput(fmt::format("in-mill breakage at {} (breakage.in_mill.lumps {}): {}: {}",
                                   rpm_label(rpm), k, f.string(), e.what()));
  }
  const bool gas = d.boolean("breakage.in_mill.gas");
  std::vector<std::string> keys = {"lump.",
                                   "mill.",
                                   "breakage.timestep",
                                   "breakage.dump_interval",
                                   "breakage.in_mill.duration",
                                   "breakage.in_mill.lead_time",
                                   "breakage.in_mill.gas",
                                   "breakage.in_mill.early_stop",
                                   "breakage.in_mill.skip_free_flight",
                                   "breakage.in_mill.neighbour_bins",
                                   "transport.sliding_threshold"};
  if (gas)
    for (const char* p : {"gas.", "flow.", "sample."}) keys.push_back(p);
  nlohmann::json base = case_keys(d, keys);
  // The adaptive step is an input only when in effect: runs with the fixed
  // step keep their job ids.
  if (adaptive_step_on(d)) base["breakage.adaptive_step"] = true;
  base["ore"] = config::ore_keys(ctx.cfg.ore);
  base["bond"] = bond_json(bond_params_for(ctx.cfg, ctx.run_dir), BondNames::job);
  base["in_mill_deck_version"] = kInMillDeckVersion;
  base["mode"] = "in_mill";
  base["rpm"] = rpm;
  if (cls) {
    // The class's lump: its representative size, the element count of the
    // calibration's element size (config/feed_classes.h).
    base["lump.diameter"] = cls->diameter_m;
    base["lump.n_elements"] = cls->n_elements;
    base["feed_class"] = cls->cls;
  }
  const std::string prefix = cls ? fmt::format("{}_c{}", rpm_label(rpm), cls->cls) : rpm_label(rpm);
  // A class lump off the calibration's element size (at feed.class_element_cap,
  // or the packing's fewest) says so in its plan line; a costly one says what
  // would cap it.
  std::string off_size;
  if (cls && std::abs(cls->element_size - 1) > 0.01)
    off_size = fmt::format(" (elements {:.2f} x the calibration's{})", cls->element_size,
                           cls->element_size > 1 ? ": feed.class_element_cap" : "");
  else if (const long n_ref = d.integer("lump.n_elements"); cls && cls->n_elements > config::kCostlyClassLumpFactor * n_ref)
    off_size = fmt::format(" ({:.0f} x lump.n_elements: feed.class_element_cap would cap it, with coarser elements)",
                           static_cast<double>(cls->n_elements) / static_cast<double>(n_ref));
  const std::string lumps = cls ? fmt::format(" feed {}, {:.4g} mm lump of {} elements{}:", cls->name,
                                              1e3 * cls->diameter_m, cls->n_elements, off_size)
                                : std::string(":");
  for (size_t i = 0; i < starts.size(); ++i) {
    const auto& s = starts[i];
    nlohmann::json in = base;
    in["repeat"] = static_cast<int>(i);
    in["particle_id"] = s.particle_id;
    in["strike_time_s"] = s.strike_time_s;
    in["start_time_s"] = s.start_time_s;
    in["position"] = s.position;
    in["velocity"] = s.velocity;
    in["rotor_angle_rad"] = s.rotor_angle_rad;
    in["strike_speed_m_s"] = s.strike_speed_m_s;
    in["strike_normal_speed_m_s"] = s.strike_normal_speed_m_s;
    in["strike_angle_deg"] = s.strike_angle_deg;
    // The run the report animates: only its inputs (and id) change.
    if (const nlohmann::json a = animation_inputs(d, plan); !a.is_null()) in["animation"] = a;
    plan.jobs.push_back(
        {fmt::format("{}_mill_p{}", prefix, s.particle_id), in,
         fmt::format(
             "{} in-mill{} lump {} of stage 1 from {:g} ms before its flywheel strike at {:.1f} "
             "m/s ({:.0f} deg), {:g} ms in the mill{}",
             rpm_label(rpm), lumps, s.particle_id, 1e3 * d.real("breakage.in_mill.lead_time"),
             s.strike_speed_m_s, s.strike_angle_deg, 1e3 * d.real("breakage.in_mill.duration"),
             in.contains("animation") ? fmt::format(", animated ({} frames)", kAnimationFrames)
                                      : std::string())});
  }
}

namespace {

// The sampled gas field of the rotor speed when breakage.in_mill.gas is set
// (else none), or MissingInput naming the command that makes it.
fs::path gas_field(const StageContext& ctx, const std::string& label, double rpm) {
  const auto& d = ctx.cfg.doc;
  if (!d.boolean("breakage.in_mill.gas")) return {};
  const fs::path field_file = ctx.run_dir / "sample" / rpm_label(rpm) / "field.h5";
  if (!fs::exists(field_file))
    throw MissingInput(fmt::format(
        "in-mill breakage ({}) needs {} (the sampled gas field at {:g} rpm, breakage.in_mill.gas: "
        "true); make it with "
        "`orchestrate --case {} --stage sample --output {}`, or set breakage.in_mill.gas: false",
        label, field_file.string(), rpm, d.file(), ctx.run_dir.string()));
  return field_file;
}

// The mill of a run, its flywheel turned to the job's angle at the start.
geometry::MillGeometry run_geometry(const config::Document& d, const nlohmann::json& in) {
  geometry::MillGeometry g = geometry::MillGeometry::from_config(d);
  g.rotor_angle = in.at("rotor_angle_rad").get<double>();
  // The hub circle drawn with kHubFacets instead of 96 facets: chosen when
  // the impact recorder tested every element against every facet (816
  // facets took half the run time; its pre-filter now tests only the facets
  // near an element); the polygon departs from the circle by
  // r (1 - cos(pi / kHubFacets)), 1.3 mm on a 0.3 m hub.
  g.arc_segments = kHubFacets;
  return g;
}

// The step bound of a run: the fastest an element is expected to move (its
// start speed plus twice the rim speed: flung by a beater, elastic at most)
// and the step that keeps it under kStepMove of the smallest element radius.
struct StepBound {
  double v_max = 0;
  double dt_speed = 0;
};

// The step bound; throws naming breakage.timestep when the case's step is larger.
StepBound step_bound(const config::Document& d, const geometry::MillGeometry& g, const LumpRun& lr,
                     const std::array<double, 3>& v0, double omega) {
  StepBound b;
  b.v_max = std::hypot(v0[0], v0[1], v0[2]) + 2 * omega * g.tip_radius();
  b.dt_speed = kStepMove * lr.r_min / b.v_max;
  const double dt_given = d.real("breakage.timestep");
  if (dt_given > b.dt_speed)
    throw std::runtime_error(
        fmt::format("{}: at up to {:.0f} m/s (start speed plus twice the rim speed) an element "
                    "moves {:.3g} m per step of {:g} s, "
                    "more than {:g} of the smallest element radius ({:.3g} m); expected "
                    "breakage.timestep <= {:.3g} s, or 0 "
                    "(automatic)",
                    d.where("breakage.timestep"), b.v_max, b.v_max * dt_given, dt_given, kStepMove,
                    lr.r_min, b.dt_speed));
  return b;
}

// The first neighbour bin size: the box holds the whole mill, so the bins
// start large enough that it holds at most breakage.in_mill.neighbour_bins.
double first_bin(const config::Document& d, const geometry::MillGeometry& g, const LumpRun& lr) {
  const double margin = 0.05;
  const double box_volume =
      (g.width + 2 * margin) * (g.height + 2 * margin) * (g.depth + 2 * margin);
  return std::max(
      4.0 * lr.lump.mean_radius,
      std::cbrt(box_volume / static_cast<double>(d.integer("breakage.in_mill.neighbour_bins"))));
}

// The -var pairs of in_mill.in.tmpl: the mill (its STL files), the lump's
// start, the gas, the time and neighbour settings, and the lump's own.
std::vector<std::pair<std::string, std::string>> in_mill_vars(
    const StageContext& ctx, const nlohmann::json& in, const geometry::MillGeometry& g,
    const geometry::StlSet& stl, const LumpRun& lr, const fs::path& field_file,
    const StepBound& step) {
  const auto& d = ctx.cfg.doc;
  const double omega = omega_of(in.at("rpm").get<double>());
  const auto x0 = vec3(in.at("position")), v0 = vec3(in.at("velocity"));
  const bool gas = !field_file.empty();
  std::vector<std::pair<std::string, std::string>> v = {
      {"housing_stl", fs::absolute(stl.housing).string()},
      {"flywheel_stl", fs::absolute(stl.flywheel).string()},
      {"axis_x", num(g.axis_x)},
      {"axis_y", num(g.axis_height)},
      {"omega", num(omega)},
      {"rim_speed", num(std::fabs(omega) * g.tip_radius())},
      {"g", num(kG)},
      {"x0", num(x0[0])},
      {"y0", num(x0[1])},
      {"z0", num(x0[2])},
      {"vx0", num(v0[0])},
      {"vy0", num(v0[1])},
      {"vz0", num(v0[2])},
      {"gas", gas ? "1" : "0"},
      {"field_file", gas ? fs::absolute(field_file).string() : std::string("none")},
      {"viscosity", num(d.real("gas.viscosity"))},
      {"tip_radius", num(g.tip_radius())},
      {"housing_top", num(g.height)},
      {"t_end", num(d.real("breakage.in_mill.duration") - in.value("free_flight_skipped_s", 0.0))},
      {"early_stop", d.boolean("breakage.in_mill.early_stop") ? "1" : "0"},
      {"stop_margin", num(in.at("lump.diameter").get<double>())},
      {"dt", num(d.real("breakage.timestep"))},
      {"dt_speed", num(step.dt_speed)},
      {"adaptive_step", adaptive_step_on(d) ? "1" : "0"},
      {"skin", num(kSkinRadii * lr.lump.mean_radius)},
      {"binsize", num(first_bin(d, g, lr))},
      {"dump_interval", num(d.real("breakage.dump_interval"))},
      {"frame_interval", num(frame_interval(in))}};
  for (const auto& kv : lump_deck_vars(ctx, lr)) v.push_back(kv);
  return v;
}

// Where the engine run starts: the job's start, or with
// breakage.in_mill.skip_free_flight (and no animation frames) the end of the
// lump's free flight from it (geometry/free_flight.h), at most lead_time
// later: the job's inputs with that position, velocity, rotor angle and
// free_flight_skipped_s.
struct DeckStart {
  nlohmann::json inputs;
  double skipped = 0;  // s
  double gap = 0;      // m, the lump's bounding sphere to the nearest surface at the deck's start
};

DeckStart deck_start(const config::Document& d, const nlohmann::json& in, const LumpRun& lr) {
  DeckStart s;
  s.inputs = in;
  const geometry::MillGeometry g = run_geometry(d, in);
  geometry::FreeFlightQuery q;
  q.x0 = vec3(in.at("position"));
  q.v0 = vec3(in.at("velocity"));
  q.gravity = {0.0, -kG, 0.0};
  q.radius = lr.lump.outer_radius;
  q.clearance = kFreeFlightClearance * lr.lump.outer_radius;
  // Without the skip, the flight looked at is none: the gap at the start
  // only. The animated run keeps its whole lead time: the report shows the
  // lump coming to the beater.
  q.horizon = d.boolean("breakage.in_mill.skip_free_flight") && frame_interval(in) <= 0
                  ? d.real("breakage.in_mill.lead_time")
                  : 0.0;
  q.axis_origin = g.axis_centre();
  q.omega = omega_of(in.at("rpm").get<double>());
  const geometry::FreeFlight f =
      geometry::free_flight_time(geometry::housing_surface(g), geometry::flywheel_surface(g), q);
  s.gap = f.gap_at_time;
  if (f.time <= 0) return s;
  const double t = f.time;
  s.skipped = t;
  nlohmann::json x = nlohmann::json::array(), v = nlohmann::json::array();
  for (int k = 0; k < 3; ++k) {
    x.push_back(q.x0[k] + q.v0[k] * t + 0.5 * q.gravity[k] * t * t);
    v.push_back(q.v0[k] + q.gravity[k] * t);
  }
  s.inputs["position"] = x;
  s.inputs["velocity"] = v;
  s.inputs["rotor_angle_rad"] = in.at("rotor_angle_rad").get<double>() + q.omega * t;
  s.inputs["free_flight_skipped_s"] = t;
  return s;
}

// Walls are impenetrable: an element beside the housing, between floor and
// roof, passed through a side wall between steps (elements that left
// through the openings in the floor or the roof fly on outside). Throws then.
void check_inside_walls(const LumpRunResult& a, const geometry::MillGeometry& g, const LumpRun& lr,
                        const std::string& label) {
  const long through =
      std::count_if(a.snap.elements.begin(), a.snap.elements.end(), [&](const post::Element& e) {
        return e.x[1] >= 0 && e.x[1] <= g.height &&
               (std::abs(e.x[0]) > 0.5 * g.width || std::abs(e.x[2]) > 0.5 * g.depth);
      });
  if (through > 0)
    throw std::runtime_error(
        fmt::format("{}: {} of {} elements ended outside the housing's side walls: they passed "
                    "through a wall between steps, the run is invalid; log: {}",
                    label, through, a.snap.elements.size(), (lr.work / "liggghts.log").string()));
}

// The record of a run: its contacts, the bonds broken at the strike and
// later, where the mass ended, when and why the run stopped.
struct MillRecord {
  post::InMillStop stop;
  post::BreakSplit split;
  post::ContactTally fly, wall;
  post::MassPlaces mass;
  double element_mass = 0;  // kg, all elements
};

MillRecord read_record(const LumpRun& lr, const LumpRunResult& a, const geometry::MillGeometry& g) {
  MillRecord r;
  r.stop = post::ReadInMillStop((lr.work / "liggghts.log").string());
  const auto contacts = post::ReadImpactsCsv((lr.work / "impacts.csv").string());
  r.split = post::SplitBreaks(post::ReadBreakLog((lr.work / "breaks.txt").string()), contacts);
  r.fly = post::TallyContacts(contacts, "flywheel");
  r.wall = post::TallyContacts(contacts, "housing");
  post::MillRegions regions;
  regions.axis_x = g.axis_x;
  regions.axis_y = g.axis_height;
  regions.tip_radius = g.tip_radius();
  regions.half_width_z = 0.5 * g.plate_width;
  regions.floor_y = 0;
  regions.roof_y = g.height;
  r.mass = post::LocateMass(a.snap.elements, regions);
  for (const auto& e : a.snap.elements) r.element_mass += e.mass;
  return r;
}

// in_mill.json: result.json's keys (lump_result_json in `j`) and the run's
// own: its start, the strike, the record.
void add_in_mill_keys(nlohmann::json& j, const config::Document& d, const nlohmann::json& in,
                      const MillRecord& r) {
  const auto tally = [](const post::ContactTally& t) {
    return nlohmann::json{{"contacts", t.n},
                          {"elements", t.n_elements},
                          {"normal_speed_mean_m_s", t.normal_speed_mean_m_s},
                          {"normal_speed_max_m_s", t.normal_speed_max_m_s}};
  };
  const auto when = [](double t) { return t >= 0 ? nlohmann::json(t) : nlohmann::json(nullptr); };
  j["mode"] = "in_mill";
  j["rpm"] = in.at("rpm").get<double>();
  if (in.contains("feed_class")) j["feed_class"] = in.at("feed_class");
  j["start"] = {
      {"particle_id", in.at("particle_id")},
      {"time_in_transport_s", in.at("start_time_s")},
      {"strike_time_in_transport_s", in.at("strike_time_s")},
      {"position_m", in.at("position")},
      {"velocity_m_s", in.at("velocity")},
      {"rotor_angle_deg", in.at("rotor_angle_rad").get<double>() * 180 / kPi},
      {"lead_time_s", d.real("breakage.in_mill.lead_time")},
      {"note",
       "the transport lump's state at its first flywheel strike, backed off ballistically (gravity "
       "only) by lead_time"}};
  j["strike"] = {{"speed_m_s", in.at("strike_speed_m_s").get<double>()},
                 {"normal_speed_m_s", in.at("strike_normal_speed_m_s")},
                 {"angle_deg", in.at("strike_angle_deg").get<double>()}};
  j["duration_s"] = d.real("breakage.in_mill.duration");
  j["stop"] = {
      {"time_s", r.stop.time_s},
      {"reason", r.stop.reason},
      {"early_stop", d.boolean("breakage.in_mill.early_stop")},
      {"definition",
       "work_done: at the end of a chunk an element had touched the flywheel or the housing, "
       "no element was within the tip radius plus one lump diameter of the axis or would get "
       "there within a chunk at its speed towards the axis, and every element whose latest "
       "flywheel contact came after its latest housing contact had left the housing; t_end: "
       "the run lasted duration_s"}};
  j["gas"] = d.boolean("breakage.in_mill.gas");
  j["element_mass_kg"] = r.element_mass;
  j["bonds_broken_at_strike"] = r.split.at_strike;
  j["bonds_broken_later"] = r.split.later;
  j["first_flywheel_contact_s"] = when(r.split.first_flywheel_contact_s);
  j["first_housing_contact_s"] = when(r.split.first_housing_contact_s);
  j["strike_definition"] =
      "at the strike: broken from the lump's first element contact with the flywheel until the "
      "first element "
      "contact with the housing; later: after it (housing impacts and later strikes)";
  j["flywheel"] = tally(r.fly);
  j["housing"] = tally(r.wall);
  j["mass_places"] = {{"rotor", r.mass.rotor},
                      {"housing", r.mass.housing},
                      {"outlet", r.mass.outlet},
                      {"inlet", r.mass.inlet}};
}

// The run's summary line.
std::string in_mill_line(const nlohmann::json& in, const LumpRunResult& a, const MillRecord& r,
                         double seconds) {
  const auto& s = a.result.summary;
  return fmt::format(
      "lump {} struck at {:.1f} m/s ({:.0f} deg): {} pieces ({} single), largest {:.1f}%, t10 "
      "{:.1f}%{}; bonds broken "
      "{:.1f}% ({} at the strike, {} later); {} flywheel and {} housing contacts; mass in the "
      "rotor region {:.0f}%, "
      "housing {:.0f}%, below the floor {:.0f}%; stopped at {:.2f} ms ({}) [{:.1f} s]",
      in.at("particle_id").get<long long>(), in.at("strike_speed_m_s").get<double>(),
      in.at("strike_angle_deg").get<double>(), s.n_pieces, s.n_single,
      100 * s.largest_mass_fraction, s.t10_percent, s.t10_resolved ? "" : " (unresolved)",
      100 * s.broken_bond_fraction, r.split.at_strike, r.split.later, r.fly.n, r.wall.n,
      100 * r.mass.rotor, 100 * r.mass.housing, 100 * r.mass.outlet, 1e3 * r.stop.time_s,
      r.stop.reason, seconds);
}

}  // namespace

std::string run_in_mill(StageContext& ctx, const JobSpec& job, const fs::path& out_dir) {
  const auto& d = ctx.cfg.doc;
  const auto& in = job.inputs;
  const std::string& label = job.label;
  const double rpm = in.at("rpm").get<double>();
  const int repeat = in.at("repeat").get<int>();
  const fs::path field_file = gas_field(ctx, label, rpm);

  // A feed class's lump: its own diameter and element count, cached apart.
  std::optional<LumpSpec> spec;
  if (in.contains("feed_class")) {
    spec = lump_spec(ctx.cfg);
    spec->diameter = in.at("lump.diameter").get<double>();
    spec->n_elements = in.at("lump.n_elements").get<long>();
    spec->tag = fmt::format("_d{:.4g}mm", 1e3 * spec->diameter);
  }
  const LumpRun lr = prepare_lump_run(ctx, repeat, out_dir, label, 1, spec ? &*spec : nullptr);
  // The engine run starts where the lump's free flight ends (or at the
  // job's start): `deck` is the job's inputs with that start.
  const DeckStart start = deck_start(d, in, lr);
  const nlohmann::json& deck = start.inputs;
  const geometry::MillGeometry g = run_geometry(d, deck);
  fs::create_directories(lr.work);
  const geometry::StlSet stl = geometry::write_stl_set(g, lr.work / "stl");
  const StepBound step = step_bound(d, g, lr, vec3(deck.at("velocity")), omega_of(rpm));

  engine::DeckRun run;
  run.deck = ctx.cfg.project_dir / "liggghts_inputs" / "in_mill.in.tmpl";
  run.workdir = lr.work;
  run.np = ctx.opts.np;
  run.job = "breakage/" + label;
  run.vars = in_mill_vars(ctx, deck, g, stl, lr, field_file, step);
  if (start.skipped > 0)
    ctx.progress.info(fmt::format(
        "[breakage] {}: free flight to {:.3f} ms of the {:g} ms lead time skipped (the lump "
        "{:.1f} mm from the nearest surface then)",
        label, 1e3 * start.skipped, 1e3 * d.real("breakage.in_mill.lead_time"), 1e3 * start.gap));
  const engine::Result res = engine::run_deck(ctx.runner, run, ctx.progress, label);

  // Fragments, judged at the strike's relative speed (its specific energy).
  const double a_strike = in.at("strike_angle_deg").get<double>();
  const LumpRunResult a = analyse_lump_run(
      ctx, lr, {in.at("strike_speed_m_s").get<double>(), std::clamp(a_strike, 0.0, 90.0), repeat},
      res.seconds, label);
  check_inside_walls(a, g, lr, label);
  MillRecord record;
  try {
    record = read_record(lr, a, g);
  } catch (const post::PostError& e) {
    throw std::runtime_error(fmt::format("{}: {}", label, e.what()));
  }

  // The record's times on the job's clock (from lead_time before the strike).
  const auto shift = [&](double& t) {
    if (t >= 0) t += start.skipped;
  };
  shift(record.stop.time_s);
  shift(record.split.first_flywheel_contact_s);
  shift(record.split.first_housing_contact_s);

  if (is_animated(job))
    render_animation(ctx, job, lr.work, lr.work / "stl", g, out_dir,
                     d.real("breakage.in_mill.lead_time") - start.skipped);

  nlohmann::json j = lump_result_json(lr, a, res.seconds);
  add_in_mill_keys(j, d, in, record);
  j["start"]["free_flight_skipped_s"] = start.skipped;
  j["start"]["deck_start"] = {
      {"position_m", deck.at("position")},
      {"velocity_m_s", deck.at("velocity")},
      {"rotor_angle_deg", deck.at("rotor_angle_rad").get<double>() * 180 / kPi},
      {"gap_to_mill_m", start.gap},
      {"note",
       "the engine run starts free_flight_skipped_s after the start above: the lump's free "
       "flight (one rigid body under gravity, no surface within half its bounding radius) is "
       "not simulated (breakage.in_mill.skip_free_flight); the times of this file count from "
       "the start above, those of run/ (impacts.csv, ledger.csv) from the engine run's"}};
  jobs::atomic_write(out_dir / "in_mill.json", j.dump(2) + "\n");
  write_lump_outputs(out_dir, a, j);
  return in_mill_line(in, a, record, res.seconds);
}

std::string damaged_in_mill_outputs(const JobSpec& job, const fs::path& dir) {
  if (auto r = damaged_lump_outputs(dir); !r.empty()) return r;
  if (is_animated(job))
    if (auto r = damaged_animation(dir); !r.empty()) return r;
  return jobs::check_json(dir / "in_mill.json");
}

std::map<double, nlohmann::json> write_in_mill_results(StageContext& ctx,
                                                       const std::vector<JobSpec>& jobs) {
  const jobs::JobStore store(ctx.stage_dir);
  const auto edges = ctx.cfg.doc.reals("breakage.size_fraction_edges");
  struct Acc {
    int n = 0;
    double lump_mm = 0;              // the runs' lump diameter
    std::optional<std::size_t> cls;  // the feed class whose runs these are
    std::vector<double> frac;
    double single = 0, largest = 0, t10 = 0;
    bool resolved = true;
    long long at_strike = 0, later = 0;
    double rotor = 0, housing = 0, outlet = 0, inlet = 0;
  };
  std::map<double, Acc> by_rpm;
  std::string csv;
  for (const auto& c : csv_columns()) csv += (csv.empty() ? "" : ",") + c;
  csv += "\n";
  for (const auto& job : jobs) {
    if (!is_in_mill_job(job)) continue;
    const fs::path jd = store.job_dir(job.label);
    std::ifstream jf(jd / "in_mill.json");
    const auto j = nlohmann::json::parse(jf);
    const double rpm = job.inputs.at("rpm").get<double>();
    Acc& a = by_rpm[rpm];
    if (a.frac.empty()) {
      a.frac.assign(edges.size() - 1, 0.0);
      a.lump_mm = 1000 * job.inputs.value("lump.diameter", ctx.cfg.doc.real("lump.diameter"));
      a.cls = in_mill_class(job);
    }
    for (const auto& f : post::ReadFractionsCsv((jd / "fractions.csv").string()))
      if (f.index < static_cast<int>(a.frac.size())) a.frac[f.index] += f.mass_fraction;
    ++a.n;
    a.single += j.at("single_mass_fraction").get<double>();
    a.largest += j.at("largest_mass_fraction").get<double>();
    a.t10 += j.at("t10_percent").get<double>();
    a.resolved = a.resolved && j.at("t10_resolved").get<bool>();
    a.at_strike += j.at("bonds_broken_at_strike").get<long long>();
    a.later += j.at("bonds_broken_later").get<long long>();
    const auto& m = j.at("mass_places");
    a.rotor += m.at("rotor").get<double>();
    a.housing += m.at("housing").get<double>();
    a.outlet += m.at("outlet").get<double>();
    a.inlet += m.at("inlet").get<double>();
    csv += fmt::format(
        "{:g},{},{},{:.9g},{:.6g},{:.6g},{},{},{},{:.9g},{:.9g},{:.6g},{},{:.9g},{},{},{},{},{:.6g}"
        ",{:.6g},"
        "{:.6g},{:.6g},{:.6g},{:.3f},{:.9g},{}\n",
        rpm, job.label, j.at("start").at("particle_id").get<long long>(),
        j.at("start").at("strike_time_in_transport_s").get<double>(),
        j.at("strike").at("speed_m_s").get<double>(), j.at("strike").at("angle_deg").get<double>(),
        j.at("lump").at("elements").get<long>(), j.at("n_pieces").get<long long>(),
        j.at("n_single").get<long long>(), j.at("largest_mass_fraction").get<double>(),
        j.at("single_mass_fraction").get<double>(), j.at("t10_percent").get<double>(),
        j.at("t10_resolved").get<bool>() ? 1 : 0, j.at("broken_bond_fraction").get<double>(),
        j.at("bonds_broken_at_strike").get<long long>(),
        j.at("bonds_broken_later").get<long long>(),
        j.at("flywheel").at("contacts").get<long long>(),
        j.at("housing").at("contacts").get<long long>(),
        j.at("housing").at("normal_speed_mean_m_s").get<double>(), m.at("rotor").get<double>(),
        m.at("housing").get<double>(), m.at("outlet").get<double>(), m.at("inlet").get<double>(),
        j.at("wall_seconds").get<double>(), j.at("stop").at("time_s").get<double>(),
        j.at("stop").at("reason").get<std::string>());
  }
  std::map<double, nlohmann::json> out;
  if (by_rpm.empty()) return out;
  jobs::atomic_write(ctx.stage_dir / "in_mill.csv", csv);
  for (auto& [rpm, a] : by_rpm) {
    const double n = a.n;
    for (auto& f : a.frac) f /= n;
    const long long broken = a.at_strike + a.later;
    nlohmann::json e = {
        {"lumps", a.n},
        {"fraction_mass", a.frac},
        {"fully_shredded_mass_fraction", a.single / n},
        {"largest_piece_mass_fraction", a.largest / n},
        {"t10_percent", a.t10 / n},
        {"t10_resolved", a.resolved},
        {"bonds_broken_at_strike_fraction",
         broken > 0 ? nlohmann::json(static_cast<double>(a.at_strike) / broken)
                    : nlohmann::json(nullptr)},
        {"mass_places",
         {{"rotor", a.rotor / n},
          {"housing", a.housing / n},
          {"outlet", a.outlet / n},
          {"inlet", a.inlet / n}}},
        {"duration_s", ctx.cfg.doc.real("breakage.in_mill.duration")},
        {"early_stop", ctx.cfg.doc.boolean("breakage.in_mill.early_stop")},
        {"lump_diameter_mm", a.lump_mm},
        {"feed_class", a.cls ? nlohmann::json(*a.cls) : nlohmann::json(nullptr)},
        {"note",
         a.cls ? "bonded lumps of lump.diameter's feed class (its representative size, "
                 "lump_diameter_mm) run in the turning mill from their first flywheel strike in "
                 "stage 1: the strike, the flight and the housing impacts (breakage/in_mill.csv "
                 "per run)"
               : "bonded lumps run in the turning mill from their first flywheel strike in stage "
                 "1: the strike, the flight and the housing impacts (breakage/in_mill.csv per "
                 "run)"}};
    e.update(passing_json(sieves_mm(edges, a.lump_mm), a.frac));
    out[rpm] = e;
    ctx.progress.info(fmt::format(
        "[breakage] in-mill product at {:g} rpm ({} lump{}): fully shredded {:.1f}% of the mass, "
        "largest piece {:.1f}%, "
        "t10 {:.1f}%{}, {} of the broken bonds broke at the beater strike",
        rpm, a.n, a.n == 1 ? "" : "s", 100 * a.single / n, 100 * a.largest / n, a.t10 / n,
        a.resolved ? "" : " (unresolved)",
        broken > 0 ? fmt::format("{:.0f}%", 100.0 * a.at_strike / broken) : std::string("none")));
  }
  return out;
}

}  // namespace mill::breakage
