// Stage 'transport': ore lumps through the sampled flow.
#include "stages/transport_stage.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <numeric>
#include <optional>
#include <sstream>

#include "config/case_config.h"
#include "config/feed_classes.h"
#include "engine/liggghts.h"
#include "geometry/mill_geometry.h"
#include "jobs/job_store.h"
#include "jobs/output_checks.h"
#include "postprocess/flow_field_io.h"
#include "postprocess/impact_stats.h"
#include "postprocess/population_balance.h"
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
  double diameter = 0;        // m
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
  // (diameter: the largest lump's; the spots and their spacing are its.)
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
std::string insert_commands(const std::vector<Lump>& lumps, double density, double dt) {
  std::ostringstream o;
  o << "# Written by orchestrate (transport stage): one block per lump.\n";
  long long step = 0;
  for (size_t i = 0; i < lumps.size(); ++i) {
    const Lump& l = lumps[i];
    o << fmt::format("# lump {} at t = {:.6g} s\n", i + 1, l.t)
      << fmt::format("create_atoms 3 single {} {} {} units box\n", num(l.x[0]), num(l.x[1]),
                     num(l.x[2]))
      << "group lump_new type 3\n"
      << fmt::format("set group lump_new diameter {} density {}\n", num(l.diameter), num(density))
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

// The job of feed class k's lumps at a rotor speed: "rpm2000_class1".
std::string class_label(double rpm, std::size_t k) {
  return fmt::format("{}_class{}", rpm_label(rpm), k);
}

// The feed classes whose lumps go through a job's run.
std::vector<std::size_t> feed_classes_of(const JobSpec& job) {
  std::vector<std::size_t> k;
  for (const auto& c : job.inputs.value("feed_classes", nlohmann::json::array()))
    k.push_back(c.at("class").get<std::size_t>());
  return k;
}

// Where a job's outputs go (transport_dir): injection.lump_diameter's lumps'.
fs::path output_dir(const StageContext& ctx, const JobSpec& job) {
  return transport_dir(ctx.run_dir, job.inputs.at("rotor.rpm").get<double>());
}

}  // namespace

Plan TransportStage::plan(const StageContext& ctx) const {
  Plan p;
  const auto& d = ctx.cfg.doc;
  // With a feed: the lumps of every feed class that gets a run of its own go
  // through the mill in the run of injection.lump_diameter's lumps.
  nlohmann::json classes = nlohmann::json::array();
  std::string sizes = fmt::format("{:g} mm", d.real("injection.lump_diameter") * 1e3);
  if (ctx.cfg.feed)
    for (const auto& c : config::plan_feed_classes(d, *ctx.cfg.feed)) {
      if (!c.transport) continue;
      classes.push_back({{"class", c.cls}, {"diameter_m", c.diameter_m}});
      sizes += fmt::format(", {:.4g} mm (feed {})", c.diameter_m * 1e3, c.name);
    }
  for (double rpm : d.reals("rotor.rpm")) {
    nlohmann::json in =
        case_keys(d, {"mill.", "gas.", "flow.", "sample.", "injection.", "transport."});
    in["rotor.rpm"] = rpm;
    in["ore"] = config::ore_keys(ctx.cfg.ore);
    in["deck_version"] = kDeckVersion;
    if (!classes.empty()) in["feed_classes"] = classes;
    p.jobs.push_back({rpm_label(rpm), in,
                      fmt::format("{} lumps {}of {} through the mill at {}",
                                  d.integer("injection.n_lumps"), classes.empty() ? "" : "each ",
                                  sizes, rpm_label(rpm))});
  }
  return p;
}

// transport/<label>/{impacts.csv, contact_ends.csv, transport.h5, summary.json}
// and the same in transport/class_<k>/<rpm label>/ for each feed class of the
// run: exist and read.
std::string TransportStage::damaged_outputs(const StageContext& ctx, const JobSpec& job) const {
  std::vector<fs::path> dirs = {output_dir(ctx, job)};
  const double rpm = job.inputs.at("rotor.rpm").get<double>();
  for (std::size_t k : feed_classes_of(job)) dirs.push_back(transport_dir(ctx.run_dir, rpm, k));
  for (const auto& out : dirs) {
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
  }
  return "";
}

namespace {

// summary.json's "feed_class" of a class run: the class and its lumps.
nlohmann::json class_json(const StageContext& ctx, std::size_t k) {
  const config::Feed& f = ctx.cfg.feed.value();
  const post::SizeClasses c = post::SizeClassesFromSieves(f.sizes_mm);
  return {{"class", k},
          {"name", c.name(k)},
          {"lower_mm", c.lower_mm(k)},
          {"upper_mm", c.upper_mm[k]},
          {"mass_fraction", f.mass_fractions[c.size() - 1 - k]},
          {"lump_diameter_mm", post::RepresentativeSize(c, k)}};
}

// The sampled gas field of the rotor speed, or MissingInput naming the
// command that makes it.
fs::path sampled_field(const StageContext& ctx, const std::string& label, double rpm) {
  const fs::path field_file = ctx.run_dir / "sample" / label / "field.h5";
  if (!fs::exists(field_file))
    throw MissingInput(fmt::format(
        "stage transport ({}) needs {} (the sampled gas field at {:g} rpm); make it with "
        "`orchestrate --case {} --stage sample --output {}` (after --stage flow)",
        label, field_file.string(), rpm, ctx.cfg.doc.file(), ctx.run_dir.string()));
  return field_file;
}

// What one transport run shares between its steps: the settings, the mill,
// the lumps injected, and what the deck left (end.txt, wall time).
// One lump size of a run: injection.lump_diameter's, or a feed class's.
struct LumpSize {
  double diameter = 0;                  // m
  std::optional<std::size_t> feed_class;  // none for injection.lump_diameter
};

struct TransportRun {
  std::string label;
  double rpm = 0, omega = 0;         // 1/min, rad/s
  double diameter = 0, density = 0;  // the largest lump's, m; the ore's, kg/m^3
  std::vector<LumpSize> sizes;       // the run's lump sizes (one: no feed)
  double dt = 0;                     // s
  geometry::MillGeometry g;
  fs::path field_file, work;
  std::vector<Lump> lumps;
  std::array<double, 4> end{};  // end time, remaining, exited, masked drag steps
  double wall_seconds = 0;
};

// The -var pairs of transport.in.tmpl: the mill's STL files and box, the
// rotor, the gas field, the injection, the output intervals and the ore.
std::vector<std::pair<std::string, std::string>> transport_vars(const StageContext& ctx,
                                                                const TransportRun& r,
                                                                const geometry::StlSet& stl) {
  const auto& d = ctx.cfg.doc;
  const geometry::MillGeometry& g = r.g;
  const double margin = std::max(0.05, r.diameter);
  const double dt = r.dt;
  const auto steps = [dt](double seconds) {
    return std::to_string(std::max(0LL, std::llround(seconds / dt)));
  };
  return {{"housing_stl", fs::absolute(stl.housing).string()},
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
          {"omega", num(r.omega)},
          {"field_file", fs::absolute(r.field_file).string()},
          {"viscosity", num(d.real("gas.viscosity"))},
          {"insert_file", "insert.in"},
          {"n_lumps", std::to_string(r.lumps.size())},
          {"nsizes", std::to_string(r.sizes.size())},
          {"t_limit", num(d.real("injection.time_limit"))},
          {"dt", num(dt)},
          {"skin", num(std::max(0.25 * r.diameter, 0.002))},
          {"traj_every", steps(d.real("transport.trajectory_interval"))},
          {"vtk_every", steps(d.real("transport.vtk_interval"))},
          {"density", num(r.density)},
          {"E", num(ctx.cfg.ore.real("youngs_modulus"))},
          {"nu", num(ctx.cfg.ore.real("poisson_ratio"))},
          {"restitution", num(ctx.cfg.ore.real("restitution"))},
          {"friction", num(ctx.cfg.ore.real("friction"))}};
}

// Writes the mill and the injection into r.work and runs the deck there.
void run_transport_deck(StageContext& ctx, TransportRun& r) {
  const auto& d = ctx.cfg.doc;
  fs::remove_all(r.work);
  fs::create_directories(r.work);
  const geometry::StlSet stl = geometry::write_stl_set(r.g, r.work / "stl");
  const post::FlowField field = post::read_flow_field(r.field_file);
  std::vector<std::string> notes;
  // The sizes take turns (lump i is of size i mod m), so each size enters over
  // m x injection.duration at the rate of a run of one size.
  const auto m = static_cast<long>(r.sizes.size());
  r.lumps = injection_schedule(r.g, field, m * d.integer("injection.n_lumps"), r.diameter,
                               static_cast<double>(m) * d.real("injection.duration"), notes);
  for (std::size_t i = 0; i < r.lumps.size(); ++i)
    r.lumps[i].diameter = r.sizes[i % r.sizes.size()].diameter;
  for (const auto& s : notes) ctx.progress.warn(fmt::format("transport {}: {}", r.label, s));
  jobs::atomic_write(r.work / "insert.in", insert_commands(r.lumps, r.density, r.dt));
  engine::DeckRun run;
  run.deck = ctx.cfg.project_dir / "liggghts_inputs" / "transport.in.tmpl";
  run.workdir = r.work;
  run.np = ctx.opts.np;
  run.job = "transport/" + r.label;
  run.vars = transport_vars(ctx, r, stl);
  r.wall_seconds = engine::run_deck(ctx.runner, run, ctx.progress, r.label).seconds;
  r.end = read_end(r.work / "end.txt");
}

// The run's impacts (labelled by part), contact ends, trajectories and their
// statistics.
struct TransportResults {
  std::vector<double> insert_time;
  std::vector<post::ImpactRecord> records;
  std::vector<post::ContactEnd> ends;
  post::Trajectories traj;
  post::TransportStats st;
};

TransportResults read_transport_results(const TransportRun& r, double sliding_threshold) {
  TransportResults t;
  for (const auto& l : r.lumps) t.insert_time.push_back(l.t);
  t.records = post::ReadImpactsCsv((r.work / "impacts.csv").string());
  t.ends = post::ReadContactEndsCsv((r.work / "contact_ends.csv").string());
  t.traj = post::ReadTrajectoryDump((r.work / "traj.dump").string(), r.dt);
  post::MillShape shape;
  shape.height = r.g.height;
  shape.width = r.g.width;
  shape.depth = r.g.depth;
  shape.axis_x = r.g.axis_x;
  shape.axis_y = r.g.axis_height;
  shape.hub_radius = r.g.hub_radius();
  shape.tip_radius = r.g.tip_radius();
  post::LabelImpacts(t.records, shape, sliding_threshold);
  t.st = post::ComputeTransportStats(t.records, t.insert_time, t.ends);
  return t;
}

// A run of m lump sizes: lump i (atom ID i + 1, in insertion order) is of
// size i mod m and the (i / m + 1)-th lump of its size.
struct SizeOfId {
  std::size_t m = 1;
  long long n = 0;  // lumps in the run
  std::size_t size(long long id) const { return static_cast<std::size_t>((id - 1) % static_cast<long long>(m)); }
  long long local(long long id) const { return (id - 1) / static_cast<long long>(m) + 1; }
  void check(long long id, const std::string& what) const {
    if (id < 1 || id > n)
      throw std::runtime_error(fmt::format(
          "{}: particle id {} is not one of the run's {} lumps (IDs 1..{} in insertion order)",
          what, id, n, n));
  }
};

// The lumps of size s of a run of several: its records, contact ends and
// trajectories with their IDs renumbered 1..n_s in insertion order, and
// their statistics.
TransportResults results_of_size(const TransportResults& all, const SizeOfId& ids,
                                 std::size_t s) {
  TransportResults t;
  for (std::size_t i = s; i < all.insert_time.size(); i += ids.m)
    t.insert_time.push_back(all.insert_time[i]);
  for (const auto& rec : all.records) {
    ids.check(rec.particle_id, "impacts.csv");
    if (ids.size(rec.particle_id) != s) continue;
    t.records.push_back(rec);
    t.records.back().particle_id = ids.local(rec.particle_id);
  }
  for (const auto& e : all.ends) {
    ids.check(e.particle_id, "contact_ends.csv");
    if (ids.size(e.particle_id) != s) continue;
    t.ends.push_back(e);
    t.ends.back().particle_id = ids.local(e.particle_id);
  }
  const post::Trajectories& a = all.traj;
  for (std::size_t k = 0; k < a.particle_id.size(); ++k) {
    const long long id = a.particle_id[k];
    ids.check(id, "traj.dump");
    if (ids.size(id) != s) continue;
    t.traj.time_s.push_back(a.time_s[k]);
    t.traj.particle_id.push_back(ids.local(id));
    t.traj.position.push_back(a.position[k]);
    t.traj.velocity.push_back(a.velocity[k]);
  }
  t.st = post::ComputeTransportStats(t.records, t.insert_time, t.ends);
  return t;
}

// The atom IDs the outlet counted (fix massflow/mesh's file: exits.txt, or
// exits.txt.<rank> per MPI rank), one per lump that left.
std::vector<long long> read_exit_ids(const fs::path& work) {
  std::vector<long long> ids;
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(work)) {
    const std::string n = e.path().filename().string();
    if (n == "exits.txt" || n.rfind("exits.txt.", 0) == 0) files.push_back(e.path());
  }
  if (files.empty())
    throw std::runtime_error(fmt::format(
        "{}: missing: the deck wrote no list of the lumps that left (expected `fix massflow/mesh "
        "... file ${{exits_file}}` in liggghts_inputs/transport.in.tmpl)",
        (work / "exits.txt").string()));
  for (const auto& f : files) {
    std::ifstream in(f);
    std::string line;
    while (std::getline(in, line)) {
      if (line.empty() || line[0] == '#') continue;
      std::istringstream ls(line);
      long long id = 0;
      if (!(ls >> id))
        throw std::runtime_error(fmt::format("{}: expected an atom id at the start of '{}'",
                                             f.string(), line));
      ids.push_back(id);
    }
  }
  return ids;
}

// remaining.txt's "size <s> remaining <n>" lines (s = 1..m): the lumps of
// each size left in the mill at the end.
std::vector<long long> read_remaining(const fs::path& file, std::size_t m) {
  std::ifstream in(file);
  if (!in)
    throw std::runtime_error(fmt::format(
        "{}: missing: the deck did not count the lumps left per size (the size_loop at the end "
        "of liggghts_inputs/transport.in.tmpl)",
        file.string()));
  std::vector<long long> n(m, -1);
  std::string word1, word2;
  std::size_t s = 0;
  double count = 0;
  while (in >> word1 >> s >> word2 >> count) {
    if (word1 != "size" || word2 != "remaining" || s < 1 || s > m)
      throw std::runtime_error(fmt::format("{}: expected 'size <1..{}> remaining <n>' lines",
                                           file.string(), m));
    n[s - 1] = std::llround(count);
  }
  for (std::size_t k = 0; k < m; ++k)
    if (n[k] < 0)
      throw std::runtime_error(
          fmt::format("{}: no count for size {} of {}", file.string(), k + 1, m));
  return n;
}

// contact_ends.csv's lines of size s, the particle_id column renumbered.
std::string contact_ends_of_size(const fs::path& file, const SizeOfId& ids, std::size_t s) {
  std::ifstream in(file);
  std::string header, line, out;
  if (!std::getline(in, header)) throw std::runtime_error(file.string() + ": empty");
  // particle_id is the second column (docs/styles/fix_impact_recorder.md).
  if (header.rfind("time_s,particle_id,", 0) != 0)
    throw std::runtime_error(
        fmt::format("{}: expected the header to start with time_s,particle_id, got '{}'",
                    file.string(), header));
  out = header + "\n";
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    const auto a = line.find(','), b = line.find(',', a + 1);
    if (a == std::string::npos || b == std::string::npos)
      throw std::runtime_error(fmt::format("{}: malformed line '{}'", file.string(), line));
    const long long id = std::stoll(line.substr(a + 1, b - a - 1));
    ids.check(id, file.string());
    if (ids.size(id) != s) continue;
    out += line.substr(0, a + 1) + std::to_string(ids.local(id)) + line.substr(b) + "\n";
  }
  return out;
}

// Cross-check (method.md): rim speed, and a ballistic impact speed: the lump
// falls from the inlet to the rotor top (drag neglected) and meets a plate
// moving at omega r_struck across its path.
struct CrossCheck {
  double v_in = 0, v_approach = 0, r_struck = 0, v_rotor = 0, v_ballistic = 0;  // m/s, m
};

CrossCheck cross_check(const TransportRun& r, const post::SurfaceStats& fly) {
  const geometry::MillGeometry& g = r.g;
  CrossCheck c;
  for (const auto& l : r.lumps) c.v_in += -l.v[1] / static_cast<double>(r.lumps.size());
  const double fall = std::max(0.0, g.height - 0.5 * r.diameter - (g.axis_height + g.tip_radius()));
  c.v_approach = std::sqrt(std::max(0.0, c.v_in) * std::max(0.0, c.v_in) + 2 * kG * fall);
  c.r_struck = fly.n > 0 ? fly.axis_distance.mean : g.tip_radius();
  c.v_rotor = r.omega * c.r_struck;
  c.v_ballistic = std::hypot(c.v_approach, c.v_rotor);
  return c;
}

// summary.json's counts of gentle contacts (touch-downs, rolling and chatter
// rather than impacts) and of outliers (a lump struck by the rotor reaches
// at most about twice the rim speed), with a warning for the latter.
void contact_counts(StageContext& ctx, nlohmann::json& j, const TransportRun& r,
                    const TransportResults& t) {
  long long gentle_fly = 0, gentle_wall = 0;
  for (const auto& rec : t.records)
    if (rec.normal_speed_m_s < 1.0) ++(rec.surface == "flywheel" ? gentle_fly : gentle_wall);
  long long outliers = 0;
  for (const auto& rec : t.records)
    if (rec.particle_speed_m_s > 3 * r.omega * r.g.tip_radius()) ++outliers;
  j["n_impacts_above_3x_rim_speed"] = outliers;
  if (outliers > 0)
    ctx.progress.warn(fmt::format(
        "transport {}: {} impacts of lumps faster than 3x the rim speed (numerical: lumps "
        "created overlapping, or a too large injection.timestep)",
        r.label, outliers));
  j["n_flywheel_contacts_below_1m_s"] = gentle_fly;
  j["n_wall_contacts_below_1m_s"] = gentle_wall;
}

// summary.json of the run.
nlohmann::json transport_summary(StageContext& ctx, const TransportRun& r,
                                 const TransportResults& t, const CrossCheck& x,
                                 const nlohmann::json& flow_converged) {
  const auto& d = ctx.cfg.doc;
  const post::TransportStats& st = t.st;
  const post::SurfaceStats& fly = st.surfaces.at("flywheel");
  const post::SurfaceStats& wall = st.surfaces.at("housing");
  const auto& end = r.end;
  nlohmann::json j;
  j["rpm"] = r.rpm;
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
  strike_keys(j, st, d.real("transport.sliding_threshold"));
  j["flow_converged"] = flow_converged;
  j["flow_allow_unconverged"] = d.boolean("flow.allow_unconverged");
  contact_counts(ctx, j, r, t);
  j["impacts_per_particle_mean"] = st.impacts_per_particle_mean;
  j["flywheel_impacts_per_particle_mean"] = st.flywheel_impacts_per_particle_mean;
  j["first_impact_time_mean_s"] = st.first_impact_time_mean_s;
  j["first_impact_time_note"] =
      "time from insertion to the first impact (any surface; sliding contacts are not impacts), "
      "over particles with one";
  j["particles_with_impact"] = st.particles_with_impact;
  j["cross_check"] = {{"rim_speed_m_s", r.omega * r.g.tip_radius()},
                      {"inlet_velocity_down_mean_m_s", x.v_in},
                      {"ballistic_approach_speed_m_s", x.v_approach},
                      {"struck_radius_m", x.r_struck},
                      {"rotor_speed_at_struck_radius_m_s", x.v_rotor},
                      {"ballistic_impact_speed_m_s", x.v_ballistic},
                      {"simulated_approach_speed_mean_m_s", fly.particle_speed.mean}};
  j["timestep_s"] = r.dt;
  j["wall_seconds"] = r.wall_seconds;
  j["units"] = "SI; angles in degrees to the surface plane (90 = normal)";
  return j;
}

// transport.h5's scalars (with units) and mill geometry.
post::TransportMeta transport_meta(const TransportRun& r) {
  const geometry::MillGeometry& g = r.g;
  post::TransportMeta meta;
  meta.scalars = {{"rpm", r.rpm},
                  {"omega", r.omega},
                  {"rim_speed", r.omega * g.tip_radius()},
                  {"timestep", r.dt},
                  {"lump_diameter", r.diameter},
                  {"lump_density", r.density},
                  {"end_time", r.end[0]}};
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
  return meta;
}

// Outputs: transport/<label>/{transport.h5, impacts.csv, contact_ends.csv,
// plots/, summary.json}, each file complete or absent.
void write_transport_outputs(StageContext& ctx, const TransportRun& r, const TransportResults& t,
                             const std::string& contact_ends_csv, const nlohmann::json& summary,
                             const fs::path& out) {
  fs::create_directories(out);
  for (const char* f : {"summary.json", "impacts.csv", "contact_ends.csv", "transport.h5"})
    fs::remove(out / f);
  post::WriteTransportH5((out / "transport.h5").string(), t.records, t.st, t.insert_time, t.traj,
                         transport_meta(r), t.ends);
  post::WriteImpactsCsv((out / "impacts.csv").string(), t.records);
  jobs::atomic_write(out / "contact_ends.csv", contact_ends_csv);
  engine::run_python(ctx.runner, ctx.cfg.project_dir / "postprocess" / "plot_transport.py",
                     {"--h5", (out / "transport.h5").string(), "--out", (out / "plots").string()},
                     out / "plots.log", "transport/" + r.label + "/plots");
  jobs::atomic_write(out / "summary.json", summary.dump(2) + "\n");
}

// The run in four lines: impacts, strikes, the cross-check, the outputs.
void log_transport(StageContext& ctx, const TransportRun& r, const TransportResults& t,
                   const CrossCheck& x, const fs::path& out) {
  const post::TransportStats& st = t.st;
  const post::SurfaceStats& fly = st.surfaces.at("flywheel");
  const post::SurfaceStats& wall = st.surfaces.at("housing");
  const std::string& label = r.label;
  ctx.progress.info(fmt::format(
      "[transport] {}: {} lumps, {} exited, {} flywheel impacts ({:.2f} per lump): speed {:.1f} +- "
      "{:.1f} m/s, "
      "normal {:.1f} m/s, angle {:.1f} deg; {} wall impacts; {} sliding contacts (below {:g} m/s "
      "normal); first impact after {:.3f} s [{:.1f} s]",
      label, st.n_particles, std::llround(r.end[2]), fly.n, st.flywheel_impacts_per_particle_mean,
      fly.speed.mean, fly.speed.std, fly.normal_speed.mean, fly.angle.mean, wall.n,
      st.sliding_contacts, ctx.cfg.doc.real("transport.sliding_threshold"),
      st.first_impact_time_mean_s, r.wall_seconds));
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
      label, r.omega * r.g.tip_radius(), x.v_ballistic, x.v_approach, x.v_rotor, x.r_struck,
      fly.speed.mean));
  ctx.progress.info(fmt::format(
      "[transport] results: {}/{{impacts.csv, contact_ends.csv, transport.h5, summary.json, "
      "plots/*.png}}",
      out.string()));
}

}  // namespace

// Runs the lumps through the mill at one rotor speed and writes the results
// into transport/<label>/, and with a feed each class's lumps' into
// transport/class_<k>/<label>/ (each file complete or absent).
void TransportStage::run_job(StageContext& ctx, const JobSpec& job, const fs::path& job_dir) {
  const auto& d = ctx.cfg.doc;
  TransportRun r;
  r.label = job.label;
  r.rpm = job.inputs.at("rotor.rpm").get<double>();
  r.field_file = sampled_field(ctx, rpm_label(r.rpm), r.rpm);
  const nlohmann::json flow_converged = check_flow_converged(ctx, rpm_label(r.rpm));
  // injection.time_limit > duration and the time step: checked with the case.
  r.g = geometry::MillGeometry::from_config(d);
  r.omega = r.rpm * 2 * kPi / 60.0;
  // injection.lump_diameter, then the feed classes' representative sizes.
  r.sizes.push_back({job.inputs.at("injection.lump_diameter").get<double>(), std::nullopt});
  for (const auto& c : job.inputs.value("feed_classes", nlohmann::json::array()))
    r.sizes.push_back({c.at("diameter_m").get<double>(), c.at("class").get<std::size_t>()});
  r.diameter = 0;
  for (const auto& z : r.sizes) r.diameter = std::max(r.diameter, z.diameter);
  r.dt = d.real("injection.timestep");
  r.density = ctx.cfg.ore.real("density");
  r.work = job_dir / "run";

  run_transport_deck(ctx, r);
  const double threshold = d.real("transport.sliding_threshold");
  const TransportResults all = read_transport_results(r, threshold);
  if (r.sizes.size() == 1) {
    const CrossCheck x = cross_check(r, all.st.surfaces.at("flywheel"));
    const nlohmann::json summary = transport_summary(ctx, r, all, x, flow_converged);
    const fs::path out = output_dir(ctx, job);
    std::ifstream in(r.work / "contact_ends.csv");
    std::stringstream ends;
    ends << in.rdbuf();
    write_transport_outputs(ctx, r, all, ends.str(), summary, out);
    log_transport(ctx, r, all, x, out);
    return;
  }

  // Several sizes in one run: each size's lumps, outputs and statistics apart.
  const SizeOfId ids{r.sizes.size(), static_cast<long long>(r.lumps.size())};
  // Per size: the lumps the outlet listed (exits.txt) and those left in the
  // mill at the end (remaining.txt); the rest were lost elsewhere.
  std::vector<long long> exited(r.sizes.size(), 0);
  for (long long id : read_exit_ids(r.work)) {
    ids.check(id, (r.work / "exits.txt").string());
    ++exited[ids.size(id)];
  }
  const std::vector<long long> remaining = read_remaining(r.work / "remaining.txt", r.sizes.size());
  const long long lost = static_cast<long long>(r.lumps.size()) - std::llround(r.end[1]) -
                         std::llround(r.end[2]);
  if (std::accumulate(exited.begin(), exited.end(), 0LL) != std::llround(r.end[2]) ||
      std::accumulate(remaining.begin(), remaining.end(), 0LL) != std::llround(r.end[1]))
    throw std::runtime_error(fmt::format(
        "{}: the lumps that left per size (exits.txt: {}) or remain (remaining.txt: {}) do not "
        "add up to the run's counts in end.txt (exited {}, remaining {})",
        r.work.string(), fmt::join(exited, " "), fmt::join(remaining, " "), std::llround(r.end[2]),
        std::llround(r.end[1])));
  nlohmann::json run_sizes = nlohmann::json::array();
  for (const auto& z : r.sizes)
    run_sizes.push_back({{"lump_diameter_mm", 1e3 * z.diameter},
                         {"feed_class", z.feed_class ? nlohmann::json(*z.feed_class) : nullptr},
                         {"n_lumps", static_cast<long long>(r.lumps.size() / r.sizes.size())}});
  for (std::size_t s = 0; s < r.sizes.size(); ++s) {
    TransportRun v = r;  // the run as seen by this size's lumps
    v.diameter = r.sizes[s].diameter;
    v.lumps.clear();
    for (std::size_t i = s; i < r.lumps.size(); i += r.sizes.size()) v.lumps.push_back(r.lumps[i]);
    v.end[2] = static_cast<double>(exited[s]);
    v.end[1] = static_cast<double>(remaining[s]);
    if (r.sizes[s].feed_class) v.label = class_label(r.rpm, *r.sizes[s].feed_class);
    const TransportResults t = results_of_size(all, ids, s);
    const CrossCheck x = cross_check(v, t.st.surfaces.at("flywheel"));
    nlohmann::json summary = transport_summary(ctx, v, t, x, flow_converged);
    summary["shared_run"] = {
        {"job", "transport/jobs/" + r.label},
        {"sizes", run_sizes},
        {"n_lumps", static_cast<long long>(r.lumps.size())},
        {"n_remaining", std::llround(r.end[1])},
        {"n_lost_elsewhere", lost},
        {"note",
         "the lumps of every size went through the mill in one run, taking turns at the inlet "
         "(lump i of size i mod m), each size over m x injection.duration; they meet one "
         "another as fed lumps do. This file's figures are this size's lumps' (IDs renumbered "
         "1..n in insertion order); end_time_s, drag_masked_particle_steps and wall_seconds "
         "are the run's; n_exited and n_remaining are this size's (the outlet's list, "
         "exits.txt, and the deck's count at the end, remaining.txt)"}};
    if (r.sizes[s].feed_class) summary["feed_class"] = class_json(ctx, *r.sizes[s].feed_class);
    const fs::path out = transport_dir(ctx.run_dir, r.rpm, r.sizes[s].feed_class);
    write_transport_outputs(ctx, v, t, contact_ends_of_size(r.work / "contact_ends.csv", ids, s),
                            summary, out);
    log_transport(ctx, v, t, x, out);
  }
}

namespace {

// The impact statistics of a class run that feed_classes.json and .csv keep
// (its summary.json's keys).
const std::vector<std::string>& class_stat_keys() {
  static const std::vector<std::string> k = {"n_particles",
                                             "n_exited",
                                             "n_flywheel_impacts",
                                             "flywheel_impacts_per_particle_mean",
                                             "flywheel_impact_speed_mean_m_s",
                                             "flywheel_impact_speed_std_m_s",
                                             "flywheel_normal_speed_mean_m_s",
                                             "flywheel_angle_mean_deg",
                                             "n_flywheel_first_strikes",
                                             "flywheel_first_strike_speed_mean_m_s",
                                             "n_wall_impacts",
                                             "wall_impact_speed_mean_m_s",
                                             "first_impact_time_mean_s"};
  return k;
}

}  // namespace

// With a feed: transport/feed_classes.json and .csv, the impact statistics
// of each feed class per rotor speed from its runs' summary.json, and why a
// class has no run.
void TransportStage::finalize(StageContext& ctx, const std::vector<JobSpec>& jobs) {
  if (!ctx.cfg.feed) return;
  std::map<std::size_t, nlohmann::json> speeds;
  std::string csv = "rpm,class,lower_mm,upper_mm,lump_diameter_mm";
  for (const auto& k : class_stat_keys()) csv += "," + k;
  csv += "\n";
  std::size_t class_runs = 0;
  for (const auto& job : jobs) {
    const double rpm = job.inputs.at("rotor.rpm").get<double>();
    for (std::size_t k : feed_classes_of(job)) {
      ++class_runs;
      const fs::path f = transport_dir(ctx.run_dir, rpm, k) / "summary.json";
      std::ifstream in(f);
      const auto s = nlohmann::json::parse(in);
      const nlohmann::json c = class_json(ctx, k);
      nlohmann::json e = {{"rpm", rpm}, {"summary", fs::relative(f, ctx.run_dir).string()}};
      csv += fmt::format("{:g},{},{:g},{:g},{:.6g}", rpm, k, c.at("lower_mm").get<double>(),
                         c.at("upper_mm").get<double>(), c.at("lump_diameter_mm").get<double>());
      for (const auto& key : class_stat_keys()) {
        const nlohmann::json v = s.value(key, nlohmann::json(nullptr));
        e[key] = v;
        csv += "," + (v.is_number() ? fmt::format("{:.9g}", v.get<double>()) : std::string());
      }
      csv += "\n";
      speeds[k].push_back(e);
    }
  }
  nlohmann::json classes = nlohmann::json::array();
  for (const auto& c : config::plan_feed_classes(ctx.cfg.doc, *ctx.cfg.feed)) {
    nlohmann::json e = class_json(ctx, c.cls);
    e["transport"] = c.transport;
    if (!c.without_runs.empty() && !c.transport) e["without_runs"] = c.without_runs;
    e["rotor_speeds"] = speeds.count(c.cls) ? speeds[c.cls] : nlohmann::json::array();
    classes.push_back(e);
  }
  const nlohmann::json j = {
      {"sizes_mm", ctx.cfg.feed->sizes_mm},
      {"classes", classes},
      {"definitions",
       {{"class", "feed.sizes_mm's classes, coarsest first (class 0), each [lower, upper)"},
        {"lump_diameter_mm",
         "the class's representative size (geometric mean of its edges), its lumps' diameter"},
        {"rotor_speeds",
         "per rotor speed, the summary.json figures of the class's lumps (SI units), which went "
         "through the mill in the run of that speed with the other sizes' lumps"}}}};
  jobs::atomic_write(ctx.stage_dir / "feed_classes.json", j.dump(2) + "\n");
  jobs::atomic_write(ctx.stage_dir / "feed_classes.csv", csv);
  ctx.progress.info(
      fmt::format("[transport] feed classes: {}/feed_classes.{{json,csv}} ({} class x rotor "
                  "speed statistics)",
                  ctx.stage_dir.string(), class_runs));
}

std::string TransportStage::damaged_merged_outputs(const StageContext& ctx,
                                                   const std::vector<JobSpec>&) const {
  if (!ctx.cfg.feed) return "";
  return jobs::check_json(ctx.stage_dir / "feed_classes.json", true);
}

}  // namespace mill
