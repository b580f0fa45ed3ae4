// The closed circuit per rotor speed (docs/population_balance.md, "The
// circuit per rotor speed").
#include "stages/breakage/circuit.h"

#include <fmt/format.h>

#include <cmath>

#include "engine/runner.h"
#include "jobs/job_store.h"
#include "lump/packing.h"
#include "postprocess/circuit_bootstrap.h"
#include "postprocess/fragments.h"
#include "progress.h"
#include "stages/breakage/summaries.h"

namespace mill::breakage {

namespace {

// A vector given coarsest first, finest first (as the case's sieves).
std::vector<double> ascending(const std::vector<double>& coarsest_first) {
  return {coarsest_first.rbegin(), coarsest_first.rend()};
}

// [low, high] of a percentile interval; +inf (not met, no steady state) as null.
nlohmann::json interval_json(const post::Interval& v) {
  const auto one = [](double x) {
    return std::isinf(x) ? nlohmann::json(nullptr) : nlohmann::json(x);
  };
  return nlohmann::json::array({one(v.low), one(v.high)});
}

// With feed.target_p80_mm: the lowest rotor speed whose closed-circuit P80
// meets it (post::LowestSpeedMeetingP80) as circuit.json's "decision", with
// its kWh/t (post::EnergyAtDecision) and the band of the lumps' bootstrap.
nlohmann::json decision_json(const config::Feed& feed, const nlohmann::json& speeds,
                             const std::map<double, post::CircuitEnergy>& energy, bool with_gas,
                             const post::CircuitBand& band) {
  std::vector<post::SpeedForP80> points;
  for (const auto& e : speeds) {
    double p80 = HUGE_VAL;  // no steady state: never meets the target
    if (e.at("steady").get<bool>())
      p80 = e.at("p80_mm").is_number() ? e.at("p80_mm").get<double>() : feed.sizes_mm.front();
    points.push_back({e.at("rpm").get<double>(), p80});
  }
  const post::TargetDecision d = post::LowestSpeedMeetingP80(points, *feed.target_p80_mm);
  const post::DecisionEnergy de = post::EnergyAtDecision(d, energy, with_gas);
  using K = post::TargetDecision::Kind;
  const char* kind = d.kind == K::crossed         ? "crossed"
                     : d.kind == K::met_at_lowest ? "met_at_lowest"
                                                  : "not_met";
  nlohmann::json b = {{"defined", band.defined}};
  if (!band.defined) {
    b["reason"] = band.reason;
  } else {
    b["rpm"] = interval_json(band.rpm);
    b["specific_energy_kWh_t"] = band.kWh_t ? interval_json(*band.kWh_t) : nlohmann::json(nullptr);
    b["met_draws"] = band.met_draws;
    b["energy_draws"] = band.kWh_t_draws;
  }
  b["sentence"] = post::BandSentence(band);
  nlohmann::json j = {
      {"target_p80_mm", *feed.target_p80_mm},
      {"kind", kind},
      {"rpm", d.kind == K::not_met ? nlohmann::json(nullptr) : nlohmann::json(d.rpm)},
      {"met_at_every_faster_speed", d.met_above},
      {"specific_energy_kWh_t", de.kWh_t ? nlohmann::json(*de.kWh_t) : nlohmann::json(nullptr)},
      {"energy_ore_only", de.ore_only},
      {"band", b},
      {"sentence",
       post::DecisionSentence(d, de.kWh_t, de.ore_only) + "; " + b["sentence"].get<std::string>()},
      {"definition",
       "the lowest rotor speed whose closed-circuit product P80 is at or below "
       "the target, interpolated linearly in rpm between the two simulated "
       "speeds where P80 crosses it; a P80 finer than the finest sieve counts as "
       "that sieve, a speed with no steady state as not met. specific_energy_kWh_t: the "
       "speeds' energy.specific_energy_kWh_t interpolated with the same weights (the "
       "speed's own when not interpolated); the ore's alone (energy_ore_only) unless every "
       "simulated speed has a gas flow run. band: the bootstrap's percentile interval "
       "(see bootstrap)"}};
  if (d.kind == K::crossed) {
    j["between_rpm"] = {d.below_rpm, d.above_rpm};
    j["interpolated"] = d.interpolated;
  }
  return j;
}

// The lumps of every rotor speed for the bootstrap, with their gas power.
std::vector<post::SpeedLumps> speed_lumps(const MeasuringRuns& runs,
                                          const std::map<double, std::optional<double>>& gas_W) {
  std::vector<post::SpeedLumps> out;
  for (const auto& [rpm, by_class] : runs) {
    post::SpeedLumps s;
    s.rpm = rpm;
    for (const auto& [j, r] : by_class) s.by_class[j] = r.lumps;
    if (auto it = gas_W.find(rpm); it != gas_W.end()) s.gas_W = it->second;
    out.push_back(std::move(s));
  }
  return out;
}

nlohmann::json bootstrap_json(const post::CircuitBand& band) {
  nlohmann::json j = {
      {"draws", band.draws},
      {"seed", band.seed},
      {"percentiles", {band.low_percent, band.high_percent}},
      {"defined", band.defined},
      {"definition",
       "a bootstrap over the in-mill lumps (Efron & Tibshirani 1993, percentile interval): per "
       "draw, at each rotor speed, each measured class's lumps resampled with replacement "
       "(std::mt19937_64 with the seed), the breakage matrix and the beater work per kg "
       "rebuilt from the drawn lumps, the circuit re-solved and the decision redone; the band "
       "is the percentiles over the draws (linear between order statistics). null: the draws "
       "at that percentile did not meet the target or had no steady state"}};
  if (!band.defined) j["reason"] = band.reason;
  return j;
}

// P80 against rpm with the target and the decision
// (postprocess/plot_circuit.py, reading circuit.json only).
void plot_circuit(StageContext& ctx) {
  const std::filesystem::path dir = ctx.stage_dir;
  engine::run_python(
      ctx.runner, ctx.cfg.project_dir / "postprocess" / "plot_circuit.py",
      {"--circuit", (dir / "circuit.json").string(), "--out", (dir / "plots").string()},
      dir / "plot_circuit.log", "breakage/circuit plot");
}

std::string mm_or_finer(const nlohmann::json& v, double finest) {
  return v.is_number() ? fmt::format("{:.3g} mm", v.get<double>())
                       : fmt::format("< {:g} mm", finest);
}

}  // namespace

ElementPieces element_piece_mm(double lump_mm, long elements, double spread) {
  // Element class k has the mass share (1 + s_k)^3 / (c n) of the lump, c the
  // mean of the cubes (mill::mean_cube_factor): its piece is lump_mm times
  // the cube root of that.
  const double per = lump_mm / std::cbrt(mean_cube_factor(spread) * static_cast<double>(elements));
  return {per * class_factor(0, spread), per * std::cbrt(mean_cube_factor(spread)),
          per * class_factor(4, spread)};
}

namespace {

// circuit.json's "resolution": the element pieces of every measured class's
// lumps (the same lumps at every speed: the first speed's).
nlohmann::json resolution_json(const MeasuringRuns& runs, double spread) {
  nlohmann::json classes = nlohmann::json::array();
  double lo = INFINITY, hi = 0;
  if (!runs.empty())
    for (const auto& [cls, r] : runs.begin()->second) {
      if (r.elements <= 0 || !(r.lump_mm > 0)) continue;
      const ElementPieces e = element_piece_mm(r.lump_mm, r.elements, spread);
      classes.push_back({{"class", cls},
                         {"lump_mm", r.lump_mm},
                         {"lump_elements", r.elements},
                         {"smallest_mm", e.smallest_mm},
                         {"mean_mm", e.mean_mm},
                         {"largest_mm", e.largest_mm}});
      lo = std::min(lo, e.smallest_mm);
      hi = std::max(hi, e.largest_mm);
    }
  if (classes.empty()) return nullptr;
  return {{"element_piece_mm", {{"smallest", lo}, {"largest", hi}}},
          {"classes", classes},
          {"p80_bound_factor", kElementBoundP80Factor},
          {"definition",
           "a piece of one element cannot break further: element_piece_mm spans the sizes such a piece "
           "takes (lump diameter x (element mass / lump mass)^(1/3), the smallest to the largest "
           "radius class of the measured classes' lumps). A shattered lump's mass sits there, so a "
           "P80 below p80_bound_factor x the largest is set by the element size, not by the rock "
           "(rotor_speeds[].p80_set_by_elements; bench/README.md, \"A class lump at the element "
           "cap\")"}};
}

}  // namespace

void write_circuit(StageContext& ctx, const std::map<double, post::AssembledMatrix>& matrices,
                   const MeasuringRuns& runs,
                   const std::map<double, std::optional<double>>& gas_W) {
  const config::Feed& feed = ctx.cfg.feed.value();
  const post::SizeClasses classes = post::SizeClassesFromSieves(feed.sizes_mm);
  const std::size_t n = classes.size();
  const std::vector<double> c = post::SharpCutClassification(classes, feed.cut_size_mm);
  std::vector<double> f(n);
  for (std::size_t i = 0; i < n; ++i) f[i] = feed.rate_tph * feed.mass_fractions[n - 1 - i];
  nlohmann::json speeds = nlohmann::json::array();
  std::map<double, post::CircuitEnergy> energy;  // the steady speeds'
  std::string csv =
      "rpm,class,lower_mm,upper_mm,feed_t_h,mill_input_t_h,returned_t_h,product_t_h,"
      "product_passing_percent,classification_returned\n";
  for (const auto& [rpm, m] : matrices) {
    nlohmann::json e = {{"rpm", rpm}};
    post::CircuitState s;
    try {
      s = post::SolveCircuit(classes, m.b, c, f);
    } catch (const post::PostError& err) {
      e["steady"] = false;
      e["problem"] = err.what();
      speeds.push_back(e);
      ctx.progress.warn(fmt::format("[breakage] closed circuit at {:g} rpm: no steady state: {}",
                                    rpm, err.what()));
      continue;
    }
    if (!(s.mass_balance_residual <= kCircuitResidualLimit))
      throw std::runtime_error(fmt::format(
          "closed circuit at {:g} rpm: mass-balance residual {:.3g} of the feed, above {:g}: the "
          "balance does not close (breakage/breakage_matrix.json holds its matrix)",
          rpm, s.mass_balance_residual, kCircuitResidualLimit));
    std::vector<double> fraction = ascending(s.product);
    for (double& x : fraction) x /= s.product_total;
    const nlohmann::json pass = passing_json(feed.sizes_mm, fraction);
    e["steady"] = true;
    e["product_t_h"] = ascending(s.product);
    e["product_total_t_h"] = s.product_total;
    e["mill_input_t_h"] = ascending(s.mill_input);
    e["returned_t_h"] = ascending(s.returned);
    e["passing_percent"] = pass.at("passing_percent");
    e["p50_mm"] = pass.at("p50_mm");
    e["p80_mm"] = pass.at("p80_mm");
    e["circulating_load"] = s.circulating_load;
    e["mass_balance_residual"] = s.mass_balance_residual;
    const std::map<std::size_t, ClassRuns>& by_class = runs.at(rpm);
    const std::vector<post::ClassWork> work = class_work(classes, by_class);
    const std::optional<double> gas = gas_W.count(rpm) ? gas_W.at(rpm) : std::nullopt;
    const post::CircuitEnergy en = post::MillEnergyPerTonne(s.mill_input, work, gas, s.feed_total);
    energy[rpm] = en;
    e["energy"] = circuit_energy_json(classes, en, work, s.mill_input, by_class);
    ctx.progress.info(fmt::format(
        "[breakage] energy at {:g} rpm: {:.3g} kWh/t of feed ({}ore {:.3g} kW over {:.3g} "
        "passes per tonne at {:g} t/h)",
        rpm, en.total_kWh_t,
        gas ? fmt::format("gas shaft {:.3g} kW + ", *gas / 1000) : std::string("no flow report: "),
        en.ore_W / 1000, en.passes_per_tonne, feed.rate_tph));
    speeds.push_back(e);
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t i = n - 1 - k;  // the class of sieve k
      csv += fmt::format("{:g},{},{:g},{:g},{:.9g},{:.9g},{:.9g},{:.9g},{:.6g},{:.6g}\n", rpm, i,
                         classes.lower_mm(i), classes.upper_mm[i], f[i], s.mill_input[i],
                         s.returned[i], s.product[i], pass.at("passing_percent")[k].get<double>(),
                         c[i]);
    }
    ctx.progress.info(fmt::format(
        "[breakage] closed circuit at {:g} rpm: product P80 {}, P50 {}, circulating load {:.3g} "
        "t per t of feed, mass-balance residual {:.2g}",
        rpm, mm_or_finer(e["p80_mm"], feed.sizes_mm.front()),
        mm_or_finer(e["p50_mm"], feed.sizes_mm.front()), s.circulating_load,
        s.mass_balance_residual));
  }
  // The finest size the lumps resolve, and which P80 it sets.
  const nlohmann::json resolution = resolution_json(runs, ctx.cfg.doc.real("lump.radius_spread"));
  const double largest_piece =
      resolution.is_null() ? 0.0 : resolution.at("element_piece_mm").at("largest").get<double>();
  for (auto& e : speeds)
    if (largest_piece > 0 && e.contains("p80_mm") && e.at("p80_mm").is_number()) {
      e["p80_set_by_elements"] = e.at("p80_mm").get<double>() < kElementBoundP80Factor * largest_piece;
      if (e["p80_set_by_elements"].get<bool>())
        ctx.progress.warn(fmt::format(
            "[breakage] closed circuit at {:g} rpm: P80 {:.3g} mm is below {:g} x the largest element's "
            "piece ({:.3g} mm): the product's fine end is the elements' size, not the rock's "
            "(bench/README.md, \"A class lump at the element cap\")",
            e.at("rpm").get<double>(), e.at("p80_mm").get<double>(), kElementBoundP80Factor, largest_piece));
    }
  // The band the lumps give: the bootstrap over each class's lumps.
  const std::vector<post::SpeedLumps> lumps = speed_lumps(runs, gas_W);
  bool with_gas = true;
  for (const auto& sl : lumps) with_gas = with_gas && sl.gas_W.has_value();
  const post::CircuitBand band = post::BootstrapCircuit({classes, c, f, feed.target_p80_mm}, lumps);
  for (const post::SpeedBand& sb : band.speeds)
    for (auto& e : speeds) {
      if (e.at("rpm").get<double>() != sb.rpm) continue;
      e["band"] = {
          {"p80_mm", interval_json(sb.p80_mm)},
          {"specific_energy_kWh_t", sb.kWh_t ? interval_json(*sb.kWh_t) : nlohmann::json(nullptr)},
          {"steady_draws", sb.steady_draws}};
    }
  ctx.progress.info("[breakage] band of the lumps: " + post::BandSentence(band));
  nlohmann::json j = {
      {"feed",
       {{"sizes_mm", feed.sizes_mm},
        {"mass_fractions", feed.mass_fractions},
        {"rate_t_h", feed.rate_tph},
        {"cut_size_mm", feed.cut_size_mm},
        {"target_p80_mm",
         feed.target_p80_mm ? nlohmann::json(*feed.target_p80_mm) : nlohmann::json(nullptr)}}},
      {"sieves_mm", feed.sizes_mm},
      {"classification_returned", ascending(c)},
      {"rotor_speeds", speeds},
      {"bootstrap", bootstrap_json(band)},
      {"resolution", resolution},
      {"units",
       {{"*_t_h", "t/h"},
        {"*_mm", "mm"},
        {"passing_percent", "% of the product's mass passing each sieve of sieves_mm"},
        {"circulating_load", "t returned to the rotor per t of fresh feed"},
        {"mass_balance_residual", "|product - feed| / feed, 1"},
        {"energy.*_kWh_t", "kWh per t of fresh feed"},
        {"energy.*_W", "W"},
        {"energy.classes[].beater_work_J_per_kg", "J per kg of lump"},
        {"energy.passes_per_tonne", "t through the rotor per t of fresh feed"},
        {"band.*", "[10th, 90th percentile] over the bootstrap's draws, in the quantity's unit"}}},
      {"definitions",
       {{"order", "every per-class list follows sieves_mm, finest first"},
        {"steady_state",
         "m = f + C B m, product P = (I - C) B m (Whiten 1974; Austin, Klimpel & Luckie 1984); B "
         "from breakage/breakage_matrix.json, C the sharp cut at feed.cut_size_mm"},
        {"steady", "false when a class above the cut never breaks: no steady state (problem)"}}}};
  if (feed.target_p80_mm && !speeds.empty()) {
    j["decision"] = decision_json(feed, speeds, energy, with_gas, band);
    ctx.progress.info(fmt::format("[breakage] product P80 <= {:g} mm in the closed circuit: {}",
                                  *feed.target_p80_mm,
                                  j["decision"]["sentence"].get<std::string>()));
  }
  jobs::atomic_write(ctx.stage_dir / "circuit.json", j.dump(2) + "\n");
  jobs::atomic_write(ctx.stage_dir / "circuit.csv", csv);
  plot_circuit(ctx);
}

}  // namespace mill::breakage
